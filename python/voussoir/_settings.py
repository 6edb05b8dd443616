"""The solver settings accepted as keyword arguments by `analyse` and `form_find`.

Every setting of the Rust `FormFindSettings` and `StressSettings` (and so of the C API's
`vsr_settings_set_*`) is here; an omitted setting keeps the library's default, which
`voussoir.defaults()` reads from the Rust `Default` implementations.
"""

from __future__ import annotations

from typing import Literal, Optional, Tuple, TypedDict


class Settings(TypedDict, total=False):
    """Keyword settings; units in brackets. Only `analyse` ignores the form-finding ones."""

    method: Literal["nearest", "paper"]
    """Form finding: the nearest self-supporting shape, or the paper's loop."""
    fairness: float
    """Nearest method: weight gamma of the height change's smoothness [dimensionless, >= 0]."""
    max_height_change: float
    """Largest height change at any vertex, either method [plan diagonals, > 0]."""
    tolerance: float
    """Stop when eps_inf = max |r_i| / mean load < tolerance [dimensionless, > 0]."""
    max_iterations: int
    """Stress steps at most [>= 1]."""
    stall_window: int
    """Stalled when the best eps_inf has not improved by 1% over this many iterations [>= 1]."""
    odt_iterations: int
    """Optimal Delaunay Triangulation sweeps of the plan [>= 0; 0: the plan never moves]."""
    odt_free_boundary: bool
    """Let ODT move free boundary vertices too."""
    proximal_weight: float
    """Weight of the proximal term on force-density changes between steps [frame units, >= 0]."""
    smoothing_decay: float
    """Per-step decay of `dual_length_smoothing` in form finding [0 <= d < 1]."""
    schedule_mu0: float
    """Paper method: first height-step weight mu_0 [>= 0]."""
    schedule_beta: float
    """Paper method: factor of mu per step [0 <= beta <= 1]."""
    schedule_mu_min: float
    """Paper method: smallest mu [>= 0]."""
    schedule_eta: float
    """Paper method: eta of the schedule [> 0]."""
    schedule_pull: float
    """Paper method: pull nu towards the input heights [>= 0]."""
    q_min: float
    """Lower bound on force densities [>= 0; relative: x mean load / half plan diagonal,
    absolute: force / length, see `q_min_kind`]."""
    q_min_kind: Literal["relative", "absolute"]
    """How `q_min` is measured."""
    q_min_scope: Literal["all", "interior"]
    """The edges `q_min` applies to."""
    q_max: Optional[float]
    """Upper bound on force densities (None or inf: no bound) [> 0, units as `q_min`]."""
    q_max_kind: Literal["relative", "absolute"]
    """How `q_max` is measured."""
    tau: Literal["optimized", "zero", "prescribed"]
    """Normal push at free boundary vertices: optimised, none, or the mesh's
    `prescribed_tau`."""
    holes: Literal["affine", "constant"]
    """How the Airy function may jump around a hole."""
    load_rule: Literal["barycentric", "voronoi", "plan_area"]
    """How face weights are shared among vertices."""
    formulation: Literal["reduced", "edge_based"]
    """Unknowns of the stress QP: Airy values (reduced) or edge force densities."""
    qp_solver: Literal["native", "clarabel"]
    """The QP solver (native falls back to clarabel when it does not converge)."""
    regularisation: float
    """epsilon of the regulariser that makes q unique [frame units, >= 0]."""
    dual_length_smoothing: float
    """Penalty mu on force-diagram edge length differences at each face [>= 0]."""
    dual_length_bounds: Optional[Tuple[float, float]]
    """(lo, hi) bounds on force-diagram edge lengths of interior edges [x mean load]."""


SETTING_NAMES = tuple(Settings.__annotations__)
