//! The sequential QP of the assessment (docs/method.md §16.3): minimise the merit
//! φ = f + ν Σ |c_i| (c the vertical residuals, exact ℓ1 penalty) by steps of `qp.rs`,
//! whose model carries the convexified Hessian of the Lagrangian (the multipliers of the
//! last accepted step) and a proximal weight ρ (Levenberg–Marquardt): a step is accepted
//! only when φ falls by at least a tenth of what its model predicts, else once retried with
//! a second-order correction (the constraints are bilinear, so their second-order term is
//! known exactly) and then ρ grows; accepted steps update ρ by Nielsen's rule, and one that
//! leaves the residuals above target is replaced by its corrected step where that is better.
//! ν grows while the linearised residuals cannot be met at its price and otherwise follows
//! the step's multipliers (ten times the largest).

use super::model::{Model, Run, State};
use super::qp::{solve_step, Correction, Layout, Step, StepInput};
use super::ray;
use super::{AssessSettings, Objective};
use crate::error::Result;
use crate::shape::ShapeStep;
use crate::solve::{Progress, Termination};
use std::time::Instant;

/// Accept a step when φ falls by this fraction of the predicted fall.
const ACCEPT: f64 = 0.1;
const RHO_START: f64 = 1e-2;
const RHO_MIN: f64 = 1e-8;
/// Only steps at most this damped say the objective has settled.
const RHO_SETTLED: f64 = 1e-3;
/// A predicted fall of φ below this fraction of the objective is the QPs' noise.
const STATIONARY: f64 = 1e-7;
/// Beyond this ρ no step of the model lowers φ: the search is stationary.
const RHO_MAX: f64 = 1e8;
/// ν at most this factor above its start.
const NU_RANGE: f64 = 1e8;
/// Steps at most that bring the last state into equilibrium after the search.
const POLISH_STEPS: usize = 30;
/// A checkpoint (`Search::checkpoint`) once the load has grown this many times past the last
/// certified one.
const CHECKPOINT_GROWTH: f64 = 10.0;
/// The search holds the residuals to this fraction of the tolerance.
const FEASIBILITY_MARGIN: f64 = 0.1;

/// How long a search runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Until {
    /// Until the objective settles (or the iteration limit).
    Optimal,
    /// Until the first certified state: the start of another analysis needs a surface in
    /// equilibrium inside the envelope, not the best one.
    Certified,
}

/// Runs the search from `from` (a state of a search on the same mesh and supports, its
/// scalar reset), or from the middle surface with its best stress.
pub(super) fn solve(
    model: &Model,
    settings: &AssessSettings,
    mut progress: Option<&mut Progress>,
    from: Option<State>,
    until: Until,
) -> Result<Run> {
    let start = Instant::now();
    let layout = Layout::new(model);
    let mut search = Search::new(model, settings);
    // `fit`'s searches, the other analyses' start included, correct a step along the heights
    // first (`projected`), so that the start reaches a certified surface instead of creeping
    // with residuals just above the certificate's.
    if model.objective == Objective::Fit {
        search.heights = ShapeStep::new(&model.problem.mesh).ok();
    }
    match from {
        Some(state) => search.restart_from(state),
        None => search.start_with_stress(&layout),
    }
    let mut termination = Termination::MaxIterations;
    let mut iterations = 0;
    let mut stalled = false;
    while iterations < settings.max_iterations {
        if search.unbounded || (until == Until::Certified && search.best_feasible.is_some()) {
            termination = Termination::Converged;
            break;
        }
        iterations += 1;
        match search.iterate(&layout) {
            Outcome::Continue => {
                let left = settings.max_iterations.saturating_sub(iterations);
                iterations += search.checkpoint(&layout, left);
            }
            Outcome::Stationary => {
                termination = search.stationary_termination();
                break;
            }
            Outcome::Infeasible => {
                termination = search.stationary_termination();
                stalled = true;
                break;
            }
            Outcome::Converged => {
                termination = Termination::Converged;
                break;
            }
        }
        if let Some(cb) = progress.as_deref_mut() {
            if !cb(iterations, search.infeasibility()) {
                termination = Termination::Cancelled;
                break;
            }
        }
    }
    let found = search.unbounded || (until == Until::Certified && search.best_feasible.is_some());
    if termination != Termination::Cancelled && !found && !stalled {
        iterations += search.polish(&layout);
    }
    let unbounded = search.unbounded;
    let state = search.answer();
    Ok(Run {
        state,
        termination,
        iterations,
        seconds: start.elapsed().as_secs_f64(),
        unbounded,
    })
}

