"""The C hostile-input table (tests/c/hostile.c) in Python: every case that Python can express
raises VoussoirError with the C API's message, the argument named as the Python signature names
it (C `positions`/`triangles` are `vertices`/`faces`; a setter's value is its keyword).

C cases without a Python form: NULL `out` pointers, NULL handles to setters and to
`_destroy` (there are no handles), lengths past the address space (numpy arrays carry their own
length), short copy-out buffers (results are whole arrays), getters a result kind lacks (an
analysis result has no `history` attribute at all) and status names (there are no statuses).
"""

from __future__ import annotations

import math
import os
import re
import stat

import numpy as np
import pytest

import voussoir
from conftest import SQUARE_ANCHORED, SQUARE_FACES, SQUARE_POSITIONS

V, F, A = SQUARE_POSITIONS, SQUARE_FACES, SQUARE_ANCHORED


def raises(message, call, *args, **kwargs):
    with pytest.raises(voussoir.VoussoirError) as caught:
        call(*args, **kwargs)
    assert str(caught.value) == message
    assert "\n" not in str(caught.value)
    return caught.value


def mesh(**loads):
    return voussoir.Mesh(V, F, A, **loads)


def test_none_in_each_slot_of_mesh():
    raises("argument `vertices` is None", voussoir.Mesh, None, F, A)
    raises("argument `faces` is None", voussoir.Mesh, V, None, A)
    raises("argument `anchored` is None", voussoir.Mesh, V, F, None)


def test_empty_mesh():
    raises(
        "argument `vertices`: empty mesh: it needs at least one vertex and one face",
        voussoir.Mesh,
        np.zeros((0, 3)),
        F,
        A,
    )
    raises(
        "argument `faces`: empty mesh: it needs at least one vertex and one face",
        voussoir.Mesh,
        V,
        np.zeros((0, 3), dtype=np.int64),
        A,
    )


def test_ragged_faces_and_wrong_types_name_the_argument():
    ragged = [list(f) for f in F]
    ragged[1] = ragged[1][:2]
    with pytest.raises(voussoir.VoussoirError, match=r"^argument `faces`: is not an array of integer ids"):
        voussoir.Mesh(V, ragged, A)
    raises("argument `up`: None is not a string", voussoir.Mesh.from_file, "any.obj", up=None)
    raises("argument `path`: 5 is not a path", voussoir.Mesh.from_file, 5)
    raises("argument `supports`: 5 is not a path", voussoir.Mesh.from_file, "any.obj", 5)
    raises(
        "argument `weld_tolerance`: 'fine' is not a number",
        voussoir.Mesh.from_file,
        "any.obj",
        weld_tolerance="fine",
    )


def test_out_of_range_ids_and_nan_coordinates():
    bad = [list(f) for f in F]
    bad[1][2] = 5
    raises(
        "argument `faces`: face 1 refers to vertex 5, but there are only 5 vertices",
        voussoir.Mesh,
        V,
        bad,
        A,
    )
    raises(
        "argument `anchored`: anchored vertex 99: out of range", voussoir.Mesh, V, F, [0, 1, 2, 99]
    )
    nan = np.array(V, dtype=float)
    nan[4, 1] = math.nan
    raises("argument `vertices`: vertex 4 has a NaN or infinite coordinate", voussoir.Mesh, nan, F, A)
    raises(
        "argument `anchored`: no vertex is anchored: a vault needs supports",
        voussoir.Mesh,
        V,
        F,
        [],
    )


def test_python_only_shapes_and_id_types():
    raises("argument `vertices`: has shape (5, 2), expected (n, 3)", voussoir.Mesh, np.zeros((5, 2)), F, A)
    raises("argument `faces`: holds float64 values, expected integer ids", voussoir.Mesh, V, np.array(F, float), A)
    raises(
        "argument `anchored`: entry 0 is -1, not a vertex id (0 to 4294967295)",
        voussoir.Mesh,
        V,
        F,
        [-1],
    )
    negative = [list(f) for f in F]
    negative[1][2] = -1
    raises(
        "argument `faces`: face 1, corner 2 is -1, not a vertex id (0 to 4294967295)",
        voussoir.Mesh,
        V,
        negative,
        A,
    )


