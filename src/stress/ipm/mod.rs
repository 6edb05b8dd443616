//! A primal–dual interior-point method (Mehrotra predictor–corrector) for sparse convex QPs of
//! the stress step's shape:
//!
//!   minimise    ½ xᵀ P x + cᵀ x,   P = Σ_k ρ_k a_kᵀ a_k   (rows a_k of `quad`)
//!   subject to  E x = f,   G x ≥ h
//!
//! Each Newton step is solved through the normal matrix P + Cᵀ W C, C = [E; G], with
//! W = 1 / (s/z + δ) on inequality rows and 1 / δ on equality rows: one sparse positive
//! definite factorisation whose symbolic analysis (fill-reducing ordering, supernodes) is
//! done once, since only W changes. δ caps the weights (their rounding would otherwise swamp
//! the small curvatures) and iterative refinement against the exact augmented system removes
//! its effect. In weight space every row a_k and c_i touches a vertex's one-ring, so the
//! matrix has the two-ring pattern of the mesh: much smaller than a generic conic solver's
//! KKT system (docs/method.md §8).
//!
//! The unknowns are relabelled once in a fill-reducing order (AMD's, or beyond 40k unknowns a
//! nested dissection by their plan positions: `ordering`), so that no factorisation permutes
//! the matrix again; large factors are factored and solved on two threads (`factorise`,
//! `supernodal`). Gondzio's centrality correctors lengthen steps that a few
//! products s_i z_i would otherwise cut short; they reuse the factor with coarse solves. Near
//! the optimum the active set is solved for directly ("polishing"): with an objective that is
//! nearly zero at the optimum, the gap alone would creep towards the tolerance in rounding.
//!
//! The method has no infeasibility certificates: it reports failure and the caller falls back
//! to clarabel, which decides.

use super::sparse::Csr;

mod dense;
mod factorise;
mod gmres;
mod graph;
mod kkt;
mod newton;
mod ordering;
mod pattern;
mod polish;
mod row_groups;
mod supernodal;
use kkt::{Kkt, Progress};
use newton::{FactorSpace, Newton, REGULARISATION};
pub use pattern::PatternCache;
use pattern::{relabel_columns, relabel_vector, stacked, Normal};
use polish::{active_guess, polish, Corrections, Point, PolishFailure, Polished, INEXACT_RETRY};
pub use row_groups::RowGroups;

/// A QP in the form above.
pub struct Qp<'a> {
    pub quad: &'a Csr,
    pub quad_weight: &'a [f64],
    pub c: &'a [f64],
    /// Constant added to ½ xᵀPx + cᵀx so that the objective is the true one (for the
    /// relative gap).
    pub constant: f64,
    pub eq: &'a Csr,
    pub f: &'a [f64],
    pub ineq: &'a Csr,
    pub h: &'a [f64],
    /// Inequality rows known to be dependent when all of a group are active (see
    /// `RowGroups`); empty when none are known.
    pub groups: &'a RowGroups,
    /// Plan position of each unknown, for the nested-dissection ordering of large QPs
    /// (`ordering`); None: AMD's order at every size.
    pub positions: Option<&'a [[f64; 2]]>,
    /// The caller's natural unit of the inequality rows' slacks, in which the starting point
    /// is built (see `caller_units`); None: the median row scale.
    pub slack_unit: Option<f64>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IpmStatus {
    Solved,
    /// The method stopped (iteration limit, no progress or numerical trouble) at a point that
    /// meets the tolerances relaxed by `Tolerances::almost`.
    AlmostSolved,
    /// The iteration limit was reached, or beyond it stopped making progress (see
    /// `Progress`), short of even the relaxed tolerances.
    MaxIterations,
    /// Factorisation failed or the iterates diverged (typically an infeasible or degenerate
    /// problem).
    NumericalError,
}

pub struct IpmOutput {
    pub x: Vec<f64>,
    pub status: IpmStatus,
    pub iterations: u32,
    /// Per inequality row, whether it is active at `x` (empty unless solved).
    pub active: Vec<bool>,
    /// The multipliers of the equality and of the inequality rows at `x` (empty unless
    /// solved).
    pub lambda: Vec<f64>,
    pub z: Vec<f64>,
}

impl IpmOutput {
    /// An answer without multipliers or active set (not solved).
    fn unsolved(x: Vec<f64>, status: IpmStatus, iterations: u32) -> IpmOutput {
        IpmOutput {
            x,
            status,
            iterations,
            active: Vec::new(),
            lambda: Vec::new(),
            z: Vec::new(),
        }
    }

    fn polished(p: Polished, iterations: u32) -> IpmOutput {
        IpmOutput {
            x: p.x,
            status: IpmStatus::Solved,
            iterations,
            active: p.active,
            lambda: p.lambda,
            z: p.z,
        }
    }
}

