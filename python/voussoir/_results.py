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
    stress_seconds: float = 0.0
    shape_seconds: float = 0.0
    total_seconds: float = 0.0

    @property
    def converged(self) -> bool:
        """True when eps_inf fell below the tolerance."""
        return self.termination == "converged"
