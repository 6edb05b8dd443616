"""COMPAS interchange: `compas.datastructures.Mesh` (and its subclasses, such as compas_tna's
`FormDiagram`) and FormDiagram JSON files, as RhinoVAULT, compas_tna and compas_tno use them.

    from voussoir.compas import read_formdiagram, write_formdiagram
    mesh = read_formdiagram("form.json", convention="tna")    # supports: `is_support`
    result = voussoir.form_find(mesh)
    write_formdiagram("found.json", mesh, result, convention="tna")

The two sign conventions of the packages (``convention=``):

- ``"tna"`` (compas_tna, RhinoVAULT): force densities `q` > 0 in compression; vertical loads
  `pz` > 0 downward (compas_tna adds the self-weight t x density x area to them). Voussoir's
  own convention.
- ``"tno"`` (compas_tno): `q` < 0 in compression; `pz` < 0 downward (the self-weight included).

Reading, `pz` becomes `extra_loads` (downward positive) and `face_density` defaults to 0 when
any `pz` is non-zero (the loads are the diagram's), else to the library's 1. Writing, `pz` is
the whole vertical load of the result (`result.loads`, the self-weight included: run
compas_tna's solvers with ``density=0`` on it), `q` the force densities and `_f` the axial
forces q x length. Polygon faces are split into fans (as `Mesh.from_file` does), and the
diagram written has those triangles. Horizontal loads (`px`, `py`) are not read: a diagram
with non-zero ones is refused.

The JSON functions need no COMPAS; `to_compas` and `from_compas` need the `compas` package
(``pip install voussoir[compas]``).
"""

from __future__ import annotations

import json
import os
import tempfile
import uuid
from typing import Any, Dict, List

import numpy as np

from . import Mesh, VoussoirError, _path

CONVENTIONS = {"tna": 1.0, "tno": -1.0}
DTYPE = "compas_tna.diagrams/FormDiagram"


def _sign(convention: str) -> float:
    if convention not in CONVENTIONS:
        raise VoussoirError(f"argument `convention`: {convention!r} is neither 'tna' nor 'tno'")
    return CONVENTIONS[convention]


def formdiagram_data(mesh: Mesh, result: Any = None, convention: str = "tna") -> Dict[str, Any]:
    """The COMPAS data dict of a FormDiagram: `mesh` with `result` (its positions, loads and
    force densities in `convention`; None: the mesh's own positions, no loads or forces).
    Vertex keys are the mesh's vertex ids, face keys its face ids; `edgedata` is keyed by
    (u, v) tuples, u < v (COMPAS's JSON writes them as "(u, v)")."""
    sign = _sign(convention)
    positions = mesh.vertices if result is None else result.positions
    anchored = set(mesh.anchored.tolist())
    vertex = {}
    for i, (x, y, z) in enumerate(positions.tolist()):
        vertex[i] = {"x": x, "y": y, "z": z, "is_support": i in anchored}
    edgedata = {}
    if result is not None:
        for i, load in enumerate(result.loads.tolist()):
            vertex[i]["pz"] = sign * load
        edges = result.edges
        lengths = np.linalg.norm(positions[edges[:, 0]] - positions[edges[:, 1]], axis=1)
        forces = result.force_densities * lengths
        for (u, v), q, f in zip(edges.tolist(), result.force_densities.tolist(), forces.tolist()):
            edgedata[u, v] = {"q": sign * q, "_f": sign * f}
    faces = mesh.faces.tolist()
    return {
        "attributes": {"name": "FormDiagram"},
        "default_vertex_attributes": {
            "x": 0.0, "y": 0.0, "z": 0.0, "px": 0.0, "py": 0.0, "pz": 0.0,
            "is_support": False,
        },  # fmt: skip
        "default_edge_attributes": {"q": sign * 1.0, "_f": 0.0, "_is_edge": True},
        "default_face_attributes": {},
        "vertex": vertex,
        "face": dict(enumerate(faces)),
        "facedata": {i: {} for i in range(len(faces))},
        "edgedata": edgedata,
        "max_vertex": len(vertex) - 1,
        "max_face": len(faces) - 1,
    }


def write_formdiagram(path: Any, mesh: Mesh, result: Any = None, convention: str = "tna") -> None:
    """Writes `mesh` and `result` as a compas_tna FormDiagram JSON file (``compas.json_load``
    and ``FormDiagram.from_json`` read it), all or nothing."""
    data = formdiagram_data(mesh, result, convention)
    data["edgedata"] = {str(edge): attrs for edge, attrs in data["edgedata"].items()}
    document = {
        "dtype": DTYPE,
        "data": data,
        "inheritance": ["compas_tna.diagrams/Diagram", "compas.datastructures/Mesh"],
        "name": "FormDiagram",
        "guid": str(uuid.uuid4()),
    }
    path = _path("path", path)
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".voussoir-", suffix=".json", dir=folder)
    try:
        with os.fdopen(fd, "w") as f:
            json.dump(document, f)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def _unwrap(document: Any, where: str) -> Dict[str, Any]:
    """The mesh data of a COMPAS 2 document ({"dtype", "data"}) or of a COMPAS 1 one."""
    if not isinstance(document, dict):
        raise VoussoirError(f"{where}: is not a JSON object")
    data = document.get("data", document) if "dtype" in document else document
    if not isinstance(data, dict) or "vertex" not in data or "face" not in data:
        raise VoussoirError(f"{where}: has no `vertex` and `face` (not a COMPAS mesh)")
    defaults = data.get("default_vertex_attributes", data.get("dva")) or {}
    return {"vertex": data["vertex"], "face": data["face"], "defaults": defaults}


