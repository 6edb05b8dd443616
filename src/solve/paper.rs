//! The paper's form-finding loop (docs/method.md §13): stress step → stop if ε∞ < tol → height step
//! pulled towards the current heights → stop if the same forces certify ε∞ < tol at the new
//! heights, repeated.

use super::{
    blocked_region, blocking_vertices, falls_short, finish, infeasibility_hint, meets_bounds,
    FormFindResult, FormFindSettings, Progress, Run, Termination, FAR_FROM_BALANCE, LIMIT_HINT,
};
use crate::error::Result;
use crate::geometry::Frame;
use crate::problem::Problem;
use crate::shape::ShapeStep;
use crate::smooth::Odt;
use crate::stress::{
    analyse_cached, Prior, StressCache, StressResult, StressSettings, StressStatus,
};
use std::borrow::Cow;
use std::time::Instant;

/// A bound on every height's change from reference heights: `max_height_change`, which the
/// paper's loop holds from its own input, and from the nearest method's input when it
/// continues from that method's best state (`Nearest::polish`).
pub(super) struct HeightLimit<'a> {
    /// The reference heights, per vertex.
    pub(super) z0: &'a [f64],
    /// The largest change allowed, physical.
    pub(super) limit: f64,
    /// The vertices a height step was brought back at so far, and a mask of them.
    pub(super) held: Vec<u32>,
    is_held: Vec<bool>,
}

impl<'a> HeightLimit<'a> {
    /// Changes from `z0` of at most `limit` (physical), none held back yet.
    pub(super) fn new(z0: &'a [f64], limit: f64) -> Self {
        HeightLimit {
            z0,
            limit,
            held: Vec::new(),
            is_held: vec![false; z0.len()],
        }
    }

    /// `z` for vertex `v`, brought back within the limit (and recorded) where it is beyond.
    fn hold(&mut self, v: usize, z: f64) -> f64 {
        let reference = self.z0[v];
        if (z - reference).abs() <= self.limit {
            return z;
        }
        if !self.is_held[v] {
            self.is_held[v] = true;
            self.held.push(v as u32);
        }
        within_limit(z, reference, self.limit)
    }

    /// How a loop held by this limit ended: one that did not converge with heights held back
    /// at the limit was blocked there (the region named from `answer`, the state answered).
    pub(super) fn ending(
        self,
        problem: &Problem,
        ended: Termination,
        answer: &StressResult,
    ) -> Termination {
        match ended {
            Termination::MaxIterations | Termination::Stalled { .. } if !self.held.is_empty() => {
                Termination::Blocked {
                    vertices: blocked_region(problem, &self.held, answer),
                    hint: LIMIT_HINT.into(),
                }
            }
            t => t,
        }
    }
}

/// `z` brought back within `limit` of `reference`, and then by ulps towards it where
/// `reference ± limit` rounds outward (a limit below the heights' resolution keeps the
/// reference): |result − reference| <= limit as computed.
pub(super) fn within_limit(z: f64, reference: f64, limit: f64) -> f64 {
    let mut h = z.clamp(reference - limit, reference + limit);
    while (h - reference).abs() > limit {
        h = one_ulp_towards(h, reference);
    }
    h
}

/// The double next to `h` on the side of `target` (`h` finite, `target` different).
pub(super) fn one_ulp_towards(h: f64, target: f64) -> f64 {
    let smallest = f64::from_bits(1);
    let bits = h.to_bits();
    match (h == 0.0, target > h, h > 0.0) {
        (true, up, _) => smallest.copysign(if up { 1.0 } else { -1.0 }),
        // Away from zero the magnitude, and so the bits, grow.
        (false, up, positive) if up == positive => f64::from_bits(bits + 1),
        _ => f64::from_bits(bits - 1),
    }
}

/// Sets the heights of `positions` to `z`, each brought back within `limit` of its reference
/// where one is given (and recorded there).
fn set_heights(positions: &mut [[f64; 3]], z: Vec<f64>, mut limit: Option<&mut HeightLimit>) {
    for (v, (p, z)) in positions.iter_mut().zip(z).enumerate() {
        p[2] = match limit.as_deref_mut() {
            Some(l) => l.hold(v, z),
            None => z,
        };
    }
}

/// One ODT sweep (docs/method.md §12), its resampled heights brought back within `limit`;
/// true when the plan has settled (the sweep no longer raises its quality).
pub(super) fn sweep_within(
    odt: &mut Odt,
    mesh: &crate::mesh::Mesh,
    positions: &mut [[f64; 3]],
    limit: Option<&mut HeightLimit>,
) -> bool {
    let settled = !odt.sweep(mesh, positions);
    let z: Vec<f64> = positions.iter().map(|p| p[2]).collect();
    set_heights(positions, z, limit);
    settled
}

