//! What one stress step leaves for the next on the same mesh (form finding keeps one
//! [`StressCache`]), and the proximal centre a step may be pulled towards.

use super::airy::{self, AiryOperator};
use super::ipm;
use crate::geometry::Plan;
use crate::mesh::Mesh;

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

/// What a stress step leaves for the next one on the same mesh:
/// - the structure of the native solver's normal matrix (its fill-reducing ordering and
///   symbolic factorisation), which depends on the mesh's connectivity and the settings but
///   not on the positions;
/// - the last answer with its active bounds;
/// - both of these also for the native fallback form (edge-based, where a reduced attempt
///   failed; see `attempts::native_fallback`);
/// - the reduced operator q = S y of the last plan, with the inputs it was built from (see
///   `PlanKey`).
///
/// Opaque; `Default` is empty. A step of another structure replaces what it holds, and a step
/// with another plan, other supports or another hole mode replaces the reduced operator.
#[derive(Default)]
pub struct StressCache {
    pub(super) normal: ipm::PatternCache,
    /// The same for the native fallback form (edge-based, after a failed reduced attempt).
    pub(super) fallback: ipm::PatternCache,
    /// The last step's answer came from the native fallback form: the next step tries it
    /// first (`attempts::attempt_list`).
    pub(super) native_fallback_first: bool,
    pub(super) reduced: Option<(PlanKey, AiryOperator)>,
    /// Solve native QPs to `ipm::Tolerances::for_form_finding` (coarse when large).
    pub(super) coarse: bool,
    /// Whether the last step's answer was solved to coarse optimality.
    pub(super) last_coarse: bool,
    /// The relative gap the next native QPs may stop at (see `StressCache::set_inexact`).
    pub(super) inexact: Option<f64>,
    /// Whether the last step's answer was solved to that gap only.
    pub(super) last_inexact: bool,
    /// Physical vertical loads added to those the QP balances (the nearest-shape method's
    /// multiplier shift); the result's residuals are still those of the true loads.
    pub(super) load_offset: Option<Vec<f64>>,
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
        self.fallback.far_from_balance(far);
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
pub(super) struct PlanKey {
    pub(super) u: Vec<[u64; 2]>,
    pub(super) faces: Vec<[u32; 3]>,
    pub(super) outer: Vec<bool>,
    pub(super) anchored: Vec<bool>,
    pub(super) holes: airy::HoleMode,
}

impl PlanKey {
    pub(super) fn of(mesh: &Mesh, plan: &Plan, holes: airy::HoleMode) -> PlanKey {
        PlanKey {
            u: plan.u.iter().map(|u| u.map(f64::to_bits)).collect(),
            faces: mesh.faces.clone(),
            outer: mesh.loops.iter().map(|l| l.is_outer).collect(),
            anchored: mesh.anchored.clone(),
            holes,
        }
    }

    pub(super) fn fits(&self, mesh: &Mesh, plan: &Plan, holes: airy::HoleMode) -> bool {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Frame;
    use crate::problem::Problem;
    use crate::stress::{analyse_cached, QpSolver, StressSettings};

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
