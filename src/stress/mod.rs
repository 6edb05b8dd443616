//! Stress optimisation: the best compressive force densities for a fixed shape
//! (docs/method.md §4–10).
//!
//! Both formulations build q = S y for their own unknowns and share one QP (`qp.rs`); the
//! result is recomputed in physical units from the returned force densities, so every figure
//! it reports (residuals, ε∞, imbalance) is a certificate, not the solver's own claim.

pub mod airy;
mod attempts;
mod cache;
mod certify;
mod framed;
mod gauge;
pub mod holes;
pub(crate) mod idle;
mod ipm;
pub(crate) mod linear;
mod physical;
mod qp;
pub mod settings;
pub mod sparse;

use crate::error::Result;
use crate::geometry::dual::{self, ForceDiagram};
use crate::problem::Problem;
use airy::HoleMode;
use attempts::{run_attempts, slot, Attempt, Attempts};
use cache::PlanKey;
pub use cache::{Prior, StressCache};
use clarabel::solver::SolverStatus;
use framed::FramedStep;
pub(crate) use framed::{carries_force, floored, force_density_bounds, non_anchored};
pub use framed::{MAX_MEAN_LOAD, MIN_MEAN_LOAD};
pub(crate) use physical::equilibrium;
use physical::{airy_and_centres, physical_hole_jumps, physical_tau, power_weights};
pub use settings::{EdgeScope, Formulation, QBound, QpSolver, StressSettings, TauMode};
use std::time::Instant;
use Formulation::Reduced;

/// How the stress QP ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum StressStatus {
    /// Solved to the solver's tolerances; in form finding beyond 20k unknowns to coarse
    /// optimality (relative gap 1e-3, bounds and equality rows as tight as ever).
    Solved,
    /// Solved to reduced accuracy.
    AlmostSolved,
    /// The constraints (q_min, q_max, prescribed forces, straight free edges) admit no stress.
    Infeasible,
    /// Stopped short of even the reduced accuracy: the iteration limit was reached, or (the
    /// native solver beyond 20k unknowns) 10 iterations went by without progress.
    MaxIterations,
    /// The solver failed numerically.
    NumericalError,
}

impl StressStatus {
    fn from_clarabel(s: SolverStatus) -> StressStatus {
        match s {
            SolverStatus::Solved => StressStatus::Solved,
            SolverStatus::AlmostSolved => StressStatus::AlmostSolved,
            SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => {
                StressStatus::Infeasible
            }
            SolverStatus::MaxIterations | SolverStatus::MaxTime => StressStatus::MaxIterations,
            _ => StressStatus::NumericalError,
        }
    }

    /// Preference among attempts: lower is better.
    fn rank(self) -> u8 {
        match self {
            StressStatus::Solved | StressStatus::Infeasible => 0,
            StressStatus::AlmostSolved => 1,
            StressStatus::MaxIterations => 2,
            StressStatus::NumericalError => 3,
        }
    }

    /// True when the force densities are a usable optimum.
    pub fn is_solved(self) -> bool {
        matches!(self, StressStatus::Solved | StressStatus::AlmostSolved)
    }
}