/// The paper's loop: stress step, then a height step pulled towards the current heights with
/// inverse-residual weights and a geometric schedule, repeated until a state is certified
/// (docs/method.md §13.1); every
/// height held within `max_height_change` of the input, and a loop that did not converge
/// with heights held back is `Blocked` there.
pub(super) fn paper(
    problem: &Problem,
    settings: &FormFindSettings,
    progress: Option<&mut Progress>,
) -> Result<FormFindResult> {
    let mesh = &problem.mesh;
    let z0: Vec<f64> = mesh.positions.iter().map(|p| p[2]).collect();
    let frame = Frame::of(mesh, &mesh.positions);
    let mut limit = HeightLimit::new(&z0, settings.max_height_change * 2.0 * frame.scale);
    let (mut result, _) = paper_within(problem, settings, progress, Some(&mut limit))?;
    let ended = std::mem::replace(&mut result.termination, Termination::MaxIterations);
    result.termination = limit.ending(problem, ended, &result.stress);
    Ok(result)
}

/// The paper's loop with every height step brought back within `limit` (None: unbounded),
/// and whether the answer's forces pass their bound check (its own: a stress step's fresh
/// answer is checked for compression, forces kept at new heights against every bound).
pub(super) fn paper_within(
    problem: &Problem,
    settings: &FormFindSettings,
    progress: Option<&mut Progress>,
    mut limit: Option<&mut HeightLimit>,
) -> Result<(FormFindResult, bool)> {
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
    let mut odt = Odt::new(mesh, &positions, settings.odt_free_boundary);
    // The mesh keeps its connectivity: the steps share one ordering and symbolic analysis.
    // Large QPs are solved to coarse optimality: the loop's answer is certified by its own
    // residuals, not by the QPs' optimality (see `StressCache::for_form_finding`).
    let mut cache = StressCache::for_form_finding();
    let (mut solvers, mut qp_iterations) = (Vec::new(), Vec::new());
    let mut lowest = Lowest::default();
    for k in 0..settings.max_iterations.max(1) {
        let t = Instant::now();
        let plan_settled = k >= settings.odt_iterations
            || sweep_within(&mut odt, mesh, &mut positions, limit.as_deref_mut());
        shape_s += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let prior = prior(last.as_ref(), settings);
        let stress_settings = &faded(settings, k);
        cache.far_from_balance(last.as_ref().is_some_and(|s| s.eps_inf > FAR_FROM_BALANCE));
        let stress = analyse_cached(problem, &positions, stress_settings, prior, &mut cache)?;
        solvers.push(stress.solver);
        qp_iterations.push(stress.iterations);
        let (stress, fresh) =
            keep_better(stress, last.take(), &cache, stress_settings, plan_settled);
        stress_s += t.elapsed().as_secs_f64();
        history.push(stress.eps_inf);
        let status = stress.status;
        let eps = stress.eps_inf;
        let fresh = fresh && stress.status == StressStatus::Solved;
        let balanced = super::certified(problem, settings, &positions, &stress, fresh);
        let within = meets_bounds(problem, stress_settings, &positions, &stress, fresh);
        lowest.offer(&positions, &stress, within);
        last = Some(stress);
        if let Some(cb) = progress.as_mut() {
            if !cb(k, eps) {
                termination = Termination::Cancelled;
                break;
            }
        }
        if let Some(failed) = failure(status, problem, settings) {
            termination = failed;
            break;
        }
        if balanced {
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
            Ok(z_new) => set_heights(&mut positions, z_new, limit.as_deref_mut()),
            Err(e) => {
                termination = super::numerical(e);
                break;
            }
        }
        // Late shape steps balance the given forces almost exactly: when these forces already
        // balance the new shape, the next stress step (the most expensive one: its optimum is
        // nearly degenerate) would only confirm it. The certificate is recomputed from the
        // forces and the new heights, as for a stress step; relative bounds move with the
        // loads, so the same forces may fall short of them at the new heights.
        let certified = s.at_heights(problem, &positions, stress_settings);
        shape_s += t.elapsed().as_secs_f64();
        let balanced = super::certified(problem, settings, &positions, &certified, false);
        history.extend(balanced.then_some(certified.eps_inf));
        last = Some(certified);
        if balanced {
            termination = Termination::Converged;
            break;
        }
    }
    let last = last.expect("at least one iteration");
    let (positions, stress, within) = lowest.unless_converged(&termination, positions, last);
    let result = finish(
        problem,
        Run {
            termination,
            iterations: solvers.len(),
            solvers,
            qp_iterations,
            positions,
            stress,
            history,
            mirrored: false,
            stress_seconds: stress_s,
            shape_seconds: shape_s,
            warm: None,
        },
        start,
    );
    Ok((result, within))
}

/// The lowest-ε∞ state of the stress steps (heights with the forces certified there, the
/// states the history lists) among those whose forces pass their bound check, else among all
/// usable ones: the answer of a loop that ends without converging (later steps of a stalled
/// loop may have moved further from balance).
#[derive(Default)]
struct Lowest {
    within: Option<(Vec<[f64; 3]>, StressResult)>,
    any: Option<(Vec<[f64; 3]>, StressResult)>,
}