def test_stacked_plan_overlaps():
    stacked = np.array(V + [[x + 0.5, y + 0.5, z + 1.0] for x, y, z in V])
    faces = F + [[a + 5, b + 5, c + 5] for a, b, c in F]
    error = pytest.raises(voussoir.VoussoirError, voussoir.Mesh, stacked, faces, [0, 1, 2, 3, 5, 6, 7, 8])
    message = str(error.value)
    assert message.startswith("argument `vertices`: the plan overlaps itself"), message


def test_coordinates_too_large_for_double_areas():
    raises(
        "argument `vertices`: vertex 1 has the coordinate 1e200: "
        "beyond ±1e150, areas and loads cannot be represented in double precision (express the "
        "model in larger units)",
        voussoir.Mesh,
        np.array(V) * 1e200,
        F,
        A,
    )


SETTER_CASES = [
    ({"tolerance": math.nan}, "argument `tolerance`: NaN is not finite"),
    ({"tolerance": -1.0}, "argument `tolerance`: -1 must be > 0"),
    ({"q_min": -0.5, "q_min_kind": "absolute"}, "argument `q_min`: -0.5 must be >= 0"),
    (
        {"q_min": 0.1, "q_min_kind": "sideways"},
        "argument `q_min_kind`: 'sideways' is not one of 'relative', 'absolute'",
    ),
    ({"q_max": math.nan}, "argument `q_max`: NaN is not finite"),
    ({"tau": "sideways"}, "argument `tau`: 'sideways' is not one of 'optimized', 'zero', 'prescribed'"),
    ({"holes": "sideways"}, "argument `holes`: 'sideways' is not one of 'affine', 'constant'"),
    (
        {"load_rule": "sideways"},
        "argument `load_rule`: 'sideways' is not one of 'barycentric', 'voronoi', 'plan_area'",
    ),
    (
        {"formulation": "sideways"},
        "argument `formulation`: 'sideways' is not one of 'reduced', 'edge_based'",
    ),
    ({"q_min_scope": "sideways"}, "argument `q_min_scope`: 'sideways' is not one of 'all', 'interior'"),
    ({"max_iterations": 0}, "argument `max_iterations`: must be >= 1"),
    ({"schedule_beta": 2.0}, "argument `schedule_beta`: 2 must be <= 1"),
    ({"method": 1}, "argument `method`: 1 is not a string"),
    ({"fairness": "much"}, "argument `fairness`: is not a number"),
    ({"smoothing_decay": 1.0}, "argument `smoothing_decay`: 1 must be < 1"),
    ({"dual_length_bounds": (2.0, 1.0)}, "argument `dual_length_bounds`: 1 must be > lo (2)"),
    ({"q_min": 2.0, "q_max": 1.0}, "argument `q_max`: must be >= q_min"),
    ({"frobnicate": 1}, "argument `frobnicate`: is not a setting (see voussoir.defaults())"),
    # Checked by the library's FormFindSettings::validate, as the C setters are.
    ({"max_height_change": math.inf}, "argument `max_height_change`: inf is not finite"),
    ({"schedule_eta": 0.0}, "argument `schedule_eta`: 0 must be > 0"),
    ({"stall_window": 0}, "argument `stall_window`: must be >= 1"),
    ({"max_iterations": -1}, "argument `max_iterations`: -1 is negative"),
    ({"dual_length_bounds": (-1.0, 2.0)}, "argument `dual_length_bounds`: -1 must be >= 0"),
]


@pytest.mark.parametrize("settings,message", SETTER_CASES, ids=lambda c: str(c)[:40])
def test_bad_settings(settings, message):
    raises(message, voussoir.analyse, mesh(), **settings)
    raises(message, voussoir.form_find, mesh(), **settings)