/// The answer of a search cancelled before its first step: `run`'s state (a search's on the
/// same mesh and supports) with `model`'s scalar at its start.
pub(super) fn stopped(model: &Model, settings: &AssessSettings, run: Run) -> Run {
    let mut search = Search::new(model, settings);
    search.restart_from(run.state);
    Run {
        unbounded: search.unbounded,
        state: search.answer(),
        termination: Termination::Cancelled,
        ..run
    }
}

enum Outcome {
    Continue,
    Stationary,
    Converged,
    /// The infeasibility has settled at the largest penalty: a stationary point of it,
    /// which a polish at that penalty would not leave either.
    Infeasible,
}

struct Search<'m, 'a> {
    model: &'m Model<'a>,
    state: State,
    /// max |c_i| at `state`.
    residual: f64,
    rho: f64,
    /// The factor of ρ's next rise: 2, doubling with every rejection in a row up to 10.
    grow: f64,
    nu: f64,
    nu_max: f64,
    feasible_below: f64,
    /// The residual a certificate accepts (the tolerance, with a margin for recomputation).
    certified_below: f64,
    /// The best certified-feasible state (lowest objective) and the least infeasible one.
    best_feasible: Option<(f64, State)>,
    least_infeasible: (f64, State),
    /// Objective values after the accepted steps.
    history: Vec<f64>,
    /// ‖c‖₁ plus the joints' excess after the accepted steps.
    violations: Vec<f64>,
    /// Once the objective has settled: ν stays high until the residuals meet the target.
    polishing: bool,
    /// The multipliers of the last accepted step's residual rows: the Hessian of the
    /// Lagrangian in the next step's model.
    mu: Option<Vec<f64>>,
    /// The last accepted step's dq and dz.
    direction: Option<(Vec<f64>, Vec<f64>)>,
    /// The analysis' settings, for the certificate of a ray's start.
    settings: AssessSettings,
    /// The best certified state lies on a ray of certified surfaces along which the
    /// objective has no bound (the greatest thrust and the largest load only; ray.rs).
    unbounded: bool,
    /// The height solve of `fit`'s projected correction (none for the other analyses' own
    /// searches, or where its analysis failed).
    heights: Option<ShapeStep>,
    /// −f where the last checkpoint was tried (see `checkpoint`).
    checkpoint_at: f64,
}

impl<'m, 'a> Search<'m, 'a> {
    fn new(model: &'m Model<'a>, settings: &AssessSettings) -> Self {
        let state = model.start_state();
        let nu = 10.0 / model.residual.len().max(1) as f64;
        let residual = model.violation(&state).0;
        Search {
            model,
            least_infeasible: (residual, state.clone()),
            state,
            residual,
            rho: RHO_START,
            grow: 2.0,
            nu,
            nu_max: nu * NU_RANGE,
            feasible_below: FEASIBILITY_MARGIN * settings.tolerance,
            certified_below: 0.5 * settings.tolerance,
            best_feasible: None,
            history: Vec::new(),
            violations: Vec::new(),
            polishing: false,
            mu: None,
            direction: None,
            unbounded: false,
            settings: settings.clone(),
            heights: None,
            checkpoint_at: 0.0,
        }
    }

    /// The start: the stress that best balances the start heights (the step with the heights
    /// held by a large proximal weight, the forces free and the residuals dear), taken
    /// whatever the merit says: the search starts from there.
    fn start_with_stress(&mut self, layout: &Layout) {
        let input = StepInput {
            rho: 1e-10,
            rho_z: 1e8,
            nu: 1e6,
            correction: None,
            multipliers: None,
            direction: None,
        };
        if let Some(step) = solve_step(self.model, layout, &self.state, &input) {
            self.state = self.apply(&step);
            self.mu = step.multipliers.clone();
            self.residual = self.model.violation(&self.state).0;
            self.record();
        }
    }

    fn restart_from(&mut self, state: State) {
        self.state = State {
            t: self.state.t,
            ..state
        };
        self.residual = self.model.violation(&self.state).0;
        self.least_infeasible = (self.residual, self.state.clone());
        self.record();
    }