/// The outcome of one stress step, in physical units.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct StressResult {
    /// How the QP ended.
    pub status: StressStatus,
    /// Force density per mesh edge (compression positive; 0 on edges that carry none).
    pub force_densities: Vec<f64>,
    /// Airy value φ per vertex (0 at unreferenced vertices). Defined up to an affine function,
    /// which changes no force: the reduced formulation pins it to 0 at three free vertices far
    /// apart per component, the edge-based one integrates it from the first face.
    pub airy: Vec<f64>,
    /// Vertex weights w = |u|² − 2φ: the power diagram of (u, w) is the force diagram, except
    /// along the holes' cuts where φ jumps (φ is multivalued there; see `hole_coefficients`).
    pub weights: Vec<f64>,
    /// Hole jump M_h(u) = c + a·u per hole as (c, a_x, a_y), in the order of the mesh's holes:
    /// the change of the Airy function continued once counter-clockwise around the hole
    /// (independent of where the solver cut the domain). The cuts form a tree: each runs from
    /// its hole to the outer loop or to a hole cut before it, and across hole h's cut φ jumps
    /// by the sum of the coefficients of h and of every hole cut through h.
    pub hole_coefficients: Vec<[f64; 3]>,
    /// Inward normal push τ per vertex (non-zero only at free boundary vertices).
    pub tau: Vec<f64>,
    /// External horizontal force per vertex needed at free edges: P − τ ν.
    pub external_horizontal: Vec<[f64; 2]>,
    /// Vertical load per vertex used by this step.
    pub loads: Vec<f64>,
    /// Vertical residual Σ_j q_ij (z_i − z_j) − p_i per non-anchored vertex (0 elsewhere).
    pub residuals: Vec<f64>,
    /// Horizontal imbalance Σ_j q_ij (u_i − u_j) + external per non-anchored vertex.
    pub horizontal_imbalance: Vec<[f64; 2]>,
    /// max |r_i| / mean p_i over non-anchored vertices.
    pub eps_inf: f64,
    /// Σ r_i² over non-anchored vertices.
    pub objective: f64,
    /// The force diagram (reciprocal figure) of the forces.
    pub force_diagram: ForceDiagram,
    /// Iterations of the QP solvers, summed over the step's attempts (a native attempt that
    /// failed and the one that answered); 0 when the native solver reached the optimum from
    /// the previous step's active set alone (form finding reuses it between steps).
    pub iterations: u32,
    /// The formulation that produced the forces: the requested one, or the edge-based one when
    /// every reduced attempt failed numerically, when the native solver answered a mesh with
    /// a vertex of more than 64 edges, or when its reduced attempt failed and its edge-based
    /// one answered (same optimum; see `docs/method.md` §9). The Airy values, hole jumps and
    /// force diagram of a native edge-based answer to a reduced request are the reduced
    /// operator's where that attempt built it (fitted to the forces).
    pub formulation: Formulation,
    /// The solver that produced the answer (clarabel after a fallback from the native one).
    pub solver: QpSolver,
    /// Whether the answer came from the lifted form of the QP (q as variables).
    pub lifted: bool,
    /// The regulariser ε actually used (larger than the setting after a numerical failure).
    pub regularisation: f64,
    /// Wall time of the step.
    pub seconds: f64,
}

/// Optimises the stress of `problem` as given (its mesh positions).
///
/// The loads must weigh down: an [`Error::InvalidArgument`](crate::Error::InvalidArgument)
/// for `loads` when their mean over the non-anchored vertices is 0 (density 0 everywhere
/// without extra loads: nothing to balance), negative, or beyond what double precision can
/// carry through the solve ([`MIN_MEAN_LOAD`], [`MAX_MEAN_LOAD`]).
pub fn analyse(problem: &Problem, settings: &StressSettings) -> Result<StressResult> {
    let positions = &problem.mesh.positions;
    analyse_cached(
        problem,
        positions,
        settings,
        None,
        &mut StressCache::default(),
    )
}

