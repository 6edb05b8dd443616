//! The nearest self-supporting shape (docs/method.md §13): minimise
//!
//!   E(z) = Σ_i a_i (Δz_i / L₀)² + γ Σ_e c_e ((Δz_i − Δz_j) / L₀)²,   Δz = z − z⁰,
//!
//! over the heights of the non-anchored vertices, subject to equilibrium r̂(z, y) = 0 under the
//! stress constraints (r̂ = r / (p̄ √n), y the stress unknowns), by the method of multipliers:
//! for fixed multipliers λ and weight w, the augmented Lagrangian L = E + w ‖r̂ + λ/2w‖² is
//! lowered by alternating exact block minimisations. For fixed forces L is a convex quadratic
//! in z (loads lagged): the height step solves it, then is shortened to the height limit and
//! until L with the loads recomputed decreases. For fixed heights the stress QP minimises
//! ‖r̂ + λ/2w‖² (the loads shifted by −p̄ √n λ/2w); an answer that does worse than the forces
//! at hand is not taken. So every accepted step lowers L. When a round no longer lowers it by
//! a fixed fraction, λ ← λ + 2w r̂, and w grows unless ‖r̂‖ has fallen enough. The answer is
//! the nearest stress step's state in equilibrium (ε∞ < tolerance, certified by recomputed
//! residuals), taken once a further one is no nearer.

use super::paper::{one_ulp_towards, paper_within, sweep_within, within_limit, HeightLimit};
use super::warm::{faces_fingerprint, Continuation};
use super::{
    area_shares, blocked_region, blocking_vertices, certified, finish, infeasibility_hint,
    meets_bounds, FormFindResult, FormFindSettings, Progress, Run, Termination, FAR_FROM_BALANCE,
    LIMIT_HINT,
};
use crate::error::Result;
use crate::geometry::Frame;
use crate::problem::Problem;
use crate::shape::ShapeStep;
use crate::smooth::Odt;
use crate::stress::{
    analyse_cached, Prior, QpSolver, StressCache, StressResult, StressSettings, StressStatus,
};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// A round (a height and a stress step) that lowers L by less than this fraction ends the
/// minimisation for the current multipliers.
const STAGE_DECREASE: f64 = 0.02;
/// Rounds at most between multiplier updates.
const STAGE_ROUNDS: usize = 6;
/// Factor on w when it grows.
const GROWTH: f64 = 10.0;
/// Halvings of a height step before it is given up.
const BACKTRACKS: usize = 6;
/// The grid of the starting weight, w × factorᵏ for k < trials, and the decrease of R its
/// first height step must reach (see `Nearest::initial_weight`).
const INITIAL_WEIGHT_FACTOR: f64 = 3.0;
const INITIAL_WEIGHT_TRIALS: usize = 40;
const INITIAL_DECREASE: f64 = 0.02;
/// The multipliers are updated where ‖r̂‖ has fallen below this fraction of its value at the
/// last update; otherwise w grows.
const RESIDUAL_FACTOR: f64 = 0.5;
/// A state in equilibrium that is no nearer than the nearest one before it by this fraction
/// of E ends the search.
const SETTLED: f64 = 1e-3;
/// The pull towards the input in the solve for the unloaded surface over the supports
/// (`Nearest::hanging_mirror`), relative to the mean diagonal of KᵀK per vertex.
const MEMBRANE_PULL: f64 = 1e-12;
/// The loosest relative gap of an inexact stress QP (see `Nearest::inexact_gap`).
const INEXACT_GAP_MAX: f64 = 1e-4;

/// Where a warm re-solve's penalty weight starts between the previous run's first (0) and
/// last (1) weight, geometrically (see `Nearest::start_from`).
const WARM_WEIGHT: f64 = 0.25;

/// Stalling is judged only once w has grown by this factor from its start: before, the pull
/// to the input may hold ε∞ up on purpose (rounds that still lower L also count as progress).
const STALL_AFTER_GROWTH: f64 = 1e3;

pub(super) fn nearest(
    problem: &Problem,
    settings: &FormFindSettings,
    progress: Option<&mut Progress>,
) -> Result<FormFindResult> {
    let start = Instant::now();
    let mut state = Nearest::new(problem, settings, progress)?;
    let ended = state.run()?;
    state.conclude(ended, start)
}

/// The nearest method started from `previous` (checked to fit by `warm::check`): its heights,
/// forces and, with `continuation`, its penalty state (see [`super::form_find_from`]).
pub(super) fn nearest_from(
    problem: &Problem,
    settings: &FormFindSettings,
    previous: &FormFindResult,
    continuation: Option<&Continuation>,
    progress: Option<&mut Progress>,
) -> Result<FormFindResult> {
    if previous.mirrored || far_from_edited(problem, previous) {
        return nearest(problem, settings, progress);
    }
    let start = Instant::now();
    let mut state = Nearest::new(problem, settings, progress)?;
    state.start_from(previous, continuation);
    match state.run_warm()? {
        Some(ended) => state.conclude(ended, start),
        // The edited input hangs: its mirror image is measured from its own forces.
        None => nearest(problem, settings, state.progress.take()),
    }
}

/// Whether `previous` lies farther from the edited input (area-weighted RMS height change
/// over the plan diagonal) than twice its own change from its input plus a hundredth of the
/// diagonal: no small edit (a model rescaled, a region redrawn), whose continuation from there
/// would settle near the previous answer, far from the cold one (method.md §13.4).
fn far_from_edited(problem: &Problem, previous: &FormFindResult) -> bool {
    let (rms, _) = super::height_change(problem, &previous.positions);
    rms > 2.0 * previous.rms_change + 0.01
}

/// A certified state: heights with the forces that certify them.
#[derive(Clone)]
struct Best {
    eps: f64,
    /// E, the nearness objective.
    energy: f64,
    positions: Vec<[f64; 3]>,
    stress: StressResult,
}