    /// Brings the last state into equilibrium at a dear penalty, at most `POLISH_STEPS`
    /// steps: the best certified state then lies near where the search ended, not only
    /// where it last happened to be feasible. Returns the steps taken.
    fn polish(&mut self, layout: &Layout) -> usize {
        self.polish_within(layout, POLISH_STEPS)
    }

    /// `polish` with at most `most` steps.
    fn polish_within(&mut self, layout: &Layout, most: usize) -> usize {
        self.polishing = true;
        self.rho = RHO_START;
        let mut steps = 0;
        while self.residual > self.feasible_below && steps < most {
            steps += 1;
            self.nu = (self.nu * 1e3).min(self.nu_max);
            if let Outcome::Stationary | Outcome::Infeasible = self.iterate(layout) {
                break;
            }
        }
        steps
    }

    /// The largest load only: where the load has grown tenfold past the best certified one
    /// (and the last checkpoint) while the residuals stay above target, the current state is
    /// brought into equilibrium at a dear penalty (at most `left` steps, `polish`'s), so that
    /// the answer, the best certified state, keeps up with a search whose load grows without
    /// visible bound. The search then goes on from the polished state with its own ρ and ν.
    /// Returns the steps taken.
    fn checkpoint(&mut self, layout: &Layout, left: usize) -> usize {
        let grown = -self.model.objective_value(&self.state);
        let certified = self.best_feasible.as_ref().map_or(0.0, |(f, _)| -f);
        let reference = certified
            .max(self.checkpoint_at)
            .max(self.objective_floor());
        if self.model.objective != Objective::MaxLoad
            || self.polishing
            || self.residual <= self.feasible_below
            || grown <= CHECKPOINT_GROWTH * reference
        {
            return 0;
        }
        self.checkpoint_at = grown;
        let (nu, rho, grow) = (self.nu, self.rho, self.grow);
        let steps = self.polish_within(layout, left.min(POLISH_STEPS));
        (self.nu, self.rho, self.grow, self.polishing) = (nu, rho, grow, false);
        steps
    }

    fn infeasibility(&self) -> f64 {
        self.residual
    }

    /// φ = f + ν (‖c‖₁ + Σ max(0, g_a)) at `state` (g the joints' excess).
    fn merit(&self, state: &State) -> f64 {
        self.model.objective_value(state) + self.nu * self.model.violation(state).1
    }

    /// One accepted step, or a larger ρ.
    fn iterate(&mut self, layout: &Layout) -> Outcome {
        crate::interrupt::poll();
        let Some(step) = self.steered_step(layout) else {
            return self.reject();
        };
        let phi = self.merit(&self.state);
        let predicted = phi - (step.model_objective + self.nu * step.slack + step.curvature);
        if self.stationary(predicted) {
            return Outcome::Converged;
        }
        let trial = self.apply(&step);
        let multipliers = step.multipliers.clone();
        let joint_multiplier = step.joint_multiplier;
        let accepted = if self.acceptable(phi, predicted, &trial) {
            Some(self.corrected_if_better(layout, &step, trial))
        } else {
            self.corrected(layout, &step, &trial, |t| {
                self.acceptable(phi, predicted, t)
            })
        };
        let Some(next) = accepted else {
            if std::env::var_os("VSR_ASSESS_TRACE").is_some() {
                let actual = phi - self.merit(&self.apply(&step));
                eprintln!(
                    "reject pred {predicted:.2e} actual {actual:.2e} rho {:.1e}",
                    self.rho
                );
            }
            return self.reject();
        };
        let before = self.model.objective_value(&self.state);
        self.direction = Some((step.dq.clone(), step.dz.clone()));
        self.state = next;
        if let Some(multipliers) = multipliers {
            self.update_penalty(&multipliers, joint_multiplier, step.slack);
            self.mu = Some(multipliers);
        }
        let (largest, l1) = self.model.violation(&self.state);
        self.residual = largest;
        self.violations.push(l1);
        self.record();
        let ratio = (phi - self.merit(&self.state)) / predicted;
        // Nielsen's update: ρ follows how well the model predicted, without the swing
        // between a rejected and an accepted ρ that a fixed tenfold fall brings.
        let shrink = (1.0 - (2.0 * ratio - 1.0).powi(3)).max(1.0 / 3.0);
        self.rho = (self.rho * shrink).max(RHO_MIN);
        self.grow = 2.0;
        let after = self.model.objective_value(&self.state);
        if std::env::var_os("VSR_ASSESS_TRACE").is_some() {
            let cmax = max_abs(&self.model.residuals(&self.state));
            let gmax = self
                .model
                .joint_excess(&self.state)
                .iter()
                .fold(0.0f64, |m, g| m.max(*g));
            eprintln!(
                "f {before:.6e} -> {after:.6e} res {:.2e} rho {:.1e} nu {:.1e} pred {predicted:.2e} t {:.5} c {cmax:.2e} g {gmax:.2e} ratio {ratio:.2}",
                self.residual, self.rho, self.nu, self.state.t
            );
        }
        self.history.push(after);
        if self.infeasibility_settled() {
            return Outcome::Infeasible;
        }
        let settled = self.rho <= RHO_SETTLED && self.settled();
        // Polishing starts once the objective has settled: equilibrium ends it.
        match (
            settled || self.polishing,
            self.residual <= self.feasible_below,
        ) {
            (true, true) => Outcome::Converged,
            // The objective has settled short of equilibrium: polish with a dear penalty.
            (true, false) => {
                self.polishing = true;
                Outcome::Continue
            }
            _ => Outcome::Continue,
        }
    }