impl Lowest {
    /// Offers a state; `within`: whether its forces pass their bound check.
    fn offer(&mut self, positions: &[[f64; 3]], stress: &StressResult, within: bool) {
        let usable = !matches!(
            stress.status,
            StressStatus::Infeasible | StressStatus::NumericalError
        );
        let slots = [(within, &mut self.within), (true, &mut self.any)];
        for (take, slot) in slots {
            if usable
                && take
                && slot
                    .as_ref()
                    .is_none_or(|(_, s)| stress.eps_inf < s.eps_inf)
            {
                *slot = Some((positions.to_vec(), stress.clone()));
            }
        }
    }

    /// The state to answer: the lowest-ε∞ one unless the loop converged in its last state
    /// (certified, so within its bounds); and whether its forces pass their bound check.
    fn unless_converged(
        self,
        termination: &Termination,
        positions: Vec<[f64; 3]>,
        stress: StressResult,
    ) -> (Vec<[f64; 3]>, StressResult, bool) {
        if *termination == Termination::Converged {
            return (positions, stress, true);
        }
        match (self.within, self.any) {
            (Some((p, s)), _) => (p, s, true),
            (None, Some((p, s))) => (p, s, false),
            (None, None) => (positions, stress, false),
        }
    }
}

/// The proximal term towards the previous step's forces, when that step was solved.
fn prior<'a>(last: Option<&'a StressResult>, settings: &FormFindSettings) -> Option<Prior<'a>> {
    last.filter(|s| s.status.is_solved()).map(|s| Prior {
        force_densities: &s.force_densities,
        weight: settings.proximal_weight,
        lifted_first: s.lifted,
    })
}

/// The stress settings of step `k`: a fixed smoothing weight would keep trading residual for
/// smoothness, so the loop could not reach ε∞ → 0; the weight fades (and is dropped once
/// negligible), the shape adapts to the smoother stress of the early steps and the proximal
/// term keeps it.
fn faded(settings: &FormFindSettings, k: usize) -> Cow<'_, StressSettings> {
    if settings.stress.dual_length_smoothing > 0.0 {
        let factor = settings.smoothing_decay.powi(k as i32);
        let mut faded = settings.stress.clone();
        faded.dual_length_smoothing *= if factor > 1e-12 { factor } else { 0.0 };
        Cow::Owned(faded)
    } else {
        Cow::Borrowed(&settings.stress)
    }
}

/// The stress step's answer (with true), or the forces at hand (the previous ones, certified
/// at these heights; with false) when the step stopped short of its optimum and balances the
/// shape worse, unless ODT has just moved the plan under them (`plan_settled` false).
fn keep_better(
    stress: StressResult,
    held: Option<StressResult>,
    cache: &StressCache,
    settings: &StressSettings,
    plan_settled: bool,
) -> (StressResult, bool) {
    // A smoothed step trades residual for smoothness on purpose: only once the smoothing has
    // faded is a coarse one judged by its residual.
    let coarse = cache.last_was_coarse() && settings.dual_length_smoothing == 0.0;
    match held {
        Some(held) if plan_settled && falls_short(&stress, coarse, &held) => (held, false),
        _ => (stress, true),
    }
}

/// The termination for a stress step that failed, if it did.
fn failure(
    status: StressStatus,
    problem: &Problem,
    settings: &FormFindSettings,
) -> Option<Termination> {
    match status {
        StressStatus::Infeasible => Some(Termination::Infeasible {
            constraint: infeasibility_hint(problem, &settings.stress),
        }),
        StressStatus::NumericalError => Some(Termination::NumericalError {
            what: "stress QP failed".into(),
        }),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::{one_ulp_towards, within_limit};

    #[test]
    fn one_ulp_steps_towards_the_target_on_either_side_of_zero() {
        let (eps, tiny) = (f64::EPSILON, f64::from_bits(1));
        assert_eq!(one_ulp_towards(1.0, 2.0), 1.0 + eps);
        assert_eq!(one_ulp_towards(1.0, 0.0), 1.0 - eps / 2.0);
        assert_eq!(one_ulp_towards(-1.0, 0.0), -1.0 + eps / 2.0);
        assert_eq!(one_ulp_towards(-1.0, -2.0), -1.0 - eps);
        assert_eq!(one_ulp_towards(0.0, 1.0), tiny);
        assert_eq!(one_ulp_towards(0.0, -1.0), -tiny);
        assert_eq!(one_ulp_towards(tiny, -1.0), 0.0);
    }

    #[test]
    fn a_height_held_at_the_limit_is_within_it_as_computed() {
        for reference in [1.6218379944259198, -0.3, 1e-300, 7.0] {
            for limit in [0.0, 1e-17, 1e-15, 3e-13, 0.1] {
                for z in [reference + 1.0, reference - 1.0, reference] {
                    let h = within_limit(z, reference, limit);
                    assert!(
                        (h - reference).abs() <= limit,
                        "{reference} {limit} {z}: {h}"
                    );
                    // At most an ulp inside the limit (or the reference itself).
                    let back = one_ulp_towards(h, z);
                    assert!(
                        h == z || (back - reference).abs() > limit,
                        "{reference} {limit} {z}"
                    );
                }
            }
        }
    }
}
