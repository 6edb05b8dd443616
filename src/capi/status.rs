//! Status codes and the enumerations that cross the C ABI.
//!
//! Values are explicit and never reused: a removed variant leaves a gap. Enum *inputs* cross as
//! `uint32_t` and are checked (`VSR_STATUS_INVALID_ENUM`, in `enum_args.rs`); enum *outputs*
//! are written as these types (`uint32_t` in C).

use crate::assess::Objective;
use crate::stress::{QpSolver, StressStatus};
use crate::Termination;

/// Result of every fallible function. `VSR_STATUS_OK` (0) is success; on any other value the
/// function wrote no output (except `needed` with `VSR_STATUS_BUFFER_TOO_SMALL`) and
/// `vsr_last_error_message()` says what was wrong. A solve that does not converge is still
/// `VSR_STATUS_OK`: read its outcome with `vsr_result_termination()`.
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VsrStatus {
    /// Success.
    Ok = 0,
    /// A required pointer argument is NULL (or an array is NULL with a non-zero length).
    NullPointer = 1,
    /// An argument has an invalid value (wrong length, negative, out of its range, ...).
    InvalidArgument = 2,
    /// A length times its row width overflows `size_t` or exceeds the supported maximum.
    LengthOverflow = 3,
    /// A vertex id (in `triangles` or `anchored`) is `>= n_vertices`.
    IndexOutOfRange = 4,
    /// A coordinate or value is NaN or infinite.
    NonFinite = 5,
    /// A `uint32_t` enum argument has no matching `VSR_*` constant.
    InvalidEnum = 6,
    /// A copy-out buffer is shorter than the data; `*needed` holds the required length.
    BufferTooSmall = 7,
    /// The mesh has no vertex or no triangle.
    EmptyMesh = 8,
    /// Connectivity is unusable: repeated vertex in a face, duplicate faces, non-manifold edge
    /// or vertex, inconsistent orientation, a hole that cannot be cut.
    InvalidTopology = 9,
    /// The plan (x, y projection) is unusable: zero-area, flipped or overlapping faces.
    InvalidPlan = 10,
    /// No vertex is anchored, or a connected component has none.
    NoSupport = 11,
    /// The result does not hold this quantity (e.g. the ε∞ history of a stress analysis).
    NotAvailable = 12,
    /// A numerical failure inside a solver (not a property of the input).
    Numerical = 13,
    /// A panic was caught at the boundary: a bug in Voussoir. The handles passed in are
    /// unchanged and may still be used or destroyed.
    Panic = 100,
}

impl VsrStatus {
    /// The constant's name as in the header, e.g. "VSR_STATUS_OK".
    pub fn name(self) -> &'static std::ffi::CStr {
        match self {
            VsrStatus::Ok => c"VSR_STATUS_OK",
            VsrStatus::NullPointer => c"VSR_STATUS_NULL_POINTER",
            VsrStatus::InvalidArgument => c"VSR_STATUS_INVALID_ARGUMENT",
            VsrStatus::LengthOverflow => c"VSR_STATUS_LENGTH_OVERFLOW",
            VsrStatus::IndexOutOfRange => c"VSR_STATUS_INDEX_OUT_OF_RANGE",
            VsrStatus::NonFinite => c"VSR_STATUS_NON_FINITE",
            VsrStatus::InvalidEnum => c"VSR_STATUS_INVALID_ENUM",
            VsrStatus::BufferTooSmall => c"VSR_STATUS_BUFFER_TOO_SMALL",
            VsrStatus::EmptyMesh => c"VSR_STATUS_EMPTY_MESH",
            VsrStatus::InvalidTopology => c"VSR_STATUS_INVALID_TOPOLOGY",
            VsrStatus::InvalidPlan => c"VSR_STATUS_INVALID_PLAN",
            VsrStatus::NoSupport => c"VSR_STATUS_NO_SUPPORT",
            VsrStatus::NotAvailable => c"VSR_STATUS_NOT_AVAILABLE",
            VsrStatus::Numerical => c"VSR_STATUS_NUMERICAL",
            VsrStatus::Panic => c"VSR_STATUS_PANIC",
        }
    }

    /// Every status, for `vsr_status_name` and tests.
    /// cbindgen:ignore
    pub const ALL: [VsrStatus; 15] = [
        VsrStatus::Ok,
        VsrStatus::NullPointer,
        VsrStatus::InvalidArgument,
        VsrStatus::LengthOverflow,
        VsrStatus::IndexOutOfRange,
        VsrStatus::NonFinite,
        VsrStatus::InvalidEnum,
        VsrStatus::BufferTooSmall,
        VsrStatus::EmptyMesh,
        VsrStatus::InvalidTopology,
        VsrStatus::InvalidPlan,
        VsrStatus::NoSupport,
        VsrStatus::NotAvailable,
        VsrStatus::Numerical,
        VsrStatus::Panic,
    ];
}