    /// An accepted `trial` that leaves the residuals above the target, or the step with its
    /// second-order correction where that lowers φ further (so it passes the same test): the
    /// bilinear term a step leaves in the residuals would otherwise hold each step short of
    /// equilibrium (the Maratos effect of an exact penalty). A trial that meets the target
    /// is projected (`fit`) where that lowers φ.
    fn corrected_if_better(&self, layout: &Layout, step: &Step, trial: State) -> State {
        // One pass over the residuals gives both the target test and φ.
        let (largest, l1) = self.model.violation(&trial);
        let phi = self.model.objective_value(&trial) + self.nu * l1;
        if largest <= self.feasible_below {
            // The residuals a feasible step leaves still cost ν each: projected away (one
            // height solve, `fit` only), they no longer hold the next steps' model ratio
            // down.
            let projected = self.projected(&trial).filter(|c| self.merit(c) < phi);
            return projected.unwrap_or(trial);
        }
        (self.corrected(layout, step, &trial, |c| self.merit(c) < phi)).unwrap_or(trial)
    }

    /// The step's second-order correction, where `better` takes it: for `fit`, first the
    /// trial's heights projected onto equilibrium with its forces (one height solve: the
    /// least change in the fit's own measure), else the step solved again with the
    /// second-order terms it leaves in the residuals and the joints on the right-hand side
    /// (one QP).
    fn corrected(
        &self,
        layout: &Layout,
        step: &Step,
        trial: &State,
        better: impl Fn(&State) -> bool,
    ) -> Option<State> {
        if let Some(projected) = self.projected(trial).filter(&better) {
            return Some(projected);
        }
        let correction = Correction::of(self.model, &self.state, step);
        let input = self.input(Some(&correction));
        let second = solve_step(self.model, layout, &self.state, &input)?;
        Some(self.apply(&second)).filter(better)
    }

    /// `trial` with the heights of its non-anchored vertices moved the least (area-weighted)
    /// to balance its forces, then brought back within the envelope: Fletcher's second-order
    /// correction as a projection onto the residuals' zero set along the heights. None where
    /// the height solve fails.
    fn projected(&self, trial: &State) -> Option<State> {
        let (model, heights) = (self.model, self.heights.as_ref()?);
        let rows = heights.vertices();
        let loads: Vec<f64> = (0..trial.z.len()).map(|v| model.load(trial, v)).collect();
        let area: Vec<f64> = rows.iter().map(|&v| model.area[v as usize]).collect();
        // A pull far below K's own scale: a projection where K is regular, and where a
        // vertex has lost all stress its height stays.
        let scale = (rows.iter())
            .map(|&v| {
                let sum: f64 = (model.incident[v as usize].iter())
                    .map(|&e| trial.q[e as usize].abs())
                    .sum();
                sum * sum
            })
            .sum::<f64>()
            / rows.len().max(1) as f64;
        let mean_area = area.iter().sum::<f64>() / rows.len().max(1) as f64;
        let rho = 1e-10 * scale / mean_area.max(f64::MIN_POSITIVE);
        let z =
            (heights.nearest(&trial.q, &loads, &trial.z, &trial.z, rho, &area, None, None)).ok()?;
        Some(State {
            z: self.within(z, trial.t),
            ..trial.clone()
        })
    }