struct Nearest<'a, 'p> {
    problem: &'a Problem,
    settings: &'a FormFindSettings,
    progress: Option<&'a mut Progress<'p>>,
    shape: ShapeStep,
    /// Input heights (after ODT, when asked for), the shape to stay near: their mirror image
    /// where the input hangs (see [`Nearest::hanging_mirror`]).
    z0: Vec<f64>,
    /// The input's own heights (before ODT), from which the height limit is measured.
    z_limit: Vec<f64>,
    /// Whether `z0` is the input's mirror image.
    mirrored: bool,
    /// Plan area share per row of `shape`.
    area: Vec<f64>,
    /// c_e per mesh edge when the fairness term is on.
    fair: Option<Vec<f64>>,
    l0: f64,
    /// Largest height change allowed, physical.
    limit: f64,
    cache: StressCache,
    positions: Vec<[f64; 3]>,
    /// The forces in use, certified at `positions`.
    held: StressResult,
    w: f64,
    /// The lowest-E state in equilibrium (ε∞ < tolerance) reached.
    feasible: Option<Best>,
    /// Whether the held forces come from a QP solved to its full tolerances (not loosened by
    /// `Nearest::inexact_gap`).
    exact: bool,
    /// Whether the held forces are the stress step's answer at the current heights (not
    /// earlier forces kept there because the answer did worse).
    held_answers: bool,
    /// Multipliers of the equilibrium rows (units of r̂), per row of `shape`.
    lambda: Vec<f64>,
    /// −p̄ √n λ / 2w per vertex, physical: the loads' shift in both steps.
    load_offset: Vec<f64>,
    best: Best,
    history: Vec<f64>,
    solvers: Vec<QpSolver>,
    qp_iterations: Vec<u32>,
    iterations: usize,
    stress_seconds: f64,
    shape_seconds: f64,
    /// The w the continuation started from.
    w_start: f64,
    /// Stress steps of earlier runs whose smoothing has faded (a warm re-solve's).
    faded: usize,
    /// A warm re-solve's previous forces, for its first stress step.
    previous_forces: Option<StressResult>,
}

impl<'a, 'p> Nearest<'a, 'p> {
    fn new(
        problem: &'a Problem,
        settings: &'a FormFindSettings,
        progress: Option<&'a mut Progress<'p>>,
    ) -> Result<Nearest<'a, 'p>> {
        let mesh = &problem.mesh;
        let mut positions = mesh.positions.clone();
        let t = Instant::now();
        // The limit holds from the input's own heights, as the paper's loop and `max_change`
        // measure it: ODT's resampled heights too.
        let z_limit: Vec<f64> = positions.iter().map(|p| p[2]).collect();
        let limit = settings.max_height_change * 2.0 * Frame::of(mesh, &positions).scale;
        if settings.odt_iterations > 0 {
            let mut odt = Odt::new(mesh, &positions, settings.odt_free_boundary);
            let mut held = HeightLimit::new(&z_limit, limit);
            for _ in 0..settings.odt_iterations {
                if sweep_within(&mut odt, mesh, &mut positions, Some(&mut held)) {
                    break;
                }
            }
        }
        let shape = ShapeStep::new(mesh)?;
        let share = area_shares(problem);
        let area: Vec<f64> = shape
            .vertices()
            .iter()
            .map(|&v| share[v as usize])
            .collect();
        let n_rows = area.len();
        let frame = Frame::of(mesh, &positions);
        let fair =
            (settings.fairness > 0.0).then(|| fairness_weights(problem, &positions, frame.scale));
        let shape_seconds = t.elapsed().as_secs_f64();
        Ok(Nearest {
            problem,
            settings,
            progress,
            shape,
            z0: positions.iter().map(|p| p[2]).collect(),
            z_limit,
            mirrored: false,
            area,
            fair,
            l0: frame.scale,
            limit,
            cache: StressCache::for_form_finding(),
            held: placeholder(),
            w: 0.0,
            feasible: None,
            exact: true,
            held_answers: true,
            lambda: vec![0.0; n_rows],
            load_offset: vec![0.0; positions.len()],
            best: Best {
                eps: f64::INFINITY,
                energy: 0.0,
                positions: positions.clone(),
                stress: placeholder(),
            },
            positions,
            history: Vec::new(),
            solvers: Vec::new(),
            qp_iterations: Vec::new(),
            iterations: 0,
            stress_seconds: 0.0,
            shape_seconds,
            w_start: 0.0,
            faded: 0,
            previous_forces: None,
        })
    }

    /// The result of a run that ended with `ended`: the polish where no state in equilibrium
    /// was found, the answer chosen, and what a warm re-solve may pick up.
    fn conclude(mut self, mut ended: Termination, start: Instant) -> Result<FormFindResult> {
        if self.feasible.is_none()
            && matches!(
                ended,
                Termination::MaxIterations | Termination::Stalled { .. }
            )
        {
            ended = self.polish()?;
        }
        // A certified state in equilibrium is the answer whatever stopped the search for a
        // nearer one; without one, the lowest-ε∞ state is.
        let (termination, best) = match self.feasible.take() {
            Some(f) if ended != Termination::Cancelled => (Termination::Converged, f),
            Some(f) => (ended, f),
            None => (ended, self.best.clone()),
        };
        let warm = self.continuation();
        let Best {
            positions, stress, ..
        } = best;
        Ok(finish(
            self.problem,
            Run {
                termination,
                iterations: self.iterations,
                solvers: self.solvers,
                qp_iterations: self.qp_iterations,
                positions,
                stress,
                history: self.history,
                mirrored: self.mirrored,
                stress_seconds: self.stress_seconds,
                shape_seconds: self.shape_seconds,
                warm,
            },
            start,
        ))
    }

    /// The penalty state for a warm re-solve, where the continuation started (w > 0); it
    /// takes the stress cache.
    fn continuation(&mut self) -> Option<Arc<Continuation>> {
        if !(self.w > 0.0 && self.w.is_finite()) {
            return None;
        }
        let mut lambda = vec![0.0; self.positions.len()];
        for (&v, &l) in self.shape.vertices().iter().zip(&self.lambda) {
            lambda[v as usize] = l;
        }
        Some(Arc::new(Continuation {
            faces: faces_fingerprint(&self.problem.mesh),
            lambda,
            w: self.w,
            w_start: self.w_start,
            faded: self.faded + self.iterations,
            cache: Mutex::new(Some(std::mem::take(&mut self.cache))),
        }))
    }

