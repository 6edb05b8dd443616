"""Result classes: the solvers' outputs as numpy arrays with documented shapes and dtypes.

Notation: n vertices, m faces, E edges, H holes, S force-diagram segments (interior edges).
Units are those of the input: lengths as in the mesh, loads as density x area, force densities
as force / length, timings in seconds.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, Dict, List, Optional

import numpy as np


@dataclass(frozen=True)
class StressResult:
    """The best compressive stress for a fixed shape (one stress step)."""

    status: str
    """How the stress QP ended: "solved", "almost_solved", "infeasible", "max_iterations" or
    "numerical_error"."""
    positions: np.ndarray
    """(n, 3) float64: the vertex positions the stress holds at."""
    edges: np.ndarray
    """(E, 2) uint32: vertex ids of every edge, smaller first, sorted; row e is edge e of the
    per-edge arrays."""
    force_densities: np.ndarray
    """(E,) float64: force density q per edge (force / length; compression positive)."""
    airy: np.ndarray
    """(n,) float64: Airy stress function value per vertex (defined up to an affine
    function)."""
    weights: np.ndarray
    """(n,) float64: vertex weights |u|^2 - 2 phi whose power diagram is the force diagram."""
    hole_coefficients: np.ndarray
    """(H, 3) float64: the Airy function's jump c + a.u around each hole as (c, a_x, a_y)."""
    tau: np.ndarray
    """(n,) float64: inward normal push per vertex (non-zero only at free boundary vertices:
    there the free edge needs a tie or buttress)."""
    external_horizontal: np.ndarray
    """(n, 2) float64: external horizontal force per vertex needed at free edges."""
    loads: np.ndarray
    """(n,) float64: vertical load per vertex (downward positive)."""
    residuals: np.ndarray
    """(n,) float64: vertical residual per non-anchored vertex (0 elsewhere)."""
    horizontal_imbalance: np.ndarray
    """(n, 2) float64: horizontal imbalance per non-anchored vertex."""
    eps_inf: float
    """max |r_i| / mean load over non-anchored vertices (dimensionless)."""
    objective: float
    """Sum of squared residuals over non-anchored vertices."""
    force_diagram_centres: np.ndarray
    """(m, 2) float64: one force-diagram point per face (force units)."""
    force_diagram_segments: np.ndarray
    """(S, 2, 2) float64: the force-diagram segment of each interior edge, two points."""
    force_diagram_segment_edges: np.ndarray
    """(S,) uint32: the edge of each force-diagram segment."""
    qp_iterations: int
    """Iterations of the QP solver (0 when warm-started at the optimum)."""
    formulation: str
    """The formulation that produced the forces: "reduced" or "edge_based"."""
    qp_solver: str
    """The solver that produced the answer: "native" or "clarabel"."""
    lifted: bool
    """Whether the answer came from the lifted form of the QP."""
    regularisation: float
    """The regulariser actually used."""
    seconds: float
    """Wall time of the stress step."""

    @classmethod
    def _from_native(cls, fields: Dict[str, Any]) -> "StressResult":
        names = [f.name for f in dataclasses.fields(cls)]
        return cls(**{name: fields[name] for name in names})


@dataclass(frozen=True)
class FormFindResult(StressResult):
    """A form-found shape: `positions` and the stress fields certify the state the loop
    ended with (the best one reached)."""

    termination: str = ""
    """Why the loop stopped: "converged", "max_iterations", "stalled", "infeasible",
    "numerical_error", "cancelled" or "blocked"."""
    termination_message: str = ""
    """The termination as a sentence (the C API's termination message)."""
    termination_vertices: np.ndarray = dataclasses.field(
        default_factory=lambda: np.zeros(0, np.uint32)
    )
    """(k,) uint32: the vertices a "stalled" or "blocked" termination lists."""
    termination_detail: Optional[str] = None
    """The constraint to relax ("infeasible"), the failure ("numerical_error") or what blocks
    ("blocked"); None otherwise."""
    history: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(0))
    """(k,) float64: eps_inf after each stress step, plus certificates of height steps."""
    iterations: int = 0
    """Stress steps taken."""
    step_solvers: List[str] = dataclasses.field(default_factory=list)
    """The QP solver that answered each stress step."""
    hausdorff: float = 0.0
    """Symmetric Hausdorff distance to the input surface / plan bounding-box diagonal."""
    l2: float = 0.0
    """Area-weighted RMS distance to the input surface / plan bounding-box diagonal."""
    rms_change: float = 0.0
    """Area-weighted RMS height change / plan bounding-box diagonal."""
    max_change: float = 0.0
    """Largest height change / plan bounding-box diagonal."""
    mirrored: bool = False
    """True when the input hung below its supports and was read upside down (its mirror
    image was the start and the shape to stay near); changes are still from the input."""
    stress_seconds: float = 0.0
    shape_seconds: float = 0.0
    total_seconds: float = 0.0
    _warm: Any = dataclasses.field(default=None, repr=False, compare=False)
    """The whole native result, for a warm re-solve (``form_find(..., start=result)``)."""

    @property
    def converged(self) -> bool:
        """True for a certified state in equilibrium: eps_inf and the horizontal imbalance
        below the tolerance, the forces within their bounds."""
        return self.termination == "converged"


