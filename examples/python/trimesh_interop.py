"""trimesh interoperability: a `trimesh.Trimesh` in, the self-supporting shape as a
`trimesh.Trimesh` out, with force densities as edge attributes for further processing.

    python examples/python/trimesh_interop.py MESH.stl

compas works the same way: ``compas.datastructures.Mesh.from_vertices_and_faces(*arrays)`` on
the arrays `form_find_arrays` returns, and ``mesh.to_vertices_and_faces()`` to call it.
"""

from __future__ import annotations

import sys
from typing import Any, Dict, Tuple

import numpy as np

import voussoir


def form_find_arrays(
    vertices: np.ndarray, faces: np.ndarray, anchored: np.ndarray, **settings
) -> Tuple[np.ndarray, np.ndarray, Dict[str, Any]]:
    """Form finding on plain arrays: (vertices, faces, extras) with the per-edge force
    densities, the edges they belong to and the termination. Needs neither trimesh nor compas."""
    mesh = voussoir.Mesh(vertices, faces, anchored)
    result = voussoir.form_find(mesh, **settings)
    extras = {
        "edges": result.edges,
        "force_densities": result.force_densities,
        "termination": result.termination,
        "eps_inf": result.eps_inf,
    }
    return result.positions, mesh.faces.astype(np.int64), extras


def boundary_vertices(faces: np.ndarray) -> np.ndarray:
    """Ids of the vertices on edges used by one face only."""
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    unique, counts = np.unique(edges, axis=0, return_counts=True)
    return np.unique(unique[counts == 1])


def form_find_trimesh(shape, **settings):
    """A new `trimesh.Trimesh` at the self-supporting shape of `shape`, anchored along its
    boundary; force densities in ``metadata["force_densities"]`` (rows of ``metadata["edges"]``)."""
    import trimesh

    faces = np.asarray(shape.faces, dtype=np.int64)
    positions, faces, extras = form_find_arrays(
        np.asarray(shape.vertices), faces, boundary_vertices(faces), **settings
    )
    return trimesh.Trimesh(vertices=positions, faces=faces, process=False, metadata=extras)


if __name__ == "__main__":
    import trimesh

    source = trimesh.load(sys.argv[1], force="mesh")
    found = form_find_trimesh(source)
    print(found.metadata["termination"], f"eps_inf {found.metadata['eps_inf']:.2e}")
    found.export(sys.argv[1].rsplit(".", 1)[0] + "-selfsupporting.stl")