/// Tolerances: the gap sᵀz must fall below `gap_abs + gap_rel |objective|`, the primal
/// residuals below `feas` and the dual one below `dual_feas`, each relative to its data.
#[derive(Debug, Clone, Copy)]
pub struct Tolerances {
    pub gap_abs: f64,
    pub gap_rel: f64,
    pub feas: f64,
    /// The same for the dual residual P x + c − Eᵀλ − Gᵀz, or its rounding floor when that
    /// is larger (see `for_size` and `DUAL_ROUNDING`).
    pub dual_feas: f64,
    /// Factor by which all tolerances are relaxed for `AlmostSolved`.
    pub almost: f64,
    pub max_iter: u32,
    /// Gondzio's centrality correctors per iteration, at most (see `CORRECTOR_STRETCH`).
    pub correctors: usize,
    /// Whether a stall (`kkt::Progress`) ends the iterations: where the caller has a cheaper
    /// way on than crawling to the budget (`for_size`, `with_stall_exit`). From a warm start
    /// only beyond 20k unknowns (see `solve`).
    pub stall_exits: bool,
}

impl Tolerances {
    /// The defaults adapted to `n` unknowns.
    /// - The dual tolerance grows as √(n / 10⁴) from 10⁴ unknowns on, besides its rounding
    ///   floor (`DUAL_ROUNDING`), because the rounding of larger factors grows too.
    /// - The iteration budget is larger beyond 20k unknowns, where the fallback (clarabel)
    ///   costs thousands of native iterations (see `fallback_is_costly`).
    /// - Beyond 20k unknowns one centrality corrector per iteration instead of three, because
    ///   each costs a solve with a large factor, and a stall ends the iterations (the caller
    ///   keeps the answer at hand rather than call clarabel).
    pub fn for_size(n: usize) -> Tolerances {
        let base = Tolerances::default();
        let large = fallback_is_costly(n);
        Tolerances {
            dual_feas: base.dual_feas * (n as f64 / 1e4).sqrt().max(1.0),
            max_iter: if large { 150 } else { 80 },
            correctors: if large { 1 } else { base.correctors },
            stall_exits: large,
            ..base
        }
    }

    /// These tolerances, with a stall ending the iterations: for an attempt that another
    /// native attempt with the same optimum follows.
    pub fn with_stall_exit(self) -> Tolerances {
        Tolerances {
            stall_exits: true,
            ..self
        }
    }

    /// The tolerances of a form-finding step with `n` unknowns: `for_size`, with coarse
    /// optimality where `fallback_is_costly` (beyond 20k unknowns; see `StressCache`): the
    /// relative gap 1e-3 and the dual residual 10⁶ times its tolerance, while the bounds and
    /// equality rows are held as tightly, so the answer is as compressive and as balanced
    /// horizontally as an exact one. A relative gap g leaves the residual vector within √(2g)
    /// (4.5%) of the optimum's in norm. There exact QPs are most of the loop's cost and their
    /// dual residual is what stalls.
    /// These tolerances with the relative gap `gap` (looser than theirs) and the dual
    /// residual's tolerance relaxed by √(gap / gap_rel), the bounds and equality rows held as
    /// tightly: an inexact early QP of a form finding (see `StressCache::set_inexact`). A
    /// relative gap g leaves the residual vector within √(2g) of the optimum's in norm.
    pub fn inexact(self, gap: f64) -> Tolerances {
        Tolerances {
            gap_rel: gap,
            dual_feas: self.dual_feas * (gap / self.gap_rel).sqrt().max(1.0),
            ..self
        }
    }

    pub fn for_form_finding(n: usize) -> Tolerances {
        let exact = Tolerances::for_size(n);
        if !fallback_is_costly(n) {
            return exact;
        }
        Tolerances {
            gap_rel: 1e-3,
            dual_feas: exact.dual_feas * 1e6,
            ..exact
        }
    }
}

/// Whether clarabel, the fallback, costs thousands of native iterations on a QP with `n`
/// unknowns: its generic KKT factorisation grows much faster with size than the two-ring
/// normal matrix does.
pub fn fallback_is_costly(n: usize) -> bool {
    n > 20_000
}

impl Default for Tolerances {
    fn default() -> Self {
        // As tight as the clarabel settings in qp.rs: residuals must be reproducible to ~1e-6
        // of the mean load, and the objective (Σ r²) is often ~0 at the optimum.
        Tolerances {
            gap_abs: 1e-12,
            gap_rel: 1e-11,
            feas: 1e-10,
            dual_feas: 1e-10,
            almost: 10.0,
            // Well-posed problems converge well within this; beyond, the caller's fallback is
            // cheaper than crawling on (see `for_size`).
            max_iter: 80,
            correctors: 3,
            stall_exits: false,
        }
    }
}

/// Gondzio's centrality correctors (at most `Tolerances::correctors` per iteration): each
/// aims at a step `stretch α + add` (α the step already reached) and is kept only if it
/// gains a tenth of that.
const CORRECTOR_STRETCH: f64 = 1.5;
const CORRECTOR_ADD: f64 = 0.1;

/// An iteration's direction gets Krylov cycles (`Newton::refine`) when refinement leaves
/// its x rows an error above this fraction of the dual residual it is to remove, or above
/// the dual tolerance, whichever is larger: the step would leave that residual where it is.
/// Not beyond 20k unknowns (`fallback_is_costly`), where a cycle is expensive and the errors
/// that call for one are the solves' own rounding, which cycles cannot remove.
const KRYLOV_GOAL: f64 = 0.1;