    /// Starts from `previous`'s heights (anchored vertices at their input heights, the rest
    /// within the height limit of the input) and, with `continuation`, its penalty state and
    /// stress cache.
    fn start_from(&mut self, previous: &FormFindResult, continuation: Option<&Continuation>) {
        for &v in self.shape.vertices() {
            let v = v as usize;
            let (z, base) = (previous.positions[v][2], self.z_limit[v]);
            self.positions[v][2] = within_limit(z, base, self.limit);
        }
        self.previous_forces = (previous.stress.status.is_solved())
            .then(|| previous.stress.clone())
            .filter(|s| s.force_densities.iter().all(|q| q.is_finite()));
        let Some(c) = continuation else {
            return;
        };
        let rows = self.shape.vertices();
        self.lambda = rows.iter().map(|&v| c.lambda[v as usize]).collect();
        (self.w_start, self.faded) = (c.w_start, c.faded);
        // A quarter of the way (geometrically) from where the previous continuation started
        // to where it ended. Nearer its end the heights are held so tightly to balance that
        // each state in equilibrium is hardly nearer than the last, and the search settles
        // near the previous answer (at the midpoint, measured: up to twice the RMS change of
        // a cold run on a cap dome with one vertex raised by 1% of the diagonal); from its
        // start it takes as many steps as a cold run.
        self.w = c.w_start * (c.w / c.w_start).powf(WARM_WEIGHT);
        if let Some(cache) = c.cache.lock().ok().and_then(|mut held| held.take()) {
            self.cache = cache;
        }
    }

    /// The warm loop: a stress step at the start heights pulled towards the previous forces,
    /// then the continuation from the previous penalty state (or from a starting weight
    /// chosen as a cold run's). None where the edited input hangs (see `hanging_mirror`).
    fn run_warm(&mut self) -> Result<Option<Termination>> {
        if self.w > 0.0 {
            // The multiplier shift of the previous run, scaled by the previous loads.
            if let Some(prev) = &self.previous_forces {
                self.held = prev.clone();
                self.shift_loads();
            }
        }
        // Certified at the start heights, so that kept in place of a worse answer they carry
        // their own residuals there.
        let prior = (self.previous_forces.take())
            .map(|p| p.at_heights(self.problem, &self.positions, &self.step_settings()));
        self.held = self.stress_step(prior.as_ref())?;
        let ended = self.after_stress_step();
        let settled = self.record();
        if let Some(t) = ended {
            return Ok(Some(t));
        }
        let input = self.z0.clone();
        if self.hanging_mirror(&input)?.is_some() {
            return Ok(None);
        }
        if settled {
            return Ok(Some(Termination::Converged));
        }
        if self.w <= 0.0 {
            self.w = match self.initial_weight() {
                Ok(w) => w,
                Err(e) => return Ok(Some(super::numerical(e))),
            };
            self.w_start = self.w;
        }
        self.shift_loads();
        self.descend().map(Some)
    }

    /// The loop; the state it ends in is read by the caller.
    fn run(&mut self) -> Result<Termination> {
        let first = self.stress_step(None)?;
        self.held = first;
        // The input's analysis is recorded whatever ends the loop here, so that even an
        // infeasible or cancelled run answers forces for its positions.
        let ended = self.after_stress_step();
        let settled = self.record();
        if let Some(t) = ended {
            return Ok(t);
        }
        if settled {
            return Ok(Termination::Converged);
        }
        if let Some(t) = self.mirror_if_hanging()? {
            return Ok(t);
        }
        self.w = match self.initial_weight() {
            Ok(w) => w,
            Err(e) => return Ok(super::numerical(e)),
        };
        self.w_start = self.w;
        self.descend()
    }

    /// The continuation from the held state and penalty weight: rounds of a height and a
    /// stress step, the multipliers updated between stages, until a state in equilibrium
    /// settles or the loop stops.
    fn descend(&mut self) -> Result<Termination> {
        let w_start = self.w_start;
        let mut last_norm = residual_term(self.problem, &self.held, self.shape.vertices()).sqrt();
        let (mut stage_rounds, mut stall_best, mut stall_at) = (0, self.best.eps, 0);
        loop {
            let before = self.merit(&self.positions, &self.held);
            let moved = match self.height_step() {
                Ok(moved) => moved,
                Err(e) => return Ok(super::numerical(e)),
            };
            if moved && self.record_height_state() {
                return Ok(Termination::Converged);
            }
            let prior = self.held.clone();
            let answer = self.stress_step(Some(&prior))?;
            self.held = answer;
            // Recorded before anything ends the loop, so that a run stopped here (budget,
            // callback) answers the best state of its whole history.
            let ended = self.after_stress_step();
            let settled = self.record();
            if let Some(t) = ended {
                return Ok(t);
            }
            if settled {
                return Ok(Termination::Converged);
            }
            stage_rounds += 1;
            let after = self.merit(&self.positions, &self.held);
            let progressed = moved && after <= (1.0 - STAGE_DECREASE) * before;
            if !progressed || stage_rounds >= STAGE_ROUNDS {
                self.update_multipliers(&mut last_norm);
                stage_rounds = 0;
            }
            // Rounds that still lower the merit are progress towards a nearer shape even where
            // ε∞ waits on them.
            if progressed
                || self.best.eps < 0.99 * stall_best
                || self.w < STALL_AFTER_GROWTH * w_start
            {
                (stall_best, stall_at) = (self.best.eps, self.iterations);
            } else if self.iterations - stall_at >= self.settings.stall_window {
                return Ok(self.stalled());
            }
        }
    }

    /// Where the input hangs (see [`Nearest::hanging_mirror`]), moves the loop to its mirror
    /// image, which becomes both the start and the shape to stay near, and takes a stress step
    /// there; returns the termination where that step ends the loop.
    fn mirror_if_hanging(&mut self) -> Result<Option<Termination>> {
        let input: Vec<f64> = self.positions.iter().map(|p| p[2]).collect();
        let Some(mirror) = self.hanging_mirror(&input)? else {
            return Ok(None);
        };
        self.positions = self.with_heights(&mirror);
        self.z0 = mirror;
        self.mirrored = true;
        self.held = self.stress_step(None)?;
        let ended = self.after_stress_step();
        let settled = self.record();
        Ok(ended.or(settled.then_some(Termination::Converged)))
    }

