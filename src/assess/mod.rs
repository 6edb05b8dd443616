//! Masonry assessment (docs/method.md §16): a compression-only thrust surface in equilibrium
//! with the masonry's weight that fits inside its envelope proves the vault safe (Heyman's
//! safe theorem). [`assess`] finds one for an [`Objective`]: the one nearest the middle
//! surface, the least thickness that still holds one, the least or greatest horizontal
//! thrust, or the largest multiple of a live load.
//!
//! The plan is the mesh's; the unknowns are the thrust surface's heights (the supports' too,
//! within the envelope, unless fixed), the stress (reduced coordinates: horizontal balance
//! is exact) and the objective's scalar. Equilibrium is bilinear in stress and heights; a
//! sequential QP with an exact ℓ1 penalty on the vertical residuals solves it, accepting
//! only steps that lower its merit function. Every returned figure is recomputed from the
//! returned heights and forces.

mod corners;
mod envelope;
mod family;
mod model;
mod qp;
mod ray;
mod sqp;

pub use envelope::Envelope;
pub use family::{min_thickness_of_family, FamilyThickness};

use crate::error::Result;
use crate::geometry::loads::LoadRule;
use crate::problem::Problem;
use crate::solve::{Progress, Termination};
use crate::stress::QBound;

/// What [`assess`] optimises over the thrust surfaces that fit inside the envelope. Its names
/// (`fit`, `min-thickness`, ...: `as_str`, `Display`, `FromStr`) are those of `src/names.rs`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Objective {
    /// Does one fit? The one nearest the middle surface (least area-weighted squared height
    /// difference).
    #[default]
    Fit,
    /// The least thickness: the smallest scale s of the envelope's half extents about the
    /// middle surface that still contains a thrust surface (the loads stay those of the given
    /// thickness: scaling all loads scales the stress, not the thrust surface).
    MinThickness,
    /// The least horizontal thrust Σ_supports |H_a| (the passive state).
    MinThrust,
    /// The greatest horizontal thrust (the active state).
    MaxThrust,
    /// The largest factor λ on [`AssessSettings::load_pattern`] added to the self-weight.
    MaxLoad,
}

/// Settings of [`assess`]. `Default` gives the documented defaults.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct AssessSettings {
    /// What to optimise. Default [`Objective::Fit`].
    pub objective: Objective,
    /// Keep the supports at the mesh's heights instead of letting the thrust meet each
    /// support anywhere within the envelope. Default false.
    pub fixed_supports: bool,
    /// Weight per unit volume of the masonry: a face weighs area × thickness × unit weight.
    /// 0: no self-weight, the problem's extra loads alone (loads given per vertex). Default 1.
    pub unit_weight: f64,
    /// How a face's weight is shared among its corners (on the middle surface). Default
    /// barycentric.
    pub load_rule: LoadRule,
    /// Downward load per vertex for [`Objective::MaxLoad`], multiplied by λ (every entry at
    /// least 0 and at most [`crate::MAX_MEAN_LOAD`], one at least > 0); ignored otherwise.
    /// Default none.
    pub load_pattern: Option<Vec<f64>>,
    /// Lower bound on the force densities (compression only: 0). Default `Absolute(0)`.
    pub q_min: QBound,
    /// Largest ε∞ (relative to the mean load) of a certified surface. Default 1e-6.
    pub tolerance: f64,
    /// Sequential QP iterations at most, per search: the start's, the analysis' own and each
    /// retry's (docs/method.md §16.3) count their own, [`AssessResult::iterations`] sums them
    /// all. Default 200.
    pub max_iterations: usize,
}

impl Default for AssessSettings {
    fn default() -> Self {
        AssessSettings {
            objective: Objective::Fit,
            fixed_supports: false,
            unit_weight: 1.0,
            load_rule: LoadRule::Barycentric,
            load_pattern: None,
            q_min: QBound::Absolute(0.0),
            tolerance: 1e-6,
            max_iterations: 200,
        }
    }
}