/// Fraction of the way to the boundary of the positive orthant taken by each step: closer to
/// 1 loses the last digits that large QPs need.
const STEP_FRACTION: f64 = 0.99;

fn inf_norm(x: &[f64]) -> f64 {
    x.iter().fold(0.0f64, |a, v| a.max(v.abs()))
}

/// max_i Σ_j |a_ij x_j|.
fn abs_row_norm(a: &Csr, x: &[f64]) -> f64 {
    (0..a.nrows())
        .map(|r| a.row(r).map(|(c, v)| (v * x[c]).abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

/// Aᵀ y for a Csr A with `n` columns.
fn mul_t(a: &Csr, y: &[f64], n: usize) -> Vec<f64> {
    sum_t_terms(a, y, n, |a, y| a * y)
}

/// |A|ᵀ |y| for a Csr A with `n` columns.
fn abs_mul_t(a: &Csr, y: &[f64], n: usize) -> Vec<f64> {
    sum_t_terms(a, y, n, |a, y| (a * y).abs())
}

/// out_c = Σ_r term(a_rc, y_r) for a Csr A with `n` columns.
fn sum_t_terms(a: &Csr, y: &[f64], n: usize, term: impl Fn(f64, f64) -> f64) -> Vec<f64> {
    let mut out = vec![0.0; n];
    for (bounds, &yr) in a.start.windows(2).zip(y) {
        let range = bounds[0]..bounds[1];
        for (&c, &v) in a.col[range.clone()].iter().zip(&a.val[range]) {
            out[c] += term(v, yr);
        }
    }
    out
}

/// Largest α ≤ 1 with v + α dv ≥ 0.
fn max_step(v: &[f64], dv: &[f64]) -> f64 {
    v.iter()
        .zip(dv)
        .filter(|(_, d)| **d < 0.0)
        .map(|(v, d)| -v / d)
        .fold(1.0, f64::min)
}

/// `m` with column j scaled by `col[j]` and row i by `row[i]`.
fn scaled(m: &Csr, col: &[f64], row: &[f64]) -> Csr {
    let mut out = m.clone();
    for (r, &rs) in row.iter().enumerate() {
        for k in m.start[r]..m.start[r + 1] {
            out.val[k] *= rs * col[m.col[k]];
        }
    }
    out
}

/// Row scale that gives every row of `m` (after the column scaling) unit ∞-norm.
fn unit_rows(m: &Csr, col: &[f64]) -> Vec<f64> {
    (0..m.nrows())
        .map(|r| {
            let norm = m.row(r).fold(0.0f64, |a, (c, v)| a.max((v * col[c]).abs()));
            if norm > 0.0 {
                1.0 / norm
            } else {
                1.0
            }
        })
        .collect()
}

/// Per inequality row, the factor that turns its scaled slack back into the caller's units,
/// times `unit` (by default the median row scale). The starting point is built in those units:
/// the stress QPs' rows bound force densities (and τ), commensurate as the caller states them,
/// while the unit-norm scaling measures a boundary edge's force density (its own unknown) about
/// 1/ℓ² times larger than an interior edge's (a combination of Airy values), so that a uniform
/// shift in the scaled units would start the boundary edges' slacks far below their optimum.
/// The iterates are otherwise invariant to the row scaling, which stays for the linear algebra.
///
/// `unit` sets the weight of the starting point's constraint term (`START_PENALTY`) in the
/// caller's units. The median row scale depends on the unknowns: the stress QPs pass their
/// own unit instead, the same for both formulations (`qp::START_UNIT`).
fn caller_units(row_scale: &[f64], unit: Option<f64>) -> Vec<f64> {
    let Some(unit) = unit.or_else(|| crate::stress::upper_median(row_scale.to_vec())) else {
        return Vec::new();
    };
    row_scale.iter().map(|r| unit / r).collect()
}

/// Solves the QP after equilibration: variables scaled so that the normal matrix at W = I has
/// a unit diagonal, constraint rows scaled to unit norm. Weights and Airy values, boundary-edge
/// forces and hole coefficients differ by orders of magnitude; unscaled, the factorisation
/// loses the accuracy the last iterations need. `cache` holds the normal matrix's structure
/// from an earlier QP of the same structure, and is left holding this one's.
pub fn solve(qp: &Qp, tol: &Tolerances, cache: &mut PatternCache) -> IpmOutput {
    let n = qp.c.len();
    let mut diag = vec![0.0; n];
    for (r, &w) in qp.quad_weight.iter().enumerate() {
        qp.quad.row(r).for_each(|(c, v)| diag[c] += w * v * v);
    }
    for m in [qp.eq, qp.ineq] {
        for r in 0..m.nrows() {
            let norm2: f64 = m.row(r).map(|(_, v)| v * v).sum();
            m.row(r)
                .for_each(|(c, v)| diag[c] += v * v / norm2.max(1e-300));
        }
    }
    let d: Vec<f64> = diag
        .iter()
        .map(|&v| if v > 0.0 { 1.0 / v.sqrt() } else { 1.0 })
        .collect();
    let ones_q = vec![1.0; qp.quad.nrows()];
    let re = unit_rows(qp.eq, &d);
    let ri = unit_rows(qp.ineq, &d);
    let start_units = caller_units(&ri, qp.slack_unit);
    let skip_last = cache.far_from_balance && fallback_is_costly(n);
    // The last answer in these scaled units: x / d, the multipliers over the row scales.
    let warm = cache.last.take().filter(|_| !skip_last).map(|w| WarmPoint {
        x: w.x.iter().zip(&d).map(|(x, d)| x / d).collect(),
        active: w.active,
        lambda: w.lambda.iter().zip(&re).map(|(l, r)| l / r).collect(),
        z: w.z.iter().zip(&ri).map(|(z, r)| z / r).collect(),
    });
    let quad = scaled(qp.quad, &d, &ones_q);
    let eq = scaled(qp.eq, &d, &re);
    let ineq = scaled(qp.ineq, &d, &ri);
    let c: Vec<f64> = qp.c.iter().zip(&d).map(|(c, d)| c * d).collect();
    let f: Vec<f64> = qp.f.iter().zip(&re).map(|(f, r)| f * r).collect();
    let h: Vec<f64> = qp.h.iter().zip(&ri).map(|(h, r)| h * r).collect();
    let groups = qp.groups.for_scaled_rows(&ri);
    let mut out = solve_scaled(
        &Qp {
            quad: &quad,
            quad_weight: qp.quad_weight,
            c: &c,
            constant: qp.constant,
            eq: &eq,
            f: &f,
            ineq: &ineq,
            h: &h,
            groups: &groups,
            positions: qp.positions,
            slack_unit: qp.slack_unit,
        },
        &start_units,
        tol,
        cache,
        warm,
    );
    out.x.iter_mut().zip(&d).for_each(|(x, d)| *x *= d);
    out.lambda.iter_mut().zip(&re).for_each(|(l, r)| *l *= r);
    out.z.iter_mut().zip(&ri).for_each(|(z, r)| *z *= r);
    if out.status == IpmStatus::Solved {
        cache.last = Some(WarmPoint {
            x: out.x.clone(),
            active: out.active.clone(),
            lambda: out.lambda.clone(),
            z: out.z.clone(),
        });
    }
    out
}

fn solve_scaled(
    qp: &Qp,
    start_units: &[f64],
    tol: &Tolerances,
    cache: &mut PatternCache,
    warm: Option<WarmPoint>,
) -> IpmOutput {
    let n = qp.c.len();
    let cons = stacked(qp.eq, qp.ineq);
    let Some((pattern, reused)) = cache.pattern(qp.quad, &cons, qp.eq.nrows(), qp.positions) else {
        return IpmOutput::unsolved(vec![0.0; n], IpmStatus::NumericalError, 0);
    };
    let normal = Normal::new(pattern, qp.quad, qp.quad_weight, &cons);
    // The iterations work in the factor's labels: no vector is permuted per solve.
    let relabelled = Relabelled::new(qp, &normal.pattern.label);
    let warm = warm.filter(|w| reused && w.fits(qp)).map(|w| WarmPoint {
        x: relabel_vector(&w.x, &normal.pattern.label),
        ..w
    });
    let mut out = iterate(
        &relabelled.qp(qp),
        &normal,
        &relabelled.cons,
        start_units,
        tol,
        warm.as_ref(),
    );
    out.x = normal.pattern.label.iter().map(|&l| out.x[l]).collect();
    out
}

/// The constraints and linear term of a QP with its unknowns relabelled (`quad` is left as
/// it is: the iterations use P only through `Normal`), and C = [E; G] in the new labels.
struct Relabelled {
    eq: Csr,
    ineq: Csr,
    cons: Csr,
    c: Vec<f64>,
}

impl Relabelled {
    fn new(qp: &Qp, label: &[usize]) -> Relabelled {
        let (eq, ineq) = (
            relabel_columns(qp.eq, label),
            relabel_columns(qp.ineq, label),
        );
        let cons = stacked(&eq, &ineq);
        let c = relabel_vector(qp.c, label);
        Relabelled { eq, ineq, cons, c }
    }

    fn qp<'a>(&'a self, qp: &Qp<'a>) -> Qp<'a> {
        Qp {
            c: &self.c,
            eq: &self.eq,
            ineq: &self.ineq,
            ..*qp
        }
    }
}

/// Weight 1 / START_PENALTY of the constraint term of the starting point's problem. CVXOPT's
/// weight 1 pulls every force density towards its bound, so that nearly every constraint
/// starts out looking active and large QPs need many more iterations.
const START_PENALTY: f64 = 100.0;

/// The interior-point iterations on a QP whose unknowns are in `normal`'s labels; the
/// starting point is built with inequality row i's slack multiplied by `start_units[i]` (see
/// `caller_units`). With the last answer of a form finding (`warm`), its active set is tried
/// first (`warm_start`), then the iterations start from the blend of that answer with the
/// cold starting point (`blend`); only if those do not solve the QP within their budget do
/// the iterations run from the cold point. Whichever start answers, the answer meets the same
/// tolerances.
fn iterate(
    qp: &Qp,
    normal: &Normal,
    cons: &Csr,
    start_units: &[f64],
    tol: &Tolerances,
    warm: Option<&WarmPoint>,
) -> IpmOutput {
    let n = qp.c.len();
    // The numeric factor's storage, shared by every Newton system of this QP (one at a time).
    let Some(mut space) = FactorSpace::for_pattern(normal.pattern) else {
        return stopped(vec![0.0; n], 0, None);
    };
    if let Some(out) = warm.and_then(|w| warm_start(qp, normal, cons, w, tol, &mut space)) {
        return out;
    }
    let Some(cold) = starting_point(qp, normal, cons, start_units, &mut space) else {
        return stopped(vec![0.0; n], 0, None);
    };
    let mut spent = 0;
    if let Some(w) = warm.filter(|w| !w.z.is_empty()) {
        let start = blend(qp, w, &cold);
        let budget = tol.max_iter.min(WARM_BUDGET);
        // The blend's first iterations may idle while it leaves the last active set: there a
        // stall hands over to the cold start only where every stall is an exit anyway.
        let warm_tol = Tolerances {
            stall_exits: fallback_is_costly(n),
            ..*tol
        };
        let out = interior_point((qp, normal, cons), start, &warm_tol, budget, &mut space);
        if out.status == IpmStatus::Solved {
            return out;
        }
        spent = out.iterations;
    }
    let mut out = interior_point((qp, normal, cons), cold, tol, tol.max_iter, &mut space);
    out.iterations += spent;
    out
}

/// Iterations at most from a warm start (`blend`) before the cold start takes over.
const WARM_BUDGET: u32 = 30;

/// Weight of the last answer in the warm start, against the cold starting point's 1 − ω.
const WARM_WEIGHT: f64 = 0.99;

/// The last answer (`warm`) blended with the cold starting point, ω warm + (1 − ω) cold, as in
/// Skajaa, Andersen and Ye's warm start of interior-point methods: the slacks of the new QP at
/// the last x (clipped at 0) and the last multipliers are near the new optimum when the QP
/// has changed little, and the cold point's share keeps every slack and multiplier strictly
/// positive and the products s_i z_i away from 0, so that the iterations can move off the
/// last active set where the new optimum leaves it.
fn blend(qp: &Qp, warm: &WarmPoint, cold: &Iterate) -> Iterate {
    let mix = |w: &[f64], c: &[f64]| -> Vec<f64> {
        (w.iter().zip(c))
            .map(|(w, c)| WARM_WEIGHT * w + (1.0 - WARM_WEIGHT) * c)
            .collect()
    };
    let gx = qp.ineq.mul(&warm.x);
    let s_warm: Vec<f64> = gx.iter().zip(qp.h).map(|(g, h)| (g - h).max(0.0)).collect();
    let z_warm: Vec<f64> = warm.z.iter().map(|z| z.max(0.0)).collect();
    Iterate {
        x: mix(&warm.x, &cold.x),
        lambda: mix(&warm.lambda, &cold.lambda),
        s: mix(&s_warm, &cold.s),
        z: mix(&z_warm, &cold.z),
    }
}

/// The iterations from `it`, at most `budget`.
fn interior_point(
    (qp, normal, cons): (&Qp, &Normal, &Csr),
    mut it: Iterate,
    tol: &Tolerances,
    budget: u32,
    space: &mut FactorSpace,
) -> IpmOutput {
    // The last iterate that met the relaxed tolerances, returned if the method stops early.
    let mut almost: Option<Vec<f64>> = None;
    let mut polishing = Polishing {
        below: f64::INFINITY,
        failed_guess: None,
    };
    let mut progress = Progress::new();
    let mut iterations = budget;
    for iteration in 0..budget {
        crate::interrupt::poll();
        let kkt = Kkt::new(qp, normal, &it.x, &it.lambda, &it.s, &it.z);
        if !kkt.objective.is_finite() || inf_norm(&it.x) > 1e15 {
            return stopped(it.x, iteration, almost);
        }
        if kkt.within(tol, tol.almost) {
            almost = Some(it.x.clone());
        }
        if kkt.within(tol, 1.0) {
            return IpmOutput {
                active: active_guess(&it.s, &it.z),
                x: it.x,
                status: IpmStatus::Solved,
                iterations: iteration,
                lambda: it.lambda,
                z: it.z,
            };
        }
        if progress.stalled(iteration, kkt.excess(tol)) && tol.stall_exits {
            iterations = iteration;
            break;
        }
        let polished = polishing.attempt((qp, normal, cons), &it, &kkt, tol, space);
        if let Some(p) = polished {
            return IpmOutput::polished(p, iteration + 1);
        }
        let Some(dir) = direction(qp, normal, cons, &it, kkt, tol, space) else {
            return stopped(it.x, iteration, almost);
        };
        it.advance(&dir);
    }
    let status = if almost.is_some() {
        IpmStatus::AlmostSolved
    } else {
        IpmStatus::MaxIterations
    };
    IpmOutput::unsolved(almost.unwrap_or(it.x), status, iterations)
}

/// The answer of iterations that stopped early: the last iterate that met the relaxed
/// tolerances as `AlmostSolved`, else `x` as `NumericalError`.
fn stopped(x: Vec<f64>, iterations: u32, almost: Option<Vec<f64>>) -> IpmOutput {
    match almost {
        Some(x) => IpmOutput::unsolved(x, IpmStatus::AlmostSolved, iterations),
        None => IpmOutput::unsolved(x, IpmStatus::NumericalError, iterations),
    }
}

/// The last answer of a form finding on the same pattern: x, its active set and the
/// multipliers of the equality and inequality rows (empty when unknown).
pub struct WarmPoint {
    pub(super) x: Vec<f64>,
    pub(super) active: Vec<bool>,
    pub(super) lambda: Vec<f64>,
    pub(super) z: Vec<f64>,
}

impl WarmPoint {
    /// Whether it has the sizes of `qp`'s unknowns and rows.
    fn fits(&self, qp: &Qp) -> bool {
        let rows = self.z.is_empty()
            || (self.z.len() == qp.ineq.nrows() && self.lambda.len() == qp.eq.nrows());
        self.x.len() == qp.c.len() && self.active.len() == qp.ineq.nrows() && rows
    }
}

/// `d` after `m_eq` zeros (the equality rows' entries).
fn with_eq_zeros(m_eq: usize, d: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; m_eq];
    out.extend_from_slice(d);
    out
}

/// A form-finding step first tries the previous step's active set: where it is nearly right,
/// a few active-set corrections reach the optimum for a fraction of the iterations' cost.
/// Only x and the active set are used: the step computes the multipliers afresh, from zero.
fn warm_start(
    qp: &Qp,
    normal: &Normal,
    cons: &Csr,
    warm: &WarmPoint,
    tol: &Tolerances,
    space: &mut FactorSpace,
) -> Option<IpmOutput> {
    let (lambda0, z0) = (vec![0.0; qp.eq.nrows()], vec![0.0; qp.ineq.nrows()]);
    let point = Point {
        x: &warm.x,
        lambda: &lambda0,
        z: &z0,
    };
    let polished = polish(
        qp,
        normal,
        cons,
        &point,
        (&warm.active, Corrections::AllWhileFewer),
        tol,
        space,
    );
    polished.ok().map(|p| IpmOutput::polished(p, 0))
}

/// A primal–dual iterate: x, the equality multipliers λ, the slacks s and their multipliers z.
struct Iterate {
    x: Vec<f64>,
    lambda: Vec<f64>,
    s: Vec<f64>,
    z: Vec<f64>,
}

/// A Newton direction (dx, dλ, ds, dz).
type Direction = (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>);

impl Iterate {
    /// Moves along `dir` 0.99 of the way to the boundary of the positive orthant, at most 1.
    fn advance(&mut self, (dx, dl, ds, dz): &Direction) {
        let alpha = (STEP_FRACTION * max_step(&self.s, ds).min(max_step(&self.z, dz))).min(1.0);
        self.x.iter_mut().zip(dx).for_each(|(a, d)| *a += alpha * d);
        (self.lambda.iter_mut())
            .zip(dl)
            .for_each(|(a, d)| *a += alpha * d);
        self.s.iter_mut().zip(ds).for_each(|(a, d)| *a += alpha * d);
        self.z.iter_mut().zip(dz).for_each(|(a, d)| *a += alpha * d);
    }
}

/// The starting point, as CVXOPT's with the constraint term weighted down by START_PENALTY:
/// minimise ½xᵀPx + cᵀx + ½‖U(Gx − h)‖² / START_PENALTY subject to Ex = f, take the slacks
/// s = Gx − h and the duals z = −s, then shift both into the positive orthant; all in the
/// caller's units (U = diag(start_units)), converted back at the end.
fn starting_point(
    qp: &Qp,
    normal: &Normal,
    cons: &Csr,
    start_units: &[f64],
    space: &mut FactorSpace,
) -> Option<Iterate> {
    let m_eq = qp.eq.nrows();
    let minus_c: Vec<f64> = qp.c.iter().map(|c| -c).collect();
    let mut rhs = qp.f.to_vec();
    rhs.extend_from_slice(qp.h);
    let penalty: Vec<f64> = start_units
        .iter()
        .map(|u| START_PENALTY / (u * u))
        .collect();
    let [x, mut w] = REGULARISATION.iter().find_map(|&reg| {
        Newton::new(normal, cons, with_eq_zeros(m_eq, &penalty), reg, space)?
            .solve(&minus_c, &rhs, 1e-8, false)
    })?;
    // The solve returns w = (Gx − h) / penalty on the inequality rows.
    let s_hat: Vec<f64> = w
        .split_off(m_eq)
        .iter()
        .zip(&penalty)
        .zip(start_units)
        .map(|((w, p), u)| w * p * u)
        .collect();
    let lambda: Vec<f64> = w.iter().map(|v| -v).collect();
    // Mehrotra's shift: into the positive orthant, then balanced so that s ∘ z starts centred.
    let mut z: Vec<f64> = s_hat.iter().map(|v| -v).collect();
    let mut s = s_hat;
    let lowest = |v: &[f64]| v.iter().fold(f64::INFINITY, |a, &b| a.min(b));
    let ds = (-1.5 * lowest(&s)).max(0.0);
    let dz = (-1.5 * lowest(&z)).max(0.0);
    s.iter_mut().for_each(|v| *v += ds);
    z.iter_mut().for_each(|v| *v += dz);
    let sz = dot(&s, &z);
    let (sum_s, sum_z) = (s.iter().sum::<f64>(), z.iter().sum::<f64>());
    let ds = if sum_z > 0.0 { 0.5 * sz / sum_z } else { 1.0 };
    let dz = if sum_s > 0.0 { 0.5 * sz / sum_s } else { 1.0 };
    s.iter_mut()
        .zip(start_units)
        .for_each(|(v, u)| *v = (*v + ds.max(1e-8)) / u);
    z.iter_mut()
        .zip(start_units)
        .for_each(|(v, u)| *v = (*v + dz.max(1e-8)) * u);
    Some(Iterate { x, lambda, s, z })
}

/// When the iterations try to solve for the active set directly (see `PolishFailure`).
struct Polishing {
    /// Polishing is attempted only while the gap is below this.
    below: f64,
    /// The guess of the last attempt that failed with an early guess: the same guess from
    /// another iterate leads to the same step (a QP's Newton step lands on the optimum for
    /// its active set wherever it starts), so it would fail again.
    failed_guess: Option<Vec<bool>>,
}

impl Polishing {
    /// Close to the optimum the active set is plain to see: solving for it directly ends the
    /// iterations the gap would otherwise need to creep down to the tolerance, which near a
    /// zero objective is at the edge of double precision. The optimum and its active set, if
    /// this iterate's guess reaches them.
    fn attempt(
        &mut self,
        (qp, normal, cons): (&Qp, &Normal, &Csr),
        it: &Iterate,
        kkt: &Kkt,
        tol: &Tolerances,
        space: &mut FactorSpace,
    ) -> Option<Polished> {
        let guess = (kkt.near(tol) && kkt.gap <= self.below).then(|| active_guess(&it.s, &it.z));
        let guess = guess.filter(|g| self.failed_guess.as_ref() != Some(g))?;
        let point = Point {
            x: &it.x,
            lambda: &it.lambda,
            z: &it.z,
        };
        match polish(
            qp,
            normal,
            cons,
            &point,
            (&guess, Corrections::Few),
            tol,
            space,
        ) {
            Ok(answer) => return Some(answer),
            Err(PolishFailure::EarlyGuess) => {
                self.below = f64::INFINITY;
                self.failed_guess = Some(guess);
            }
            Err(PolishFailure::Inexact) => {
                self.below = INEXACT_RETRY * kkt.gap;
                self.failed_guess = None;
            }
        }
        None
    }
}

/// The right-hand sides of an iteration's Newton systems and the recovery of (ds, dz) from
/// their solutions.
struct NewtonSides<'a> {
    qp: &'a Qp<'a>,
    s: &'a [f64],
    z: &'a [f64],
    r_e: &'a [f64],
    r_i: &'a [f64],
}

impl NewtonSides<'_> {
    /// The constraint rows' right side for a complementarity target r_c (Z ds + S dz = r_c):
    /// in augmented form P dx + Eᵀ(−dλ) + Gᵀ(−dz) = −r_d,  E dx = −r_e,
    /// G dx − (s/z)(−dz) = r_c/z − r_i.
    fn rhs(&self, r_c: &[f64]) -> Vec<f64> {
        let (z, m) = (self.z, self.s.len());
        let mut b2: Vec<f64> = self.r_e.iter().map(|v| -v).collect();
        b2.extend((0..m).map(|i| r_c[i] / z[i] - self.r_i[i]));
        b2
    }

    /// The direction from a solution (dx, w) of the augmented system for target `r_c`.
    fn split(&self, [dx, mut w]: [Vec<f64>; 2], r_c: &[f64]) -> Direction {
        let (s, z, m) = (self.s, self.z, self.s.len());
        let w_in = w.split_off(self.qp.eq.nrows());
        let dl: Vec<f64> = w.iter().map(|w| -w).collect();
        // Of ds and dz, the one of the larger variable comes from the linear system, the
        // other from complementarity: dividing by the tiny one would amplify errors.
        let gdx = self.qp.ineq.mul(&dx);
        let (mut ds, mut dz) = (vec![0.0; m], vec![0.0; m]);
        for i in 0..m {
            if s[i] >= z[i] {
                ds[i] = gdx[i] + self.r_i[i];
                dz[i] = (r_c[i] - z[i] * ds[i]) / s[i];
            } else {
                dz[i] = -w_in[i];
                ds[i] = (r_c[i] - s[i] * dz[i]) / z[i];
            }
        }
        (dx, dl, ds, dz)
    }

    /// The longest step ≤ 1 along (ds, dz) that keeps s and z non-negative.
    fn step_length(&self, ds: &[f64], dz: &[f64]) -> f64 {
        max_step(self.s, ds).min(max_step(self.z, dz))
    }
}