    /// The mirror image of the input (heights `input`) about the unloaded surface its supports
    /// span, where the input hangs; None where it does not. With K = L_q[V_N, V_N] for the held force
    /// densities (the input's stress step), the unloaded surface z̄ solves K z̄ = b with no
    /// loads and the supports' heights (horizontal balance makes every plane such a surface, so
    /// over coplanar supports it is their plane). A shape in equilibrium under downward loads
    /// lies above z̄ of its own forces at every vertex (the discrete maximum principle), so no
    /// standing shape is near one below it. The input hangs where its area-weighted mean height
    /// above z̄ is negative; its mirror 2 z̄ − z is the reading taken where it lies within the
    /// height limit of the input.
    fn hanging_mirror(&self, input: &[f64]) -> Result<Option<Vec<f64>>> {
        let rows = self.shape.vertices();
        let q = &self.held.force_densities;
        let z = input.to_vec();
        // A pull small enough to leave K's solution (KᵀK's diagonal over its condition number)
        // and to fix the heights of parts that K leaves free.
        let rho = MEMBRANE_PULL * self.mean_ktk_diagonal(q) * rows.len() as f64;
        if !(rho.is_finite() && rho > 0.0) {
            return Ok(None);
        }
        let unloaded = vec![0.0; z.len()];
        let surface = (self.shape).nearest(q, &unloaded, &z, &z, rho, &self.area, None, None)?;
        let height_above: f64 = (rows.iter().zip(&self.area))
            .map(|(&v, a)| a * (z[v as usize] - surface[v as usize]))
            .sum();
        if height_above.is_nan() || height_above >= 0.0 {
            return Ok(None);
        }
        let mut mirror = z;
        for &v in rows {
            let v = v as usize;
            mirror[v] = 2.0 * surface[v] - mirror[v];
            if (mirror[v] - self.z_limit[v]).abs() > self.limit {
                return Ok(None);
            }
        }
        Ok(Some(mirror))
    }

    /// Stress steps the nearest method may take: all but a quarter of `max_iterations`, which
    /// [`Nearest::polish`] may need.
    fn budget(&self) -> usize {
        let max = self.settings.max_iterations.max(1);
        max - max / 4
    }

    /// Where the nearest method found no state in equilibrium (height steps whose lagged loads
    /// do not settle, as on nearly vertical strips), the paper's loop from the best state
    /// reached, with the rest of the iteration budget: its proximal steps damp what the
    /// nearest method's exact ones cannot. Its height steps are held within the height limit
    /// of the input (a loop that held some back and did not converge is `Blocked` there), and
    /// its answer replaces the best state if it balances better.
    fn polish(&mut self) -> Result<Termination> {
        let remaining = self.settings.max_iterations.saturating_sub(self.iterations);
        if remaining == 0 || !self.best.eps.is_finite() {
            return Ok(Termination::MaxIterations);
        }
        let mut start = self.problem.clone();
        start.mesh.positions = self.best.positions.clone();
        let settings = FormFindSettings {
            method: crate::FormMethod::Paper,
            max_iterations: remaining,
            odt_iterations: 0,
            ..self.settings.clone()
        };
        let offset = self.iterations;
        let mut limit = HeightLimit::new(&self.z_limit, self.limit);
        let (r, within) = match self.progress.as_mut() {
            Some(cb) => {
                let mut shifted = |k: usize, eps: f64| cb(k + offset, eps);
                paper_within(&start, &settings, Some(&mut shifted), Some(&mut limit))?
            }
            None => paper_within(&start, &settings, None, Some(&mut limit))?,
        };
        self.iterations += r.iterations;
        self.solvers.extend(&r.solvers);
        self.qp_iterations.extend(&r.qp_iterations);
        self.history.extend(&r.history);
        self.stress_seconds += r.stress_seconds;
        self.shape_seconds += r.shape_seconds;
        // A converged answer passed the certificate; another replaces the best state only if
        // it balances better with its forces within their bounds, as the paper's loop checked
        // them: a stress step's own answer (solved at those heights, possibly to a coarse
        // optimum) for compression, forces kept at new heights against every bound.
        let converged = r.termination == Termination::Converged;
        if converged || (r.stress.eps_inf < self.best.eps && within) {
            self.best = Best {
                eps: r.stress.eps_inf,
                energy: self.energy(&r.positions),
                positions: r.positions,
                stress: r.stress,
            };
        }
        Ok(limit.ending(self.problem, r.termination, &self.best.stress))
    }

    /// Records a height step's state (the held forces certified at new heights) as a state in
    /// equilibrium where it is one and its forces still meet their bounds at these heights
    /// (relative bounds move with the loads); see [`Nearest::record`].
    fn record_height_state(&mut self) -> bool {
        if !self.balances(&self.held, false) {
            return false;
        }
        self.history.push(self.held.eps_inf);
        self.record()
    }

    /// Whether `s` is a state in equilibrium at the current heights: balanced vertically and
    /// horizontally to the tolerance, its forces within their bounds (see `certified`;
    /// `fresh`: the last stress step's own answer).
    fn balances(&self, s: &StressResult, fresh: bool) -> bool {
        certified(self.problem, self.settings, &self.positions, s, fresh)
    }

    /// Whether the held forces are the last stress step's own answer, solved (see
    /// `meets_bounds`); `record_height_state` checks forces kept at new heights first.
    fn fresh(&self) -> bool {
        self.held_answers && self.held.status == StressStatus::Solved
    }

    /// Whether the force densities of `s` meet their bounds at the current heights.
    fn meets_bounds(&self, s: &StressResult, fresh: bool) -> bool {
        meets_bounds(
            self.problem,
            &self.settings.stress,
            &self.positions,
            s,
            fresh,
        )
    }

