"""Rhino and COMPAS interchange (voussoir.rhino, voussoir.compas) with the real packages:
rhino3dm, compas, compas_tna and compas_tno, installed by `.ci/hosts interchange` in a venv.

On every shared model: a mesh through a .3dm file, a compas Mesh (and COMPAS's own JSON) or a
FormDiagram JSON file in either sign convention comes back with every bit, so form finding it
gives the Python API's result bit for bit. compas_tna's and compas_tno's own vertical
equilibrium solvers, run on the diagrams written, find our heights: the signs are theirs.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import voussoir
from conftest import MODEL_NAMES, host_import

CONVENTIONS = ("tna", "tno")


@pytest.fixture(scope="module")
def solved(models):
    """Each shared model with the Python API's form-found result."""
    out = {}
    for name in MODEL_NAMES:
        mesh = voussoir.Mesh.from_file(models / f"{name}.obj", models / f"{name}.json")
        out[name] = mesh, voussoir.form_find(mesh)
    return out


def same_mesh(a, b):
    assert np.array_equal(a.vertices, b.vertices)
    assert np.array_equal(a.faces, b.faces)
    assert np.array_equal(a.anchored, b.anchored)


def same_result(a, b):
    assert a.termination == b.termination and a.iterations == b.iterations
    assert np.array_equal(a.positions, b.positions)
    assert np.array_equal(a.force_densities, b.force_densities)


@pytest.mark.parametrize("name", MODEL_NAMES)
def test_3dm_round_trip_keeps_every_bit(name, solved, tmp_path):
    host_import("interchange", "rhino3dm")
    from voussoir.rhino import read_3dm, write_3dm

    mesh, result = solved[name]
    write_3dm(tmp_path / "input.3dm", mesh)
    back = read_3dm(tmp_path / "input.3dm")
    same_mesh(back, mesh)
    same_result(voussoir.form_find(back), result)

    write_3dm(tmp_path / "found.3dm", mesh, result.positions, name="found")
    found = read_3dm(tmp_path / "found.3dm", name="found")
    assert np.array_equal(found.vertices, result.positions)


def test_3dm_quads_split_and_errors(tmp_path):
    rhino3dm = host_import("interchange", "rhino3dm")
    from voussoir.rhino import read_3dm

    geometry = rhino3dm.Mesh()
    geometry.Vertices.UseDoublePrecisionVertices = True
    for p in ([0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 0.3], [2, 0.5, 0]):
        geometry.Vertices.AddPoint3d(*p)
    geometry.Faces.AddFace(0, 1, 4)
    geometry.Faces.AddFace(1, 5, 2, 4)  # a quad
    geometry.Faces.AddFace(2, 3, 4)
    geometry.Faces.AddFace(3, 0, 4)
    model = rhino3dm.File3dm()
    model.Objects.AddMesh(geometry)
    model.Write(str(tmp_path / "quad.3dm"), 7)
    mesh = read_3dm(tmp_path / "quad.3dm", anchored=[0, 1, 2, 3, 5])
    assert mesh.faces.tolist() == [[0, 1, 4], [1, 5, 2], [1, 2, 4], [2, 3, 4], [3, 0, 4]]
    with pytest.raises(voussoir.VoussoirError, match="voussoir.anchored"):
        read_3dm(tmp_path / "quad.3dm")
    with pytest.raises(voussoir.VoussoirError, match="no mesh named 'vault'"):
        read_3dm(tmp_path / "quad.3dm", name="vault")