@dataclass(frozen=True)
class AssessmentResult:
    """A masonry assessment: a thrust surface over the mesh's plan (`positions`) and the
    force densities that hold it in equilibrium with the masonry's self-weight (`loads`),
    between intrados and extrados (`lower`, `upper`), optimal for the objective. When
    `feasible` is False the fields hold the least infeasible state reached."""

    objective: str
    """The analysis: "fit", "min-thickness", "min-thrust", "max-thrust" or "max-load"."""
    feasible: bool
    """True when the surface is certified: eps_inf and the horizontal imbalance below the
    tolerance, every force density >= q_min (compression), every height within [lower, upper]
    to 1e-9 of the plan diagonal, and the springing joints' check."""
    termination: str
    """How the search ended: "converged" (the objective's optimum), "max_iterations",
    "stalled", "numerical_error" or "cancelled"."""
    termination_message: str
    """The termination as a sentence."""
    termination_vertices: np.ndarray
    """(k,) uint32: the vertices with the largest residuals of a "stalled" search."""
    termination_detail: Optional[str]
    """The failure of a "numerical_error"; None otherwise."""
    iterations: int
    """Sequential QP steps taken."""
    positions: np.ndarray
    """(n, 3) float64: the thrust surface, the mesh's plan with the heights found."""
    edges: np.ndarray
    """(E, 2) uint32: the mesh's edges, the rows of `force_densities`."""
    force_densities: np.ndarray
    """(E,) float64: force density per edge (force / length, compression positive)."""
    loads: np.ndarray
    """(n,) float64: vertical load per vertex: self-weight (thickness x unit weight x area on
    the middle surface), the mesh's extra loads, and load_factor x load_pattern."""
    residuals: np.ndarray
    """(n,) float64: vertical residual per vertex (0 at supports)."""
    eps_inf: float
    """max |residual| / mean load over the non-anchored vertices."""
    horizontal_imbalance: float
    """Largest horizontal imbalance at a non-anchored vertex / mean load."""
    lower: np.ndarray
    """(n,) float64: lower bound per vertex at the reported thickness (the intrados scaled by
    `thickness_scale` about the middle surface)."""
    upper: np.ndarray
    """(n,) float64: upper bound per vertex at the reported thickness."""
    thickness_scale: float
    """Scale s of the envelope's half extents: the least one for "min-thickness", else 1."""
    safety_factor: float
    """1 / thickness_scale: the geometric safety factor of "min-thickness"."""
    reactions: np.ndarray
    """(n, 2) float64: horizontal reaction per vertex (non-zero at supports)."""
    thrust_horizontal: float
    """Sum over the supports of |reaction| (force)."""
    load_factor: float
    """The factor lambda on the load pattern ("max-load"; else 0)."""
    unbounded: bool
    """"max-thrust" and "max-load": the objective has no bound. The surface is certified, and
    its force densities (and load factor) scaled by any s from some s0 >= 1 on (the heights
    approaching a limit surface) give certified surfaces too, so thrust_horizontal or
    load_factor is a value reached, not the greatest (docs/method.md section 16.4). False
    otherwise."""
    worst_bound: float
    """The largest excess of a height over its bounds (0 when all are inside)."""
    worst_bound_vertex: Optional[int]
    """Its vertex, or None."""
    worst_residual_vertex: Optional[int]
    """The vertex of the largest residual, or None."""
    joint_vertices: np.ndarray
    """(J,) uint32: the free supports with a springing joint (none with fixed supports)."""
    stranded: np.ndarray
    """(S,) uint32, increasing: the vertices of the loaded parts that no compressive state
    joins to a support (cut off by free corners or straight free edges, docs/method.md
    section 16.3; a part a max-load live load reaches is left to the search). Where there
    are any, no thrust surface exists in any envelope and the answer came without a search
    (termination "infeasible"); empty otherwise."""
    joints: np.ndarray
    """(J, 9) float64 per joint, recomputed from the returned surface (docs/method.md §16.1):
    the springing plane's height and the reach at the reported thickness; the horizontal
    reaction H (x, y) and the vertical reaction V (the vault pushes the support with (H, -V));
    the point (x, y, z) where the reaction's line meets the springing plane; its plan distance
    from the support, at most the reach on a certified surface."""
    worst_joint: float
    """The largest joint excess max(0, (z - s)|H| - b V) over b x the mean load."""
    worst_joint_vertex: Optional[int]
    """Its support, or None."""
    seconds: float
    """Wall time of the search."""
    envelope_lower: np.ndarray
    """(n,) float64: the intrados height per vertex, as given."""
    envelope_upper: np.ndarray
    """(n,) float64: the extrados height per vertex, as given."""
    envelope_middle: np.ndarray
    """(n,) float64: the middle surface's height per vertex."""
    face_thickness: np.ndarray
    """(m,) float64: thickness per face along the middle surface's normal (its weight is
    area x thickness x unit weight)."""
    thickness_min: Optional[float] = None
    """thickness_scale x the thickness when one uniform thickness was given (the least
    thickness for "min-thickness"); the least thickness of `min_thickness_of_family`; None
    for per-face thicknesses and surfaces, and when the surface is not certified."""
    rounds: Optional[int] = None
    """`min_thickness_of_family`: the least-thickness analyses run; None otherwise."""
    family_converged: Optional[bool] = None
    """`min_thickness_of_family`: the last round's scale met the tolerance; None otherwise."""

    @classmethod
    def _from_native(
        cls, fields: Dict[str, Any], thickness_min: Optional[float]
    ) -> "AssessmentResult":
        extra = ("thickness_min", "rounds", "family_converged")
        names = [f.name for f in dataclasses.fields(cls) if f.name not in extra]
        return cls(
            **{name: fields[name] for name in names},
            thickness_min=thickness_min,
            rounds=fields.get("rounds"),
            family_converged=fields.get("family_converged"),
        )

    @property
    def converged(self) -> bool:
        """A certified surface, optimal for the objective."""
        return self.feasible and self.termination == "converged"
