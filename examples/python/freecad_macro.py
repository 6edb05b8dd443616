"""FreeCAD macro: form-find a Mesh object of the active document and add the self-supporting
shape as a new Mesh object beside it.

Install the wheel into FreeCAD's Python first (docs/python.md: ``pip install --no-deps --target
~/.local/share/FreeCAD/Mod/voussoir voussoir-*.whl``), then run this file from Macro > Macros
with a Mesh object selected (else the document's first Mesh object is used). Supports are the
mesh's lowest vertices (within ANCHOR_TOLERANCE of the lowest height, relative to the
bounding-box diagonal); call `form_find_object` with ``anchored=`` to choose them.

Headless, in ``freecadcmd`` or any script with FreeCAD imported::

    import freecad_macro
    target, summary = freecad_macro.form_find_object(doc, doc.getObject("Vault"), fairness=0.1)

The Voussoir part is `form_find_points`, a plain function of arrays that runs without FreeCAD.
FreeCAD keeps mesh points in single precision: the new object's points are the library's
positions rounded to float32, in the source's vertex and facet order.
"""

from __future__ import annotations

from typing import Any, List, Optional, Sequence, Tuple

import numpy as np

import voussoir

ANCHOR_TOLERANCE = 0.01

Point = Tuple[float, float, float]


def lowest_vertices(points: np.ndarray, tolerance: float) -> np.ndarray:
    """Ids of the vertices within `tolerance` x the bounding-box diagonal of the lowest one."""
    diagonal = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
    return np.flatnonzero(points[:, 2] <= points[:, 2].min() + tolerance * diagonal)


def form_find_points(
    points: Sequence[Point],
    facets: Sequence[Tuple[int, int, int]],
    anchored: Optional[Sequence[int]] = None,
    anchor_tolerance: float = ANCHOR_TOLERANCE,
    **settings: Any,
) -> Tuple[List[Point], str]:
    """The form-found positions of a triangle mesh given as points and facets (vertex ids),
    supported at `anchored` (default: its lowest vertices), with a one-line summary."""
    vertices = np.asarray(points, dtype=np.float64)
    if anchored is None:
        anchored = lowest_vertices(vertices, anchor_tolerance)
    mesh = voussoir.Mesh(vertices, facets, anchored)
    result = voussoir.form_find(mesh, **settings)
    summary = (
        f"{result.termination_message}; eps_inf {result.eps_inf:.2e}, largest height change "
        f"{100 * result.max_change:.2f}% of the plan diagonal"
    )
    return [tuple(p) for p in result.positions.tolist()], summary


def form_find_object(
    doc: Any,
    source: Any,
    anchored: Optional[Sequence[int]] = None,
    name: Optional[str] = None,
    **settings: Any,
) -> Tuple[Any, str]:
    """Adds to `doc` a Mesh object (named `name`, default SOURCE_selfsupporting) holding the
    form-found shape of the Mesh object `source`, in global coordinates, and recomputes;
    returns it with the summary. `anchored` and `settings` as for `form_find_points`."""
    import FreeCAD
    import Mesh as FreeCADMesh

    points, facets = source.Mesh.Topology  # global coordinates (the Placement applied)
    found, summary = form_find_points(
        [(p.x, p.y, p.z) for p in points], facets, anchored, **settings
    )
    target = doc.addObject("Mesh::Feature", name or f"{source.Name}_selfsupporting")
    # (points, facets) keeps the vertex and facet order; a list of triangles would not.
    target.Mesh = FreeCADMesh.Mesh(([FreeCAD.Vector(*p) for p in found], facets))
    doc.recompute()
    return target, summary


def selected_mesh(doc: Any) -> Any:
    """The Mesh object selected in the GUI, else the document's first Mesh object."""
    import FreeCAD

    selected = []
    if FreeCAD.GuiUp:
        import FreeCADGui

        selected = [o for o in FreeCADGui.Selection.getSelection() if hasattr(o, "Mesh")]
    meshes = selected or [o for o in doc.Objects if hasattr(o, "Mesh")]
    if not meshes:
        raise ValueError(f"document {doc.Name} has no Mesh object to form-find")
    return meshes[0]


def run_in_freecad(doc: Any = None, **settings: Any) -> Any:
    """The macro: form-finds the selected (or first) Mesh object of `doc` (default: the active
    document), prints the summary to FreeCAD's report view and returns the new object."""
    import FreeCAD

    doc = doc or FreeCAD.ActiveDocument
    if doc is None:
        raise ValueError("no document is open")
    target, summary = form_find_object(doc, selected_mesh(doc), **settings)
    FreeCAD.Console.PrintMessage(f"Voussoir: {target.Label}: {summary}\n")
    return target


if __name__ == "__main__":  # pragma: no cover - a FreeCAD macro runs as __main__
    run_in_freecad()
