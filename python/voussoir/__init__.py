"""Voussoir: self-supporting masonry shapes (de Goes et al. 2013) from Python.

    import voussoir
    mesh = voussoir.Mesh.from_file("vault.obj", supports="vault.json")
    result = voussoir.form_find(mesh, progress=lambda k, eps: print(k, eps))
    result.positions          # (n, 3) float64: the self-supporting shape

`Mesh` holds a validated triangle mesh with its supports and loads; `analyse` finds the best
compressive stress of a shape as it stands, `form_find` the nearest self-supporting shape,
`assess` a thrust surface inside the masonry's thickness (Heyman's safe theorem).
Both take the library's settings as keyword arguments (see `Settings`; `defaults()` lists
every default) and release the GIL while they solve. Bad input raises `VoussoirError`, a
`ValueError`, with the library's one-line message naming the argument at fault.

Interchange, imported on their own: `voussoir.rhino` (.3dm meshes; the `rhino` extra) and
`voussoir.compas` (compas meshes, the `compas` extra; FormDiagram JSON, no extra needed).
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any, Callable, Dict, List, Optional, Tuple, Union

import numpy as np

from . import _voussoir as _native
from ._results import AssessmentResult, FormFindResult, StressResult
from ._settings import Settings

if TYPE_CHECKING:
    from typing_extensions import Unpack

VoussoirError = _native.VoussoirError
__version__: str = _native.__version__

__all__ = [
    "Mesh",
    "analyse",
    "form_find",
    "assess",
    "min_thickness_of_family",
    "defaults",
    "AssessmentResult",
    "FormFindResult",
    "StressResult",
    "Settings",
    "VoussoirError",
]

PathLike = Union[str, "os.PathLike[str]"]
Progress = Callable[[int, float], Optional[bool]]


def _floats(name: str, value: Any) -> Optional[np.ndarray]:
    if value is None:
        return None
    try:
        array = np.asarray(value, dtype=np.float64)
        # A single number stays 0-d: it stands for every face or vertex.
        return array if array.ndim == 0 else np.ascontiguousarray(array)
    except (TypeError, ValueError) as e:
        raise VoussoirError(f"argument `{name}`: is not an array of numbers ({e})") from None


def _ids(name: str, value: Any) -> np.ndarray:
    try:
        array = np.asarray(value)
    except (TypeError, ValueError) as e:
        raise VoussoirError(f"argument `{name}`: is not an array of integer ids ({e})") from None
    if array.size == 0:
        return np.zeros(array.shape, dtype=np.int64)
    if array.dtype.kind not in "iu":
        raise VoussoirError(
            f"argument `{name}`: holds {array.dtype} values, expected integer ids"
        )
    if array.dtype.kind == "u" and array.size and array.max() > np.iinfo(np.int64).max:
        raise VoussoirError(f"argument `{name}`: holds an id beyond 2^63")
    return np.ascontiguousarray(array, dtype=np.int64)


def _number(name: str, value: Any) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        raise VoussoirError(f"argument `{name}`: {value!r} is not a number") from None


def _text(name: str, value: Any) -> str:
    if not isinstance(value, str):
        raise VoussoirError(f"argument `{name}`: {value!r} is not a string")
    return value


def _path(name: str, value: Any) -> str:
    """A file path argument as text, or VoussoirError naming it."""
    try:
        return os.fspath(_required(name, value))
    except TypeError:
        raise VoussoirError(f"argument `{name}`: {value!r} is not a path") from None


def _required(name: str, value: Any) -> Any:
    if value is None:
        raise VoussoirError(f"argument `{name}` is None")
    return value


class Mesh:
    """A validated triangle mesh (x, y plan, z up), its anchored vertices and its loads.

    Args:
        vertices: (n, 3) float64 positions.
        faces: (m, 3) integer vertex ids per triangle (either orientation).
        anchored: (k,) integer ids of the supported vertices.
        face_density: (m,) weight per unit area of each face (density x thickness x g),
            finite and >= 0; default 1.
        extra_loads: (n,) extra vertical load per vertex (downward positive); default 0.
        horizontal_forces: (n, 2) prescribed horizontal force per vertex, non-zero only at
            free boundary vertices; default 0.
        prescribed_tau: (n,) inward normal push per free boundary vertex, used with
            ``tau="prescribed"``; finite and >= 0; default 0.
        polygon_diagonals: (k, 2) integer vertex ids of the edges that split the model's
            polygons into triangles (interior edges): q_min does not bind them. `from_file`
            marks those of a file's polygons.
        A single number given for `face_density`, `extra_loads` or `prescribed_tau` stands
            for every face or vertex.

    Raises:
        VoussoirError: the mesh or a load is invalid; the message names the argument, and the
            vertex, face or edge at fault.
    """

    _native: _native.Mesh

    def __init__(
        self,
        vertices: Any,
        faces: Any,
        anchored: Any,
        *,
        face_density: Any = None,
        extra_loads: Any = None,
        horizontal_forces: Any = None,
        prescribed_tau: Any = None,
        polygon_diagonals: Any = None,
    ) -> None:
        self._native = _native.Mesh(
            _floats("vertices", _required("vertices", vertices)),
            _ids("faces", _required("faces", faces)),
            _ids("anchored", _required("anchored", anchored)),
            _floats("face_density", face_density),
            _floats("extra_loads", extra_loads),
            _floats("horizontal_forces", horizontal_forces),
            _floats("prescribed_tau", prescribed_tau),
            None if polygon_diagonals is None else _ids("polygon_diagonals", polygon_diagonals),
        )

    @classmethod
    def from_file(
        cls,
        path: PathLike,
        supports: Optional[PathLike] = None,
        *,
        anchored: Any = None,
        anchor_boundary: bool = False,
        anchor_lowest: Optional[float] = None,
        anchor_lowest_absolute: bool = False,
        weld: bool = True,
        weld_tolerance: Optional[float] = None,
        repair_tolerance: Optional[float] = None,
        up: str = "z",
        face_density: Any = None,
        extra_loads: Any = None,
        horizontal_forces: Any = None,
        prescribed_tau: Any = None,
    ) -> "Mesh":
        """Reads an OBJ, OFF, STL or PLY file (by its extension; polygons split into fans,
        whose diagonals q_min does not bind), as the library's ``io::read_model`` does.

        Args:
            path: the mesh file.
            supports: a JSON file of anchored vertex ids (``{"anchored": [ids]}`` or
                ``[ids]``), the file's own 0-based vertex ids; or None to give `anchored`,
                `anchor_boundary` or `anchor_lowest` instead (one of the four).
            anchored: anchored file vertex ids when `supports` is None.
            anchor_boundary: anchor every boundary vertex.
            anchor_lowest: anchor every vertex within this of the lowest height, relative to
                the bounding-box diagonal (absolute with ``anchor_lowest_absolute=True``).
            weld: False keeps the file's vertices as they are (STL files, whose triangles
                never share vertices, are welded all the same).
            weld_tolerance: vertices closer than this x the bounding-box diagonal are merged
                (0: only equal positions); default ``voussoir.WELD_TOLERANCE``.
            repair_tolerance: faces whose plan area is below this x the median plan area are
                mended by plan edge flips or the smallest plan move of a vertex (0: none, and
                the faces the default would mend are rejected); default
                ``voussoir.REPAIR_TOLERANCE``.
            up: "z", or "y" for a Y-up file (as most modellers export): the mesh is turned
                Z-up, and `write` turns positions back.
            face_density, extra_loads, horizontal_forces, prescribed_tau: as for `Mesh`,
                per face or vertex of the mesh read (after welding); a single number stands
                for every face or vertex.
        """
        mesh = cls.__new__(cls)
        if not weld:
            tolerance = None
        elif weld_tolerance is None:
            tolerance = _native.WELD_TOLERANCE
        else:
            tolerance = _number("weld_tolerance", weld_tolerance)
        mesh._native = _native.Mesh.read(
            _path("path", path),
            None if supports is None else _path("supports", supports),
            None if anchored is None else _ids("anchored", anchored),
            tolerance,
            (
                _native.REPAIR_TOLERANCE
                if repair_tolerance is None
                else _number("repair_tolerance", repair_tolerance)
            ),
            bool(anchor_boundary),
            None if anchor_lowest is None else _number("anchor_lowest", anchor_lowest),
            bool(anchor_lowest_absolute),
            _text("up", up),
            _floats("face_density", face_density),
            _floats("extra_loads", extra_loads),
            _floats("horizontal_forces", horizontal_forces),
            _floats("prescribed_tau", prescribed_tau),
        )
        return mesh

    @property
    def vertices(self) -> np.ndarray:
        """(n, 3) float64 vertex positions."""
        return self._native.vertices

    @property
    def faces(self) -> np.ndarray:
        """(m, 3) uint32 faces, in the orientation given."""
        return self._native.faces

    @property
    def anchored(self) -> np.ndarray:
        """(k,) uint32 anchored vertex ids, sorted."""
        return self._native.anchored

    @property
    def edges(self) -> np.ndarray:
        """(E, 2) uint32 edges, smaller id first, sorted (the rows of per-edge results)."""
        return self._native.edges

    @property
    def welded_ids(self) -> np.ndarray:
        """(n_file,) uint32: the mesh vertex of each vertex of the file read."""
        return self._native.welded_ids

    @property
    def polygon_diagonals(self) -> np.ndarray:
        """(k, 2) uint32 marked polygon diagonals (q_min does not bind them), smaller id
        first, in edge order."""
        return self._native.polygon_diagonals

    @property
    def plan_repairs(self) -> List[str]:
        """The plan repairs made while reading, one sentence each."""
        return self._native.plan_repairs

    @property
    def n_holes(self) -> int:
        """The number of holes (inner boundary loops)."""
        return self._native.n_holes

    @property
    def face_density(self) -> np.ndarray:
        """(m,) float64 weight per unit area of each face."""
        return self._native.face_density

    @property
    def extra_loads(self) -> np.ndarray:
        """(n,) float64 extra vertical load per vertex."""
        return self._native.extra_loads

    @property
    def horizontal_forces(self) -> np.ndarray:
        """(n, 2) float64 prescribed horizontal force per vertex."""
        return self._native.horizontal_forces

    @property
    def prescribed_tau(self) -> np.ndarray:
        """(n,) float64 prescribed normal push per vertex."""
        return self._native.prescribed_tau

    def write(self, path: PathLike, positions: Any = None) -> None:
        """Writes `positions` (default: the mesh's own) with the faces to `path`: .obj, .off,
        .ply (every bit kept) or .stl (single precision), all or nothing, in the axes of the
        file the mesh was read from (Y-up for ``up="y"``)."""
        points = self.vertices if positions is None else _floats("positions", positions)
        _native.write_mesh(self._native, points, _path("path", path))

    def __repr__(self) -> str:
        def count(n: int, one: str, many: str) -> str:
            return f"{n} {one if n == 1 else many}"

        return (
            f"Mesh({count(len(self.vertices), 'vertex', 'vertices')}, "
            f"{count(len(self.faces), 'face', 'faces')}, {len(self.anchored)} anchored, "
            f"{count(self.n_holes, 'hole', 'holes')})"
        )


def _check_mesh(mesh: Any) -> _native.Mesh:
    if not isinstance(mesh, Mesh):
        raise VoussoirError(f"argument `mesh`: is a {type(mesh).__name__}, not a voussoir.Mesh")
    return mesh._native


def defaults() -> Dict[str, Any]:
    """Every setting with its default, read from the Rust library's `Default` impls."""
    return dict(_native.defaults())


def analyse(mesh: Mesh, **settings: "Unpack[Settings]") -> StressResult:
    """The best compressive stress of `mesh` as it stands (no shape change).

    Settings are keyword arguments (see `Settings`; form-finding-only ones are checked and
    ignored). The GIL is released while it solves.

    Raises:
        VoussoirError: a setting is invalid, or the loads are zero.
    """
    fields = _native.analyse(_check_mesh(mesh), settings)
    return StressResult._from_native(fields)


def form_find(
    mesh: Mesh,
    progress: Optional[Progress] = None,
    *,
    start: Optional[FormFindResult] = None,
    **settings: "Unpack[Settings]",
) -> FormFindResult:
    """The nearest self-supporting shape to `mesh` (or the paper's loop: ``method="paper"``).

    Args:
        mesh: the vault.
        progress: called as ``progress(iteration, eps_inf)`` after every stress step (0-based
            iteration; eps_inf dimensionless). Returning False (any false value but None)
            stops the loop: the result then reports ``termination == "cancelled"`` and holds
            the state reached. An exception it raises stops the loop too and propagates.
        start: a warm re-solve after an edit: an earlier result of `form_find` on a mesh
            with the same vertices and faces. The answer is the same kind as without it (the
            nearest self-supporting shape to `mesh` as it is now, same tolerance and
            terminations), reached in fewer stress steps after a small edit. Between the
            calls any heights, the supports, the loads and every setting but ``method`` may
            change; `start`'s heights, forces and penalty state are the starting point (see
            docs/method.md §13.4). Nearest method only.
        **settings: see `Settings`; omitted ones keep `defaults()`.

    The GIL is released while it solves; Ctrl-C (KeyboardInterrupt) stops a running solve
    within one iteration and propagates.

    Raises:
        VoussoirError: a setting is invalid, or the loads are zero; `start` is not a
            FormFindResult, or its vertex or edge count or faces differ from `mesh`'s
            (naming ``start``); ``method="paper"`` with `start`.
    """
    warm = None
    if start is not None:
        warm = getattr(start, "_warm", None) if isinstance(start, FormFindResult) else None
        if warm is None:
            raise VoussoirError("argument `start`: is not a result of form_find in this process "
                                "(a FormFindResult; an unpickled one carries no warm state)")
    fields = _native.form_find(_check_mesh(mesh), settings, progress, False, warm)
    return FormFindResult._from_native(fields)


Surface = Tuple[Any, Any]
"""A surface as (vertices (n, 3), faces (m, 3) integer ids)."""


def _surface(name: str, value: Any) -> Optional[Tuple[np.ndarray, np.ndarray]]:
    if value is None:
        return None
    try:
        vertices, faces = value
    except (TypeError, ValueError):
        raise VoussoirError(f"argument `{name}`: is not a pair (vertices, faces)") from None
    points = _floats(name, vertices)
    ids = _ids(name, faces)
    return points, ids


def assess(
    mesh: Mesh,
    thickness: Any = None,
    *,
    intrados: Optional[Surface] = None,
    extrados: Optional[Surface] = None,
    objective: str = "fit",
    fixed_supports: bool = False,
    unit_weight: float = 1.0,
    load_pattern: Any = None,
    springing: Any = None,
    reach: Any = None,
    progress: Optional[Progress] = None,
    **settings: Any,
) -> AssessmentResult:
    """A compression-only thrust surface in equilibrium with the masonry's self-weight that
    lies inside the masonry: by Heyman's safe theorem the vault then stands.

    The mesh is the masonry's middle surface and its plan the form diagram. Give the
    masonry's envelope as `thickness` or as `intrados` and `extrados`.

    Args:
        mesh: the vault (its face densities are not used: the envelope's thickness x
            `unit_weight` is the self-weight; its extra loads are added).
        thickness: one thickness, or one per face (m,), along the middle surface's normals,
            half above and half below (read vertically as t / (2 n_z) at each vertex).
        intrados, extrados: instead of `thickness`, the two surfaces as (vertices (k, 3),
            faces (l, 3)) in any triangulation, sampled on the vertical through each vertex.
        objective: "fit" (the surface nearest the middle surface), "min-thickness" (the
            least uniform scale of the thickness that still holds one; `safety_factor` is its
            inverse), "min-thrust" / "max-thrust" (the least / greatest horizontal thrust at
            the supports) or "max-load" (the largest factor on `load_pattern`).
        fixed_supports: keep the supports at the mesh's heights (by default a support's
            height is free within the envelope and its reaction's line must meet the
            springing joint: the envelope's bottom on the support's vertical, within half the
            thickness; docs/method.md §16.1).
        unit_weight: weight per unit volume (>= 0; 0: the mesh's extra loads alone).
        load_pattern: (n,) downward load per vertex that "max-load" multiplies.
        springing, reach: the springing joints of free supports (docs/method.md section
            16.1), each one number (at every support) or (n,) per vertex (read at free
            supports only): the
            height of the springing plane, on or below which no free support may sit, and the
            joint's reach, how far in plan from the support its reaction's line may meet the
            plane. ``reach=math.inf`` drops the joint (the vertical reading: the support's
            height bounded by the envelope alone). None keeps the envelope's default (from a
            thickness: the plane through the middle surface's vertex, reach t / (2 |n_h|);
            from surfaces: the intrados, half the vertex's thickness).
        progress: called as ``progress(step, infeasibility)`` after every step of every
            search, the start's, the retries' and the ``needed_scale`` one's (1-based, one sequence;
            infeasibility: the largest vertical residual over the mean load). Returning False
            stops the search (``termination == "cancelled"``); an exception it raises stops
            it too and propagates.
        **settings: ``load_rule`` ("barycentric", "voronoi", "plan_area"), ``q_min`` and
            ``q_min_kind`` (default 0, "absolute": compression only), ``tolerance`` (on
            eps_inf, default 1e-6), ``max_iterations`` (per search: the start's, the analysis'
            own and each retry's; default 200).

    The GIL is released while it searches; Ctrl-C stops it within one step and propagates.

    Raises:
        VoussoirError: a bad envelope (thickness <= 0 or not finite, intrados above extrados,
            a surface that does not cover a vertex: the message names the vertex or face), a
            bad setting, a load pattern of the wrong length, or bad springing joints (a length
            other than n, a springing height not finite or above the extrados, a reach that is
            NaN or negative: the message names the argument and vertex).
    """
    native = _check_mesh(mesh)
    kwargs: Dict[str, Any] = dict(settings)
    kwargs.update(objective=objective, fixed_supports=fixed_supports, unit_weight=unit_weight)
    if load_pattern is not None:
        kwargs["load_pattern"] = _floats("load_pattern", load_pattern)
    uniform: Optional[float] = None
    t = None
    if thickness is not None:
        t = np.atleast_1d(_floats("thickness", thickness)).ravel()
        if np.ndim(thickness) == 0:
            uniform = float(t[0])
    fields = _native.assess(
        native,
        t,
        _surface("intrados", intrados),
        _surface("extrados", extrados),
        kwargs,
        progress,
        springing=_floats("springing", springing),
        reach=_floats("reach", reach),
    )
    least = None if uniform is None or not fields["feasible"] else fields["thickness_scale"] * uniform
    return AssessmentResult._from_native(fields, least)


def min_thickness_of_family(
    mesh: Mesh,
    envelope_at: Callable[[float], Tuple[Any, Any]],
    thickness: float,
    *,
    scale_tolerance: float = 1e-3,
    fixed_supports: bool = False,
    unit_weight: float = 1.0,
    **settings: Any,
) -> AssessmentResult:
    """The least thickness t of a family of envelopes whose bounds are functions of t, such as
    Heyman's dome (the spheres R +- t/2 read vertically) or compas_tno's ``zlb``/``zub``.

    Each round runs the "min-thickness" analysis on ``envelope_at(t)`` (self-weight: area x t x
    `unit_weight` on its middle surface) and moves t towards the thickness whose least scale is
    1 (secant steps inside a bracket, at most twelve rounds); see docs/method.md section 16.5.

    Args:
        mesh: the vault; its plan is the form diagram.
        envelope_at: called with a thickness t, returns ``(lower, upper)``, the (n,) intrados
            and extrados heights per vertex of that thickness, or ``(lower, upper, springing,
            reach)`` with the springing joints of that thickness too (as for `assess`; None
            keeps the default: the plane at `lower`, half of t).
        thickness: the first thickness tried (the vault's own, say).
        scale_tolerance: the search ends when the least scale lies in [1 - this, 1].
        fixed_supports, unit_weight, **settings: as for `assess`.

    Returns:
        The "min-thickness" analysis at the least certified thickness; ``thickness_min`` is
        that thickness, ``rounds`` the analyses run and ``family_converged`` whether the last
        scale met `scale_tolerance` (a local least thickness of a nested family).

    Raises:
        VoussoirError: `envelope_at` returned something else than two arrays of n finite
            floats with lower <= upper (the message names the vertex), no round found a
            certified surface, or a bad setting. An exception `envelope_at` raises propagates.
    """
    native = _check_mesh(mesh)
    if not callable(envelope_at):
        raise VoussoirError("argument `envelope_at`: is not callable")

    def member(t: float) -> Tuple[Optional[np.ndarray], ...]:
        answer = envelope_at(t)
        try:
            parts = tuple(answer)
        except TypeError:
            parts = ()
        if len(parts) not in (2, 4):
            raise VoussoirError(
                f"argument `envelope_at`: envelope_at({t}) did not return a pair (lower, upper) or "
                "(lower, upper, springing, reach)"
            )
        return tuple(_floats("envelope_at", part) for part in parts)

    kwargs: Dict[str, Any] = dict(settings)
    kwargs.update(fixed_supports=fixed_supports, unit_weight=unit_weight)
    fields = _native.min_thickness_of_family(
        native,
        member,
        _number("thickness", thickness),
        _number("scale_tolerance", scale_tolerance),
        kwargs,
    )
    return AssessmentResult._from_native(fields, fields["thickness"])


WELD_TOLERANCE: float = _native.WELD_TOLERANCE
REPAIR_TOLERANCE: float = _native.REPAIR_TOLERANCE
