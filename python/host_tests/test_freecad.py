"""The FreeCAD macro (examples/python/freecad_macro.py) inside a real FreeCAD: `freecadcmd`
with the wheel in its Mod folder ($VSR_FREECAD_HOME/.local/share/FreeCAD/Mod/voussoir, as
docs/python.md installs it) runs freecad_driver.py: every shared model read by FreeCAD into a
Mesh object, the macro's entry point, the document saved and reopened.

FreeCAD keeps mesh points in single precision, so the reference is the Python API (this venv's
wheel) on the model's points rounded to float32, as FreeCAD holds them; the new Mesh object's
points must equal its positions rounded to float32, bit for bit, before and after the reload.
"""

from __future__ import annotations

import json
import os
import subprocess

import numpy as np
import pytest

import voussoir
from conftest import MODEL_NAMES, REPO, host_missing, host_program, read_obj

MACRO = REPO / "examples" / "python" / "freecad_macro.py"
DRIVER = REPO / "python" / "host_tests" / "freecad_driver.py"
SETTINGS = {"fairness": 0.1, "max_iterations": 60}
# The macro as a user runs it: default settings, supports at the lowest vertices.
MACRO_MODEL = "dome_with_doors"


def as_freecad_reads(models, name):
    """The model as FreeCAD reads it: vertices no face uses dropped (hex has two), the others
    in the file's order; with the faces and the supports renumbered so."""
    vertices, faces = read_obj(models / f"{name}.obj")
    anchored = json.loads((models / f"{name}.json").read_text())["anchored"]
    used = np.unique(faces)
    new_id = np.full(len(vertices), -1)
    new_id[used] = np.arange(len(used))
    anchored = [int(new_id[a]) for a in anchored if new_id[a] >= 0]
    return vertices[used], new_id[faces], anchored


def jobs(models, tmp):
    """One job per shared model (its supports, SETTINGS) and the macro's own run."""
    listed = []
    for name in MODEL_NAMES:
        anchored = as_freecad_reads(models, name)[2]
        listed.append(
            {
                "name": name,
                "entry": "form_find_object",
                "model": str(models / f"{name}.obj"),
                "anchored": anchored,
                "settings": SETTINGS,
            }
        )
    listed.append(
        {
            "name": "macro",
            "entry": "run_in_freecad",
            "model": str(models / f"{MACRO_MODEL}.obj"),
            "anchored": None,
            "settings": {},
        }
    )
    for job in listed:
        job["document"] = f"voussoir_{job['name']}"
        job["fcstd"] = str(tmp / f"{job['name']}.FCStd")
        job["out"] = str(tmp / f"{job['name']}.npz")
    return listed


@pytest.fixture(scope="module")
def freecad_runs(models, tmp_path_factory):
    freecadcmd = host_program("freecad", "freecadcmd")
    home = os.environ.get("VSR_FREECAD_HOME")
    if not home or not os.path.isdir(os.path.join(home, ".local/share/FreeCAD/Mod/voussoir")):
        host_missing("freecad", "VSR_FREECAD_HOME has no .local/share/FreeCAD/Mod/voussoir")
    tmp = tmp_path_factory.mktemp("freecad")
    listed = jobs(models, tmp)
    (tmp / "jobs.json").write_text(json.dumps(listed))
    env = dict(
        os.environ,
        HOME=home,
        VSR_MACRO=str(MACRO),
        VSR_FREECAD_JOBS=str(tmp / "jobs.json"),
        VSR_FREECAD_DONE=str(tmp / "done"),
    )
    # The venv's variables would point FreeCAD's Python at this venv's packages.
    for key in ("VIRTUAL_ENV", "PYTHONPATH", "PYTHONHOME"):
        env.pop(key, None)
    run = subprocess.run(
        [freecadcmd, str(DRIVER)], env=env, capture_output=True, text=True, errors="replace"
    )
    assert run.returncode == 0 and (tmp / "done").is_file(), (
        f"freecadcmd exited {run.returncode}:\n{run.stdout[-3000:]}\n{run.stderr[-3000:]}"
    )
    return {job["name"]: dict(np.load(job["out"])) for job in listed}


def float32_points(vertices):
    return vertices.astype(np.float32).astype(np.float64)


def reference(models, name, anchored, settings):
    """The Python API on the model as FreeCAD holds it (float32 points, as_freecad_reads)."""
    vertices, faces, _ = as_freecad_reads(models, name)
    mesh = voussoir.Mesh(float32_points(vertices), faces, anchored)
    return mesh, voussoir.form_find(mesh, **settings)


@pytest.mark.parametrize("name", MODEL_NAMES)
def test_macro_entry_point_equals_the_python_api(name, models, freecad_runs):
    run = freecad_runs[name]
    vertices, faces, anchored = as_freecad_reads(models, name)
    assert np.array_equal(run["source_points"], float32_points(vertices))
    assert np.array_equal(run["source_facets"], faces)

    _, result = reference(models, name, anchored, SETTINGS)
    assert np.array_equal(run["found_facets"], faces)
    assert np.array_equal(run["found_points"], float32_points(result.positions))
    assert str(run["summary"]).startswith(result.termination_message)
    # The anchored vertices stay; the shape moved.
    assert np.array_equal(run["found_points"][anchored], run["source_points"][anchored])
    assert not np.array_equal(run["found_points"], run["source_points"])


@pytest.mark.parametrize("name", MODEL_NAMES)
def test_document_saves_and_reloads(name, freecad_runs):
    run = freecad_runs[name]
    assert list(run["labels"]) == ["Vault", "Vault_selfsupporting"]
    assert np.array_equal(run["reloaded_points"], run["found_points"])
    assert np.array_equal(run["reloaded_facets"], run["found_facets"])


def test_macro_without_gui_takes_the_first_mesh_and_its_lowest_vertices(models, freecad_runs):
    macro = voussoir_macro()
    run = freecad_runs["macro"]
    points = run["source_points"]
    anchored = macro.lowest_vertices(points, macro.ANCHOR_TOLERANCE)
    assert 0 < len(anchored) < len(points)
    _, result = reference(models, MACRO_MODEL, anchored, {})
    assert result.termination == "converged"
    assert np.array_equal(run["found_points"], float32_points(result.positions))
    assert np.array_equal(run["reloaded_points"], run["found_points"])


def voussoir_macro():
    import importlib.util

    spec = importlib.util.spec_from_file_location("freecad_macro", MACRO)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
