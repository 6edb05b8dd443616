"""voussoir.compas's FormDiagram JSON without COMPAS installed: both sign conventions round
trip every bit, and bad diagrams are refused with a message naming what is wrong. (With the
real compas, compas_tna and compas_tno: python/host_tests/test_interchange.py.)"""

from __future__ import annotations

import json

import numpy as np
import pytest

import voussoir
from conftest import SQUARE_ANCHORED, SQUARE_FACES, SQUARE_POSITIONS
from voussoir.compas import read_formdiagram, write_formdiagram


@pytest.fixture(scope="module")
def square():
    mesh = voussoir.Mesh(SQUARE_POSITIONS, SQUARE_FACES, SQUARE_ANCHORED)
    return mesh, voussoir.form_find(mesh)


@pytest.mark.parametrize("convention, sign", [("tna", 1.0), ("tno", -1.0)])
def test_round_trip_in_both_conventions(square, tmp_path, convention, sign):
    mesh, result = square
    write_formdiagram(tmp_path / "f.json", mesh, result, convention)
    document = json.loads((tmp_path / "f.json").read_text())
    assert document["dtype"] == "compas_tna.diagrams/FormDiagram"
    data = document["data"]
    assert data["vertex"]["4"]["pz"] == sign * result.loads[4]
    assert [data["edgedata"][str(tuple(e))]["q"] for e in result.edges.tolist()] == (
        sign * result.force_densities
    ).tolist()
    back = read_formdiagram(tmp_path / "f.json", convention)
    assert np.array_equal(back.vertices, result.positions)
    assert np.array_equal(back.anchored, mesh.anchored)
    assert np.array_equal(back.extra_loads, result.loads)
    assert np.all(back.face_density == 0)


def test_compas1_polygons_and_is_anchor(tmp_path):
    document = {
        "dva": {"x": 0.0, "y": 0.0, "z": 0.0, "pz": 0.0, "is_anchor": False},
        "vertex": {
            "10": {"x": 0, "y": 0, "is_anchor": True},
            "11": {"x": 1, "y": 0, "is_anchor": True},
            "12": {"x": 1, "y": 1, "is_anchor": True},
            "13": {"x": 0, "y": 1, "is_anchor": True},
            "14": {"x": 0.5, "y": 0.5, "z": 0.2},
            "15": {"x": 2, "y": 0.5, "is_anchor": True},
        },
        "face": {"0": [10, 11, 14], "1": [11, 15, 12, 14], "2": [12, 13, 14], "3": [13, 10, 14]},
    }
    (tmp_path / "old.json").write_text(json.dumps(document))
    mesh = read_formdiagram(tmp_path / "old.json")
    assert mesh.faces.tolist() == [[0, 1, 4], [1, 5, 2], [1, 2, 4], [2, 3, 4], [3, 0, 4]]
    assert mesh.anchored.tolist() == [0, 1, 2, 3, 5]
    assert np.all(mesh.face_density == 1)  # no pz: the library's own self-weight


@pytest.mark.parametrize(
    "change, message",
    [
        (lambda d: d["data"]["vertex"]["4"].update(px=0.5), "vertex 4 has a horizontal load `px`"),
        (lambda d: d["data"]["face"].update({"9": [0, 1, 77]}), "face 9 refers to vertex 77"),
        (lambda d: d["data"].pop("face"), "has no `vertex` and `face`"),
    ],
)
def test_bad_diagrams_are_refused(square, tmp_path, change, message):
    mesh, result = square
    write_formdiagram(tmp_path / "f.json", mesh, result)
    document = json.loads((tmp_path / "f.json").read_text())
    change(document)
    (tmp_path / "bad.json").write_text(json.dumps(document))
    with pytest.raises(voussoir.VoussoirError, match=message):
        read_formdiagram(tmp_path / "bad.json")
    with pytest.raises(voussoir.VoussoirError, match="'rv' is neither"):
        read_formdiagram(tmp_path / "f.json", "rv")
    with pytest.raises(voussoir.VoussoirError, match="cannot read"):
        read_formdiagram(tmp_path / "missing.json")