def _attribute(attrs: Dict[str, Any], defaults: Dict[str, Any], name: str, default: Any) -> Any:
    return attrs.get(name, defaults.get(name, default))


def mesh_from_data(
    data: Dict[str, Any],
    convention: str = "tna",
    anchored: Any = None,
    face_density: Any = None,
    where: str = "argument `data`",
    **mesh_kwargs: Any,
) -> Mesh:
    """A `Mesh` from COMPAS mesh data: vertices in the order of its `vertex` dict, polygon faces
    split into fans, supports where `is_support` (or the older `is_anchor`) is true unless
    `anchored` (vertex ids in that order) is given, `pz` as `extra_loads`."""
    sign = _sign(convention)
    data = _unwrap(data, where)
    defaults = data["defaults"]
    keys = list(data["vertex"])
    index = {str(k): i for i, k in enumerate(keys)}
    xyz, pz, supports = [], [], []
    for i, key in enumerate(keys):
        attrs = data["vertex"][key] or {}
        xyz.append([_attribute(attrs, defaults, c, 0.0) for c in "xyz"])
        for c in ("px", "py"):
            if _attribute(attrs, defaults, c, 0.0):
                raise VoussoirError(
                    f"{where}: vertex {key} has a horizontal load `{c}`, which is not read; "
                    "pass horizontal_forces= instead"
                )
        pz.append(_attribute(attrs, defaults, "pz", 0.0))
        if any(_attribute(attrs, defaults, a, False) for a in ("is_support", "is_anchor")):
            supports.append(i)
    faces: List[List[int]] = []
    for fkey, polygon in data["face"].items():
        try:
            ids = [index[str(v)] for v in polygon]
        except KeyError as e:
            raise VoussoirError(
                f"{where}: face {fkey} refers to vertex {e.args[0]}, which is not in `vertex`"
            ) from None
        if len(ids) < 3:
            raise VoussoirError(f"{where}: face {fkey} has {len(ids)} vertices")
        faces += [[ids[0], ids[k], ids[k + 1]] for k in range(1, len(ids) - 1)]
    if anchored is None:
        anchored = supports
    extra_loads = sign * np.asarray(pz, dtype=np.float64)
    if face_density is None and np.any(extra_loads != 0):
        face_density = np.zeros(len(faces))
    return Mesh(
        np.asarray(xyz, dtype=np.float64),
        np.asarray(faces, dtype=np.int64).reshape(-1, 3),
        np.asarray(anchored, dtype=np.int64),
        face_density=face_density,
        extra_loads=extra_loads,
        **mesh_kwargs,
    )


def read_formdiagram(path: Any, convention: str = "tna", **kwargs: Any) -> Mesh:
    """A `Mesh` from a FormDiagram (or any COMPAS mesh) JSON file, COMPAS 1 or 2; keyword
    arguments as for `mesh_from_data`."""
    path = _path("path", path)
    try:
        with open(path) as f:
            document = json.load(f)
    except (OSError, ValueError) as e:
        raise VoussoirError(f"argument `path`: cannot read {path}: {e}") from None
    return mesh_from_data(document, convention, where=path, **kwargs)


def to_compas(mesh: Mesh, result: Any = None, convention: str = "tna", cls: Any = None) -> Any:
    """A `compas.datastructures.Mesh` (or `cls`, such as compas_tna's `FormDiagram`) of `mesh`
    and `result`, with the attributes `write_formdiagram` writes."""
    if cls is None:
        from compas.datastructures import Mesh as cls
    data = formdiagram_data(mesh, result, convention)
    out = cls()
    out.attributes.update(data["attributes"])
    out.update_default_vertex_attributes(data["default_vertex_attributes"])
    out.update_default_edge_attributes(data["default_edge_attributes"])
    for key, attrs in data["vertex"].items():
        out.add_vertex(key=key, attr_dict=attrs)
    for key, face in data["face"].items():
        out.add_face(face, fkey=key)
    for edge, attrs in data["edgedata"].items():
        out.edge_attributes(edge, list(attrs), list(attrs.values()))
    return out


def from_compas(compas_mesh: Any, convention: str = "tna", **kwargs: Any) -> Mesh:
    """A `Mesh` from a `compas.datastructures.Mesh` or a subclass (vertices in the order of
    ``compas_mesh.vertices()``); keyword arguments as for `mesh_from_data`."""
    data = compas_mesh.__data__
    return mesh_from_data(data, convention, where="argument `compas_mesh`", **kwargs)


__all__ = [
    "CONVENTIONS",
    "formdiagram_data",
    "write_formdiagram",
    "mesh_from_data",
    "read_formdiagram",
    "to_compas",
    "from_compas",
]