/// A live load pattern pushes down (>= 0 at every vertex) and somewhere: λ multiplies it. Its
/// loads are at most the largest mean load a stress step accepts, so that sums of them stay
/// finite; λ scales inversely with the pattern, so a smaller one loses nothing.
fn downward(pattern: &[f64]) -> Result<()> {
    use crate::stress::MAX_MEAN_LOAD;
    let upward = pattern.iter().position(|&p| p < 0.0);
    let huge = pattern.iter().position(|&p| p > MAX_MEAN_LOAD);
    let reason = match (upward, huge) {
        (Some(v), _) => format!(
            "vertex {v}: {} is upward; the pattern's loads push down (>= 0)",
            pattern[v]
        ),
        (None, Some(v)) => format!(
            "vertex {v}: {:e} is beyond {MAX_MEAN_LOAD:e}, where sums of loads overflow; scale \
             the pattern down (λ scales up as much)",
            pattern[v]
        ),
        _ if pattern.iter().all(|&p| p == 0.0) => "every load is 0: nothing to multiply".into(),
        _ => return Ok(()),
    };
    Err(crate::Error::InvalidArgument {
        name: "load_pattern",
        reason,
    })
}

impl AssessSettings {
    /// Checks every setting; errors name it, worded as `FormFindSettings::validate` words
    /// its own (the C API and Python report these reasons under their argument names).
    pub fn validate(&self) -> Result<()> {
        use crate::validate::{above, all_finite, at_least, count, within};
        at_least("unit_weight", self.unit_weight, 0.0)?;
        above("tolerance", self.tolerance, 0.0)?;
        within("tolerance", self.tolerance, 0.0, 1.0, true)?;
        count("max_iterations", self.max_iterations, 1)?;
        let (QBound::Absolute(q) | QBound::Relative(q)) = self.q_min;
        at_least("q_min", q, 0.0)?;
        if let Some(pattern) = &self.load_pattern {
            all_finite("load_pattern", pattern, "vertex")?;
            downward(pattern)?;
        }
        Ok(())
    }

    /// These settings with `load_pattern` set to `pattern`.
    #[must_use]
    pub fn with_load_pattern(mut self, pattern: Vec<f64>) -> Self {
        self.load_pattern = Some(pattern);
        self
    }
}

crate::setters::with_setters!(AssessSettings {
    with_objective: objective: Objective,
    with_fixed_supports: fixed_supports: bool,
    with_unit_weight: unit_weight: f64,
    with_load_rule: load_rule: LoadRule,
    with_q_min: q_min: QBound,
    with_tolerance: tolerance: f64,
    with_max_iterations: max_iterations: usize,
});

/// Where the reaction of a free support meets its springing plane (docs/method.md §16.1).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct SpringingJoint {
    /// The support vertex.
    pub vertex: u32,
    /// Height of the springing plane at the reported thickness scale σ: m − σ (m − s).
    pub springing: f64,
    /// The joint's reach at the reported scale: σ b.
    pub reach: f64,
    /// Horizontal reaction H_a (as `AssessResult::reactions`): the force the vault pushes
    /// the support with is (H_a, −V_a).
    pub horizontal: [f64; 2],
    /// Vertical reaction V_a = Σ q_e (z_j − z_a) + p_a, the support's own load included.
    pub vertical: f64,
    /// Where the reaction's line through the support point meets the springing plane:
    /// the support's plan point moved by (z_a − springing) H_a / V_a (the support's own
    /// point where H_a = 0; infinitely far where V_a ≤ 0 < |H_a|).
    pub point: [f64; 3],
    /// Plan distance of `point` from the support: at most `reach` (to the tolerance of
    /// `AssessResult::worst_joint`) on a certified surface.
    pub offset: f64,
}

impl SpringingJoint {
    /// The joint as one row of numbers, the order of the C API's `vsr_assessment_joints` and
    /// Python's `joints`: springing, reach, H (x, y), V, point (x, y, z), offset.
    pub fn row(&self) -> [f64; 9] {
        let ([hx, hy], [px, py, pz]) = (self.horizontal, self.point);
        let (s, b, v, o) = (self.springing, self.reach, self.vertical, self.offset);
        [s, b, hx, hy, v, px, py, pz, o]
    }
}

