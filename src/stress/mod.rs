//! Stress optimisation: the best compressive force densities for a fixed shape
//! (docs/method.md §4–10).
//!
//! Both formulations build q = S y for their own unknowns and share one QP (`qp.rs`); the
//! result is recomputed in physical units from the returned force densities, so every figure
//! it reports (residuals, ε∞, imbalance) is a certificate, not the solver's own claim.

pub mod airy;
mod gauge;
pub mod holes;
mod ipm;
pub(crate) mod linear;
mod qp;
pub mod settings;
pub mod sparse;

use crate::error::Result;
use crate::geometry::dual::{self, ForceDiagram};
use crate::geometry::{loads, Frame, Plan};
use crate::mesh::Mesh;
use crate::problem::Problem;
use airy::AiryOperator;
use clarabel::solver::SolverStatus;
pub use settings::{EdgeScope, Formulation, QBound, QpSolver, StressSettings, TauMode};
use sparse::Csr;
use std::time::Instant;
use Formulation::{EdgeBased, Reduced};

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
    pub force_diagram: ForceDiagram,
    /// Iterations of the QP solver; 0 when the native solver reached the optimum from the
    /// previous step's active set alone (form finding reuses it between steps).
    pub iterations: u32,
    /// The formulation that produced the forces: the requested one, or the edge-based one when
    /// every reduced attempt failed numerically, or when the native solver answered a mesh with
    /// a vertex of more than 64 edges (same optimum; see `docs/method.md` §9).
    pub formulation: Formulation,
    /// The solver that produced the answer (clarabel after a fallback from the native one).
    pub solver: QpSolver,
    /// Whether the answer came from the lifted form of the QP (q as variables).
    pub lifted: bool,
    /// The regulariser ε actually used (larger than the setting after a numerical failure).
    pub regularisation: f64,
    pub seconds: f64,
}

/// Optimises the stress of `problem` as given (its mesh positions).
///
/// The loads must weigh down: an [`Error::InvalidArgument`](crate::Error::InvalidArgument)
/// for `loads` when their mean over the non-anchored vertices is 0 (density 0 everywhere
/// without extra loads: nothing to balance), negative, or beyond what double precision can
/// carry through the solve ([`MIN_MEAN_LOAD`], [`MAX_MEAN_LOAD`]).
pub fn analyse(problem: &Problem, settings: &StressSettings) -> Result<StressResult> {
    analyse_at(problem, &problem.mesh.positions, settings)
}

/// Vertices whose equations count: referenced and not anchored.
pub fn non_anchored(mesh: &Mesh) -> Vec<u32> {
    (0..mesh.positions.len() as u32)
        .filter(|&v| mesh.is_non_anchored(v as usize))
        .collect()
}

/// Unit outward normals (sum of the two boundary edges' normals) at boundary vertices.
pub fn boundary_normals(mesh: &Mesh, u: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut nrm = vec![[0.0; 2]; u.len()];
    for lp in &mesh.loops {
        let n = lp.vertices.len();
        for k in 0..n {
            let (a, b) = (lp.vertices[k] as usize, lp.vertices[(k + 1) % n] as usize);
            let d = [u[b][0] - u[a][0], u[b][1] - u[a][1]];
            let len = d[0].hypot(d[1]);
            let out = [d[1] / len, -d[0] / len];
            for v in [a, b] {
                nrm[v][0] += out[0];
                nrm[v][1] += out[1];
            }
        }
    }
    for m in &mut nrm {
        let len = m[0].hypot(m[1]);
        if len > 0.0 {
            *m = [m[0] / len, m[1] / len];
        }
    }
    nrm
}

/// Optimises the stress of `problem` with the vertices at `positions`.
pub fn analyse_at(
    problem: &Problem,
    positions: &[[f64; 3]],
    settings: &StressSettings,
) -> Result<StressResult> {
    analyse_near(problem, positions, settings, None)
}

