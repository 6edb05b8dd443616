//! The Newton system of the interior-point method in augmented form, solved with the
//! regularised factor of the normal matrix and refined against the exact system.

use super::dense::Source;
use super::pattern::{Normal, Pattern};
use super::{factorise, fallback_is_costly, gmres, inf_norm, mul_t, supernodal};
use crate::stress::sparse::Csr;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::linalg::cholesky::{LdltRef, SymbolicCholesky};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par};

/// Regularisation δ of the constraint rows (scaled units): inequality weights z/s are capped
/// near 1/δ, equality rows weigh 1/δ_eq. Larger weights would lose the small curvatures to
/// rounding; refinement removes the regularisation's effect on the solution, and smaller δ
/// let rounding stall the dual residual of large QPs.
pub(super) const DELTA: f64 = 1e-7;
pub(super) const DELTA_EQ: f64 = 1e-6;

/// δ_eq beyond 20k unknowns (`fallback_is_costly`), in every Newton system of such a QP (the
/// start, the iterations, polishing): there the factor's rounding, amplified by equality
/// weights of 1e6, would hold the dual residual above its tolerance wherever equality rows
/// are many (the edge-based formulation's two rows per free vertex).
pub(super) const DELTA_EQ_LARGE: f64 = 1e-4;

/// Static regularisations of the normal matrix, used in turn until the factor is sound.
pub(super) const REGULARISATION: [f64; 3] = [1e-12, 1e-9, 1e-6];

/// GMRES cycles, and basis vectors per cycle, run where refinement stalls short of its
/// target (`Newton::krylov`).
const KRYLOV_CYCLES: usize = 3;
const KRYLOV_BASIS: usize = 30;

/// The Newton system in augmented form, for unknowns (dx, w):
///
///   P dx + Cᵀ w = b1,   C dx − D w = b2      (C = [E; G], D = 0 on E, s / z on G)
///
/// solved with the factor of P + Cᵀ (D + δ)⁻¹ C, then refined against the exact system.
pub(super) struct Newton<'a> {
    pub(super) normal: &'a Normal<'a>,
    pub(super) cons: &'a Csr,
    /// D per constraint row, and the weights 1 / (D + δ) the factor uses.
    pub(super) d: Vec<f64>,
    pub(super) w_reg: Vec<f64>,
    pub(super) space: &'a mut FactorSpace,
}

/// Storage of the numeric factor and its working memory, allocated once per QP: every Newton step
/// refactors the same pattern.
pub(super) struct FactorSpace {
    pub(super) values: Vec<f64>,
    /// Expected pivot signs (all positive) for faer's dynamic regularisation.
    pub(super) signs: Vec<i8>,
    pub(super) l_values: Vec<f64>,
    pub(super) buffer: MemBuffer,
    /// Working storage of `supernodal::solve_in_place`.
    pub(super) work: Vec<f64>,
}

impl FactorSpace {
    /// The space for factors of `pattern`'s matrix, whose split rows' unknowns (beyond n)
    /// have negative pivots.
    pub(super) fn for_pattern(pattern: &Pattern) -> Option<FactorSpace> {
        let mut space = FactorSpace::new(&pattern.symbolic, pattern.row_idx.len())?;
        space.signs[pattern.n..].fill(-1);
        Some(space)
    }

    pub(super) fn new(symbolic: &SymbolicCholesky<usize>, n_values: usize) -> Option<FactorSpace> {
        let par = Par::Seq;
        let stack = symbolic
            .factorize_numeric_ldlt_scratch::<f64>(par, Default::default())
            .or(symbolic.solve_in_place_scratch::<f64>(1, par));
        Some(FactorSpace {
            values: vec![0.0; n_values],
            signs: vec![1; symbolic.nrows()],
            l_values: vec![0.0; symbolic.len_val()],
            buffer: MemBuffer::try_new(stack).ok()?,
            work: Vec::new(),
        })
    }
}