def test_bad_loads():
    raises(
        "argument `face_density`: face 2 has -1 (must be finite and >= 0)",
        mesh,
        face_density=[1, 1, -1, 1],
    )
    raises(
        "argument `face_density`: has 3 rows, expected 4 (one row per face)",
        mesh,
        face_density=[1, 1, 1],
    )
    raises("argument `extra_loads`: entry 4 (row 4) is NaN", mesh, extra_loads=[0, 0, 0, 0, math.nan])
    raises(
        "argument `horizontal_forces`: has shape (5,), expected (n, 2)",
        mesh,
        horizontal_forces=[0, 0, 0, 0, 0],
    )
    raises(
        "argument `horizontal_forces`: vertex 4 is not a free boundary vertex",
        mesh,
        horizontal_forces=[[0, 0]] * 4 + [[1, 0]],
    )


def test_bad_polygon_diagonals():
    raises(
        "argument `polygon_diagonals`: pair 0 (0, 1) is not an interior edge of the mesh",
        mesh,
        polygon_diagonals=[[0, 1]],
    )
    raises(
        "argument `polygon_diagonals`: pair 1 has vertex 9, but there are only 5 vertices",
        mesh,
        polygon_diagonals=[[0, 4], [4, 9]],
    )
    raises("argument `polygon_diagonals`: has shape (3,), expected (n, 2)", mesh, polygon_diagonals=[0, 4, 2])
    assert mesh(polygon_diagonals=[]).polygon_diagonals.shape == (0, 2)


def test_zero_density_is_nothing_to_balance():
    zero = mesh(face_density=[0, 0, 0, 0])
    for solve in (voussoir.analyse, voussoir.form_find):
        with pytest.raises(voussoir.VoussoirError) as caught:
            solve(zero)
        message = str(caught.value)
        assert message.startswith("argument `loads`: "), message
        assert "invalid argument" not in message, message
    voussoir.analyse(mesh())  # the same input with weight solves


def test_not_a_mesh():
    raises("argument `mesh`: is a list, not a voussoir.Mesh", voussoir.analyse, [V, F, A])
    raises("argument `mesh`: is a NoneType, not a voussoir.Mesh", voussoir.form_find, None)


def test_a_valid_mesh_after_failures_solves_and_keeps_its_positions():
    for bad in ({"tolerance": -1.0}, {"tau": "sideways"}):
        with pytest.raises(voussoir.VoussoirError):
            voussoir.analyse(mesh(), **bad)
    result = voussoir.analyse(mesh())
    assert result.status == "solved"
    assert np.array_equal(result.positions, np.array(V, dtype=float))
    assert result.positions[4, 2] == 0.3


def test_bad_progress():
    raises("argument `progress`: is not callable", voussoir.form_find, mesh(), progress=3)


BAD_OFF = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"
GOOD_OFF = (
    "OFF\n5 4 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 0.3\n3 0 1 4\n3 1 2 4\n3 2 3 4\n3 3 0 4\n"
)


