//! The attempts of a stress step: the native solver, then clarabel on the reduced QP plain
//! and lifted, with a larger ε, then the edge-based formulation, until one answer is final.

use super::airy::{self, AiryOperator};
use super::cache::{PlanKey, Prior, StressCache};
use super::framed::FramedStep;
use super::sparse::Csr;
use super::{ipm, qp, Formulation, QpSolver, StressSettings, StressStatus};
use crate::error::Result;
use crate::geometry::Plan;
use crate::mesh::Mesh;
use crate::problem::Problem;
use Formulation::{EdgeBased, Reduced};

/// The attempts of a stress step in order: (solver, formulation, lifted, factor on ε).
///
/// The native solver goes first, in `native` form, then (with `edge_fallback`) natively in
/// the edge-based form, whose optimum is the same (see `native_fallback`); with `edge_first`
/// (the last step's answer came from that fallback) the edge-based form goes first. Interior-point
/// methods can fail on degenerate problems (straight free edges force q = 0: no strictly
/// feasible point), and only clarabel certifies infeasibility, so when the native attempts
/// do not converge clarabel takes over: the plain reduced QP is fastest; the lifted one (q
/// as variables) copes with problems where the plain one reaches only reduced accuracy.
/// Then ε is raised, then the edge-based formulation (same optimum) is used; the result
/// says which solver, formulation and ε.
pub(super) fn attempt_list(
    settings: &StressSettings,
    lifted_first: bool,
    native: Formulation,
    (edge_fallback, edge_first): (bool, bool),
) -> Vec<(QpSolver, Formulation, bool, f64)> {
    use QpSolver::{Clarabel, Native};
    let (a, b) = (lifted_first, !lifted_first);
    let mut attempts: Vec<(QpSolver, Formulation, bool, f64)> = Vec::new();
    if settings.solver == Native {
        attempts.push((Native, native, false, 1.0));
        if edge_fallback && native == Reduced {
            let at = if edge_first { 0 } else { 1 };
            attempts.insert(at, (Native, EdgeBased, false, 1.0));
        }
    }
    match settings.formulation {
        Reduced => attempts.extend_from_slice(&[
            (Clarabel, Reduced, a, 1.0),
            (Clarabel, Reduced, b, 1.0),
            (Clarabel, Reduced, a, 100.0),
            (Clarabel, Reduced, b, 100.0),
            (Clarabel, EdgeBased, false, 1.0),
            (Clarabel, EdgeBased, false, 100.0),
        ]),
        EdgeBased => attempts.extend_from_slice(&[
            (Clarabel, EdgeBased, false, 1.0),
            (Clarabel, EdgeBased, false, 100.0),
            (Clarabel, EdgeBased, false, 1e4),
        ]),
    }
    attempts
}

/// A vertex with more edges than this is a hub (a fan's centre, a UV sphere's pole): see
/// `native_formulation`.
const HUB_EDGES: usize = 64;

/// The formulation of the native attempt: the requested one, except that the reduced QP of a
/// mesh with a hub is solved in the edge-based form, which has the same optimum (§9 of
/// docs/method.md; with constant hole jumps only where there are no holes). A hub's thin
/// fan of faces makes the Airy values' map to force densities ill-conditioned (its cotangents
/// grow with the fan's size) and the bounds of the edges around it dependent when all are
/// active: on a wheel of 1000 spokes the interior-point iterations stalled short of the
/// tolerances, while in the edge-based form each bound is a force density of its own.
fn native_formulation(mesh: &Mesh, settings: &StressSettings) -> Formulation {
    let hub = (0..mesh.positions.len()).any(|v| mesh.edges_at(v).len() > HUB_EDGES);
    if settings.formulation == Reduced && same_optimum(mesh, settings) && hub {
        EdgeBased
    } else {
        settings.formulation
    }
}

/// Whether the reduced QP's optimum is the edge-based one (§9 of docs/method.md): with
/// affine hole jumps, or without holes.
fn same_optimum(mesh: &Mesh, settings: &StressSettings) -> bool {
    settings.holes == airy::HoleMode::Affine || mesh.holes().next().is_none()
}

/// Whether a reduced native attempt that fails is followed by a native edge-based one, before
/// clarabel: where both forms have the same optimum. The reduced unknowns are Airy values,
/// about (L/h)² larger than the force densities they are differences of (L the extent of
/// the mesh, h an edge length), and near balance, where the optimum is flat and tiny and
/// many bounds are nearly active, the interior-point directions carry that cancellation's
/// rounding: on cheese's last nearest-method QP (3 987 unknowns, Airy values ~1e5 in the
/// scaled units, the objective computed to ±5e-6 where it is ~1e-11) the dual residual
/// stalls at 1–30 times its tolerance, steps are cut short by rows whose slacks the
/// directions move by a hundred times their size, and the gap stays near 1e-9 (its
/// tolerance 1e-12) through the whole iteration budget. In the edge-based form each bound
/// is a force density of its own and the same QP solves cold in 25 iterations.
fn native_fallback(mesh: &Mesh, settings: &StressSettings) -> bool {
    settings.formulation == Reduced && same_optimum(mesh, settings)
}