/// A proximal centre for the stress step: the regulariser becomes
/// `weight` Σ l_e² (q_e − prior_e)² (frame units) instead of ε Σ l_e² q_e². Form finding passes
/// the previous iteration's forces: among equally good stresses the step then stays close to
/// the last one, and at a self-supporting fixed point the term vanishes.
#[derive(Debug, Clone, Copy)]
pub struct Prior<'a> {
    /// Physical force density per edge.
    pub force_densities: &'a [f64],
    pub weight: f64,
    /// Start with the lifted reduced QP (the form that produced the previous step's answer).
    pub lifted_first: bool,
}

/// [`analyse_at`] with an optional proximal centre.
pub fn analyse_near(
    problem: &Problem,
    positions: &[[f64; 3]],
    settings: &StressSettings,
    prior: Option<Prior>,
) -> Result<StressResult> {
    analyse_cached(
        problem,
        positions,
        settings,
        prior,
        &mut StressCache::default(),
    )
}

/// What a stress step leaves for the next one on the same mesh:
/// - the structure of the native solver's normal matrix (its fill-reducing ordering and
///   symbolic factorisation), which depends on the mesh's connectivity and the settings but
///   not on the positions;
/// - the last answer with its active bounds;
/// - the reduced operator q = S y of the last plan, with the inputs it was built from (see
///   `PlanKey`).
///
/// Opaque; `Default` is empty. A step of another structure replaces what it holds, and a step
/// with another plan, other supports or another hole mode replaces the reduced operator.
#[derive(Default)]
pub struct StressCache {
    normal: ipm::PatternCache,
    reduced: Option<(PlanKey, AiryOperator)>,
    /// Solve native QPs to `ipm::Tolerances::for_form_finding` (coarse when large).
    coarse: bool,
    /// Whether the last step's answer was solved to coarse optimality.
    last_coarse: bool,
    /// The relative gap the next native QPs may stop at (see `StressCache::set_inexact`).
    inexact: Option<f64>,
    /// Whether the last step's answer was solved to that gap only.
    last_inexact: bool,
    /// Physical vertical loads added to those the QP balances (the nearest-shape method's
    /// multiplier shift); the result's residuals are still those of the true loads.
    load_offset: Option<Vec<f64>>,
}

impl StressCache {
    /// The cache of a form finding: its QPs beyond 20k unknowns are solved to coarse
    /// optimality (relative gap 1e-3, dual residual 1e-4 of its scale; bounds and equality
    /// rows held as tightly as ever), because the loop stops on residuals recomputed from
    /// forces and heights, which an inexact optimum does not falsify, while exact QPs are most
    /// of a large loop's time. Below 20k unknowns QPs stay exact, since there coarse answers
    /// lengthen the loop or stall it on degenerate QPs.
    pub fn for_form_finding() -> StressCache {
        StressCache {
            coarse: true,
            ..Default::default()
        }
    }

    /// Tells the next step whether its shape is far from balance (form finding: ε∞ > 0.1
    /// with the last forces at the new heights). Beyond 20k unknowns such a step does not try
    /// the last answer's active set, because a height step there moves much of the shape, the
    /// set is wrong in hundreds of rows and the failed attempt costs several factorisations.
    pub fn far_from_balance(&mut self, far: bool) {
        self.normal.far_from_balance(far);
    }

    /// Loads (physical, per vertex) the next steps add to the true loads in the QP's target;
    /// `None`: the true loads.
    pub(crate) fn set_load_offset(&mut self, offset: Option<Vec<f64>>) {
        self.load_offset = offset;
    }

    /// Whether the last step's answer is a native QP's solved to coarse optimality: short of
    /// its optimum by design (coarse beyond 20k unknowns, or inexact: see
    /// [`StressCache::set_inexact`]), as one at the iteration limit is by necessity.
    pub fn last_was_coarse(&self) -> bool {
        self.last_coarse || self.last_inexact
    }

    /// A relative gap at which the next native QPs may stop where it is looser than their
    /// tolerances' (`None`: their own). The dual residual's tolerance is relaxed with it
    /// (by the square root of the ratio); bounds and horizontal balance are held as tightly.
    /// Form finding loosens early QPs, whose answers it judges by its own merit (a step
    /// that does worse than the forces at hand is not taken), and solves them exactly once
    /// the shape nears balance.
    pub(crate) fn set_inexact(&mut self, gap: Option<f64>) {
        self.inexact = gap;
    }