    /// Records the current state as the best so far where it is; true when it is in
    /// equilibrium and no nearer, by more than `SETTLED`, than the nearest such state before
    /// it: the search for a nearer one has settled.
    fn record(&mut self) -> bool {
        let usable = !matches!(
            self.held.status,
            StressStatus::Infeasible | StressStatus::NumericalError
        );
        let current = Best {
            eps: self.held.eps_inf,
            energy: self.energy(&self.positions),
            positions: self.positions.clone(),
            stress: self.held.clone(),
        };
        // Forces outside their bounds are no answer, however well they balance.
        let first = self.best.stress.force_densities.is_empty();
        let better = usable && self.held.eps_inf < self.best.eps;
        if first || (better && self.meets_bounds(&self.held, self.fresh())) {
            self.best = current.clone();
        }
        // An answer in equilibrium counts once its QP met the full tolerances, so that the
        // horizontal rows hold as tightly as an analysis's (and an analysis of the shape afresh
        // finds it standing: a looser answer's state did not always, on cheese), and only where
        // the recomputed certificate holds (bounds and horizontal balance included: force
        // densities many orders of magnitude apart can leave a solved QP's rows loose).
        let solved = self.held.status == StressStatus::Solved && self.exact;
        if !(solved && self.balances(&self.held, self.fresh())) {
            return false;
        }
        let settled = match &self.feasible {
            None => current.energy == 0.0,
            Some(f) => current.energy > (1.0 - SETTLED) * f.energy,
        };
        if self
            .feasible
            .as_ref()
            .is_none_or(|f| current.energy < f.energy)
        {
            self.feasible = Some(current);
        }
        settled
    }

    /// One stress QP at the current heights, with the held forces as proximal centre. An
    /// answer that stopped short of its optimum and lowers L less than the held forces gives
    /// way to them once the dual-length smoothing has faded.
    fn stress_step(&mut self, held: Option<&StressResult>) -> Result<StressResult> {
        let t = Instant::now();
        let settings = self.step_settings();
        let prior = held.filter(|s| s.status.is_solved()).map(|s| Prior {
            force_densities: &s.force_densities,
            weight: self.settings.proximal_weight,
            lifted_first: s.lifted,
        });
        self.cache
            .far_from_balance(held.is_some_and(|s| s.eps_inf > FAR_FROM_BALANCE));
        // Only where the merit judges a loosened answer (see below), and only until a state
        // has reached the tolerance: from then on every answer must be able to count.
        let judged = settings.dual_length_smoothing == 0.0;
        let balanced = self.best.eps < self.settings.tolerance;
        self.cache
            .set_inexact(held.filter(|_| judged && !balanced).and_then(inexact_gap));
        let answer = analyse_cached(
            self.problem,
            &self.positions,
            &settings,
            prior,
            &mut self.cache,
        )?;
        self.solvers.push(answer.solver);
        self.qp_iterations.push(answer.iterations);
        // A solved answer is the optimum over the constraints at these heights (relative
        // bounds move with the loads), which the held forces may no longer meet.
        let short = self.cache.last_was_coarse()
            || matches!(
                answer.status,
                StressStatus::AlmostSolved | StressStatus::MaxIterations
            );
        let kept = held.filter(|h| {
            short
                && settings.dual_length_smoothing == 0.0
                && self.merit(&self.positions, h) < self.merit(&self.positions, &answer)
        });
        self.held_answers = kept.is_none();
        if kept.is_none() {
            self.exact = !self.cache.last_was_inexact();
        }
        let answer = kept.cloned().unwrap_or(answer);
        self.iterations += 1;
        self.history.push(answer.eps_inf);
        self.stress_seconds += t.elapsed().as_secs_f64();
        Ok(answer)
    }

    /// The stress settings of the next step: the dual-length smoothing fades geometrically.
    fn step_settings(&self) -> StressSettings {
        let s = &self.settings.stress;
        let steps = (self.faded + self.iterations).min(i32::MAX as usize);
        let factor = self.settings.smoothing_decay.powi(steps as i32);
        StressSettings {
            dual_length_smoothing: if factor > 1e-12 {
                s.dual_length_smoothing * factor
            } else {
                0.0
            },
            ..s.clone()
        }
    }

    /// Bookkeeping after a stress step: best state, progress callback, and the terminations
    /// a stress step decides.
    fn after_stress_step(&mut self) -> Option<Termination> {
        let (k, eps) = (self.iterations - 1, self.held.eps_inf);
        if let Some(cb) = self.progress.as_mut() {
            if !cb(k, eps) {
                return Some(Termination::Cancelled);
            }
        }
        match self.held.status {
            StressStatus::Infeasible => {
                return Some(Termination::Infeasible {
                    constraint: infeasibility_hint(self.problem, &self.settings.stress),
                })
            }
            StressStatus::NumericalError => {
                return Some(Termination::NumericalError {
                    what: "the stress QP failed".into(),
                })
            }
            _ => {}
        }
        (self.iterations >= self.budget()).then_some(Termination::MaxIterations)
    }

    /// The starting w: the least, on a geometric grid from the weight that balances the
    /// diagonals of both terms' Hessians, whose height step (held forces) lowers the residual
    /// term R by `INITIAL_DECREASE`. Smaller weights spend stress steps on a shape the pull
    /// holds in place; larger ones start the continuation where little of the input is kept.
    fn initial_weight(&self) -> Result<f64> {
        let kappa = self.mean_ktk_diagonal(&self.held.force_densities);
        let p_bar = self.problem.mean_load(&self.held.loads);
        let r0 = residual_term(self.problem, &self.held, self.shape.vertices());
        let start = if kappa > 0.0 {
            p_bar * p_bar / (self.l0 * self.l0 * kappa)
        } else {
            1.0
        };
        let mut w = start;
        let settings = self.step_settings();
        for _ in 0..INITIAL_WEIGHT_TRIALS {
            let target = self.height_target(w)?;
            let trial = self.with_heights(&target);
            let r = residual_term(
                self.problem,
                &self.held.at_heights(self.problem, &trial, &settings),
                self.shape.vertices(),
            );
            if r <= (1.0 - INITIAL_DECREASE) * r0 {
                return Ok(w);
            }
            w *= INITIAL_WEIGHT_FACTOR;
        }
        Ok(start)
    }

