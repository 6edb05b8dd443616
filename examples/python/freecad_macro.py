"""FreeCAD macro: form-find the selected (or first) Mesh object of the active document and add
the self-supporting shape as a new Mesh object.

Install the wheel into FreeCAD's Python (``FreeCAD -c "import pip; ..."`` or its bundled
``python -m pip install voussoir-*.whl``), then run this file from Macro > Macros. Supports are
the mesh's lowest vertices (within ANCHOR_TOLERANCE of the lowest height, relative to the
bounding-box diagonal); edit it for your model. The Voussoir part is `form_find_points`, a plain
function of arrays that runs (and is tested) without FreeCAD.
"""

from __future__ import annotations

from typing import List, Sequence, Tuple

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
    anchor_tolerance: float = ANCHOR_TOLERANCE,
    **settings,
) -> Tuple[List[Point], str]:
    """The form-found positions of a triangle mesh given as points and facets (vertex ids),
    supported at its lowest vertices, with a one-line summary."""
    vertices = np.asarray(points, dtype=np.float64)
    mesh = voussoir.Mesh(vertices, facets, lowest_vertices(vertices, anchor_tolerance))
    result = voussoir.form_find(mesh, **settings)
    summary = (
        f"{result.termination_message}; eps_inf {result.eps_inf:.2e}, largest height change "
        f"{100 * result.max_change:.2f}% of the plan diagonal"
    )
    return [tuple(p) for p in result.positions.tolist()], summary


def run_in_freecad() -> None:  # pragma: no cover - needs FreeCAD
    import FreeCAD
    import FreeCADGui
    import Mesh as FreeCADMesh

    doc = FreeCAD.ActiveDocument
    selected = [o for o in FreeCADGui.Selection.getSelection() if hasattr(o, "Mesh")]
    source = selected[0] if selected else next(o for o in doc.Objects if hasattr(o, "Mesh"))
    points, facets = source.Mesh.Topology
    found, summary = form_find_points([(p.x, p.y, p.z) for p in points], facets)
    triangles = [[found[i] for i in facet] for facet in facets]
    target = doc.addObject("Mesh::Feature", f"{source.Name}_selfsupporting")
    target.Mesh = FreeCADMesh.Mesh(triangles)
    doc.recompute()
    FreeCAD.Console.PrintMessage(f"Voussoir: {summary}\n")

if __name__ == "__main__":  # pragma: no cover - a FreeCAD macro runs as __main__
    run_in_freecad()