impl<'a> Newton<'a> {
    pub(super) fn new(
        normal: &'a Normal<'a>,
        cons: &'a Csr,
        d: Vec<f64>,
        reg: f64,
        space: &'a mut FactorSpace,
    ) -> Option<Newton<'a>> {
        let pattern = normal.pattern;
        let (n, n_factor) = (pattern.n, pattern.n + pattern.dense.count());
        let delta_eq = if fallback_is_costly(n) {
            DELTA_EQ_LARGE
        } else {
            DELTA_EQ
        };
        let w_reg: Vec<f64> = d
            .iter()
            .enumerate()
            .map(|(r, d)| 1.0 / (d + if r < pattern.m_eq { delta_eq } else { DELTA }))
            .collect();
        let values = &mut space.values;
        values.copy_from_slice(&normal.p_values);
        for (r, &w) in w_reg.iter().enumerate() {
            let range = pattern.row_start[r]..pattern.row_start[r + 1];
            for (&slot, &prod) in pattern.row_slot[range.clone()]
                .iter()
                .zip(&normal.row_prod[range])
            {
                values[slot] += w * prod;
            }
        }
        // A static regularisation keeps columns that only inactive bounds hold (pivots
        // ~ z/s → 0) away from zero; refinement removes its effect.
        for &k in &pattern.diag {
            values[k] += reg;
        }
        // C's split rows: u = w c·x, with the diagonal −1/w (see `dense`).
        for (&(source, r), &slot) in pattern.dense.rows.iter().zip(&pattern.dense.diag) {
            if source == Source::Cons {
                values[slot] = -1.0 / w_reg[r];
            }
        }
        // Pivots that rounding makes non-positive are replaced by a huge value: that
        // direction then stays put for this solve instead of being amplified.
        let factored = match &pattern.plan {
            Some(plan) => plan.factorise(
                (&pattern.col_ptr, &pattern.row_idx, &space.values),
                &mut space.l_values,
            ),
            None => {
                let matrix = SparseColMatRef::new(
                    SymbolicSparseColMatRef::new_checked(
                        n_factor,
                        n_factor,
                        &pattern.col_ptr,
                        None,
                        &pattern.row_idx,
                    ),
                    &space.values[..],
                );
                pattern
                    .symbolic
                    .factorize_numeric_ldlt(
                        &mut space.l_values,
                        matrix,
                        faer::Side::Lower,
                        LdltRegularization {
                            dynamic_regularization_signs: Some(&space.signs),
                            dynamic_regularization_delta: factorise::HUGE_PIVOT,
                            dynamic_regularization_epsilon: factorise::TINY_PIVOT,
                        },
                        Par::Seq,
                        MemStack::new(&mut space.buffer),
                        Default::default(),
                    )
                    .is_ok()
            }
        };
        if !factored {
            return None;
        }
        Some(Newton {
            normal,
            cons,
            d,
            w_reg,
            space,
        })
    }

    /// One solve with the regularised factor.
    pub(super) fn approximate(&mut self, b1: &[f64], b2: &[f64]) -> [Vec<f64>; 2] {
        let n = self.normal.pattern.n;
        let t: Vec<f64> = b2.iter().zip(&self.w_reg).map(|(b, w)| b * w).collect();
        let mut dx = mul_t(self.cons, &t, n);
        dx.iter_mut().zip(b1).for_each(|(x, b)| *x += b);
        // The split rows' unknowns (see `dense`): their equations' right side is 0.
        let n_factor = n + self.normal.pattern.dense.count();
        dx.resize(n_factor, 0.0);
        let space = &mut *self.space;
        let symbolic = &self.normal.pattern.symbolic;
        // Our own loops over the supernodes (`supernodal`); faer's solve only for a factor
        // that is not supernodal or is permuted.
        let split = self.normal.pattern.solve_split.as_ref();
        if !supernodal::solve_in_place(symbolic, &space.l_values, &mut dx, &mut space.work, split) {
            LdltRef::new(symbolic, &space.l_values).solve_in_place_with_conj(
                Conj::No,
                MatMut::from_column_major_slice_mut(&mut dx, n_factor, 1),
                Par::Seq,
                MemStack::new(&mut space.buffer),
            );
        }
        dx.truncate(n);
        let cdx = self.cons.mul(&dx);
        let w = (0..b2.len())
            .map(|i| self.w_reg[i] * (cdx[i] - b2[i]))
            .collect();
        [dx, w]
    }

    /// Solves the exact augmented system: the regularised solve, then iterative refinement.
    /// Refinement stops at a relative error `tol` (or when it stops converging); None when the
    /// factor is unfit (a pivot was lost) and needs more regularisation.
    pub(super) fn solve(
        &mut self,
        b1: &[f64],
        b2: &[f64],
        tol: f64,
        x_rows: bool,
    ) -> Option<[Vec<f64>; 2]> {
        let sol = self.approximate(b1, b2);
        self.refine(sol, b1, b2, tol, x_rows, None)
    }

    /// Iterative refinement of an approximate solution `sol` against the exact augmented
    /// system, as in `solve`.
    /// `x_rows`: go on while the x rows' error falls by a quarter a round, even once the
    /// weighted error has stalled (for a final answer, whose dual residual is that error).
    /// `krylov_goal`: where refinement stops short of `tol` with the x rows' error above this,
    /// GMRES cycles take it further (`krylov`).
    pub(super) fn refine(
        &mut self,
        mut sol: [Vec<f64>; 2],
        b1: &[f64],
        b2: &[f64],
        tol: f64,
        x_rows: bool,
        krylov_goal: Option<f64>,
    ) -> Option<[Vec<f64>; 2]> {
        // Equality rows count as they are (their violation is what matters), inequality rows
        // as they enter dx (times their weight): inactive ones carry huge right-hand sides
        // whose rounding does not matter.
        let m_eq = self.normal.pattern.m_eq;
        let w_reg = self.w_reg.clone();
        let weighted = |b1: &[f64], b2: &[f64]| {
            b2.iter()
                .zip(&w_reg)
                .enumerate()
                .fold(inf_norm(b1), |a, (r, (b, w))| {
                    a.max(if r < m_eq { b.abs() } else { (b * w).abs() })
                })
        };
        let b_norm = weighted(b1, b2);
        let (mut last, mut last_x) = (f64::INFINITY, f64::INFINITY);
        let (mut e_norm, mut e_x, mut terms) = (0.0, 0.0, 0.0);
        // The error of `sol` where refinement stopped short of its round limit.
        let mut error = None;
        for _ in 0..10 {
            let (e1, e2, t) = self.error(&sol, b1, b2);
            (e_norm, e_x, terms) = (weighted(&e1, &e2), inf_norm(&e1), t);
            let x_progress = x_rows && e_norm <= last && e_x <= 0.75 * last_x;
            if e_norm <= tol * b_norm || (e_norm > 0.5 * last && !x_progress) {
                error = Some([e1, e2]);
                break;
            }
            (last, last_x) = (e_norm, e_x);
            let corr = self.approximate(&e1, &e2);
            for (s, c) in sol.iter_mut().zip(&corr) {
                s.iter_mut().zip(c).for_each(|(s, c)| *s += c);
            }
        }
        // Refined, an error in the x rows (the dual residual) still as large as the right-hand
        // side, and beyond rounding of the terms that make it up: a lost pivot. Constraint rows
        // converge at a rate set by δ / (s/z + δ), slowly where constraints are strongly
        // active, whatever the factor: an inexact direction there is still a good one.
        if !(e_x <= 0.5 * b_norm || e_x <= 1e-10 * terms) {
            return None;
        }
        // The x rows' error that remains is what the step leaves of the dual residual.
        if let Some(goal) = krylov_goal.filter(|&g| e_x > g && e_norm > tol * b_norm) {
            let error = error.unwrap_or_else(|| {
                let (e1, e2, _) = self.error(&sol, b1, b2);
                [e1, e2]
            });
            let bounds = (tol * b_norm, goal, 0.5 * b_norm);
            self.krylov(&mut sol, error, b1, b2, bounds, &weighted);
        }
        Some(sol)
    }

    /// The error b − K sol of the exact augmented system, by block, and the size of the x
    /// rows' terms.
    fn error(&self, [dx, w]: &[Vec<f64>; 2], b1: &[f64], b2: &[f64]) -> (Vec<f64>, Vec<f64>, f64) {
        let n = self.normal.pattern.n;
        let px = self.normal.mul_p(dx);
        let ct_w = mul_t(self.cons, w, n);
        let e1: Vec<f64> = (0..n).map(|i| b1[i] - px[i] - ct_w[i]).collect();
        let cdx = self.cons.mul(dx);
        let e2: Vec<f64> = (0..b2.len())
            .map(|i| b2[i] - cdx[i] + self.d[i] * w[i])
            .collect();
        (e1, e2, inf_norm(&px).max(inf_norm(&ct_w)))
    }

    /// K sol = (P dx + Cᵀ w, C dx − D w), summed in its own order, since only the Krylov
    /// cycles use it and `error`'s order fixes the rounding of everything else.
    fn product(&self, [dx, w]: &[Vec<f64>; 2]) -> [Vec<f64>; 2] {
        let n = self.normal.pattern.n;
        let px = self.normal.mul_p(dx);
        let ct_w = mul_t(self.cons, w, n);
        let k1 = px.iter().zip(&ct_w).map(|(a, b)| a + b).collect();
        let cdx = self.cons.mul(dx);
        let k2 = cdx
            .iter()
            .zip(&self.d)
            .zip(w)
            .map(|((c, d), w)| c - d * w)
            .collect();
        [k1, k2]
    }

    /// GMRES cycles on the exact augmented system, right-preconditioned by the regularised
    /// solve, rows scaled as refinement weighs them; from `sol`, whose error is `error`. Each
    /// cycle must reduce the weighted error; `sound` bounds the x rows' error of the answer
    /// (as `refine`'s test of a lost pivot does).
    fn krylov(
        &mut self,
        sol: &mut [Vec<f64>; 2],
        mut error: [Vec<f64>; 2],
        b1: &[f64],
        b2: &[f64],
        (target, goal, sound): (f64, f64, f64),
        weighted: &dyn Fn(&[f64], &[f64]) -> f64,
    ) {
        let n = self.normal.pattern.n;
        let m_eq = self.normal.pattern.m_eq;
        let scale: Vec<f64> = self
            .w_reg
            .iter()
            .enumerate()
            .map(|(r, w)| if r < m_eq { 1.0 } else { *w })
            .collect();
        let flatten = |[e1, e2]: &[Vec<f64>; 2]| -> Vec<f64> {
            e1.iter()
                .copied()
                .chain(e2.iter().zip(&scale).map(|(e, s)| e * s))
                .collect()
        };
        // A scaled residual back in the system's rows.
        let unscale = |v: &[f64]| -> (Vec<f64>, Vec<f64>) {
            (
                v[..n].to_vec(),
                v[n..].iter().zip(&scale).map(|(v, s)| v / s).collect(),
            )
        };
        let (mut e_norm, mut e_x) = (weighted(&error[0], &error[1]), inf_norm(&error[0]));
        let start_x = e_x;
        let mut current: Option<[Vec<f64>; 2]> = None;
        for _ in 0..KRYLOV_CYCLES {
            let r0 = flatten(&error);
            let mut op = |v: &[f64]| -> Vec<f64> {
                let (v1, v2) = unscale(v);
                let u = self.approximate(&v1, &v2);
                flatten(&self.product(&u))
            };
            let Some((y, _)) = gmres::cycle(&mut op, &r0, KRYLOV_BASIS, target.max(goal)) else {
                break;
            };
            let (y1, y2) = unscale(&y);
            let corr = self.approximate(&y1, &y2);
            let from = current.as_ref().unwrap_or(sol);
            let trial: [Vec<f64>; 2] =
                [0, 1].map(|k| from[k].iter().zip(&corr[k]).map(|(s, c)| s + c).collect());
            let (e1, e2, _) = self.error(&trial, b1, b2);
            let (trial_norm, trial_x) = (weighted(&e1, &e2), inf_norm(&e1));
            // (NaN included.)
            if trial_norm.partial_cmp(&e_norm) != Some(std::cmp::Ordering::Less) {
                break;
            }
            (current, error, e_norm, e_x) = (Some(trial), [e1, e2], trial_norm, trial_x);
            if e_norm <= target || e_x <= goal {
                break;
            }
        }
        // A cycle minimises the whole scaled error, so the x rows' part can rise on the way:
        // the cycles' answer is taken only if its x rows' error is no larger than
        // refinement's or within the bound that made refinement's answer sound.
        if let Some(current) = current.filter(|_| e_x <= start_x.max(sound)) {
            *sol = current;
        }
    }
}