    /// Whether the last step's answer was solved to the looser gap of `set_inexact` only.
    pub(crate) fn last_was_inexact(&self) -> bool {
        self.last_inexact
    }
}

/// What the reduced operator of a step was built from: the plan positions, the connectivity,
/// which boundary loops are holes, the supports and the hole mode, not the heights. A form
/// finding without ODT (the default) keeps them, and so builds the operator once. Plan
/// positions are compared bit for bit: the operator is a function of the bits, and
/// unreferenced vertices may be NaN (never equal to itself).
struct PlanKey {
    u: Vec<[u64; 2]>,
    faces: Vec<[u32; 3]>,
    outer: Vec<bool>,
    anchored: Vec<bool>,
    holes: airy::HoleMode,
}

impl PlanKey {
    fn of(mesh: &Mesh, plan: &Plan, holes: airy::HoleMode) -> PlanKey {
        PlanKey {
            u: plan.u.iter().map(|u| u.map(f64::to_bits)).collect(),
            faces: mesh.faces.clone(),
            outer: mesh.loops.iter().map(|l| l.is_outer).collect(),
            anchored: mesh.anchored.clone(),
            holes,
        }
    }

    fn fits(&self, mesh: &Mesh, plan: &Plan, holes: airy::HoleMode) -> bool {
        self.holes == holes
            && self
                .u
                .iter()
                .copied()
                .eq(plan.u.iter().map(|u| u.map(f64::to_bits)))
            && self.faces == mesh.faces
            && self.outer.iter().eq(mesh.loops.iter().map(|l| &l.is_outer))
            && self.anchored == mesh.anchored
    }
}

/// [`analyse_near`] reusing, and updating, `cache`: form finding's steps keep one cache, so
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
    let start = Instant::now();
    let mesh = &problem.mesh;
    let n = positions.len();
    let step = FramedStep::new(problem, positions, settings, cache.load_offset.as_deref())?;
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
    let q_frame = map.s().mul(&y);
    let airy_op = map.airy();
    let tau_frame = if usable { out.tau } else { vec![0.0; n] };

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

/// Heights over `l0`, relative to the mean height of the anchored vertices (of all referenced
/// ones without any) where that lies far from them (`crate::geometry::far_base`): the QP sees
/// only their differences, which keep their digits where a model lifted by 10⁷ would lose
/// seven of them to z / L₀ rounded at that size. Elsewhere the heights are taken as they are,
/// so that ordinary models are solved with the same arithmetic wherever they stand.
fn relative_heights(mesh: &Mesh, positions: &[[f64; 3]], l0: f64) -> Vec<f64> {
    let heights = |keep: &dyn Fn(usize) -> bool| {
        (0..positions.len())
            .filter(|&v| mesh.referenced[v] && keep(v))
            .map(|v| positions[v][2])
            .collect::<Vec<f64>>()
    };
    let supports = heights(&|v| mesh.anchored[v]);
    let all = heights(&|_| true);
    let base = crate::geometry::far_base(if supports.is_empty() { &all } else { &supports }, &all);
    positions.iter().map(|p| (p[2] - base) / l0).collect()
}

struct FramedStep {
    frame: Frame,
    plan: Plan,
    /// Physical loads, the non-anchored vertices and their mean load p̄.
    load: Vec<f64>,
    free: Vec<u32>,
    p_bar: f64,
    /// The natural force density scale p̄ / L₀.
    unit: f64,
    /// Heights in frame units, relative to the supports' mean height (`relative_heights`).
    z: Vec<f64>,
    p: Vec<f64>,
    normal: Vec<[f64; 2]>,
    external: Vec<[f64; 2]>,
    tau_normal: Vec<Option<[f64; 2]>>,
    edges: Vec<[u32; 2]>,
    bounds: Vec<Option<(f64, f64)>>,
    smoothing_pairs: Vec<[usize; 2]>,
}