    /// Mean diagonal of KᵀK, K = L_q[V_N, V_N]: (Σ_e q_e)² at the vertex plus q_e² per free
    /// neighbour.
    fn mean_ktk_diagonal(&self, q: &[f64]) -> f64 {
        let mesh = &self.problem.mesh;
        let rows = self.shape.vertices();
        let sum: f64 = rows
            .iter()
            .map(|&v| {
                let edges = mesh.edges_at(v as usize);
                let total: f64 = edges.iter().map(|&e| q[e as usize]).sum();
                let free: f64 = edges
                    .iter()
                    .filter(|&&e| mesh.is_non_anchored(mesh.other_end(e as usize, v) as usize))
                    .map(|&e| q[e as usize].powi(2))
                    .sum();
                total * total + free
            })
            .sum();
        sum / rows.len().max(1) as f64
    }

    /// The augmented Lagrangian E + λᵀr̂ + w ‖r̂‖² (up to a constant: E + w ‖r̂ + λ/2w‖²) at
    /// heights `positions` with forces `s` certified there, r̂ = r / (p̄ √n).
    fn merit(&self, positions: &[[f64; 3]], s: &StressResult) -> f64 {
        let rows = self.shape.vertices();
        let scale = self.problem.mean_load(&s.loads) * (rows.len() as f64).sqrt();
        let shifted: f64 = (rows.iter().zip(&self.lambda))
            .map(|(&v, l)| (s.residuals[v as usize] / scale + l / (2.0 * self.w)).powi(2))
            .sum();
        self.energy(positions) + self.w * shifted
    }

    /// The method of multipliers' update: λ ← λ + 2w r̂ where ‖r̂‖ has fallen below
    /// `RESIDUAL_FACTOR` of its value at the last update, else w grows and λ stays (so the
    /// shift λ/2w shrinks).
    fn update_multipliers(&mut self, last_norm: &mut f64) {
        let rows = self.shape.vertices();
        let scale = self.problem.mean_load(&self.held.loads) * (rows.len() as f64).sqrt();
        let r: Vec<f64> = rows
            .iter()
            .map(|&v| self.held.residuals[v as usize] / scale)
            .collect();
        let norm = r.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm <= RESIDUAL_FACTOR * *last_norm {
            for (l, ri) in self.lambda.iter_mut().zip(&r) {
                *l += 2.0 * self.w * ri;
            }
            *last_norm = norm;
        } else {
            self.w *= GROWTH;
        }
        self.shift_loads();
    }

    /// The load offset −p̄ √n λ / 2w per vertex that makes the stress and height steps minimise
    /// ‖r̂ + λ/2w‖²; handed to the stress steps through the cache.
    fn shift_loads(&mut self) {
        let rows = self.shape.vertices();
        let scale = self.problem.mean_load(&self.held.loads) * (rows.len() as f64).sqrt();
        let mut offset = vec![0.0; self.positions.len()];
        for (l, &v) in self.lambda.iter().zip(rows) {
            offset[v as usize] = -scale * l / (2.0 * self.w);
        }
        self.load_offset = offset.clone();
        self.cache.set_load_offset(Some(offset));
    }

    /// E: the area-weighted squared change plus the fairness term, in frame units.
    fn energy(&self, positions: &[[f64; 3]]) -> f64 {
        let d = |v: u32| (positions[v as usize][2] - self.z0[v as usize]) / self.l0;
        let rows = self.shape.vertices();
        let mut e: f64 = rows
            .iter()
            .zip(&self.area)
            .map(|(&v, a)| a * d(v).powi(2))
            .sum();
        if let Some(c) = &self.fair {
            let mesh = &self.problem.mesh;
            let gamma = self.settings.fairness;
            for (edge, ce) in mesh.edges.iter().zip(c) {
                let [i, j] = edge.v;
                e += gamma * ce * (d(i) - d(j)).powi(2);
            }
        }
        e
    }

    /// A height step for the held forces: the minimiser of L with the loads lagged, shortened
    /// to the height limit and until L (loads recomputed) decreases. Returns whether the
    /// heights moved; `held` is then certified at the new heights.
    fn height_step(&mut self) -> Result<bool> {
        let t = Instant::now();
        let z: Vec<f64> = self.positions.iter().map(|p| p[2]).collect();
        let target = self.height_target(self.w)?;
        let mut step = self.limit_step(&z, &target);
        let settings = self.step_settings();
        let current = self.merit(&self.positions, &self.held);
        let mut moved = false;
        for _ in 0..=BACKTRACKS {
            // The step to the limit may round past it.
            let partial: Vec<f64> = (z.iter().zip(&target).zip(&self.z_limit))
                .map(|((a, b), &base)| within_limit(a + step * (b - a), base, self.limit))
                .collect();
            let trial = self.with_heights(&partial);
            let certified = self.held.at_heights(self.problem, &trial, &settings);
            if self.merit(&trial, &certified) < current {
                self.positions = trial;
                self.held = certified;
                moved = true;
                break;
            }
            step *= 0.5;
        }
        self.shape_seconds += t.elapsed().as_secs_f64();
        Ok(moved)
    }

    /// The minimiser over z of L for the held forces, loads lagged.
    fn height_target(&self, w: f64) -> Result<Vec<f64>> {
        let rows = self.shape.vertices();
        let p_bar = self.problem.mean_load(&self.held.loads);
        let rho = rows.len() as f64 * p_bar * p_bar / (w * self.l0 * self.l0);
        let z: Vec<f64> = self.positions.iter().map(|p| p[2]).collect();
        let fair = self.fair.as_deref().map(|c| (self.settings.fairness, c));
        let jacobian = crate::geometry::loads::load_jacobian(
            &self.problem.mesh,
            &self.positions,
            self.settings.stress.load_rule,
            &self.problem.face_density,
        );
        let loads: Vec<f64> = (self.held.loads.iter().zip(&self.load_offset))
            .map(|(p, o)| p + o)
            .collect();
        self.shape.nearest(
            &self.held.force_densities,
            &loads,
            &z,
            &self.z0,
            rho,
            &self.area,
            fair,
            Some(&jacobian),
        )
    }