/// Why form finding stopped (`vsr_result_termination`).
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VsrTermination {
    /// A certified state in equilibrium: ε∞ and the horizontal imbalance below the tolerance,
    /// the forces within their bounds.
    Converged = 0,
    /// The iteration limit was reached first.
    MaxIterations = 1,
    /// ε∞ stopped improving; `vsr_result_stalled_vertices` lists vertices that carry (almost)
    /// no stress and cannot be balanced by moving heights (raise q_min).
    Stalled = 2,
    /// The stress constraints admit no solution; `vsr_result_termination_message` names the
    /// setting to relax.
    Infeasible = 3,
    /// A solver failed numerically; `vsr_result_termination_message` says where.
    NumericalError = 4,
    /// The progress callback returned non-zero.
    Cancelled = 5,
    /// No state in equilibrium under the stress constraints was reached within the height
    /// limit (`vsr_settings_set_max_height_change`) or below q_max (a local search: no proof
    /// that none exists): `vsr_result_termination_message` names what held it (q_max or the
    /// limit) and `vsr_result_stalled_vertices` lists where.
    Blocked = 6,
}

impl VsrTermination {
    pub(crate) fn of(t: &Termination) -> VsrTermination {
        match t {
            Termination::Converged => VsrTermination::Converged,
            Termination::MaxIterations => VsrTermination::MaxIterations,
            Termination::Stalled { .. } => VsrTermination::Stalled,
            Termination::Infeasible { .. } => VsrTermination::Infeasible,
            Termination::NumericalError { .. } => VsrTermination::NumericalError,
            Termination::Cancelled => VsrTermination::Cancelled,
            Termination::Blocked { .. } => VsrTermination::Blocked,
        }
    }
}

/// How the (last) stress QP ended (`vsr_result_stress_status`).
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VsrStressStatus {
    /// Solved to the solver's tolerances; in form finding beyond 20k unknowns to coarse
    /// optimality (relative gap 1e-3, bounds and equality rows as tight as ever).
    Solved = 0,
    /// Solved to reduced accuracy.
    AlmostSolved = 1,
    /// The constraints (q_min, q_max, prescribed forces, straight free edges) admit no stress.
    Infeasible = 2,
    /// Stopped short of even the reduced accuracy: the iteration limit was reached, or (the
    /// native solver beyond 20k unknowns) 10 iterations went by without progress.
    MaxIterations = 3,
    /// A solver failed numerically; `vsr_result_termination_message` says where.
    NumericalError = 4,
}

impl VsrStressStatus {
    pub(crate) fn of(s: StressStatus) -> VsrStressStatus {
        match s {
            StressStatus::Solved => VsrStressStatus::Solved,
            StressStatus::AlmostSolved => VsrStressStatus::AlmostSolved,
            StressStatus::Infeasible => VsrStressStatus::Infeasible,
            StressStatus::MaxIterations => VsrStressStatus::MaxIterations,
            StressStatus::NumericalError => VsrStressStatus::NumericalError,
        }
    }
}

/// Which solve produced a result (`vsr_result_kind`).
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VsrResultKind {
    /// `vsr_analyse`: stress of the fixed input shape.
    Analysis = 0,
    /// `vsr_form_find`: heights moved until the shape stands (or the loop stopped).
    FormFinding = 1,
}

/// Normal stress τ at free boundary vertices (`vsr_settings_set_tau_mode`).
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VsrTauMode {
    /// Default: an optimised inward push τ >= 0 per free vertex (as in the paper); non-zero τ
    /// means the edge needs a tie or buttress there.
    Optimized = 0,
    /// No normal stress: a truly free edge.
    Zero = 1,
    /// The values given with `vsr_mesh_set_prescribed_tau`.
    Prescribed = 2,
}