/// The stress of `problem` with its vertices at `positions`, pulled towards `prior` if given
/// (see [`Prior`]), reusing and updating `cache`: form finding's steps keep one cache, so
/// that only the first step (and the first with a proximal centre) orders and analyses the
/// normal matrix, and each later step first tries the previous step's active set (bounds
/// held as equalities; not beyond 20k unknowns after [`StressCache::far_from_balance`]
/// with `true`), corrected a few times; only if that does not meet the solver's
/// tolerances do the interior-point iterations run. Either way the answer meets the same
/// optimality tolerances as without the cache (the optimum itself, not necessarily the same
/// point where the optimum is not unique), unless the cache is
/// [`StressCache::for_form_finding`]'s.
pub fn analyse_cached(
    problem: &Problem,
    positions: &[[f64; 3]],
    settings: &StressSettings,
    prior: Option<Prior>,
    cache: &mut StressCache,
) -> Result<StressResult> {
    settings.validate()?;
    crate::interrupt::poll();
    let start = Instant::now();
    let mesh = &problem.mesh;
    let n = positions.len();
    let step = FramedStep::new(problem, positions, settings, cache.load_offset.as_deref())?;
    crate::interrupt::poll();
    let (frame, plan, p_bar, unit) = (&step.frame, &step.plan, step.p_bar, step.unit);
    let l0 = frame.scale;
    let Attempts {
        best,
        mut models,
        kept_key,
    } = run_attempts(problem, &step, settings, prior, cache)?;
    let Attempt {
        solver,
        formulation: formulation_used,
        lifted,
        out,
        regularisation,
    } = best;
    cache.last_coarse = out.coarse;
    cache.last_inexact = out.inexact;
    let (map, _) = models[slot(formulation_used)]
        .take()
        .expect("model of the attempt");
    let status = out.status;
    let usable = status.is_solved() || status == StressStatus::MaxIterations;
    let y = if usable {
        out.y
    } else {
        vec![0.0; map.s().ncols]
    };
    let mut q_frame = map.s().mul(&y);
    let mut tau_frame = if usable { out.tau } else { vec![0.0; n] };
    let polished = (usable && status != StressStatus::Infeasible)
        .then(|| polish(problem, &step, settings, prior, cache, &q_frame, &tau_frame))
        .flatten();
    let y = match polished {
        Some(c) => {
            let y = refit(&map, &y, &q_frame, &c.q);
            (q_frame, tau_frame) = (c.q, c.tau);
            y
        }
        None => y,
    };
    let (airy_op, y) = match map.airy() {
        None if solver == QpSolver::Native => match reduced_view(&mut models, &q_frame) {
            Some((op, fitted)) => (Some(op), fitted),
            None => (None, y),
        },
        op => (op, y),
    };

    // Back to physical units.
    let force_densities: Vec<f64> = q_frame.iter().map(|q| q * unit).collect();
    let tau = physical_tau(problem, settings, &tau_frame, p_bar, n);
    let external_horizontal: Vec<[f64; 2]> = (0..n)
        .map(|v| {
            let f = problem.horizontal_forces[v];
            let normal = step.normal[v];
            [f[0] - tau[v] * normal[0], f[1] - tau[v] * normal[1]]
        })
        .collect();
    let (airy_frame, hole_frame, centres_frame) =
        airy_and_centres(mesh, plan, airy_op.as_ref(), &y, &q_frame);
    let airy: Vec<f64> = airy_frame.iter().map(|f| f * p_bar * l0).collect();
    let weights = power_weights(mesh, positions, &airy);
    let hole_coefficients = physical_hole_jumps(&hole_frame, p_bar, frame);
    let force_diagram = dual::diagram(mesh, &centres_frame, airy_op.as_ref(), &y, p_bar);
    let reduced_op = airy_op.or_else(|| models[slot(Reduced)].take().and_then(|m| m.0.airy()));
    cache.reduced = reduced_op.map(|op| {
        let key = kept_key.unwrap_or_else(|| PlanKey::of(mesh, plan, settings.holes));
        (key, op)
    });

    let (residuals, horizontal_imbalance) = equilibrium(
        mesh,
        positions,
        &force_densities,
        &step.load,
        &external_horizontal,
    );
    let max_r = (step.free.iter())
        .map(|&v| residuals[v as usize].abs())
        .fold(0.0, f64::max);
    let objective = (step.free.iter())
        .map(|&v| residuals[v as usize].powi(2))
        .sum();
    Ok(StressResult {
        status,
        force_densities,
        airy,
        weights,
        hole_coefficients,
        tau,
        external_horizontal,
        loads: step.load,
        residuals,
        horizontal_imbalance,
        eps_inf: max_r / p_bar,
        objective,
        force_diagram,
        iterations: out.iterations,
        solver,
        formulation: formulation_used,
        lifted,
        regularisation,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Whether the certificate polish runs on a step's answer: in a fresh analysis (not in form
/// finding, whose loop judges its steps by recomputed residuals), where the reduced optimum is
/// the edge-based one (affine hole jumps, or no holes), and where the answer nearly stands
/// (ε∞ below `POLISH_BELOW`), where the solvers' tolerances bound its residuals loosely.
const POLISH_BELOW: f64 = 1e-2;

/// The answer `q_frame`, `tau_frame` polished in edge coordinates (`certify`), if the polish
/// runs and improves it.
fn polish(
    problem: &Problem,
    step: &FramedStep,
    settings: &StressSettings,
    prior: Option<Prior>,
    cache: &StressCache,
    q_frame: &[f64],
    tau_frame: &[f64],
) -> Option<certify::Certified> {
    let mesh = &problem.mesh;
    let same_optimum = settings.holes == HoleMode::Affine || mesh.holes().next().is_none();
    if cache.coarse || cache.load_offset.is_some() || !same_optimum {
        return None;
    }
    let eps = (step.free.iter())
        .map(|&v| {
            let v = v as usize;
            let sum: f64 = (mesh.edges_at(v).iter())
                .map(|&e| {
                    let [a, b] = mesh.edges[e as usize].v.map(|x| x as usize);
                    let w = if a == v { b } else { a };
                    q_frame[e as usize] * (step.z[v] - step.z[w])
                })
                .sum();
            (sum - step.p[v]).abs()
        })
        .fold(0.0, f64::max);
    if eps.is_nan() || eps >= POLISH_BELOW {
        return None;
    }
    let (s, balance) = attempts::force_model(
        mesh,
        &step.plan,
        settings.holes,
        Formulation::EdgeBased,
        &step.bounds,
        &step.free,
        None,
    )
    .ok()?;
    let prior_frame: Option<Vec<f64>> =
        prior.map(|p| p.force_densities.iter().map(|q| q / step.unit).collect());
    let inp = qp::QpInput {
        s: s.s(),
        edges: &step.edges,
        length: &step.plan.length,
        u: &step.plan.u,
        z: &step.z,
        residual_vertices: &step.free,
        load: &step.p,
        balance_vertices: &balance,
        external: &step.external,
        tau_normal: &step.tau_normal,
        bounds: &step.bounds,
        regularisation: prior.map_or(settings.regularisation, |p| p.weight),
        prior: prior_frame.as_deref(),
        smoothing_pairs: &step.smoothing_pairs,
        smoothing: settings.dual_length_smoothing,
        lift_forces: false,
    };
    certify::certify(&inp, q_frame, tau_frame)
}

/// The unknowns of `map` for the polished force densities `q_new`: y itself in the edge-based
/// formulation; in the reduced one y moved by the least-squares fit of S Δy = q_new − q_old.
fn refit(map: &attempts::ForceMap, y: &[f64], q_old: &[f64], q_new: &[f64]) -> Vec<f64> {
    let dq: Vec<f64> = q_new.iter().zip(q_old).map(|(a, b)| a - b).collect();
    match map {
        attempts::ForceMap::Selection(s) => {
            let mut y = y.to_vec();
            for (e, &d) in dq.iter().enumerate() {
                if let Some((c, _)) = s.row(e).next() {
                    y[c] += d;
                }
            }
            y
        }
        attempts::ForceMap::Airy(op) => match certify::least_squares_fit(&op.s, &dq, q_new) {
            Some(dy) => y.iter().zip(&dy).map(|(a, b)| a + b).collect(),
            None => y.to_vec(),
        },
    }
}

/// The reduced view of a native answer of the edge-based form where the reduced attempt
/// before it failed (`attempts::native_fallback`; the reduced model is then built): the
/// reduced unknowns fitted by least squares to its force densities, so that its Airy values,
/// hole jumps and force diagram are the reduced operator's, as a reduced answer's are. The
/// fit is exact to rounding, because both forms have the same feasible force densities. The
/// model is left in place when there is none to fit or the fit fails.
fn reduced_view(
    models: &mut [Option<attempts::ForceModel>; 2],
    q_frame: &[f64],
) -> Option<(airy::AiryOperator, Vec<f64>)> {
    let (map, balance) = models[slot(Reduced)].take()?;
    let attempts::ForceMap::Airy(op) = map else {
        models[slot(Reduced)] = Some((map, balance));
        return None;
    };
    match certify::least_squares_fit(&op.s, q_frame, q_frame) {
        Some(y) => Some((op, y)),
        None => {
            models[slot(Reduced)] = Some((attempts::ForceMap::Airy(op), balance));
            None
        }
    }
}

/// The upper median (element len/2 in increasing order), found in linear time.
pub(crate) fn upper_median(mut values: Vec<f64>) -> Option<f64> {
    let k = values.len() / 2;
    (!values.is_empty()).then(|| *values.select_nth_unstable_by(k, f64::total_cmp).1)
}