/// The index of a formulation's force model in `Attempts::models`.
pub(super) fn slot(f: Formulation) -> usize {
    (f == EdgeBased) as usize
}

/// What the attempts of a stress step leave: the best answer (its iterations summed over every
/// attempt), the force models built (index `slot`), and the key of the reduced operator taken
/// from the cache, if one was.
pub(super) struct Attempts {
    pub(super) best: Attempt,
    pub(super) models: [Option<ForceModel>; 2],
    pub(super) kept_key: Option<PlanKey>,
}

/// Runs the attempts of `attempt_list` until one is final (`attempt_is_final`), building
/// each formulation's force model at most once, and keeps the best answer.
pub(super) fn run_attempts(
    problem: &Problem,
    step: &FramedStep,
    settings: &StressSettings,
    prior: Option<Prior>,
    cache: &mut StressCache,
) -> Result<Attempts> {
    use QpSolver::{Clarabel, Native};
    let mesh = &problem.mesh;
    let plan = &step.plan;
    let native = native_formulation(mesh, settings);
    let attempts = attempt_list(
        settings,
        prior.is_some_and(|p| p.lifted_first),
        native,
        (native_fallback(mesh, settings), cache.native_fallback_first),
    );
    let base = prior.map_or(settings.regularisation, |p| p.weight);
    let prior_frame: Option<Vec<f64>> =
        prior.map(|p| p.force_densities.iter().map(|q| q / step.unit).collect());
    let mut models: [Option<ForceModel>; 2] = [None, None];
    let mut best: Option<Attempt> = None;
    let mut clarabel_tries = 0;
    // The key of a kept reduced operator, stored back with it after the step.
    let mut kept_key = None;
    let mut iterations = 0;
    for (k, &(solver, formulation, lift_forces, factor)) in attempts.iter().enumerate() {
        if models[slot(formulation)].is_none() {
            let kept = (cache.reduced.take())
                .filter(|(key, _)| formulation == Reduced && key.fits(mesh, plan, settings.holes))
                .map(|(key, op)| {
                    kept_key = Some(key);
                    op
                });
            models[slot(formulation)] = Some(force_model(
                mesh,
                plan,
                settings.holes,
                formulation,
                &step.bounds,
                &step.free,
                kept,
            )?);
        }
        let (map, balance) = models[slot(formulation)].as_ref().expect("built above");
        let s = map.s();
        let regularisation = (base * factor).max(if factor > 1.0 { 1e-12 } else { 0.0 });
        let input = qp::QpInput {
            s,
            edges: &step.edges,
            length: &plan.length,
            u: &plan.u,
            z: &step.z,
            residual_vertices: &step.free,
            load: &step.p,
            balance_vertices: balance,
            external: &step.external,
            tau_normal: &step.tau_normal,
            bounds: &step.bounds,
            regularisation,
            prior: prior_frame.as_deref(),
            smoothing_pairs: &step.smoothing_pairs,
            smoothing: settings.dual_length_smoothing,
            lift_forces,
        };
        let out = match solver {
            Native => {
                // The fallback form keeps its own structure and last answer, so that the
                // native form's warm start carries on at the next step.
                let normal = if formulation == native {
                    &mut cache.normal
                } else {
                    &mut cache.fallback
                };
                // In form finding (whose loop judges each answer and takes another step) a
                // stall hands over to the next native attempt, which has the same optimum. A
                // fresh analysis crawls on: an answer near the tolerances is what its
                // certificate polish needs, and the hard QPs it meets reach one only there.
                let stall_exit = cache.coarse && attempts.get(k + 1).is_some_and(|a| a.0 == Native);
                qp::solve_native(&input, normal, (cache.coarse, cache.inexact), stall_exit)
            }
            Clarabel => {
                clarabel_tries += 1;
                qp::solve_clarabel(&input)
            }
        };
        let status = out.status;
        let n_unknowns = out.y.len();
        iterations += out.iterations;
        if best
            .as_ref()
            .is_none_or(|b| status.rank() < b.out.status.rank())
        {
            best = Some(Attempt {
                solver,
                formulation,
                lifted: lift_forces,
                out,
                regularisation,
            });
        }
        if attempt_is_final(solver, status, n_unknowns, clarabel_tries) {
            break;
        }
    }
    let mut best = best.expect("at least one attempt");
    best.out.iterations = iterations;
    // Consecutive QPs of a form finding differ little: the form that answered goes first.
    cache.native_fallback_first =
        best.solver == Native && best.formulation != native && best.out.status.is_solved();
    Ok(Attempts {
        best,
        models,
        kept_key,
    })
}