    /// ν at ten times the largest multiplier where the step met its linearised residuals
    /// (so the penalty stays exact without drowning the objective), never below its start;
    /// while polishing, a thousand times that.
    fn update_penalty(&mut self, multipliers: &[f64], joint: f64, slack: f64) {
        if slack <= 1e-12 * self.model.residual.len() as f64 {
            let factor = if self.polishing { 1e4 } else { 10.0 };
            let largest = max_abs(multipliers).max(joint);
            self.nu = (factor * largest).clamp(self.nu_max / NU_RANGE, self.nu_max);
        }
    }

    /// A feasible state where a step barely damped predicts no fall of φ above a relative
    /// `STATIONARY` of the objective: a first-order stationary point of the merit to the
    /// QPs' accuracy (the predicted fall of an ℓ1 model is zero exactly at a KKT point).
    fn stationary(&self, predicted: f64) -> bool {
        let f = self.model.objective_value(&self.state);
        self.rho <= RHO_SETTLED
            && self.residual <= self.feasible_below
            && predicted <= STATIONARY * (f.abs() + self.objective_floor())
    }

    /// At the largest penalty with the residuals above target, the violation moved by less
    /// than a relative 1e-5 over the last five accepted steps: the search creeps along a
    /// stationary point of the infeasibility (a plan whose free edges no compression-only
    /// stress balances ends there), which the iteration limit would not see it leave.
    fn infeasibility_settled(&self) -> bool {
        let v = &self.violations;
        self.nu >= self.nu_max * (1.0 - 1e-9)
            && self.residual > self.feasible_below
            && v.len() >= 6
            && (v[v.len() - 6] - v[v.len() - 1]).abs() <= 1e-5 * v[v.len() - 1]
    }

    /// The objective moved by less than a relative 1e-5 over the last five accepted steps
    /// (or 1e-12 over the last one).
    fn settled(&self) -> bool {
        let h = &self.history;
        let floor = self.objective_floor();
        let last = *h.last().expect("called after a step");
        let moved = |k: usize| (h[h.len() - 1 - k] - last).abs() / (last.abs() + floor);
        (h.len() >= 2 && moved(1) <= 1e-12) || (h.len() >= 6 && moved(5) <= 1e-5)
    }

    fn reject(&mut self) -> Outcome {
        self.rho *= self.grow;
        self.grow = (self.grow * 2.0).min(10.0);
        if self.rho > RHO_MAX {
            Outcome::Stationary
        } else {
            Outcome::Continue
        }
    }

    /// The objective's natural size below which changes do not count.
    fn objective_floor(&self) -> f64 {
        match self.model.objective {
            Objective::Fit => 1e-9,
            _ => 1e-6,
        }
    }

    /// The step at the current ρ, with ν raised while the linearised residuals are left
    /// unmet at its price.
    fn steered_step(&mut self, layout: &Layout) -> Option<Step> {
        for _ in 0..2 {
            let input = self.input(None);
            let step = solve_step(self.model, layout, &self.state, &input)?;
            let l1 = self.model.violation(&self.state).1;
            let unmet = self.residual > self.feasible_below && step.slack > 0.1 * l1;
            if unmet && self.nu < self.nu_max {
                self.nu *= 10.0;
                continue;
            }
            return Some(step);
        }
        solve_step(self.model, layout, &self.state, &self.input(None))
    }

    /// The step's inputs at the current ρ and ν, with the last multipliers' curvature.
    fn input<'s>(&'s self, correction: Option<&'s Correction>) -> StepInput<'s> {
        StepInput {
            rho: self.rho,
            rho_z: self.rho,
            nu: self.nu,
            correction,
            // The fit's own curvature (the area shares) is small beside the convexified
            // Lagrangian's, which would dwarf it: its steps keep the proximal term alone.
            multipliers: self
                .mu
                .as_deref()
                .filter(|_| self.model.objective != Objective::Fit),
            direction: (self.direction.as_ref()).map(|(dq, dz)| (dq.as_slice(), dz.as_slice())),
        }
    }