@pytest.mark.parametrize("name", MODEL_NAMES)
def test_compas_mesh_and_its_json_keep_every_bit(name, solved, tmp_path):
    compas = host_import("interchange", "compas")
    from compas.datastructures import Mesh as CompasMesh

    from voussoir.compas import from_compas, to_compas

    mesh, result = solved[name]
    cmesh = to_compas(mesh)
    assert isinstance(cmesh, CompasMesh)
    assert cmesh.number_of_vertices() == len(mesh.vertices)
    compas.json_dump(cmesh, str(tmp_path / "mesh.json"))
    back = from_compas(compas.json_load(str(tmp_path / "mesh.json")))
    same_mesh(back, mesh)
    same_result(voussoir.form_find(back), result)

    found = to_compas(mesh, result)
    xyz = np.array(found.vertices_attributes("xyz"))
    assert np.array_equal(xyz, result.positions)
    q = np.array([found.edge_attribute(tuple(e), "q") for e in result.edges.tolist()])
    assert np.array_equal(q, result.force_densities)


@pytest.mark.parametrize("convention", CONVENTIONS)
@pytest.mark.parametrize("name", MODEL_NAMES)
def test_formdiagram_json_in_both_conventions(name, convention, solved, tmp_path):
    compas = host_import("interchange", "compas")
    diagrams = host_import("interchange", "compas_tna.diagrams")
    from voussoir.compas import read_formdiagram, write_formdiagram

    mesh, result = solved[name]
    path = tmp_path / "form.json"
    write_formdiagram(path, mesh, result, convention)
    form = compas.json_load(str(path))
    assert isinstance(form, diagrams.FormDiagram)
    sign = 1.0 if convention == "tna" else -1.0
    keys = list(form.vertices())
    assert keys == list(range(len(mesh.vertices)))
    assert np.array_equal(np.array(form.vertices_attribute("pz")), sign * result.loads)
    assert sorted(form.vertices_where(is_support=True)) == mesh.anchored.tolist()
    q = np.array([form.edge_attribute(tuple(e), "q") for e in result.edges.tolist()])
    assert np.array_equal(q, sign * result.force_densities)
    # Compression only: q of one sign.
    assert np.all(sign * q >= 0) and np.any(sign * q > 0)

    # Back in: the form-found shape, its supports and its loads (pz), every bit.
    back = read_formdiagram(path, convention)
    assert np.array_equal(back.vertices, result.positions)
    assert np.array_equal(back.faces, mesh.faces)
    assert np.array_equal(back.anchored, mesh.anchored)
    assert np.array_equal(back.extra_loads, result.loads)
    assert np.array_equal(voussoir.analyse(back).loads, result.loads)
    with pytest.raises(voussoir.VoussoirError, match="convention"):
        read_formdiagram(path, "rv")


def plan_diagonal(xyz):
    return float(np.linalg.norm(xyz[:, :2].max(axis=0) - xyz[:, :2].min(axis=0)))


@pytest.mark.parametrize("name", MODEL_NAMES)
def test_compas_tna_and_tno_solvers_find_our_heights(name, solved, tmp_path):
    compas = host_import("interchange", "compas")
    tna = host_import("interchange", "compas_tna.equilibrium")
    tno = host_import("interchange", "compas_tno.algorithms")
    from voussoir.compas import write_formdiagram

    mesh, result = solved[name]
    assert result.termination == "converged"
    tolerance = 1e-4 * plan_diagonal(result.positions)
    free = np.setdiff1d(np.arange(len(mesh.vertices)), mesh.anchored)
    for convention, solve in (
        ("tna", lambda form: tna.vertical_from_q(form, density=0.0)),
        ("tno", tno.vertical_equilibrium_fdm),
    ):
        write_formdiagram(tmp_path / f"{convention}.json", mesh, result, convention)
        form = compas.json_load(str(tmp_path / f"{convention}.json"))
        for key in form.vertices():  # start from a flat network: only q and pz decide
            if not form.vertex_attribute(key, "is_support"):
                form.vertex_attribute(key, "z", 0.0)
        solve(form)  # in place
        z = np.array(form.vertices_attribute("z"))
        used = np.unique(mesh.faces)
        free_used = np.intersect1d(free, used)
        error = np.abs(z[free_used] - result.positions[free_used, 2]).max()
        assert error < tolerance, (convention, error, tolerance)