/// The outcome of [`assess`], in physical units.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct AssessResult {
    /// The analysis that was run.
    pub objective: Objective,
    /// True when `positions` with `force_densities` is a certified thrust surface: ε∞ and the
    /// horizontal imbalance below the tolerance, every q within its bounds (q ≥ 0), every
    /// height within `[lower − 1e-9 d, upper + 1e-9 d]`, d the plan diagonal, and the
    /// springing joints' check (docs/method.md §16.3).
    pub feasible: bool,
    /// Converged; or how the search ended (the best state reached is returned).
    pub termination: Termination,
    /// Sequential QP iterations of every search (the start's and the retries' included).
    pub iterations: usize,
    /// The thrust surface: the mesh's plan with the found heights.
    pub positions: Vec<[f64; 3]>,
    /// Force density per mesh edge (compression positive).
    pub force_densities: Vec<f64>,
    /// Vertical load per vertex: self-weight plus extra loads plus λ × pattern.
    pub loads: Vec<f64>,
    /// Vertical residual per vertex (0 at supports).
    pub residuals: Vec<f64>,
    /// max |r| / mean load over the non-anchored vertices.
    pub eps_inf: f64,
    /// Largest horizontal imbalance at a non-anchored vertex over the mean load.
    pub horizontal_imbalance: f64,
    /// Lower bound per vertex: the envelope at the reported thickness (scaled by
    /// `thickness_scale`).
    pub lower: Vec<f64>,
    /// Upper bound per vertex, likewise.
    pub upper: Vec<f64>,
    /// Scale of the envelope's half extents: 1, or the least scale found by
    /// [`Objective::MinThickness`].
    pub thickness_scale: f64,
    /// 1 / `thickness_scale`: the geometric safety factor of a minimum-thickness analysis.
    pub safety_factor: f64,
    /// Horizontal reaction per vertex (non-zero at supports): the force the vault pushes
    /// the support with.
    pub reactions: Vec<[f64; 2]>,
    /// Σ over supports of |reaction|.
    pub thrust_horizontal: f64,
    /// λ of [`Objective::MaxLoad`] (0 otherwise).
    pub load_factor: f64,
    /// [`Objective::MaxThrust`] and [`Objective::MaxLoad`]: the objective has no bound. The
    /// returned surface is certified, and its force densities (and λ) scaled by every s from
    /// some s₀ ≥ 1 on, with heights approaching a limit surface over the same supports, give
    /// certified surfaces too (docs/method.md §16.4), so `thrust_horizontal` or
    /// `load_factor` is a value reached, not the greatest. False otherwise.
    pub unbounded: bool,
    /// The largest excess of a height over its bound (0 when inside) and its vertex.
    pub worst_bound: (f64, Option<u32>),
    /// The springing joint of every free support with a finite reach (none with fixed
    /// supports), recomputed from the returned heights, forces and loads.
    pub joints: Vec<SpringingJoint>,
    /// The largest joint excess max(0, (z_a − s_a) |H_a| − b_a V_a) over b_a × the mean
    /// load (at scale 1; b_a at the reported scale in the product), and its support: below
    /// `tolerance` for a certified surface.
    pub worst_joint: (f64, Option<u32>),
    /// The largest residual's vertex (None when there is no non-anchored vertex).
    pub worst_residual_vertex: Option<u32>,
    /// When an analysis other than the least thickness found no certified surface: the
    /// least thickness scale at which one was found (above 1: the envelope is too thin), and
    /// the vertex where that surface leaves the given envelope the most. None otherwise.
    pub needed_scale: Option<(f64, Option<u32>)>,
    /// The vertices of the loaded parts that no compressive state joins to a support (cut
    /// off by free corners or straight free edges, docs/method.md §16.3; a part a `max-load`
    /// live load reaches is left to the search), in increasing order. Where there are any,
    /// no surface exists in any envelope: `feasible` is false and the analysis answered
    /// without a search. Empty otherwise.
    pub stranded: Vec<u32>,
    /// Wall time of the whole analysis (its start included), seconds.
    pub seconds: f64,
}

impl AssessResult {
    /// The termination as a sentence, in an assessment's words: a stalled search lists the
    /// vertices with the largest residuals of its least infeasible state (its retries put a
    /// floor on q themselves, so form finding's advice to raise q_min does not apply).
    pub fn termination_message(&self) -> String {
        match &self.termination {
            Termination::Stalled { vertices } if !vertices.is_empty() => {
                let ids: Vec<String> = vertices.iter().map(|v| v.to_string()).collect();
                format!(
                    "stalled: no step lowers the infeasibility; the largest residuals at \
                     vertices {}",
                    ids.join(", ")
                )
            }
            other => other.to_string(),
        }
    }
}

