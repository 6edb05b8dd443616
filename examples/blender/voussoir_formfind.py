"""Blender add-on: Object > Form-find selected mesh (Voussoir).

Adds the nearest self-supporting shape of the active mesh object as a new object beside it,
with the same vertices, faces and transform. Supports are the vertices of the vertex group
named in the operator ("anchored" by default) or, without that group, the lowest vertices.
The report line and the new object's custom properties (voussoir_*) tell how it ended.

Install: the voussoir wheel into Blender's Python (docs/python.md), then Edit > Preferences >
Add-ons > Install from Disk... with this file. Headless, with Blender as a Python module
(``pip install bpy``) or ``blender --background``: register() and call
``bpy.ops.object.voussoir_form_find()`` with a mesh object active, or `form_find_object`.

Blender keeps vertex coordinates in single precision: the new object's coordinates are the
library's positions (computed in world coordinates, z up) rounded to float32. Polygons are
split into fans (0, k, k + 1), as `voussoir.Mesh.from_file` splits them.
"""

# No `from __future__ import annotations`: Blender reads the operator's properties from its
# class annotations, which must stay objects.
from typing import Any, Dict, Optional, Tuple

import bpy
import numpy as np
from bpy.props import EnumProperty, FloatProperty, IntProperty, StringProperty

import voussoir

bl_info = {
    "name": "Voussoir form finding",
    "author": "Voussoir",
    "version": (0, 1, 0),
    "blender": (4, 2, 0),
    "location": "View3D > Object > Form-find selected mesh",
    "description": "The nearest self-supporting (compression-only) shape of a mesh",
    "category": "Mesh",
}

ANCHOR_TOLERANCE = 0.01


def mesh_arrays(obj: Any) -> Tuple[np.ndarray, np.ndarray]:
    """World-space vertex positions (n, 3) of a mesh object and its polygons split into fans
    (m, 3), in Blender's vertex and polygon order."""
    mesh = obj.data
    local = np.empty(3 * len(mesh.vertices), dtype=np.float32)
    mesh.vertices.foreach_get("co", local)
    local = local.reshape(-1, 3).astype(np.float64)
    matrix = np.array(obj.matrix_world, dtype=np.float64)
    world = local @ matrix[:3, :3].T + matrix[:3, 3]
    triangles = [
        (p.vertices[0], p.vertices[k], p.vertices[k + 1])
        for p in mesh.polygons
        for k in range(1, len(p.vertices) - 1)
    ]
    return world, np.array(triangles, dtype=np.int64).reshape(-1, 3)


def anchored_vertices(obj: Any, points: np.ndarray, group: str, tolerance: float) -> np.ndarray:
    """The vertices of vertex group `group` when the object has it, else those within
    `tolerance` x the bounding-box diagonal of the lowest one."""
    if group and group in obj.vertex_groups:
        index = obj.vertex_groups[group].index
        ids = [v.index for v in obj.data.vertices if any(g.group == index for g in v.groups)]
        return np.array(ids, dtype=np.int64)
    diagonal = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
    return np.flatnonzero(points[:, 2] <= points[:, 2].min() + tolerance * diagonal)


def form_find_object(
    obj: Any,
    group: str = "anchored",
    anchor_tolerance: float = ANCHOR_TOLERANCE,
    name: Optional[str] = None,
    **settings: Any,
) -> Tuple[Any, Any]:
    """Links a copy of mesh object `obj` with the form-found shape into obj's collections;
    returns it with the `voussoir.FormFindResult`. `settings` go to `voussoir.form_find`."""
    points, triangles = mesh_arrays(obj)
    anchored = anchored_vertices(obj, points, group, anchor_tolerance)
    result = voussoir.form_find(voussoir.Mesh(points, triangles, anchored), **settings)
    inverse = np.linalg.inv(np.array(obj.matrix_world, dtype=np.float64))
    local = result.positions @ inverse[:3, :3].T + inverse[:3, 3]

    found = obj.copy()
    found.data = obj.data.copy()
    found.name = name or f"{obj.name}_selfsupporting"
    found.data.name = found.name
    found.data.vertices.foreach_set("co", local.astype(np.float32).ravel())
    found.data.update()
    for collection in obj.users_collection:
        collection.objects.link(found)
    found["voussoir_termination"] = result.termination
    found["voussoir_eps_inf"] = result.eps_inf
    found["voussoir_max_change"] = result.max_change
    return found, result