impl FramedStep {
    /// `load_offset`: physical loads added to the true ones in the QP's target (see
    /// `StressCache::set_load_offset`).
    fn new(
        problem: &Problem,
        positions: &[[f64; 3]],
        settings: &StressSettings,
        load_offset: Option<&[f64]>,
    ) -> Result<FramedStep> {
        let mesh = &problem.mesh;
        let frame = Frame::of(mesh, positions);
        let plan = Plan::new(mesh, positions, &frame);
        let l0 = frame.scale;
        let (load, free, p_bar) = loads_at(problem, positions, settings);
        check_mean_load(&load, &free)?;
        let unit = p_bar / l0;
        let z = relative_heights(mesh, positions, l0);
        let p: Vec<f64> = match load_offset {
            Some(offset) => (load.iter().zip(offset))
                .map(|(x, o)| (x + o) / p_bar)
                .collect(),
            None => load.iter().map(|x| x / p_bar).collect(),
        };
        let normal = boundary_normals(mesh, &plan.u);
        let (external, tau_normal) = horizontal_terms(problem, settings, &normal, p_bar);
        let edges: Vec<[u32; 2]> = mesh.edges.iter().map(|e| e.v).collect();
        let bounds = edge_bounds(problem, &plan, settings, unit);
        let smoothing_pairs = if settings.dual_length_smoothing > 0.0 {
            face_edge_pairs(mesh)
        } else {
            Vec::new()
        };
        Ok(FramedStep {
            frame,
            plan,
            load,
            free,
            p_bar,
            unit,
            z,
            p,
            normal,
            external,
            tau_normal,
            edges,
            bounds,
            smoothing_pairs,
        })
    }
}

/// The external horizontal forces in frame units (prescribed τ included) and, per free
/// boundary vertex with an optimised τ, the normal it pushes along.
fn horizontal_terms(
    problem: &Problem,
    settings: &StressSettings,
    normal: &[[f64; 2]],
    p_bar: f64,
) -> (Vec<[f64; 2]>, Vec<Option<[f64; 2]>>) {
    let mesh = &problem.mesh;
    let n = normal.len();
    let mut external: Vec<[f64; 2]> = problem
        .horizontal_forces
        .iter()
        .map(|f| [f[0] / p_bar, f[1] / p_bar])
        .collect();
    let mut tau_normal = vec![None; n];
    for v in 0..n {
        if !mesh.is_free_boundary(v) {
            continue;
        }
        match settings.tau {
            TauMode::Optimized => tau_normal[v] = Some(normal[v]),
            TauMode::Zero => {}
            TauMode::Prescribed => {
                let t = problem.prescribed_tau[v] / p_bar;
                external[v][0] -= t * normal[v][0];
                external[v][1] -= t * normal[v][1];
            }
        }
    }
    (external, tau_normal)
}

/// Per edge, None for an edge without force (boundary, both ends anchored), else its bounds
/// (lower, upper) on q in frame units: q_min on the edges of its scope but polygon diagonals,
/// q_max, and the dual length bounds of interior edges.
fn edge_bounds(
    problem: &Problem,
    plan: &Plan,
    settings: &StressSettings,
    unit: f64,
) -> Vec<Option<(f64, f64)>> {
    let mesh = &problem.mesh;
    let active = |e: usize| {
        let edge = &mesh.edges[e];
        !edge.is_boundary() || edge.v.iter().any(|&v| !mesh.anchored[v as usize])
    };
    let q_min = settings.q_min.physical(unit) / unit;
    let q_max = settings
        .q_max
        .map_or(f64::INFINITY, |b| b.physical(unit) / unit);
    (0..mesh.edges.len())
        .map(|e| {
            active(e).then(|| {
                let interior = !mesh.edges[e].is_boundary();
                let scoped = (settings.q_min_scope == EdgeScope::All || interior)
                    && !problem.polygon_diagonal[e];
                let (mut lo, mut hi) = (if scoped { q_min } else { 0.0 }, q_max);
                // Dual length d* = q l is p̄ q' l' in frame units: bounds on it are per-edge q bounds.
                if let (Some((d_lo, d_hi)), true) = (settings.dual_length_bounds, interior) {
                    lo = lo.max(d_lo / plan.length[e]);
                    hi = hi.min(d_hi / plan.length[e]);
                }
                (lo, hi)
            })
        })
        .collect()
}