/// Finds a certified thrust surface inside `envelope` for `settings.objective`.
///
/// `problem` gives the mesh (its plan is the form diagram; with fixed supports its anchored
/// heights), the extra point loads and prescribed horizontal forces; its face densities are
/// replaced by the envelope's thickness × `unit_weight` on the middle surface. Without a
/// certified surface the result has `feasible == false` with the best state reached (least
/// infeasibility) and where it fails.
///
/// A search that ends without a certified surface proves nothing: the analysis then runs
/// again from surfaces of a stricter problem and of the least thickness (docs/method.md
/// §16.3) before it answers `feasible == false`. A stranded part of the plan does prove it:
/// free corners (free vertices whose edges all leave them on one side in plan) and straight
/// free edges carry no force off themselves, and a loaded part left with no compressive
/// path to a support has no surface in any envelope. The answer, without a search, is then
/// `feasible == false` with [`Termination::Infeasible`] naming the corners and the part.
///
/// `progress` sees every step of every search (the start's `fit` search, the retries and the
/// search for [`AssessResult::needed_scale`]), numbered as one sequence; returning false
/// cancels the analysis.
pub fn assess(
    problem: &Problem,
    envelope: &Envelope,
    settings: &AssessSettings,
    progress: Option<&mut Progress>,
) -> Result<AssessResult> {
    settings.validate()?;
    let start = std::time::Instant::now();
    let mut steps = Steps {
        progress,
        before: 0,
        cancelled: false,
    };
    let model = model::Model::new(problem, envelope, settings)?;
    if let Some(stranded) = corners::stranded(&model, settings.tolerance) {
        let run = corners::unbalanced(&model, &stranded);
        let result = finish(&model, run, settings, &steps, start);
        return Ok(AssessResult {
            stranded: stranded.vertices,
            ..result
        });
    }
    let idle = corners::floored_idle(&model, settings);
    if !idle.is_empty() {
        let run = corners::unfloored(&model, &idle);
        return Ok(finish(&model, run, settings, &steps, start));
    }
    let run = analyse(&model, problem, envelope, settings, &mut steps)?;
    let mut result = finish(&model, run, settings, &steps, start);
    if result.feasible || result.termination == Termination::Cancelled {
        return Ok(result);
    }
    // A search that stalls proves nothing: from a surface certified for a stricter problem
    // (the same analysis with form finding's floor on the force densities) the analysis
    // runs again.
    let floored = floored_surface(problem, envelope, settings, &mut steps)?;
    if steps.cancelled {
        result.termination = Termination::Cancelled;
        return Ok(result);
    }
    if let Some(again) = floored.map(|state| retry(&model, settings, &mut steps, state, start)) {
        let again = again?;
        if again.feasible || again.termination == Termination::Cancelled {
            return Ok(again);
        }
    }
    if settings.objective != Objective::MinThickness {
        let thinnest = needed_scale(problem, envelope, settings, &mut steps)?;
        if steps.cancelled {
            result.termination = Termination::Cancelled;
            return Ok(result);
        }
        if let Some(found) = thinnest.as_ref().filter(|t| t.fits) {
            // The thinnest surface fits this envelope: the analysis runs again from it.
            let again = retry(&model, settings, &mut steps, found.state.clone(), start)?;
            if again.feasible || again.termination == Termination::Cancelled {
                return Ok(again);
            }
        }
        result.needed_scale = thinnest.map(|t| (t.scale, t.outside));
    }
    // The answer is the first search's; its figures of effort count every search.
    result.iterations = steps.before;
    result.seconds = start.elapsed().as_secs_f64();
    Ok(result)
}

/// The analysis' start (see [`feasible_start`]) and its search.
fn analyse(
    model: &model::Model,
    problem: &Problem,
    envelope: &Envelope,
    settings: &AssessSettings,
    steps: &mut Steps,
) -> Result<model::Run> {
    match feasible_start(problem, envelope, settings, steps)? {
        Some(run) if run.termination == Termination::Cancelled => {
            Ok(sqp::stopped(model, settings, run))
        }
        begun => {
            let from = begun.map(|run| run.state);
            steps.search(|p| sqp::solve(model, settings, p, from, sqp::Until::Optimal))
        }
    }
}

/// The analysis' search again, from `state` (a state of a search on the same mesh).
fn retry(
    model: &model::Model,
    settings: &AssessSettings,
    steps: &mut Steps,
    state: model::State,
    start: std::time::Instant,
) -> Result<AssessResult> {
    let from = Some(state);
    let run = steps.search(|p| sqp::solve(model, settings, p, from, sqp::Until::Optimal))?;
    Ok(finish(model, run, settings, steps, start))
}

/// The certified figures of a run, its steps and seconds those of the whole analysis so far.
fn finish(
    model: &model::Model,
    mut run: model::Run,
    settings: &AssessSettings,
    steps: &Steps,
    start: std::time::Instant,
) -> AssessResult {
    run.iterations = steps.before;
    run.seconds = start.elapsed().as_secs_f64();
    model.certify(run, settings)
}