    fn acceptable(&self, phi: f64, predicted: f64, trial: &State) -> bool {
        let actual = phi - self.merit(trial);
        predicted > 0.0 && actual >= ACCEPT * predicted
    }

    fn apply(&self, step: &Step) -> State {
        let model = self.model;
        let s = &self.state;
        let y: Vec<f64> = (s.y.iter().zip(&step.dy)).map(|(a, b)| a + b).collect();
        // q = S y exactly (the QP meets it to its tolerance): the reduced coordinates' exact
        // horizontal balance must not drift with the QPs' residuals.
        let sy = model.stress.s().mul(&y);
        let q = (sy.iter().zip(&model.stress.bounds))
            .map(|(q, b)| b.map_or(0.0, |(lo, hi)| q.clamp(lo, hi)))
            .collect();
        let t = match model.objective {
            Objective::MinThickness => (s.t + step.dt).max(0.0),
            _ => s.t + step.dt,
        };
        let z = (s.z.iter().zip(&step.dz)).map(|(z, dz)| z + dz).collect();
        // Within the envelope (the QP meets it to its tolerance).
        State {
            y,
            q,
            z: self.within(z, t),
            t,
        }
    }

    /// Heights `z` brought within the envelope at the scale of the scalar `t`, and on or
    /// above the springing planes.
    fn within(&self, mut z: Vec<f64>, t: f64) -> Vec<f64> {
        let model = self.model;
        let scale = model.scale(&State {
            t,
            ..State::default()
        });
        for (v, z) in z.iter_mut().enumerate() {
            if model.variable[v] {
                let (m, h) = (model.middle[v], scale * model.half[v]);
                *z = z.clamp(m - h, m + h);
            }
        }
        for joint in &model.joints {
            let a = joint.support as usize;
            let m = model.middle[a];
            z[a] = z[a].max(m - scale * (m - joint.springing));
        }
        z
    }

    fn record(&mut self) {
        let f = self.model.objective_value(&self.state);
        if self.residual <= self.certified_below
            && self.best_feasible.as_ref().is_none_or(|(b, _)| f <= *b)
        {
            self.best_feasible = Some((f, self.state.clone()));
        }
        self.find_ray();
        if self.residual < self.least_infeasible.0 {
            self.least_infeasible = (self.residual, self.state.clone());
        }
    }

    /// For the greatest thrust and the largest load: where the current force densities start
    /// a ray of certified surfaces (the objective has no bound), its state far enough along
    /// to pass the best state found becomes the answer, where the result's own certificate
    /// accepts it.
    fn find_ray(&mut self) {
        if !matches!(
            self.model.objective,
            Objective::MaxThrust | Objective::MaxLoad
        ) {
            return;
        }
        let f = self.model.objective_value(&self.state);
        let at_least = match &self.best_feasible {
            Some((best, _)) if f < 0.0 && *best < 0.0 => best / f,
            _ => 1.0,
        };
        let Some(start) = ray::ray_start(self.model, &self.state, at_least) else {
            return;
        };
        let run = Run {
            state: start.clone(),
            termination: Termination::Converged,
            iterations: 0,
            seconds: 0.0,
            unbounded: true,
        };
        if self.model.certify(run, &self.settings).feasible {
            let f = self.model.objective_value(&start);
            self.best_feasible = Some((f, start));
            self.unbounded = true;
        }
    }

    fn stationary_termination(&self) -> Termination {
        if self.best_feasible.is_some() {
            Termination::Converged
        } else {
            Termination::Stalled {
                vertices: self.worst_vertices(),
            }
        }
    }

    /// The ten non-anchored vertices with the largest residuals in the least infeasible state.
    fn worst_vertices(&self) -> Vec<u32> {
        let c = self.model.residuals(&self.least_infeasible.1);
        let mut order: Vec<usize> = (0..c.len()).collect();
        order.sort_by(|&a, &b| c[b].abs().total_cmp(&c[a].abs()));
        order
            .into_iter()
            .take(10)
            .map(|k| self.model.residual[k])
            .collect()
    }

    fn answer(self) -> State {
        match self.best_feasible {
            Some((_, s)) => s,
            None => self.least_infeasible.1,
        }
    }
}

fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |m, v| m.max(v.abs()))
}