/// What the corrector of one iteration aims at, besides the sides of its systems.
struct Aims<'a> {
    minus_rd: &'a [f64],
    mu: f64,
    /// The accuracy the refined direction needs, and the error worth Krylov cycles.
    precision: f64,
    krylov_goal: Option<f64>,
}

/// An iteration's direction: the predictor (affine scaling), then the centred, second-order
/// corrected step, with the least regularisation whose factor is sound.
fn direction(
    qp: &Qp,
    normal: &Normal,
    cons: &Csr,
    it: &Iterate,
    kkt: Kkt,
    tol: &Tolerances,
    space: &mut FactorSpace,
) -> Option<Direction> {
    let n = qp.c.len();
    let m = qp.ineq.nrows();
    let (s, z) = (&it.s, &it.z);
    let dual_tolerance = (tol.dual_feas * kkt.dual_scale).max(kkt.dual_floor);
    let Kkt {
        r_d,
        r_e,
        r_i,
        gap,
        dual_scale,
        ..
    } = kkt;
    let mu = if m > 0 { gap / m as f64 } else { 0.0 };
    let minus_rd: Vec<f64> = r_d.iter().map(|v| -v).collect();
    let sides = NewtonSides {
        qp,
        s,
        z,
        r_e: &r_e,
        r_i: &r_i,
    };
    let d: Vec<f64> = (0..m).map(|i| s[i] / z[i]).collect();
    // The corrector needs an accuracy just ahead of the iterate's own.
    let precision = (1e-3 * inf_norm(&r_d) / dual_scale).clamp(1e-2 * tol.feas, 1e-6);
    // The direction's own error in the dual residual worth Krylov cycles to remove.
    let krylov_goal =
        (!fallback_is_costly(n)).then(|| (KRYLOV_GOAL * inf_norm(&r_d)).max(dual_tolerance));
    let aims = Aims {
        minus_rd: &minus_rd,
        mu,
        precision,
        krylov_goal,
    };
    REGULARISATION.iter().find_map(|&reg| {
        let mut newton = Newton::new(normal, cons, with_eq_zeros(qp.eq.nrows(), &d), reg, space)?;
        corrected_direction(&sides, &mut newton, &aims, tol)
    })
}