def test_a_compas_tna_diagram_comes_in(tmp_path):
    compas = host_import("interchange", "compas")
    diagrams = host_import("interchange", "compas_tna.diagrams")
    from voussoir.compas import from_compas, read_formdiagram

    form = diagrams.FormDiagram.create_cross(x_span=(0, 10), y_span=(0, 10), n=6)
    boundary = set(form.vertices_on_boundary())
    for key in boundary:
        form.vertex_attribute(key, "is_support", True)
    compas.json_dump(form, str(tmp_path / "cross.json"))
    mesh = read_formdiagram(tmp_path / "cross.json")
    assert len(mesh.vertices) == form.number_of_vertices()
    assert len(mesh.anchored) == len(boundary)
    # No pz: the library's own self-weight.
    assert np.all(mesh.face_density == 1) and np.all(mesh.extra_loads == 0)
    result = voussoir.form_find(mesh)
    assert result.termination == "converged"
    same_result(voussoir.form_find(from_compas(form)), result)
    assert json.loads((tmp_path / "cross.json").read_text())["dtype"].endswith("FormDiagram")


@pytest.mark.parametrize("name", MODEL_NAMES)
def test_the_signs_are_the_packages_own(name, solved, tmp_path):
    """The solvers above see q and pz flipped together alike: the signs themselves are checked
    against what the packages do. "tna": compas_tna's vertical solver, adding its own
    self-weight (t x density x tributary area) to pz = 0, lifts the shell as ours stands.
    "tno": q lies within compas_tno's default bounds, and pz has the sign of the self-weight
    compas_tna's envelopes (which compas_tno uses) put on a diagram."""
    compas = host_import("interchange", "compas")
    tna = host_import("interchange", "compas_tna.equilibrium")
    optimisers = host_import("interchange", "compas_tno.optimisers")
    from voussoir.compas import write_formdiagram

    mesh, result = solved[name]
    free = np.setdiff1d(np.unique(mesh.faces), mesh.anchored)
    write_formdiagram(tmp_path / "tna.json", mesh, result, "tna")
    form = compas.json_load(str(tmp_path / "tna.json"))
    for key in form.vertices():
        form.vertex_attribute(key, "pz", 0.0)
    tna.vertical_from_q(form, density=1.0)
    z = np.array(form.vertices_attribute("z"))
    assert np.corrcoef(z[free], result.positions[free, 2])[0, 1] > 0.9

    write_formdiagram(tmp_path / "tno.json", mesh, result, "tno")
    form = compas.json_load(str(tmp_path / "tno.json"))
    settings = optimisers.Optimiser().settings
    q = np.array(form.edges_attribute("q"))
    assert np.all((settings["qmin"] <= q) & (q <= settings["qmax"]))
    assert np.all(np.array(form.vertices_attribute("pz"))[free] < 0)


def test_a_compas_tna_envelope_self_weight_reads_as_tno(tmp_path):
    compas = host_import("interchange", "compas")
    diagrams = host_import("interchange", "compas_tna.diagrams")
    envelope = host_import("interchange", "compas_tna.envelope")
    from voussoir.compas import read_formdiagram

    form = diagrams.FormDiagram.create_cross(x_span=(0, 10), y_span=(0, 10), n=6)
    dome = envelope.DomeEnvelope(center=(5.0, 5.0), radius=7.5, thickness=0.5)
    dome.apply_selfweight_to_formdiagram(form)
    pz = np.array(form.vertices_attribute("pz"))
    assert np.all(pz <= 0) and np.any(pz < 0)
    for key in form.vertices_on_boundary():
        form.vertex_attribute(key, "is_support", True)
    compas.json_dump(form, str(tmp_path / "form.json"))
    mesh = read_formdiagram(tmp_path / "form.json", "tno")
    assert np.array_equal(mesh.extra_loads, -pz) and np.all(mesh.face_density == 0)
    assert voussoir.form_find(mesh).termination == "converged"