    /// The current positions with heights `z`.
    fn with_heights(&self, z: &[f64]) -> Vec<[f64; 3]> {
        (self.positions.iter().zip(z))
            .map(|(p, &h)| [p[0], p[1], h])
            .collect()
    }

    /// The largest fraction of the step from `z` to `target` (at most 1) that keeps every
    /// height within the limit of the input.
    fn limit_step(&self, z: &[f64], target: &[f64]) -> f64 {
        let mut step = 1.0f64;
        for &v in self.shape.vertices() {
            let v = v as usize;
            let (from, to) = (z[v] - self.z_limit[v], target[v] - self.z_limit[v]);
            if to.abs() > self.limit {
                let edge = self.limit.copysign(to);
                step = step.min(((edge - from) / (to - from)).clamp(0.0, 1.0));
            }
        }
        step
    }

    /// The vertices whose height change is at the limit: within a millionth of it, or one ulp
    /// further out would pass it (`within_limit` may stop that ulp short).
    fn at_limit(&self) -> Vec<u32> {
        (self.shape.vertices().iter().copied())
            .filter(|&v| {
                let (z, base) = (self.positions[v as usize][2], self.z_limit[v as usize]);
                let outwards = one_ulp_towards(z, f64::INFINITY.copysign(z - base));
                (z - base).abs() >= self.limit * (1.0 - 1e-6)
                    || (outwards - base).abs() > self.limit
            })
            .collect()
    }

    /// The termination of a loop whose best ε∞ stopped improving: blocked by the height limit
    /// or by q_max where either holds, else stalled at vertices that carry no stress.
    fn stalled(&self) -> Termination {
        let capped = self.at_q_max();
        let q_max = "q_max holds the force densities down where the shape is out of balance";
        let at_limit = self.at_limit();
        if !at_limit.is_empty() {
            let hint = if capped.is_empty() {
                LIMIT_HINT.into()
            } else {
                format!("{q_max}, so standing needs heights beyond the limit (raise q_max)")
            };
            return Termination::Blocked {
                vertices: blocked_region(self.problem, &at_limit, &self.best.stress),
                hint,
            };
        }
        if !capped.is_empty() {
            return Termination::Blocked {
                vertices: capped,
                hint: format!("{q_max} (raise q_max)"),
            };
        }
        Termination::Stalled {
            vertices: blocking_vertices(self.problem, &self.held),
        }
    }

    /// Non-anchored vertices with a residual above a tenth of the largest one and an edge at
    /// q_max (empty without q_max).
    fn at_q_max(&self) -> Vec<u32> {
        let Some(bound) = self.settings.stress.q_max else {
            return Vec::new();
        };
        let mesh = &self.problem.mesh;
        let rows = self.shape.vertices();
        let q_max = bound.physical(self.problem.mean_load(&self.held.loads) / self.l0);
        let r = &self.held.residuals;
        let r_max = rows
            .iter()
            .map(|&v| r[v as usize].abs())
            .fold(0.0, f64::max);
        (rows.iter().copied())
            .filter(|&v| r[v as usize].abs() > 0.1 * r_max)
            .filter(|&v| {
                mesh.edges_at(v as usize)
                    .iter()
                    .any(|&e| self.held.force_densities[e as usize] >= q_max * (1.0 - 1e-3))
            })
            .collect()
    }
}

/// The relative gap at which a stress QP may stop, given the forces at hand certified at its
/// heights (`held`): ε∞², at most `INEXACT_GAP_MAX`, where that is looser than the QP's
/// own tolerance (an inexact Newton method's forcing term: a relative gap g leaves the
/// residual vector within √(2g) of the optimum's, so the answer's residuals are right to about
/// ε∞ of themselves). Far from balance the loop moves the shape anyway; near it the QPs are
/// solved to their full tolerances, and only such answers count as states in equilibrium
/// (`Nearest::record`). The smoothing-free loop judges every inexact answer by its merit
/// (`Nearest::stress_step`).
fn inexact_gap(held: &StressResult) -> Option<f64> {
    let gap = held.eps_inf.powi(2).min(INEXACT_GAP_MAX);
    gap.is_finite().then_some(gap)
}

/// R: the mean over the rows of (r_i / p̄)².
fn residual_term(problem: &Problem, s: &StressResult, rows: &[u32]) -> f64 {
    let p_bar = problem.mean_load(&s.loads);
    let sum: f64 = rows
        .iter()
        .map(|&v| (s.residuals[v as usize] / p_bar).powi(2))
        .sum();
    sum / rows.len().max(1) as f64
}

/// c_e = (plan area of the faces beside e) / (3 l_e²) over the plan area of the mesh, in frame
/// units (lengths over `l0`): Σ_e c_e (Δ_i − Δ_j)² approximates the mean squared gradient of Δ
/// over the plan.
fn fairness_weights(problem: &Problem, positions: &[[f64; 3]], l0: f64) -> Vec<f64> {
    let mesh = &problem.mesh;
    let face_area: Vec<f64> = mesh
        .faces
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|v| positions[v as usize]);
            ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).abs() / 2.0
        })
        .collect();
    let total: f64 = face_area.iter().sum();
    mesh.edges
        .iter()
        .map(|e| {
            let beside: f64 = [e.left, e.right]
                .iter()
                .flatten()
                .map(|s| face_area[s.face as usize])
                .sum();
            let [a, b] = e.v.map(|v| positions[v as usize]);
            let l2 = (b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2);
            if l2 > 0.0 && total > 0.0 {
                beside * l0 * l0 / (3.0 * l2 * total)
            } else {
                0.0
            }
        })
        .collect()
}