/// Mehrotra's predictor–corrector with Gondzio's centrality correctors on one factor.
fn corrected_direction(
    sides: &NewtonSides,
    newton: &mut Newton,
    aims: &Aims,
    tol: &Tolerances,
) -> Option<Direction> {
    let (s, z, m) = (sides.s, sides.z, sides.s.len());
    let (minus_rd, mu) = (aims.minus_rd, aims.mu);
    let r_aff: Vec<f64> = (0..m).map(|i| -s[i] * z[i]).collect();
    let sol = newton.approximate(minus_rd, &sides.rhs(&r_aff));
    let (_, _, ds_a, dz_a) = sides.split(sol, &r_aff);
    let alpha_a = sides.step_length(&ds_a, &dz_a);
    let mu_aff = if m > 0 {
        (0..m)
            .map(|i| (s[i] + alpha_a * ds_a[i]) * (z[i] + alpha_a * dz_a[i]))
            .sum::<f64>()
            / m as f64
    } else {
        0.0
    };
    let sigma = if mu > 0.0 {
        (mu_aff / mu).clamp(0.0, 1.0).powi(3)
    } else {
        0.0
    };
    let r_c: Vec<f64> = (0..m)
        .map(|i| -s[i] * z[i] + sigma * mu - ds_a[i] * dz_a[i])
        .collect();
    let (r_c, b2, sol) = gondzio_correctors(sides, newton, minus_rd, r_c, sigma * mu, tol);
    let sol = newton.refine(sol, minus_rd, &b2, aims.precision, false, aims.krylov_goal)?;
    Some(sides.split(sol, &r_c))
}