def test_mesh_files(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "bad.off").write_text(BAD_OFF)
    (tmp_path / "short.stl").write_bytes(bytes(90))
    (tmp_path / "good.off").write_text(GOOD_OFF)
    read = voussoir.Mesh.from_file
    raises("argument `path` is None", read, None, anchored=A)
    raises(
        "argument `path`: missing.obj: No such file or directory (os error 2)",
        read,
        "missing.obj",
        anchored=A,
    )
    raises(
        "argument `path`: good.xyz: unknown extension `.xyz`; "
        "the mesh formats are .obj, .off, .stl and .ply (and .3mf, written only)",
        read,
        "good.xyz",
        anchored=A,
    )
    raises(
        "argument `path`: bad.off:6: face 0 refers to vertex 7, but the file has only 3 vertices",
        read,
        "bad.off",
        anchored=[0, 1, 2],
    )
    raises(
        "argument `path`: short.stl: header: binary STL declaring 0 triangles has 84 bytes, "
        "this file has 90 bytes",
        read,
        "short.stl",
        anchored=A,
    )
    raises(
        "argument `supports`: missing.json: No such file or directory (os error 2)",
        read,
        "good.off",
        "missing.json",
    )
    raises(
        "argument `weld_tolerance`: NaN is not a finite number >= 0",
        read,
        "good.off",
        anchored=A,
        weld_tolerance=math.nan,
    )
    raises(
        "argument `repair_tolerance`: -1 is not a finite number >= 0",
        read,
        "good.off",
        anchored=A,
        repair_tolerance=-1.0,
    )
    (tmp_path / "supports.json").write_text('{"anchored": [0, 1, 2, 3]}')
    raises(
        "argument `anchored`: give either `supports` or `anchored`, not both",
        read,
        "good.off",
        "supports.json",
        anchored=A,
    )
    good = read("good.off", "supports.json")
    raises("argument `path` is None", good.write, None)
    raises("argument `positions`: has shape (4, 3), expected (5, 3)", good.write, "x.off", np.zeros((4, 3)))
    message = str(pytest.raises(voussoir.VoussoirError, good.write, "no_such_dir/out.off").value)
    assert re.match(r"argument `path`: .*no_such_dir", message), message
    assert not (tmp_path / "no_such_dir").exists()
    good.write("out.off")
    assert (tmp_path / "out.off").is_file()


HUGE_COUNT_PLY = (
    "ply\nformat ascii 1.0\nelement vertex 99999999999999999999999\nproperty float x\n"
    "property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\n"
    "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"
)


def test_issue_48_files_and_outputs(tmp_path, monkeypatch):
    # A PLY count beyond 64 bits raised PanicException (which `except Exception` misses); a
    # face line with more indices than its count lost one; outputs replaced links and FIFOs.
    monkeypatch.chdir(tmp_path)
    read = voussoir.Mesh.from_file
    (tmp_path / "huge.ply").write_text(HUGE_COUNT_PLY)
    raises(
        "argument `path`: huge.ply:3: bad header: element `vertex`: count "
        "`99999999999999999999999` is larger than 18446744073709551615, more than any file holds",
        read,
        "huge.ply",
        anchored=[0, 1],
    )
    long_face = HUGE_COUNT_PLY.replace("99999999999999999999999", "3").replace("3 0 1 2", "3 0 1 2 0")
    (tmp_path / "long.ply").write_text(long_face)
    raises(
        "argument `path`: long.ply:13: face 0: 1 more number than its properties take, in "
        "`3 0 1 2 0` (one face per line, a list with as many items as its count)",
        read,
        "long.ply",
        anchored=[0, 1],
    )
    (tmp_path / "good.off").write_text(GOOD_OFF)
    good = read("good.off", anchored=A)
    (tmp_path / "real.off").write_text("old")
    os.symlink("real.off", tmp_path / "link.off")
    good.write("link.off")
    assert (tmp_path / "link.off").is_symlink()
    assert (tmp_path / "real.off").read_text().startswith("OFF")
    os.mkfifo(tmp_path / "fifo.off")
    raises(
        "argument `path`: fifo.off: is a FIFO (named pipe), not a regular file: outputs replace "
        "regular files only",
        good.write,
        "fifo.off",
    )
    assert stat.S_ISFIFO(os.stat(tmp_path / "fifo.off").st_mode)
    # "1 holes" in the summary.
    ring = [[0, 0, 0], [3, 0, 0], [3, 3, 0], [0, 3, 0], [1, 1, 1], [2, 1, 1], [2, 2, 1], [1, 2, 1]]
    faces = [f for k in range(4) for f in ([k, (k + 1) % 4, 4 + (k + 1) % 4],
                                            [k, 4 + (k + 1) % 4, 4 + k])]
    assert repr(voussoir.Mesh(ring, faces, [0, 1, 2, 3])) == (
        "Mesh(8 vertices, 8 faces, 4 anchored, 1 hole)"
    )