/// Stress through holes (`vsr_settings_set_hole_mode`).
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VsrHoleMode {
    /// A constant Airy jump per hole (the paper's hole-induced stress): a net torque only.
    Constant = 0,
    /// Default: an affine jump, also a net horizontal force through the hole; the reduced
    /// optimum then equals the edge-based one.
    Affine = 1,
}

/// How a face's weight is shared among its vertices (`vsr_settings_set_load_rule`).
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VsrLoadRule {
    /// Default: one third of the 3-D triangle area each (the paper's rule).
    Barycentric = 0,
    /// Mixed Voronoi area of the 3-D triangle.
    Voronoi = 1,
    /// One third of the plan (projected) area each.
    PlanArea = 2,
}

/// Stress formulation (`vsr_settings_set_formulation`).
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VsrFormulation {
    /// Default: de Goes et al. 2013, Airy values as unknowns.
    Reduced = 0,
    /// Vouga et al. 2012, one force density per edge: the reference solver.
    EdgeBased = 1,
}

/// Solver of the stress QP (`vsr_settings_set_qp_solver`, `vsr_result_qp_solver`).
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VsrQpSolver {
    /// Default: the structured interior-point method; falls back to clarabel when it does not
    /// converge (beyond 20k unknowns an answer at tenfold relaxed tolerances is kept instead,
    /// with status VSR_STRESS_STATUS_ALMOST_SOLVED, and the last iterate at the iteration
    /// limit, or after 10 iterations without progress, with status
    /// VSR_STRESS_STATUS_MAX_ITERATIONS).
    Native = 0,
    /// clarabel's generic conic solver only: the reference.
    Clarabel = 1,
}

impl VsrQpSolver {
    pub(crate) fn of(s: QpSolver) -> VsrQpSolver {
        match s {
            QpSolver::Native => VsrQpSolver::Native,
            QpSolver::Clarabel => VsrQpSolver::Clarabel,
        }
    }
}

/// Units of a force-density bound (`vsr_settings_set_q_min`, `vsr_settings_set_q_max`).
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VsrBoundKind {
    /// Force per length, in the model's units.
    Absolute = 0,
    /// A multiple of the problem's natural scale p̄ / L₀ (mean load over non-anchored
    /// vertices / half the plan diagonal).
    Relative = 1,
}

/// Edges a lower bound q_min applies to (`vsr_settings_set_q_min_scope`).
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VsrEdgeScope {
    /// Interior edges only.
    Interior = 0,
    /// Default: interior and boundary edges.
    All = 1,
}

/// How form finding moves the shape (`vsr_settings_set_method`).
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VsrMethod {
    /// Default: the nearest self-supporting shape (least area-weighted squared height change,
    /// plus the fairness term, subject to equilibrium).
    Nearest = 0,
    /// The paper's loop: height steps pulled towards the current heights with the proximal
    /// schedule (`vsr_settings_set_schedule_*`).
    Paper = 1,
}

/// What `vsr_assess` optimises (`vsr_assess_settings_set_objective`,
/// `vsr_assessment_objective`).
#[repr(u32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VsrObjective {
    /// Default: does a thrust surface fit? The one nearest the middle surface (least
    /// area-weighted squared height difference).
    Fit = 0,
    /// The least thickness: the smallest scale s of the envelope's half extents about the
    /// middle surface that still holds a thrust surface (the loads stay those of the given
    /// thickness); the geometric safety factor is 1 / s.
    MinThickness = 1,
    /// The least horizontal thrust, Σ over supports of |H| (the passive state).
    MinThrust = 2,
    /// The greatest horizontal thrust (the active state).
    MaxThrust = 3,
    /// The largest factor λ on the load pattern (`vsr_assess_settings_set_load_pattern`)
    /// added to the self-weight.
    MaxLoad = 4,
}

impl VsrObjective {
    pub(crate) fn of(o: Objective) -> VsrObjective {
        match o {
            Objective::Fit => VsrObjective::Fit,
            Objective::MinThickness => VsrObjective::MinThickness,
            Objective::MinThrust => VsrObjective::MinThrust,
            Objective::MaxThrust => VsrObjective::MaxThrust,
            Objective::MaxLoad => VsrObjective::MaxLoad,
        }
    }
}