/// Gondzio's centrality correctors, with coarse solves: a few blocking products s_i z_i
/// otherwise hold the step to a fraction of the way. Returns the kept target, the right side
/// of its system and its unrefined solution.
fn gondzio_correctors(
    sides: &NewtonSides,
    newton: &mut Newton,
    minus_rd: &[f64],
    mut r_c: Vec<f64>,
    target: f64,
    tol: &Tolerances,
) -> (Vec<f64>, Vec<f64>, [Vec<f64>; 2]) {
    let (s, z, m) = (sides.s, sides.z, sides.s.len());
    let mut b2 = sides.rhs(&r_c);
    let mut sol = newton.approximate(minus_rd, &b2);
    let mut dir = sides.split(sol.clone(), &r_c);
    let mut alpha = sides.step_length(&dir.2, &dir.3);
    for _ in 0..tol.correctors {
        if alpha >= 0.9 || target <= 0.0 {
            break;
        }
        let trial = (CORRECTOR_STRETCH * alpha + CORRECTOR_ADD).min(1.0);
        let mut r_try = r_c.clone();
        for i in 0..m {
            let v = (s[i] + trial * dir.2[i]) * (z[i] + trial * dir.3[i]);
            let want = v.clamp(0.1 * target, 10.0 * target);
            r_try[i] += (want - v).max(-10.0 * target);
        }
        let b_try = sides.rhs(&r_try);
        let sol_try = newton.approximate(minus_rd, &b_try);
        let dir_try = sides.split(sol_try.clone(), &r_try);
        let a = sides.step_length(&dir_try.2, &dir_try.3);
        if a < alpha + 0.1 * (trial - alpha) {
            break;
        }
        (alpha, r_c, b2, sol, dir) = (a, r_try, b_try, sol_try, dir_try);
    }
    (r_c, b2, sol)
}

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_dense;