/// A stand-in result before the first stress step.
fn placeholder() -> StressResult {
    StressResult {
        status: StressStatus::NumericalError,
        force_densities: Vec::new(),
        airy: Vec::new(),
        weights: Vec::new(),
        hole_coefficients: Vec::new(),
        tau: Vec::new(),
        external_horizontal: Vec::new(),
        loads: Vec::new(),
        residuals: Vec::new(),
        horizontal_imbalance: Vec::new(),
        eps_inf: f64::INFINITY,
        objective: f64::INFINITY,
        force_diagram: Default::default(),
        iterations: 0,
        solver: QpSolver::Native,
        formulation: Default::default(),
        lifted: false,
        regularisation: 0.0,
        seconds: 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::{self, KnownPlan, Perturbation};

    #[test]
    fn every_accepted_step_lowers_the_merit() {
        let settings = FormFindSettings::default();
        let truth = generate::self_supporting(KnownPlan::Disk, 300, &settings).unwrap();
        let problem = Problem::new(generate::perturb(&truth, Perturbation::Dent, 1));
        let mut s = Nearest::new(&problem, &settings, None).unwrap();
        s.held = s.stress_step(None).unwrap();
        s.w = s.initial_weight().unwrap();
        let mut last_norm = residual_term(s.problem, &s.held, s.shape.vertices()).sqrt();
        let mut merit = s.merit(&s.positions, &s.held);
        let mut moves = 0;
        for round in 0..12 {
            moves += s.height_step().unwrap() as usize;
            let after_height = s.merit(&s.positions, &s.held);
            assert!(
                after_height <= merit,
                "round {round}: {merit:e} -> {after_height:e}"
            );
            let prior = s.held.clone();
            s.held = s.stress_step(Some(&prior)).unwrap();
            let after_stress = s.merit(&s.positions, &s.held);
            assert!(
                after_stress <= after_height,
                "round {round}: stress step raised it"
            );
            merit = after_stress;
            if round % 3 == 2 {
                // A new multiplier estimate is a new merit function.
                s.update_multipliers(&mut last_norm);
                merit = s.merit(&s.positions, &s.held);
            }
        }
        assert!(moves >= 10, "only {moves} height steps were taken");
    }

    /// Far from balance a stress step stops at its loosened gap; once some state has reached
    /// the tolerance, the same step is solved to the full tolerances, so that it can count.
    #[test]
    fn qps_are_exact_once_a_state_has_reached_the_tolerance() {
        let settings = FormFindSettings::default();
        assert_eq!(settings.stress.dual_length_smoothing, 0.0);
        let truth = generate::self_supporting(KnownPlan::Disk, 300, &settings).unwrap();
        let problem = Problem::new(generate::perturb(&truth, Perturbation::Dent, 1));
        let mut s = Nearest::new(&problem, &settings, None).unwrap();
        s.held = s.stress_step(None).unwrap();
        let prior = s.held.clone();
        assert!(prior.eps_inf > 1e-2, "{}", prior.eps_inf);
        s.stress_step(Some(&prior)).unwrap();
        assert!(s.cache.last_was_inexact());
        s.best.eps = 0.5 * settings.tolerance;
        s.stress_step(Some(&prior)).unwrap();
        assert!(!s.cache.last_was_inexact());
    }

    /// The certificate a converged answer needs, recomputed: a form-found state passes; the
    /// same state with one force density 1% below q_min (kept from other heights), in tension
    /// (the QP's own answer), or with a horizontal imbalance of 1e-3 of the mean load at one
    /// vertex, does not.
    #[test]
    fn the_certificate_checks_bounds_and_horizontal_balance() {
        let settings = FormFindSettings::default();
        let truth = generate::self_supporting(KnownPlan::Disk, 300, &settings).unwrap();
        let problem = Problem::new(truth);
        let r = crate::form_find(&problem, &settings, None).unwrap();
        assert_eq!(r.termination, Termination::Converged);
        let positions = &r.positions;
        assert!(certified(&problem, &settings, positions, &r.stress, false));
        let mesh = &problem.mesh;
        let free: Vec<usize> = (0..mesh.positions.len())
            .filter(|&v| mesh.is_non_anchored(v))
            .collect();
        let p_bar = free.iter().map(|&v| r.stress.loads[v]).sum::<f64>() / free.len() as f64;
        let unit = p_bar / Frame::of(mesh, positions).scale;
        let q_min = settings.stress.q_min.physical(unit);
        let interior = (mesh.edges.iter()).position(|e| !e.is_boundary()).unwrap();
        let mut short = r.stress.clone();
        short.force_densities[interior] = 0.99 * q_min;
        assert!(!meets_bounds(
            &problem,
            &settings.stress,
            positions,
            &short,
            false
        ));
        assert!(!certified(&problem, &settings, positions, &short, false));
        // A QP's own answer is held to compression: 1% short of q_min passes, tension not.
        assert!(meets_bounds(
            &problem,
            &settings.stress,
            positions,
            &short,
            true
        ));
        short.force_densities[interior] = -1e-3 * q_min;
        assert!(!meets_bounds(
            &problem,
            &settings.stress,
            positions,
            &short,
            true
        ));
        let mut loose = r.stress.clone();
        loose.horizontal_imbalance[free[0]] = [1e-3 * p_bar, 0.0];
        assert!(meets_bounds(
            &problem,
            &settings.stress,
            positions,
            &loose,
            false
        ));
        assert!(!certified(&problem, &settings, positions, &loose, true));
    }

    #[test]
    fn a_height_step_stops_at_the_limit() {
        let settings = FormFindSettings {
            max_height_change: 0.01,
            ..Default::default()
        };
        let problem = Problem::new(generate::cap_dome(1.4, 300).unwrap());
        let mut s = Nearest::new(&problem, &settings, None).unwrap();
        s.held = s.stress_step(None).unwrap();
        s.w = 1e6 * s.initial_weight().unwrap();
        for _ in 0..3 {
            s.height_step().unwrap();
        }
        let diag = 2.0 * s.l0;
        let moved = (problem.mesh.positions.iter().zip(&s.positions))
            .map(|(a, b)| (a[2] - b[2]).abs())
            .fold(0.0, f64::max);
        assert!(moved <= 0.01 * diag * (1.0 + 1e-9), "moved {moved}");
        assert!(moved > 0.005 * diag, "moved only {moved}");
        assert!(moved < 0.01 * diag * (1.0 - 1e-6) || !s.at_limit().is_empty());
    }
}
