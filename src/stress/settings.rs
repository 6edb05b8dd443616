//! Options of the stress step, validated before any work is done.

use super::airy::HoleMode;
use crate::error::{Error, Result};
use crate::geometry::loads::LoadRule;

/// Which edges a lower bound q_min applies to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum EdgeScope {
    /// Interior edges only; boundary creases stay merely q ≥ 0.
    Interior,
    /// Interior and boundary edges (default).
    #[default]
    All,
}

/// Normal stress at free boundary vertices (docs/method.md §6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum TauMode {
    /// An optimised inward push τ ≥ 0 per free vertex, as the paper does. Non-zero τ means the
    /// free edge needs a tie or buttress there: results report it per vertex.
    #[default]
    Optimized,
    /// No normal stress: a truly free edge.
    Zero,
    /// The per-vertex values given in [`crate::Problem::prescribed_tau`].
    Prescribed,
}

/// A force-density bound, either physical (force per length) or relative to the problem's
/// natural scale p̄ / L₀ (mean load over non-anchored vertices / half the plan diagonal).
/// Serialised (in reports) as `{"absolute": v}` or `{"relative": v}`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum QBound {
    /// Force per length, in the model's units.
    Absolute(f64),
    /// A multiple of p̄ / L₀.
    Relative(f64),
}

impl QBound {
    /// The bound in physical units for a problem with natural scale `unit` = p̄ / L₀.
    pub fn physical(self, unit: f64) -> f64 {
        match self {
            QBound::Absolute(v) => v,
            QBound::Relative(v) => v * unit,
        }
    }

    fn value(self) -> f64 {
        match self {
            QBound::Absolute(v) | QBound::Relative(v) => v,
        }
    }
}

/// Which formulation solves the stress QP.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Formulation {
    /// de Goes et al. 2013: Airy values (vertex weights) as unknowns, one equation per vertex.
    #[default]
    Reduced,
    /// Vouga et al. 2012: one force density per edge, three equations per vertex. Reference.
    EdgeBased,
}

/// Which solver minimises the stress QP.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum QpSolver {
    /// The structured interior-point method (sparse LDLᵀ of the two-ring Newton matrix, one
    /// symbolic analysis); when it does not converge the step falls back to clarabel, except
    /// beyond 20k unknowns, where an answer at tenfold relaxed tolerances is kept as
    /// `AlmostSolved`, and the last iterate at the iteration limit as `MaxIterations`
    /// (clarabel would take many minutes there).
    #[default]
    Native,
    /// clarabel's generic conic interior-point method only: the reference.
    Clarabel,
}

/// Settings of one stress step. The defaults are those of form finding
/// (`FormFindSettings::default().stress`) and of the C API's `vsr_settings_create`, so that
/// `analyse` and `vsr_analyse` give the same answer. Serialised (in reports) with the names
/// of Python's keyword settings.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[non_exhaustive]
pub struct StressSettings {
    /// Lower bound on force densities (default: 0.05 p̄/L₀, `QBound::Relative(0.05)`, on all
    /// edges). Set q_min to 0 (`QBound::Absolute(0.0)`) for plain compression.
    pub q_min: QBound,
    /// The edges q_min applies to (default: all).
    pub q_min_scope: EdgeScope,
    /// Optional upper bound on force densities (allowable stress × thickness).
    pub q_max: Option<QBound>,
    /// Normal stress at free boundary vertices (default optimised).
    pub tau: TauMode,
    /// How the Airy function may jump around a hole (default affine: the true optimum).
    pub holes: HoleMode,
    /// How face weights become vertex loads (default barycentric).
    pub load_rule: LoadRule,
    /// The formulation of the QP (default reduced).
    pub formulation: Formulation,
    /// Bounds (lo, hi) on the dual (force-diagram) edge length of interior edges, in units of
    /// the mean load p̄: lo ≤ q_e l_e / p̄ ≤ hi. A lower bound keeps every force-diagram edge
    /// visible, an upper bound smooths the diagram. Default none.
    pub dual_length_bounds: Option<(f64, f64)>,
    /// Weight μ of the penalty μ Σ (d*_a − d*_b)² / p̄² on the variation of dual lengths
    /// d* = q l over each pair of interior edges that share a face (the force-diagram edges
    /// meeting at that face's power centre). μ > 0 trades residual in the stress step for a
    /// smoother force diagram; form finding then shapes the vault to carry it. Default 0.
    pub dual_length_smoothing: f64,
    /// ε of the regulariser ε Σ (l_e q_e)² (frame units) that makes q unique. Default 1e-16:
    /// a tie-breaker whose bias on the residual stays far below the equilibrium tolerance (it
    /// grows with the mesh's conditioning; docs/method.md §8). When the solver reports a
    /// numerical failure (degenerate problems: straight free edges force q = 0) the
    /// step is repeated with ε × 100, up to twice, and the result says which ε was used.
    pub regularisation: f64,
    /// The QP solver (default native).
    #[serde(rename = "qp_solver")]
    pub solver: QpSolver,
}

impl Default for StressSettings {
    fn default() -> Self {
        StressSettings {
            q_min: QBound::Relative(0.05),
            q_min_scope: EdgeScope::All,
            q_max: None,
            tau: TauMode::Optimized,
            holes: HoleMode::Affine,
            load_rule: LoadRule::Barycentric,
            formulation: Formulation::Reduced,
            dual_length_bounds: None,
            dual_length_smoothing: 0.0,
            regularisation: 1e-16,
            solver: QpSolver::Native,
        }
    }
}

impl StressSettings {
    /// Checks every field, naming the first bad one ([`Error::InvalidArgument`] with the
    /// field's name; `dual_length_bounds.lo` and `.hi` for the bounds): q_min finite and at
    /// least 0; q_max finite and positive, and at least q_min when both have the same kind;
    /// the dual length bounds with lo finite and at least 0, hi above lo (hi may be +∞); the
    /// smoothing weight and the regularisation finite and at least 0. Every layer (C, Python,
    /// command line) calls this.
    pub fn validate(&self) -> Result<()> {
        use crate::validate::{above, at_least};
        let q_min = self.q_min.value();
        at_least("q_min", q_min, 0.0)?;
        if let Some(q_max) = self.q_max {
            let v = q_max.value();
            above("q_max", v, 0.0)?;
            if std::mem::discriminant(&q_max) == std::mem::discriminant(&self.q_min) && v < q_min {
                return Err(crate::validate::below_other("q_max", "q_min"));
            }
        }
        if let Some((lo, hi)) = self.dual_length_bounds {
            at_least("dual_length_bounds.lo", lo, 0.0)?;
            if hi.is_nan() || hi <= lo {
                return Err(Error::InvalidArgument {
                    name: "dual_length_bounds.hi",
                    reason: format!("{hi} must be > lo ({lo})"),
                });
            }
        }
        at_least("dual_length_smoothing", self.dual_length_smoothing, 0.0)?;
        at_least("regularisation", self.regularisation, 0.0)
    }
}

crate::setters::with_setters!(StressSettings {
    with_q_min: q_min: QBound,
    with_q_min_scope: q_min_scope: EdgeScope,
    with_q_max: q_max: Option<QBound>,
    with_tau: tau: TauMode,
    with_holes: holes: HoleMode,
    with_load_rule: load_rule: LoadRule,
    with_formulation: formulation: Formulation,
    with_dual_length_bounds: dual_length_bounds: Option<(f64, f64)>,
    with_dual_length_smoothing: dual_length_smoothing: f64,
    with_regularisation: regularisation: f64,
    with_solver: solver: QpSolver,
});