def summary(result: Any) -> str:
    return (
        f"{result.termination_message}; eps_inf {result.eps_inf:.2e}, largest height change "
        f"{100 * result.max_change:.2f}% of the plan diagonal"
    )


class VOUSSOIR_OT_form_find(bpy.types.Operator):
    """Add the nearest self-supporting shape of the active mesh as a new object"""

    bl_idname = "object.voussoir_form_find"
    bl_label = "Form-find selected mesh"
    bl_options = {"REGISTER", "UNDO"}

    method: EnumProperty(  # type: ignore[valid-type]
        name="Method",
        items=[
            ("nearest", "Nearest", "The nearest self-supporting shape"),
            ("paper", "Paper", "de Goes et al.'s loop"),
        ],
        default="nearest",
    )
    fairness: FloatProperty(name="Fairness", min=0.0, default=0.03)  # type: ignore[valid-type]
    max_height_change: FloatProperty(  # type: ignore[valid-type]
        name="Max height change", description="In plan diagonals", min=1e-6, default=1.0
    )
    tolerance: FloatProperty(  # type: ignore[valid-type]
        name="Tolerance", description="Stop when eps_inf is below", min=1e-12, default=1e-6,
        precision=8,
    )  # fmt: skip
    max_iterations: IntProperty(  # type: ignore[valid-type]
        name="Max iterations", min=1, default=100
    )
    group: StringProperty(  # type: ignore[valid-type]
        name="Supports group", description="Vertex group of the supports", default="anchored"
    )
    anchor_tolerance: FloatProperty(  # type: ignore[valid-type]
        name="Lowest within", description="Without the group: supports within this x the "
        "bounding-box diagonal of the lowest vertex", min=0.0, default=ANCHOR_TOLERANCE,
    )  # fmt: skip

    @classmethod
    def poll(cls, context: Any) -> bool:
        obj = context.active_object
        return obj is not None and obj.type == "MESH"

    def settings(self) -> Dict[str, Any]:
        """The keyword arguments of `voussoir.form_find`. Blender keeps float properties in
        single precision: 7 significant digits give back the decimal typed (0.03, not
        0.029999999329447746), so that the defaults are exactly the library's."""
        out: Dict[str, Any] = {"method": self.method, "max_iterations": self.max_iterations}
        for name in ("fairness", "max_height_change", "tolerance"):
            out[name] = float(f"{getattr(self, name):.7g}")
        return out

    def execute(self, context: Any) -> set:
        source = context.active_object
        try:
            found, result = form_find_object(
                source, self.group, self.anchor_tolerance, **self.settings()
            )
        except voussoir.VoussoirError as e:
            self.report({"ERROR"}, f"Voussoir: {e}")
            return {"CANCELLED"}
        source.select_set(False)
        found.select_set(True)
        context.view_layer.objects.active = found
        self.report({"INFO"}, f"Voussoir: {found.name}: {summary(result)}")
        return {"FINISHED"}


def menu(self: Any, context: Any) -> None:
    self.layout.operator(VOUSSOIR_OT_form_find.bl_idname)


def register() -> None:
    bpy.utils.register_class(VOUSSOIR_OT_form_find)
    bpy.types.VIEW3D_MT_object.append(menu)


def unregister() -> None:
    bpy.types.VIEW3D_MT_object.remove(menu)
    bpy.utils.unregister_class(VOUSSOIR_OT_form_find)


if __name__ == "__main__":
    register()
