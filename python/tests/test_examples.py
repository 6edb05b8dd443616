"""The examples in examples/python: the matplotlib plot (headless, Agg), the FreeCAD macro's
Voussoir part, and the trimesh interoperability. matplotlib and trimesh are optional: their
tests skip without them unless VSR_REQUIRE_EXAMPLES=1 (set by CI, which installs them)."""

from __future__ import annotations

import importlib
import importlib.util
import os

import numpy as np
import pytest

from conftest import REPO

EXAMPLES = REPO / "examples" / "python"


def example(name):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def optional(package):
    """The package, or a skip; an ImportError where CI requires the examples to run."""
    if os.environ.get("VSR_REQUIRE_EXAMPLES") == "1":
        return importlib.import_module(package)
    return pytest.importorskip(package)


def pillow_dome(n=9):
    """A dome over the square [-1, 1]^2 whose boundary is its lowest part."""
    xs = np.linspace(-1, 1, n)
    x, y = np.meshgrid(xs, xs)
    z = 0.8 * (1 - x**2) * (1 - y**2)
    vertices = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
    faces = []
    for i in range(n - 1):
        for j in range(n - 1):
            a, b, c, d = i * n + j, i * n + j + 1, (i + 1) * n + j + 1, (i + 1) * n + j
            faces += [[a, b, c], [a, c, d]]
    return vertices, np.array(faces)


def test_plot_runs_headless(models, tmp_path):
    optional("matplotlib")
    plot = example("plot_form_finding")
    out = plot.main(
        [str(models / "three_pillar.obj"), str(models / "three_pillar.json"), "--out", str(tmp_path / "p.png")]
    )
    import matplotlib

    assert matplotlib.get_backend().lower() == "agg"
    data = out.read_bytes()
    assert data.startswith(b"\x89PNG") and len(data) > 20_000


def test_freecad_macro_form_finds_points_and_facets():
    macro = example("freecad_macro")
    vertices, faces = pillow_dome()
    points = [tuple(p) for p in vertices.tolist()]
    facets = [tuple(f) for f in faces.tolist()]
    found, summary = macro.form_find_points(points, facets)
    assert len(found) == len(points) and all(len(p) == 3 for p in found)
    found = np.array(found)
    boundary = macro.lowest_vertices(vertices, macro.ANCHOR_TOLERANCE)
    assert len(boundary) == 4 * (9 - 1)
    assert np.array_equal(found[boundary], vertices[boundary])
    assert np.array_equal(found[:, :2], vertices[:, :2])
    assert summary.startswith("converged"), summary


def test_interop_arrays_without_trimesh():
    interop = example("trimesh_interop")
    vertices, faces = pillow_dome()
    boundary = interop.boundary_vertices(faces)
    assert len(boundary) == 32
    positions, out_faces, extras = interop.form_find_arrays(vertices, faces, boundary)
    assert positions.shape == vertices.shape and np.array_equal(out_faces, faces)
    assert extras["termination"] == "converged"
    assert extras["force_densities"].shape == (len(extras["edges"]),)


def test_interop_with_trimesh():
    trimesh = optional("trimesh")
    interop = example("trimesh_interop")
    vertices, faces = pillow_dome()
    shape = trimesh.Trimesh(vertices=vertices, faces=faces, process=False)
    found = interop.form_find_trimesh(shape)
    assert isinstance(found, trimesh.Trimesh)
    assert np.array_equal(found.faces, faces)
    assert found.metadata["termination"] == "converged"
    positions, _, _ = interop.form_find_arrays(vertices, faces, interop.boundary_vertices(faces))
    assert np.array_equal(found.vertices, positions)
