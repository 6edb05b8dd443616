"""The Blender add-on (examples/blender/voussoir_formfind.py) in Blender as a Python module
(`bpy` from PyPI, installed by `.ci/hosts blender`, with the wheel in Blender's user
scripts/modules folder as docs/python.md installs it): every shared model is built as a mesh
object with its supports as the vertex group "anchored", the operator "Form-find selected
mesh" runs headless, and the new object's vertices must equal the Python API's positions
rounded to float32, bit for bit (Blender keeps coordinates in single precision, so the
reference is the API on the model's float32 coordinates, as Blender holds them).
"""

from __future__ import annotations

import importlib.util
import json
import os

import numpy as np
import pytest

from conftest import MODEL_NAMES, REPO, host_missing, read_obj

try:
    import bpy

    # What Blender does at start: put the user's scripts/modules folder on sys.path.
    bpy.utils.refresh_script_paths()
    import voussoir
except ImportError as e:
    bpy = voussoir = None
    MISSING = f"cannot import bpy and voussoir: {e}"

ADDON = REPO / "examples" / "blender" / "voussoir_formfind.py"


def test_the_wheel_is_in_blenders_user_modules():
    if bpy is None:
        host_missing("blender", MISSING)
    modules = bpy.utils.user_resource("SCRIPTS", path="modules")
    assert os.path.commonpath([voussoir.__file__, modules]) == modules, voussoir.__file__


@pytest.fixture(scope="module")
def addon():
    if bpy is None:
        host_missing("blender", MISSING)
    spec = importlib.util.spec_from_file_location("voussoir_formfind", ADDON)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.register()
    yield module
    module.unregister()


def vault_object(models, name, group=True):
    """An empty scene with the model as the active, selected mesh object."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    vertices, faces = read_obj(models / f"{name}.obj")
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(vertices.tolist(), [], faces.tolist())
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    if group:
        anchored = json.loads((models / f"{name}.json").read_text())["anchored"]
        obj.vertex_groups.new(name="anchored").add(anchored, 1.0, "REPLACE")
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    return obj


def coordinates(obj):
    co = np.empty(3 * len(obj.data.vertices), dtype=np.float32)
    obj.data.vertices.foreach_get("co", co)
    return co.reshape(-1, 3).astype(np.float64)


def float32_points(points):
    return points.astype(np.float32).astype(np.float64)


def test_operator_defaults_are_the_library_defaults(addon):
    module = addon
    operator = module.VOUSSOIR_OT_form_find
    defaults = voussoir.defaults()
    names = ("method", "fairness", "max_height_change", "tolerance", "max_iterations")
    for key in names:
        assert defaults[key] == operator.__annotations__[key].keywords["default"], key


@pytest.mark.parametrize("name", MODEL_NAMES)
def test_operator_equals_the_python_api(name, addon, models):
    source = vault_object(models, name)
    assert bpy.ops.object.voussoir_form_find() == {"FINISHED"}
    found = bpy.context.active_object
    assert found.name == f"{name}_selfsupporting" and found is not source

    vertices, faces = read_obj(models / f"{name}.obj")
    anchored = json.loads((models / f"{name}.json").read_text())["anchored"]
    expected = voussoir.form_find(voussoir.Mesh(float32_points(vertices), faces, anchored))
    assert np.array_equal(coordinates(source), float32_points(vertices))
    assert np.array_equal(coordinates(found), float32_points(expected.positions))
    assert [tuple(p.vertices) for p in found.data.polygons] == [tuple(f) for f in faces]
    assert found["voussoir_termination"] == expected.termination


def test_operator_settings_and_lowest_vertices(addon, models):
    module = addon
    vault_object(models, "dome_with_doors", group=False)
    bpy.context.active_object.location = (10.0, -4.0, 2.0)  # world coordinates are solved
    bpy.context.view_layer.update()
    result = bpy.ops.object.voussoir_form_find(fairness=0.1, max_iterations=60, method="paper")
    assert result == {"FINISHED"}
    found = bpy.context.active_object

    vertices, faces = read_obj(models / "dome_with_doors.obj")
    world = float32_points(vertices) + [10.0, -4.0, 2.0]
    lowest = module.anchored_vertices(found, world, "", module.ANCHOR_TOLERANCE)
    expected = voussoir.form_find(
        voussoir.Mesh(world, faces, lowest), fairness=0.1, max_iterations=60, method="paper"
    )
    local = expected.positions - [10.0, -4.0, 2.0]
    assert np.array_equal(coordinates(found), float32_points(local))
    assert tuple(found.location) == (10.0, -4.0, 2.0)


def test_operator_reports_bad_input(addon, models):
    obj = vault_object(models, "neumunster", group=False)
    obj.vertex_groups.new(name="anchored")  # an empty supports group
    with pytest.raises(RuntimeError, match="Voussoir: .*anchored"):
        bpy.ops.object.voussoir_form_find()
    assert [o.name for o in bpy.data.objects] == ["neumunster"]
