"""Rhino interchange: meshes in `.3dm` files through `rhino3dm` (``pip install
voussoir[rhino]``), the file library of Rhino, usable without Rhino.

    from voussoir.rhino import read_3dm, write_3dm
    mesh = read_3dm("vault.3dm", name="vault")       # supports: see below
    result = voussoir.form_find(mesh)
    write_3dm("found.3dm", mesh, result.positions)

Vertices are written in double precision (every bit kept) and read as Rhino holds them; quads
are split into two triangles (0, 1, 2), (0, 2, 3), as `Mesh.from_file` splits polygons. The
supports travel as the object's user text ``voussoir.anchored`` (a JSON list of vertex ids),
which `write_3dm` sets and `read_3dm` reads unless ``anchored=`` is given.
"""

from __future__ import annotations

import json
import os
import tempfile
from typing import Any, Optional

import numpy as np

from . import Mesh, VoussoirError, _path

ANCHORED_KEY = "voussoir.anchored"


def _rhino3dm() -> Any:
    try:
        import rhino3dm
    except ImportError as e:
        raise ImportError(f"voussoir.rhino needs rhino3dm: pip install voussoir[rhino] ({e})")
    return rhino3dm


def _mesh_object(model: Any, name: Optional[str], path: str) -> Any:
    rhino3dm = _rhino3dm()
    meshes = [o for o in model.Objects if isinstance(o.Geometry, rhino3dm.Mesh)]
    if name is not None:
        meshes = [o for o in meshes if o.Attributes.Name == name]
    if not meshes:
        what = "no mesh" if name is None else f"no mesh named {name!r}"
        raise VoussoirError(f"{path}: has {what}")
    return meshes[0]


def read_3dm(
    path: Any, name: Optional[str] = None, anchored: Any = None, **mesh_kwargs: Any
) -> Mesh:
    """A `Mesh` from the first mesh object of a .3dm file (or the first one named `name`).
    Supports: `anchored`, else the object's ``voussoir.anchored`` user text. Other keyword
    arguments (loads) go to `Mesh`."""
    rhino3dm = _rhino3dm()
    path = _path("path", path)
    model = rhino3dm.File3dm.Read(path)
    if model is None:
        raise VoussoirError(f"argument `path`: cannot read {path} as a .3dm file")
    obj = _mesh_object(model, name, path)
    geometry = obj.Geometry
    vertices = geometry.Vertices
    points = [vertices.Point3dAt(i) for i in range(len(vertices))]
    xyz = np.array([[p.X, p.Y, p.Z] for p in points], dtype=np.float64).reshape(-1, 3)
    faces = []
    for i in range(geometry.Faces.Count):
        a, b, c, d = geometry.Faces[i]
        faces.append([a, b, c])
        if d != c:
            faces.append([a, c, d])
    if anchored is None:
        text = obj.Attributes.GetUserString(ANCHORED_KEY)
        if not text:
            raise VoussoirError(
                f"{path}: the mesh has no `{ANCHORED_KEY}` user text; give anchored="
            )
        try:
            anchored = json.loads(text)
        except ValueError as e:
            raise VoussoirError(f"{path}: user text `{ANCHORED_KEY}` is not JSON: {e}") from None
    return Mesh(xyz, np.array(faces, dtype=np.int64).reshape(-1, 3), anchored, **mesh_kwargs)


def write_3dm(path: Any, mesh: Mesh, positions: Any = None, name: str = "voussoir") -> None:
    """Writes `mesh` with `positions` (default: its own) as a mesh object named `name` of a new
    .3dm file (Rhino 7 and later), double precision, its supports as user text; all or
    nothing."""
    rhino3dm = _rhino3dm()
    xyz = mesh.vertices if positions is None else np.asarray(positions, dtype=np.float64)
    if xyz.shape != mesh.vertices.shape:
        raise VoussoirError(
            f"argument `positions`: has shape {xyz.shape}, the mesh {mesh.vertices.shape}"
        )
    geometry = rhino3dm.Mesh()
    geometry.Vertices.UseDoublePrecisionVertices = True
    for x, y, z in xyz.tolist():
        geometry.Vertices.AddPoint3d(x, y, z)
    for a, b, c in mesh.faces.tolist():
        geometry.Faces.AddFace(a, b, c)
    attributes = rhino3dm.ObjectAttributes()
    attributes.Name = name
    attributes.SetUserString(ANCHORED_KEY, json.dumps(mesh.anchored.tolist()))
    model = rhino3dm.File3dm()
    model.Objects.AddMesh(geometry, attributes)
    path = _path("path", path)
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".voussoir-", suffix=".3dm", dir=folder)
    os.close(fd)
    try:
        if not model.Write(tmp, 7):
            raise VoussoirError(f"argument `path`: cannot write {path}")
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


__all__ = ["ANCHORED_KEY", "read_3dm", "write_3dm"]