/// The attempts of a stress step in order: (solver, formulation, lifted, factor on ε).
///
/// The native solver goes first. Interior-point methods can fail on degenerate problems
/// (straight free edges force q = 0: no strictly feasible point), and only clarabel
/// certifies infeasibility, so when it does not converge clarabel takes over: the plain
/// reduced QP is fastest; the lifted one (q as variables) copes with problems where the
/// plain one reaches only reduced accuracy. Then ε is raised, then the edge-based
/// formulation (same optimum) is used; the result says which solver, formulation and ε.
fn attempt_list(
    settings: &StressSettings,
    lifted_first: bool,
    native: Formulation,
) -> Vec<(QpSolver, Formulation, bool, f64)> {
    use QpSolver::{Clarabel, Native};
    let (a, b) = (lifted_first, !lifted_first);
    let mut attempts: Vec<(QpSolver, Formulation, bool, f64)> = Vec::new();
    if settings.solver == Native {
        attempts.push((Native, native, false, 1.0));
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
    let same_optimum = settings.holes == airy::HoleMode::Affine || mesh.holes().next().is_none();
    let hub = (0..mesh.positions.len()).any(|v| mesh.edges_at(v).len() > HUB_EDGES);
    if settings.formulation == Reduced && same_optimum && hub {
        EdgeBased
    } else {
        settings.formulation
    }
}

/// The index of a formulation's force model in `Attempts::models`.
fn slot(f: Formulation) -> usize {
    (f == EdgeBased) as usize
}

/// What the attempts of a stress step leave: the best answer, the force models built (index
/// `slot`), and the key of the reduced operator taken from the cache, if one was.
struct Attempts {
    best: Attempt,
    models: [Option<ForceModel>; 2],
    kept_key: Option<PlanKey>,
}

/// Runs the attempts of `attempt_list` until one is final (`attempt_is_final`), building
/// each formulation's force model at most once, and keeps the best answer.
fn run_attempts(
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
    let attempts = attempt_list(settings, prior.is_some_and(|p| p.lifted_first), native);
    let base = prior.map_or(settings.regularisation, |p| p.weight);
    let prior_frame: Option<Vec<f64>> =
        prior.map(|p| p.force_densities.iter().map(|q| q / step.unit).collect());
    let mut models: [Option<ForceModel>; 2] = [None, None];
    let mut best: Option<Attempt> = None;
    let mut clarabel_tries = 0;
    // The key of a kept reduced operator, stored back with it after the step.
    let mut kept_key = None;
    for &(solver, formulation, lift_forces, factor) in &attempts {
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
            Native => qp::solve_native(&input, &mut cache.normal, cache.coarse, cache.inexact),
            Clarabel => {
                clarabel_tries += 1;
                qp::solve_clarabel(&input)
            }
        };
        let status = out.status;
        let n_unknowns = out.y.len();
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
    Ok(Attempts {
        best: best.expect("at least one attempt"),
        models,
        kept_key,
    })
}

/// τ at each of the `n` vertices in physical units: the prescribed values, or the optimised
/// ones scaled back.
fn physical_tau(
    problem: &Problem,
    settings: &StressSettings,
    tau_frame: &[f64],
    p_bar: f64,
    n: usize,
) -> Vec<f64> {
    let mesh = &problem.mesh;
    match settings.tau {
        TauMode::Prescribed => (0..n)
            .map(|v| {
                if mesh.is_free_boundary(v) {
                    problem.prescribed_tau[v]
                } else {
                    0.0
                }
            })
            .collect(),
        _ => tau_frame.iter().map(|t| t * p_bar).collect(),
    }
}

/// Airy values, hole jumps and force-diagram centres in frame units: from the reduced
/// operator when the answer has one, else integrated from the force densities.
fn airy_and_centres(
    mesh: &Mesh,
    plan: &Plan,
    airy_op: Option<&AiryOperator>,
    y: &[f64],
    q_frame: &[f64],
) -> (Vec<f64>, Vec<[f64; 3]>, Vec<[f64; 2]>) {
    match airy_op {
        Some(op) => {
            let phi = op.airy_values(y);
            let holes = op.hole_periods(y);
            let centres = dual::centres_from_airy(mesh, plan, op, &phi, y);
            (phi, holes, centres)
        }
        None => {
            let centres = dual::centres_from_forces(mesh, plan, q_frame);
            let phi = dual::airy_from_centres(mesh, plan, &centres);
            (phi, Vec::new(), centres)
        }
    }
}

/// Vertex weights w = |u|² − 2φ (0 at unreferenced vertices).
fn power_weights(mesh: &Mesh, positions: &[[f64; 3]], airy: &[f64]) -> Vec<f64> {
    (0..positions.len())
        .map(|v| {
            let p = positions[v];
            if mesh.referenced[v] {
                p[0] * p[0] + p[1] * p[1] - 2.0 * airy[v]
            } else {
                0.0
            }
        })
        .collect()
}

/// Hole jumps (c, a_x, a_y) from frame units to physical ones, about the physical origin.
fn physical_hole_jumps(hole_frame: &[[f64; 3]], p_bar: f64, frame: &Frame) -> Vec<[f64; 3]> {
    let l0 = frame.scale;
    hole_frame
        .iter()
        .map(|m| {
            let a = [m[1] * p_bar, m[2] * p_bar];
            [
                p_bar * l0 * m[0] - a[0] * frame.centre[0] - a[1] * frame.centre[1],
                a[0],
                a[1],
            ]
        })
        .collect()
}

impl StressResult {
    /// The same force densities certified at new heights (plan unchanged): loads, residuals,
    /// ε∞ and objective are recomputed at `positions`.
    pub fn at_heights(
        &self,
        problem: &Problem,
        positions: &[[f64; 3]],
        settings: &StressSettings,
    ) -> StressResult {
        let mesh = &problem.mesh;
        let (load, free, p_bar) = loads_at(problem, positions, settings);
        let (residuals, horizontal_imbalance) = equilibrium(
            mesh,
            positions,
            &self.force_densities,
            &load,
            &self.external_horizontal,
        );
        let max_r = free
            .iter()
            .map(|&v| residuals[v as usize].abs())
            .fold(0.0, f64::max);
        StressResult {
            eps_inf: max_r / p_bar,
            objective: free.iter().map(|&v| residuals[v as usize].powi(2)).sum(),
            loads: load,
            residuals,
            horizontal_imbalance,
            ..self.clone()
        }
    }
}

/// Pairs of interior edges (all of which carry force) that share a face: their dual segments
/// meet at the face's power centre.
fn face_edge_pairs(mesh: &Mesh) -> Vec<[usize; 2]> {
    let interior = |e: u32| !mesh.edges[e as usize].is_boundary();
    let mut pairs = Vec::new();
    for fe in &mesh.face_edges {
        for k in 0..3 {
            let (a, b) = (fe[k], fe[(k + 1) % 3]);
            if interior(a) && interior(b) {
                pairs.push([a as usize, b as usize]);
            }
        }
    }
    pairs
}

/// One solve of the stress QP: the formulation, the outcome and ε.
struct Attempt {
    solver: QpSolver,
    formulation: Formulation,
    lifted: bool,
    out: qp::QpOutput,
    regularisation: f64,
}

/// The force map q = S y of a formulation: the reduced operator, whose S it is, or the
/// edge-based selection of the edges that carry force.
enum ForceMap {
    Airy(AiryOperator),
    Selection(Csr),
}

impl ForceMap {
    fn s(&self) -> &Csr {
        match self {
            ForceMap::Airy(op) => &op.s,
            ForceMap::Selection(s) => s,
        }
    }

    fn airy(self) -> Option<AiryOperator> {
        match self {
            ForceMap::Airy(op) => Some(op),
            ForceMap::Selection(_) => None,
        }
    }
}

/// A formulation's force map and the vertices that need explicit horizontal balance rows.
type ForceModel = (ForceMap, Vec<u32>);

fn force_model(
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

/// Largest mean load on the non-anchored vertices that a stress step accepts. With the plan's
/// extent L₀ within what [`Mesh::new`] accepts, force densities (of order p̄/L₀), Airy values
/// (p̄ L₀) and the objective (squared residuals, of order p̄²) stay representable.
pub const MAX_MEAN_LOAD: f64 = 1e150;
/// Smallest positive mean load a stress step accepts (see [`MAX_MEAN_LOAD`]).
pub const MIN_MEAN_LOAD: f64 = 1e-150;

/// A stress step needs weight to balance, of a size double precision can represent: the mean
/// load p̄ on the non-anchored vertices is the unit of ε∞, of relative q bounds and of the
/// problem's scaling, so it must be positive and within [`MIN_MEAN_LOAD`], [`MAX_MEAN_LOAD`].
fn check_mean_load(load: &[f64], free: &[u32]) -> Result<()> {
    let mean = mean_over(load, free);
    let reason = if free.is_empty() {
        // Every vertex is anchored: nothing to balance, and nothing wrong.
        return Ok(());
    } else if mean == 0.0 {
        "the loads on the non-anchored vertices are all 0 (density 0 on every face and no extra \
         load): there is no weight to balance; give the faces a positive density"
            .to_string()
    } else if mean < 0.0 {
        format!(
            "the loads on the non-anchored vertices average {mean:e}, upwards: a compression-only \
             vault stands under a downward load"
        )
    } else if mean.is_nan() || mean > MAX_MEAN_LOAD {
        format!(
            "the loads on the non-anchored vertices average {mean:e}: beyond {MAX_MEAN_LOAD:e}, \
             force densities and squared residuals cannot be represented in double precision \
             (express the model in larger units or lower the density)"
        )
    } else if mean < MIN_MEAN_LOAD {
        format!(
            "the loads on the non-anchored vertices average {mean:e}: below {MIN_MEAN_LOAD:e}, \
             force densities and squared residuals cannot be represented in double precision \
             (express the model in smaller units or raise the density)"
        )
    } else {
        return Ok(());
    };
    Err(crate::Error::InvalidArgument {
        name: "loads",
        reason,
    })
}

/// Loads at `positions`, the non-anchored vertices, and their mean load p̄ (1 when not
/// positive: a stress step rejects such loads, see [`check_mean_load`], and a certificate at
/// new heights keeps a scale).
fn loads_at(
    problem: &Problem,
    positions: &[[f64; 3]],
    settings: &StressSettings,
) -> (Vec<f64>, Vec<u32>, f64) {
    let mesh = &problem.mesh;
    let load = loads::vertex_loads(
        mesh,
        positions,
        settings.load_rule,
        &problem.face_density,
        &problem.extra_loads,
    );
    let free = non_anchored(mesh);
    let mean_load = mean_over(&load, &free);
    (load, free, if mean_load > 0.0 { mean_load } else { 1.0 })
}

/// The upper median (element len/2 in increasing order), found in linear time.
pub(crate) fn upper_median(mut values: Vec<f64>) -> Option<f64> {
    let k = values.len() / 2;
    (!values.is_empty()).then(|| *values.select_nth_unstable_by(k, f64::total_cmp).1)
}

fn mean_over(x: &[f64], ids: &[u32]) -> f64 {
    if ids.is_empty() {
        return 0.0;
    }
    ids.iter().map(|&v| x[v as usize]).sum::<f64>() / ids.len() as f64
}

/// Vertical residual and horizontal imbalance at every non-anchored vertex, recomputed from
/// positions, force densities, loads and external horizontal forces (zero elsewhere).
pub fn equilibrium(
    mesh: &Mesh,
    positions: &[[f64; 3]],
    q: &[f64],
    load: &[f64],
    external: &[[f64; 2]],
) -> (Vec<f64>, Vec<[f64; 2]>) {
    let n = positions.len();
    let mut r = vec![0.0; n];
    let mut h = vec![[0.0; 2]; n];
    for v in 0..n {
        if mesh.is_non_anchored(v) {
            r[v] = -load[v];
            h[v] = external[v];
        }
    }
    for (e, edge) in mesh.edges.iter().enumerate() {
        let [i, j] = edge.v.map(|v| v as usize);
        for (a, b) in [(i, j), (j, i)] {
            if mesh.is_non_anchored(a) {
                r[a] += q[e] * (positions[a][2] - positions[b][2]);
                h[a][0] += q[e] * (positions[a][0] - positions[b][0]);
                h[a][1] += q[e] * (positions[a][1] - positions[b][1]);
            }
        }
    }
    (r, h)
}

/// Whether an attempt's answer ends the list of attempts in `analyse_cached`.
/// - Native: only a converged answer stands (at reduced accuracy it can sit at a point that
///   is not optimal), except on large problems, where the fallback would take many minutes:
///   there an answer at reduced accuracy, at the iteration limit or where the iterations
///   stalled is kept and reported as such.
/// - Clarabel solved or infeasible: done. Reduced accuracy: one more try with the other form
///   of the same problem, then keep the better. Numerical failure: go down the list.
fn attempt_is_final(
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

    fn plan_at(mesh: &Mesh, positions: &[[f64; 3]]) -> Plan {
        Plan::new(mesh, positions, &Frame::of(mesh, positions))
    }

    /// The kept reduced operator serves steps at other heights, also on meshes with a NaN
    /// unreferenced vertex, and no other plan, supports or hole mode.
    #[test]
    fn the_reduced_operator_is_kept_for_the_same_plan_only() {
        let dome = crate::generate::dome_with_hole(300).unwrap();
        let mut positions = dome.positions.clone();
        positions.push([f64::NAN; 3]);
        let anchored: Vec<u32> = (0..dome.anchored.len() as u32)
            .filter(|&v| dome.anchored[v as usize])
            .collect();
        let mesh = Mesh::new(positions, dome.faces.clone(), &anchored).unwrap();
        let problem = Problem::new(mesh);
        let mesh = &problem.mesh;
        let settings = StressSettings {
            solver: QpSolver::Native,
            ..StressSettings::default()
        };
        let mut cache = StressCache::default();
        analyse_cached(&problem, &mesh.positions, &settings, None, &mut cache).unwrap();
        let lowered: Vec<[f64; 3]> = (mesh.positions.iter())
            .map(|p| [p[0], p[1], 0.8 * p[2]])
            .collect();
        assert!(plan_at(mesh, &lowered)
            .u
            .iter()
            .flatten()
            .any(|x| x.is_nan()));
        let (kept, _) = cache.reduced.as_ref().expect("kept after a reduced step");
        let affine = settings.holes;
        assert_eq!(affine, airy::HoleMode::Affine);
        assert!(kept.fits(mesh, &plan_at(mesh, &lowered), affine));
        let moved: Vec<[f64; 3]> = (mesh.positions.iter())
            .map(|p| [p[0] * 1.1, p[1], p[2]])
            .collect();
        assert!(!kept.fits(mesh, &plan_at(mesh, &moved), affine));
        let same = plan_at(mesh, &mesh.positions);
        assert!(!kept.fits(mesh, &same, airy::HoleMode::Constant));
        let mut other = mesh.clone();
        let free = (0..other.anchored.len())
            .find(|&v| !other.anchored[v])
            .unwrap();
        other.anchored[free] = true;
        assert!(!kept.fits(&other, &same, affine));
        let mut flipped = mesh.clone();
        flipped
            .loops
            .iter_mut()
            .for_each(|l| l.is_outer = !l.is_outer);
        assert!(!kept.fits(&flipped, &same, affine));
        analyse_cached(&problem, &lowered, &settings, None, &mut cache).unwrap();
        assert!(cache.reduced.is_some());
    }
}