/// With compression only (no floor on q), the certified state of the same analysis with
/// every force density at least form finding's default floor, 0.05 p̄/L₀: a stricter problem,
/// so its surface is certified here too, and its search does not stall where a region loses
/// all stress (a stationary point of the penalty that compression only allows).
fn floored_surface(
    problem: &Problem,
    envelope: &Envelope,
    settings: &AssessSettings,
    steps: &mut Steps,
) -> Result<Option<model::State>> {
    let (QBound::Absolute(q) | QBound::Relative(q)) = settings.q_min;
    if q > 0.0 {
        return Ok(None);
    }
    let floored = AssessSettings {
        q_min: crate::stress::StressSettings::default().q_min,
        ..settings.clone()
    };
    let model = model::Model::new(problem, envelope, &floored)?;
    let run = analyse(&model, problem, envelope, &floored, steps)?;
    let state = run.state.clone();
    let found = model.certify(run, &floored);
    Ok((found.feasible && found.termination != Termination::Cancelled).then_some(state))
}

/// The caller's progress callback across successive searches, their steps numbered as one
/// sequence.
struct Steps<'p, 'a> {
    progress: Option<&'p mut Progress<'a>>,
    /// Steps taken by the searches so far.
    before: usize,
    /// Whether a search was cancelled.
    cancelled: bool,
}

impl Steps<'_, '_> {
    /// Runs one search with the callback shifted by the steps before it.
    fn search(
        &mut self,
        run: impl FnOnce(Option<&mut Progress>) -> Result<model::Run>,
    ) -> Result<model::Run> {
        let before = self.before;
        let mut shifted =
            (self.progress.as_deref_mut()).map(|p| move |k: usize, eps: f64| p(before + k, eps));
        let done = run(shifted.as_mut().map(|f| f as &mut Progress))?;
        self.before += done.iterations;
        self.cancelled |= done.termination == Termination::Cancelled;
        Ok(done)
    }
}

/// For every analysis but `fit`: the `fit` search's run up to its first certified surface
/// inside the envelope (when one is found), to start from, so that the objective is
/// pursued from equilibrium rather than traded against it.
fn feasible_start(
    problem: &Problem,
    envelope: &Envelope,
    settings: &AssessSettings,
    steps: &mut Steps,
) -> Result<Option<model::Run>> {
    if settings.objective == Objective::Fit {
        return Ok(None);
    }
    let fit = AssessSettings {
        objective: Objective::Fit,
        load_pattern: None,
        ..settings.clone()
    };
    let model = model::Model::new(problem, envelope, &fit)?;
    let run = steps.search(|p| sqp::solve(&model, &fit, p, None, sqp::Until::Certified))?;
    Ok(Some(run))
}

/// The least thickness scale with a certified surface: the surface and where it leaves the
/// envelope at scale 1 the most.
struct Thinnest {
    scale: f64,
    /// Whether the surface lies inside the envelope at scale 1 (its joints not checked).
    fits: bool,
    outside: Option<u32>,
    state: model::State,
}

/// The least thickness search (the start's `fit` search first) for an analysis that found
/// no certified surface.
fn needed_scale(
    problem: &Problem,
    envelope: &Envelope,
    settings: &AssessSettings,
    steps: &mut Steps,
) -> Result<Option<Thinnest>> {
    let thinnest = AssessSettings {
        objective: Objective::MinThickness,
        load_pattern: None,
        ..settings.clone()
    };
    let model = model::Model::new(problem, envelope, &thinnest)?;
    let from = match feasible_start(problem, envelope, &thinnest, steps)? {
        Some(run) if run.termination == Termination::Cancelled => return Ok(None),
        begun => begun.map(|run| run.state),
    };
    let run = steps.search(|p| sqp::solve(&model, &thinnest, p, from, sqp::Until::Optimal))?;
    if run.termination == Termination::Cancelled {
        return Ok(None);
    }
    let state = run.state.clone();
    let found = model.certify(run, &thinnest);
    if !found.feasible {
        return Ok(None);
    }
    let diag = envelope::plan_diagonal(&problem.mesh);
    let (excess, vertex) = (0..found.positions.len())
        .filter(|&v| problem.mesh.referenced[v])
        .map(|v| {
            let z = found.positions[v][2];
            ((envelope.lower[v] - z).max(z - envelope.upper[v]), v as u32)
        })
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .unwrap_or((0.0, 0));
    Ok(Some(Thinnest {
        scale: found.thickness_scale,
        fits: found.thickness_scale <= 1.0 && excess <= 1e-9 * diag,
        outside: (excess > 0.0).then_some(vertex),
        state,
    }))
}
