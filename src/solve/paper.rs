//! The paper's form-finding loop (MATH §11): stress step → stop if ε∞ < tol → height step
//! pulled towards the current heights → stop if the same forces certify ε∞ < tol at the new
//! heights, repeated.

use super::{
    blocking_vertices, falls_short, finish, infeasibility_hint, FormFindResult, FormFindSettings,
    Progress, Run, Termination, FAR_FROM_BALANCE,
};
use crate::error::Result;
use crate::problem::Problem;
use crate::shape::ShapeStep;
use crate::stress::{
    analyse_cached, Prior, StressCache, StressResult, StressSettings, StressStatus,
};
use std::time::Instant;

/// The paper's loop: stress step, then a height step pulled towards the current heights with
/// inverse-residual weights and a geometric schedule, repeated until ε∞ < tolerance.
pub(super) fn paper(
    problem: &Problem,
    settings: &FormFindSettings,
    progress: Option<&mut Progress>,
) -> Result<FormFindResult> {
    let start = Instant::now();
    let mesh = &problem.mesh;
    let z0: Vec<f64> = mesh.positions.iter().map(|p| p[2]).collect();
    let mut positions = mesh.positions.clone();
    let shape = ShapeStep::new(mesh)?;
    let mut progress = progress;
    let (mut history, mut stress_s, mut shape_s) = (Vec::new(), 0.0, 0.0);
    let mut best = f64::INFINITY;
    let mut best_at = 0;
    let mut last: Option<StressResult> = None;
    let mut termination = Termination::MaxIterations;
    let fans = crate::smooth::vertex_faces(mesh);
    // The mesh keeps its connectivity: the steps share one ordering and symbolic analysis.
    // Large QPs are solved to coarse optimality: the loop's answer is certified by its own
    // residuals, not by the QPs' optimality (see `StressCache::for_form_finding`).
    let mut cache = StressCache::for_form_finding();
    let mut stress_steps = 0;
    let mut solvers = Vec::new();
    for k in 0..settings.max_iterations.max(1) {
        if k < settings.odt_iterations {
            let t = Instant::now();
            crate::smooth::odt_sweep(mesh, &fans, &mut positions, settings.odt_free_boundary);
            shape_s += t.elapsed().as_secs_f64();
        }
        let t = Instant::now();
        let prior = last
            .as_ref()
            .filter(|s| s.status.is_solved())
            .map(|s| Prior {
                force_densities: &s.force_densities,
                weight: settings.proximal_weight,
                lifted_first: s.lifted,
            });
        // A fixed smoothing weight would keep trading residual for smoothness, so the loop
        // could not reach ε∞ → 0: the weight fades (and is dropped once negligible), the shape
        // adapts to the smoother stress of the early steps and the proximal term keeps it.
        let faded;
        let stress_settings = if settings.stress.dual_length_smoothing > 0.0 {
            let factor = settings.smoothing_decay.powi(k as i32);
            faded = StressSettings {
                dual_length_smoothing: settings.stress.dual_length_smoothing
                    * if factor > 1e-12 { factor } else { 0.0 },
                ..settings.stress.clone()
            };
            &faded
        } else {
            &settings.stress
        };
        cache.far_from_balance(last.as_ref().is_some_and(|s| s.eps_inf > FAR_FROM_BALANCE));
        let stress = analyse_cached(problem, &positions, stress_settings, prior, &mut cache)?;
        solvers.push(stress.solver);
        // A step that stopped short of its optimum may balance the shape worse than the forces
        // at hand (the previous ones, certified at these heights): those are kept instead,
        // unless ODT has just moved the plan under them.
        let stress = match last.take() {
            // A smoothed step trades residual for smoothness on purpose: only once the
            // smoothing has faded is a coarse one judged by its residual.
            Some(held)
                if k >= settings.odt_iterations
                    && falls_short(
                        &stress,
                        cache.last_was_coarse() && stress_settings.dual_length_smoothing == 0.0,
                        &held,
                    ) =>
            {
                held
            }
            _ => stress,
        };
        stress_s += t.elapsed().as_secs_f64();
        stress_steps += 1;
        history.push(stress.eps_inf);
        let status = stress.status;
        let eps = stress.eps_inf;
        last = Some(stress);
        if let Some(cb) = progress.as_mut() {
            if !cb(k, eps) {
                termination = Termination::Cancelled;
                break;
            }
        }
        match status {
            StressStatus::Infeasible => {
                termination = Termination::Infeasible {
                    constraint: infeasibility_hint(&settings.stress),
                };
                break;
            }
            StressStatus::NumericalError => {
                termination = Termination::NumericalError {
                    what: "stress QP failed".into(),
                };
                break;
            }
            _ => {}
        }
        if eps < settings.tolerance {
            termination = Termination::Converged;
            break;
        }
        if eps < best * 0.99 {
            best = eps;
            best_at = k;
        } else if k - best_at >= settings.stall_window {
            termination = Termination::Stalled {
                vertices: blocking_vertices(problem, last.as_ref().unwrap()),
            };
            break;
        }
        if k + 1 >= settings.max_iterations {
            break;
        }
        let t = Instant::now();
        let s = last.as_ref().unwrap();
        let z: Vec<f64> = positions.iter().map(|p| p[2]).collect();
        match shape.step(&s.force_densities, &s.loads, &z, &z0, k, &settings.schedule) {
            Ok(z_new) => positions.iter_mut().zip(z_new).for_each(|(p, z)| p[2] = z),
            Err(e) => {
                termination = Termination::NumericalError {
                    what: e.to_string(),
                };
                break;
            }
        }
        // Late shape steps balance the given forces almost exactly: when these forces already
        // balance the new shape, the next stress step (the most expensive one: its optimum is
        // nearly degenerate) would only confirm it. The certificate is recomputed from the
        // forces and the new heights, as for a stress step.
        let certified = s.at_heights(problem, &positions, stress_settings);
        shape_s += t.elapsed().as_secs_f64();
        let certified_eps = certified.eps_inf;
        last = Some(certified);
        if certified_eps < settings.tolerance {
            history.push(certified_eps);
            termination = Termination::Converged;
            break;
        }
    }
    let stress = last.expect("at least one iteration");
    Ok(finish(
        problem,
        Run {
            termination,
            iterations: stress_steps,
            solvers,
            positions,
            stress,
            history,
            stress_seconds: stress_s,
            shape_seconds: shape_s,
        },
        start,
    ))
}