/// One solve of the stress QP: the formulation, the outcome and ε.
pub(super) struct Attempt {
    pub(super) solver: QpSolver,
    pub(super) formulation: Formulation,
    pub(super) lifted: bool,
    pub(super) out: qp::QpOutput,
    pub(super) regularisation: f64,
}

/// The force map q = S y of a formulation: the reduced operator, whose S it is, or the
/// edge-based selection of the edges that carry force.
pub(super) enum ForceMap {
    Airy(AiryOperator),
    Selection(Csr),
}

impl ForceMap {
    pub(super) fn s(&self) -> &Csr {
        match self {
            ForceMap::Airy(op) => &op.s,
            ForceMap::Selection(s) => s,
        }
    }

    pub(super) fn airy(self) -> Option<AiryOperator> {
        match self {
            ForceMap::Airy(op) => Some(op),
            ForceMap::Selection(_) => None,
        }
    }
}

/// A formulation's force map and the vertices that need explicit horizontal balance rows.
pub(super) type ForceModel = (ForceMap, Vec<u32>);

pub(super) fn force_model(
    mesh: &Mesh,
    plan: &Plan,
    holes: airy::HoleMode,
    formulation: Formulation,
    bounds: &[Option<(f64, f64)>],
    free: &[u32],
    kept: Option<AiryOperator>,
) -> Result<ForceModel> {
    Ok(match formulation {
        Formulation::Reduced => {
            let op = match kept {
                Some(op) => op,
                None => AiryOperator::new(mesh, plan, holes)?,
            };
            let balance = free
                .iter()
                .copied()
                .filter(|&v| mesh.on_boundary[v as usize])
                .collect();
            (ForceMap::Airy(op), balance)
        }
        Formulation::EdgeBased => {
            let mut s = Csr::new(bounds.iter().flatten().count());
            let mut col = 0;
            for b in bounds {
                s.push_row(if b.is_some() {
                    vec![(col, 1.0)]
                } else {
                    Vec::new()
                });
                col += b.is_some() as usize;
            }
            // Interior point supports take vertical reactions only (docs/method.md §6).
            let balance = (0..mesh.positions.len())
                .filter(|&v| mesh.referenced[v] && (!mesh.anchored[v] || !mesh.on_boundary[v]))
                .map(|v| v as u32)
                .collect();
            (ForceMap::Selection(s), balance)
        }
    })
}

/// Whether an attempt's answer ends the list of attempts in `analyse_cached`.
/// - Native: only a converged answer stands (at reduced accuracy it can sit at a point that
///   is not optimal), except on large problems, where the fallback would take many minutes:
///   there an answer at reduced accuracy, at the iteration limit or where the iterations
///   stalled is kept and reported as such.
/// - Clarabel solved or infeasible: done. Reduced accuracy: one more try with the other form
///   of the same problem, then keep the better. Numerical failure: go down the list.
pub(super) fn attempt_is_final(
    solver: QpSolver,
    status: StressStatus,
    n_unknowns: usize,
    clarabel_tries: usize,
) -> bool {
    use QpSolver::Native;
    match (solver, status) {
        (Native, StressStatus::AlmostSolved | StressStatus::MaxIterations) => {
            ipm::fallback_is_costly(n_unknowns)
        }
        (Native, s) => s == StressStatus::Solved,
        (_, StressStatus::Solved | StressStatus::Infeasible) => true,
        (_, StressStatus::AlmostSolved | StressStatus::MaxIterations) => clarabel_tries >= 2,
        (_, StressStatus::NumericalError) => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn large_native_answers_short_of_the_optimum_are_kept() {
        use QpSolver::{Clarabel, Native};
        use StressStatus::*;
        let (small, large) = (5_000, 100_000);
        for status in [AlmostSolved, MaxIterations] {
            assert!(!attempt_is_final(Native, status, small, 0));
            assert!(attempt_is_final(Native, status, large, 0));
            assert!(!attempt_is_final(Clarabel, status, large, 1));
            assert!(attempt_is_final(Clarabel, status, large, 2));
        }
        // Only clarabel certifies infeasibility: a failed native solve falls back at any size.
        assert!(!attempt_is_final(Native, NumericalError, large, 0));
        assert!(attempt_is_final(Native, Solved, small, 0));
        assert!(attempt_is_final(Clarabel, Infeasible, large, 1));
    }
}
