"""Masonry assessment from Python: `voussoir.assess` equals the Rust API (the formfind example's
`--assess`, whose OBJ and JSON keep every bit) bit for bit, its certificate holds when
recomputed from the result's arrays, bad input raises VoussoirError naming the argument, and
`python -m voussoir --assess` writes the same as formfind."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import voussoir


def dome(rings: int = 3, segments: int = 12, angle: float = math.radians(60), dz: float = 0.0,
         scale: float = 1.0):
    """A spherical cap over the unit disk (the C ABI tests' dome): a centre vertex and
    `rings` rings of `segments` vertices, odd rings turned by half a step; the outer ring is
    the boundary."""
    sphere = 1.0 / math.sin(angle)
    height = lambda r: math.sqrt(sphere * sphere - r * r) - sphere * math.cos(angle)  # noqa: E731
    points = [(0.0, 0.0, height(0.0))]
    for k in range(1, rings + 1):
        r = k / rings
        for m in range(segments):
            a = 2 * math.pi * (m + 0.5 * (k % 2)) / segments
            points.append((r * math.cos(a), r * math.sin(a), height(r)))
    ring = lambda k, m: 1 + (k - 1) * segments + m % segments  # noqa: E731
    faces = [(0, ring(1, m), ring(1, m + 1)) for m in range(segments)]
    for k in range(1, rings):
        for m in range(segments):
            a0, a1, b0, b1 = ring(k, m), ring(k, m + 1), ring(k + 1, m), ring(k + 1, m + 1)
            faces += [(b0, b1, a0), (a0, b1, a1)] if k % 2 == 1 else [(a0, b0, a1), (a1, b0, b1)]
    v = np.array(points) * [scale, scale, 1.0] + [0, 0, dz]
    f = np.array(faces, dtype=np.int64)
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    area = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    clockwise = area < 0
    f[clockwise] = f[clockwise][:, [0, 2, 1]]
    rim = list(range(1 + (rings - 1) * segments, 1 + rings * segments))
    return v, f, rim


def dented_dome():
    """The dome with its crown lowered by 0.03: the cap itself balances as it stands (its
    least thickness is 0), the dented one does not."""
    v, f, rim = dome()
    v[0, 2] -= 0.03
    return v, f, rim


def write_obj(path, vertices, faces):
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in vertices.tolist()]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in faces.tolist()]
    path.write_text("\n".join(lines) + "\n")


def read_obj_vertices(path):
    rows = [line.split()[1:4] for line in path.read_text().splitlines() if line.startswith("v ")]
    return np.array(rows, dtype=np.float64)


def check_certificate(r: voussoir.AssessmentResult, anchored):
    """Equilibrium, compression and bounds recomputed from the result's arrays."""
    assert r.feasible
    n = len(r.positions)
    free = np.ones(n, bool)
    free[anchored] = False
    i, j = r.edges[:, 0].astype(int), r.edges[:, 1].astype(int)
    q = r.force_densities
    assert (q >= 0).all()
    dz = r.positions[i, 2] - r.positions[j, 2]
    vertical = -r.loads.copy()
    np.add.at(vertical, i, q * dz)
    np.add.at(vertical, j, -q * dz)
    mean = r.loads[free].mean()
    assert np.abs(vertical[free]).max() < 1e-6 * mean
    d = r.positions[i, :2] - r.positions[j, :2]
    horizontal = np.zeros((n, 2))
    np.add.at(horizontal, i, q[:, None] * d)
    np.add.at(horizontal, j, -q[:, None] * d)
    assert np.abs(horizontal[free]).max() < 1e-9 * mean
    z = r.positions[:, 2]
    assert (z >= r.lower - 1e-9).all() and (z <= r.upper + 1e-9).all()
    check_joints(r, q, i, j, mean)


def check_joints(r: voussoir.AssessmentResult, q, i, j, mean):
    """Each joint's reaction line, recomputed from heights, forces and loads, meets its
    springing plane within the reach."""
    a = r.joint_vertices.astype(int)
    assert r.joints.shape == (len(a), 9)
    springing, reach, h, v_given, offset = (r.joints[:, 0], r.joints[:, 1], r.joints[:, 2:4],
                                            r.joints[:, 4], r.joints[:, 8])
    assert np.allclose(h, r.reactions[a], rtol=1e-9, atol=1e-12 * mean)
    dz = r.positions[j, 2] - r.positions[i, 2]
    vertical = r.loads.copy()
    np.add.at(vertical, i, q * dz)
    np.add.at(vertical, j, -q * dz)
    v = vertical[a]
    assert np.allclose(v, v_given, rtol=1e-9, atol=1e-12 * mean)
    z = r.positions[a, 2]
    assert (z >= springing - 1e-9).all()
    recomputed = (z - springing) * np.hypot(h[:, 0], h[:, 1]) / v
    assert np.allclose(offset, recomputed, rtol=1e-9, atol=1e-12)
    assert (recomputed <= reach * (1 + 1e-6 * mean / v) + 1e-12).all()
    assert r.worst_joint < 1e-6


@pytest.fixture
def files(tmp_path):
    v, f, rim = dented_dome()
    write_obj(tmp_path / "dome.obj", v, f)
    (tmp_path / "dome.json").write_text(json.dumps({"anchored": rim}))
    return tmp_path


@pytest.mark.parametrize(
    "objective, extra",
    [("fit", []), ("min-thickness", []), ("max-load", ["--load-pattern", "pattern.json"])],
)
def test_assess_equals_the_rust_api(objective, extra, files, formfind):
    pattern = np.zeros(37)
    pattern[0] = 1.0
    (files / "pattern.json").write_text(json.dumps({"loads": pattern.tolist()}))
    args = [formfind, "dome.obj", "--supports", "dome.json", "--assess", objective,
            "--thickness", "0.1", "--unit-weight", "2", "--out", "out.obj",
            "--report", "report.json", *extra]
    rust = subprocess.run(args, cwd=files, capture_output=True, text=True)
    assert rust.returncode in (0, 3), rust.stderr
    report = json.loads((files / "report.json").read_text())
    a = report["assessment"]

    mesh = voussoir.Mesh.from_file(files / "dome.obj", files / "dome.json")
    load = pattern if objective == "max-load" else None
    r = voussoir.assess(mesh, 0.1, objective=objective, unit_weight=2.0, load_pattern=load)

    assert np.array_equal(r.positions, read_obj_vertices(files / "out.obj"))
    assert np.array_equal(r.force_densities, np.array(report["force_densities"]))
    assert np.array_equal(r.loads, np.array(report["loads"]))
    assert np.array_equal(r.lower, np.array(a["bounds"]["lower"]))
    assert np.array_equal(r.upper, np.array(a["bounds"]["upper"]))
    assert np.array_equal(r.envelope_lower, np.array(a["envelope"]["lower"]))
    for key in ("feasible", "termination", "iterations", "thickness_scale", "safety_factor",
                "thrust_horizontal", "load_factor", "unbounded", "eps_inf", "thickness_min"):
        assert getattr(r, key) == a[key], key
    check_certificate(r, mesh.anchored)
    assert len(r.joint_vertices) == len(mesh.anchored) > 0
    assert np.array_equal(r.joint_vertices, [k["vertex"] for k in a["joints"]])
    assert np.array_equal(r.joints[:, 8], [k["offset"] for k in a["joints"]])
    if objective == "min-thickness":
        assert 0 < r.thickness_scale < 1 and r.thickness_min == r.thickness_scale * 0.1
    if objective == "max-load":
        assert r.load_factor > 0


def test_a_thick_shallow_cap_has_no_greatest_thrust():
    """A cap 0.09 high in a shell 0.4 thick holds ever flatter surfaces: its greatest thrust
    is unbounded, and the returned force densities scaled by 10 and 1000 (heights from the
    same supports, recomputed here) still fit; a steeper, thinner dome's thrust is bounded."""
    v, f, rim = dome(angle=math.radians(10))
    mesh = voussoir.Mesh(v, f, rim)
    r = voussoir.assess(mesh, 0.4, objective="max-thrust")
    assert r.feasible and r.converged and r.unbounded
    check_certificate(r, mesh.anchored)
    n = len(v)
    free = [i for i in range(n) if i not in set(rim)]
    row = {vtx: k for k, vtx in enumerate(free)}
    laplacian = np.zeros((len(free), len(free)))
    held = np.zeros(len(free))
    for (i, j), q in zip(r.edges.tolist(), r.force_densities):
        for a, b in ((i, j), (j, i)):
            if a in row:
                laplacian[row[a], row[a]] += q
                if b in row:
                    laplacian[row[a], row[b]] -= q
                else:
                    held[row[a]] += q * r.positions[b, 2]
    unloaded = np.linalg.solve(laplacian, held)
    loaded = np.linalg.solve(laplacian, r.loads[free])
    for s in (10.0, 1000.0):
        z = unloaded + loaded / s
        slack = 1e-9 * 2.0
        assert np.all(z >= r.lower[free] - slack) and np.all(z <= r.upper[free] + slack), s
    bounded = voussoir.assess(mesh, 0.02, objective="max-thrust")
    assert not bounded.unbounded


def test_surfaces_and_per_face_thickness():
    v, f, rim = dome()
    mesh = voussoir.Mesh(v, f, rim)
    lo, lo_faces, _ = dome(6, 24, dz=-0.05, scale=1.05)
    hi, hi_faces, _ = dome(6, 24, dz=0.05, scale=1.05)
    r = voussoir.assess(mesh, intrados=(lo, lo_faces), extrados=(hi, hi_faces))
    check_certificate(r, rim)
    assert r.thickness_min is None
    assert np.allclose(r.envelope_upper - r.envelope_lower, 0.1, atol=1e-12, rtol=0)
    per_face = np.full(len(f), 0.1)
    uniform = voussoir.assess(mesh, 0.1)
    faces = voussoir.assess(mesh, per_face)
    assert faces.thickness_min is None and uniform.thickness_min == 0.1
    assert np.array_equal(uniform.positions, faces.positions)
    assert uniform.positions.shape == (37, 3) and uniform.edges.dtype == np.uint32
    assert uniform.reactions.shape == (37, 2) and uniform.face_thickness.shape == (len(f),)


def test_fixed_supports_and_settings():
    v, f, rim = dome()
    mesh = voussoir.Mesh(v, f, rim)
    free = voussoir.assess(mesh, 0.1, objective="min-thrust")
    fixed = voussoir.assess(mesh, 0.1, objective="max-thrust", fixed_supports=True)
    assert np.array_equal(fixed.positions[rim, 2], v[rim, 2])
    # From a thickness a free support stands on or above its springing plane, the middle
    # surface's height (docs/method.md §16.1): the least thrust keeps it there, the
    # greatest raises it within the springing joint.
    assert np.all(free.positions[rim, 2] >= v[rim, 2] - 1e-9)
    most = voussoir.assess(mesh, 0.1, objective="max-thrust")
    assert np.abs(most.positions[rim, 2] - v[rim, 2]).max() > 1e-3
    assert free.thrust_horizontal < most.thrust_horizontal
    few = voussoir.assess(mesh, 0.1, objective="min-thrust", max_iterations=2, load_rule="voronoi")
    assert few.iterations <= 2 + 30  # the limit, plus the polishing steps


@pytest.mark.parametrize(
    "kwargs, argument, detail",
    [
        ({"thickness": 0.0}, "thickness", "face 0"),
        ({"thickness": -1.0}, "thickness", "face 0"),
        ({"thickness": float("nan")}, "thickness", "not finite"),
        ({"thickness": [0.1, 0.2]}, "thickness", "one per face"),
        ({}, "thickness", "give the masonry's envelope"),
        ({"thickness": 0.1, "objective": "max"}, "objective", "'fit'"),
        ({"thickness": 0.1, "unit_weight": -1.0}, "unit_weight", ">= 0"),
        ({"thickness": 0.1, "tolerance": 2.0}, "tolerance", "2 must be < 1"),
        ({"thickness": 0.1, "max_iterations": 0}, "max_iterations", "must be >= 1"),
        ({"thickness": 0.1, "max_iterations": -1}, "max_iterations", "-1 is negative"),
        ({"thickness": 0.1, "q_min_kind": "sideways"}, "q_min_kind", "'relative', 'absolute'"),
        ({"thickness": 0.1, "load_rule": "area"}, "load_rule", "'plan_area'"),
        ({"thickness": 0.1, "q_min": -1.0}, "q_min", ">= 0"),
        ({"thickness": 0.1, "tau": "zero"}, "tau", "not an assessment setting"),
        ({"thickness": 0.1, "objective": "max-load"}, "load_pattern", "needs a load pattern"),
        ({"thickness": 0.1, "objective": "max-load", "load_pattern": [1.0, 2.0]},
         "load_pattern", "has 2 entries"),
        ({"thickness": 0.1, "progress": 3}, "progress", "not callable"),
    ],
)
def test_bad_input_names_the_argument(kwargs, argument, detail):
    v, f, rim = dome()
    mesh = voussoir.Mesh(v, f, rim)
    with pytest.raises(voussoir.VoussoirError) as e:
        voussoir.assess(mesh, **kwargs)
    message = str(e.value)
    assert f"argument `{argument}`" in message and detail in message, message
    assert "\n" not in message


BAD_SETTINGS = json.loads(
    (Path(__file__).resolve().parents[2] / "tests" / "assess_data" / "bad_settings.json").read_text()
)["cases"]


@pytest.mark.parametrize("case", BAD_SETTINGS, ids=lambda c: f"{c['setting']}={c['value']}")
def test_bad_settings_give_the_reason_of_the_rust_validation(case):
    """The cases tests/settings_validation.rs checks in Rust and through the C setters: the
    same reason, under the Python keyword."""
    value = case["value"]
    if isinstance(value, list):
        value = np.array([float(x) for x in value])
    elif isinstance(value, str):
        value = float(value)
    v, f, rim = dome()
    mesh = voussoir.Mesh(v, f, rim)
    with pytest.raises(voussoir.VoussoirError) as e:
        voussoir.assess(mesh, 0.1, **{case["setting"]: value})
    assert str(e.value) == f"argument `{case['python_argument']}`: {case['reason']}"


def test_bad_surfaces_name_the_vertex():
    v, f, rim = dome()
    mesh = voussoir.Mesh(v, f, rim)
    lo, lo_faces, _ = dome(6, 24, dz=-0.05, scale=1.05)
    hi, hi_faces, _ = dome(6, 24, dz=0.05, scale=1.05)
    small, small_faces, _ = dome(6, 24, dz=0.05, scale=0.5)
    cases = [
        (dict(intrados=(hi, hi_faces), extrados=(lo, lo_faces)), "intrados", "at vertex 0"),
        (dict(intrados=(lo, lo_faces), extrados=(small, small_faces)), "extrados",
         "does not cover vertex"),
        (dict(intrados=(lo, lo_faces)), "thickness", "give the masonry's envelope"),
        (dict(thickness=0.1, intrados=(lo, lo_faces), extrados=(hi, hi_faces)), "thickness",
         "not both"),
        (dict(intrados=(lo[:, :2], lo_faces), extrados=(hi, hi_faces)), "intrados",
         "expected (n, 3)"),
        (dict(intrados=(lo, lo_faces + 1000), extrados=(hi, hi_faces)), "intrados",
         "beyond its"),
        (dict(intrados=lo, extrados=(hi, hi_faces)), "intrados", "pair"),
        (dict(intrados=(np.where(np.arange(len(lo))[:, None] == 3, np.nan, lo), lo_faces),
              extrados=(hi, hi_faces)), "intrados", "vertex 3 has a coordinate that is not finite"),
    ]
    for kwargs, argument, detail in cases:
        with pytest.raises(voussoir.VoussoirError) as e:
            voussoir.assess(mesh, **kwargs)
        assert f"argument `{argument}`" in str(e.value) and detail in str(e.value), str(e.value)


def test_progress_sees_each_step_and_can_stop():
    v, f, rim = dome()
    mesh = voussoir.Mesh(v, f, rim)
    steps = []

    def stop_at_three(step, infeasibility):
        steps.append((step, infeasibility))
        return len(steps) < 3

    r = voussoir.assess(mesh, 0.1, objective="min-thrust", progress=stop_at_three)
    assert [s for s, _ in steps] == [1, 2, 3]
    # The callback sees the start's steps too (fit's search up to its first certified
    # surface), numbered with the main search's as one sequence: three steps in all.
    assert r.termination == "cancelled" and r.iterations == 3

    def fail(step, infeasibility):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        voussoir.assess(mesh, 0.1, progress=fail)


def test_the_command_line_assesses_as_formfind(files, formfind):
    rust = subprocess.run(
        [formfind, "dome.obj", "--supports", "dome.json", "--assess", "min-thickness",
         "--thickness", "0.1", "--fixed-supports", "--out", "rust.obj", "--report", "rust.json"],
        cwd=files, capture_output=True, text=True,
    )
    assert rust.returncode == 0, rust.stderr
    python = subprocess.run(
        [sys.executable, "-m", "voussoir", "dome.obj", "--supports", "dome.json",
         "--assess", "min-thickness", "--thickness", "0.1", "--fixed-supports",
         "--out", "py.obj", "--report", "py.json"],
        cwd=files, capture_output=True, text=True,
    )
    assert python.returncode == 0, python.stderr
    py, rust_obj = read_obj_vertices(files / "py.obj"), read_obj_vertices(files / "rust.obj")
    assert np.array_equal(py, rust_obj)
    a, b = (json.loads((files / f"{n}.json").read_text())["assessment"] for n in ("py", "rust"))
    for key in ("objective", "feasible", "termination", "thickness_min", "thickness_scale",
                "safety_factor", "thrust_horizontal", "load_factor", "eps_inf", "bounds"):
        assert a[key] == b[key], key
    bad = subprocess.run(
        [sys.executable, "-m", "voussoir", "dome.obj", "--supports", "dome.json",
         "--assess", "fit", "--thickness", "0", "--out", "bad.obj"],
        cwd=files, capture_output=True, text=True,
    )
    assert bad.returncode == 2 and "--thickness" in bad.stderr
    assert not (files / "bad.obj").exists()


@pytest.mark.parametrize("extra, message", [
    (["--thickness", "0.1", "--unit-weight", "-1"], "-1 must be >= 0"),
    (["--thickness", "density", "--unit-weight", "0"],
     "--unit-weight: 0 must be > 0 with --thickness density"),
])
def test_both_command_lines_take_the_unit_weight_range_from_the_library(files, formfind, extra,
                                                                        message):
    """--unit-weight is checked by the library (>= 0: 0 means no self-weight), and only the
    density thickness, which divides by it, asks for more."""
    for command in ([formfind], [sys.executable, "-m", "voussoir"]):
        run = subprocess.run(
            [*command, "dome.obj", "--supports", "dome.json", "--assess", "fit", *extra,
             "--out", "bad.obj"],
            cwd=files, capture_output=True, text=True,
        )
        assert run.returncode == 2 and message in run.stderr, (command, run.stderr)
        assert not (files / "bad.obj").exists()


@pytest.mark.parametrize("extra, message", [
    (["--reach", "-1"], "has -1, not a number >= 0"),
    (["--reach", "nan"], "--reach: expected a length or `inf`"),
    (["--springing", "5"], "has 5: it must be finite and at most the upper bound"),
    (["--reach", "inf", "--fixed-supports"],
     "--reach sets the joint of free supports: it does not go with --fixed-supports"),
])
def test_both_command_lines_check_the_springing_joint_alike(files, formfind, extra, message):
    """--springing and --reach are checked by the library (`Envelope::with_springing`)."""
    for command in ([formfind], [sys.executable, "-m", "voussoir"]):
        run = subprocess.run(
            [*command, "dome.obj", "--supports", "dome.json", "--assess", "min-thrust",
             "--thickness", "0.1", *extra, "--out", "bad.obj"],
            cwd=files, capture_output=True, text=True,
        )
        assert run.returncode == 2 and message in run.stderr, (command, run.stderr)
        assert not (files / "bad.obj").exists()


@pytest.mark.parametrize("extra", [["--springing", "-0.02", "--reach", "0.03"],
                                   ["--reach", "inf"]])
def test_both_command_lines_set_the_springing_joint_at_every_support(files, formfind, extra):
    """The same joint at every support in both command lines and in `assess`: the same
    thrust surface, its joints carrying the values given (none with an infinite reach)."""
    runs = [subprocess.run([*cmd, "dome.obj", "--supports", "dome.json", "--assess",
                            "min-thrust", "--thickness", "0.1", *extra, "--out", f"{name}.obj",
                            "--report", f"{name}.json"],
                           cwd=files, capture_output=True, text=True)
            for name, cmd in (("rust", [formfind]), ("py", [sys.executable, "-m", "voussoir"]))]
    for r in runs:
        assert r.returncode == 0, r.stderr
    py, rust = read_obj_vertices(files / "py.obj"), read_obj_vertices(files / "rust.obj")
    assert np.array_equal(py, rust)
    joints = [json.loads((files / f"{n}.json").read_text())["assessment"]["joints"]
              for n in ("py", "rust")]
    assert joints[0] == joints[1]
    v, f, rim = dented_dome()
    values = dict(zip(extra[::2], extra[1::2]))
    if values.get("--reach") == "inf":
        assert joints[0] == []
    else:
        assert sorted(j["vertex"] for j in joints[0]) == sorted(rim)
        for j in joints[0]:
            assert j["springing"] == pytest.approx(-0.02, abs=1e-12)
            assert j["reach"] == pytest.approx(0.03, abs=1e-12)
            assert j["offset"] <= j["reach"] + 1e-9
    mesh = voussoir.Mesh(v, f, rim)
    library = voussoir.assess(mesh, 0.1, objective="min-thrust",
                              springing=float(values.get("--springing", "nan"))
                              if "--springing" in values else None,
                              reach=float(values["--reach"]))
    assert np.array_equal(library.positions, rust)


def test_both_command_lines_read_surfaces_and_load_patterns_alike(files, formfind):
    """--intrados, --extrados and --load-pattern are read by the library's `io::read_surface`
    and `io::read_load_pattern` in both command lines: the same answer, the same errors."""
    v, f, _ = dome(scale=1.05)
    write_obj(files / "lo.obj", v - [0, 0, 0.05], f)
    write_obj(files / "hi.obj", v + [0, 0, 0.05], f)
    (files / "p.json").write_text(json.dumps({"loads": {"0": 1.0, "5": 0.5}}))
    (files / "far.json").write_text(json.dumps({"loads": {"99": 1.0}}))
    (files / "nan.json").write_text("[" + ", ".join(["1"] * 36 + ["null"]) + "]")
    both = [
        [formfind, "dome.obj", "--out", "rust.obj", "--report", "rust.json"],
        [sys.executable, "-m", "voussoir", "dome.obj", "--out", "py.obj", "--report", "py.json"],
    ]
    args = ["--supports", "dome.json", "--assess", "max-load", "--intrados", "lo.obj",
            "--extrados", "hi.obj"]
    runs = [subprocess.run([*cmd, *args, "--load-pattern", "p.json"], cwd=files,
                           capture_output=True, text=True) for cmd in both]
    for r in runs:
        assert r.returncode in (0, 3), r.stderr
    assert np.array_equal(read_obj_vertices(files / "py.obj"), read_obj_vertices(files / "rust.obj"))
    a, b = (json.loads((files / f"{n}.json").read_text())["assessment"] for n in ("py", "rust"))
    for key in ("feasible", "termination", "load_factor", "thrust_horizontal", "bounds"):
        assert a[key] == b[key], key
    for bad, expected in [("far.json", "`99` is not a vertex id of MESH (0 to 36"),
                          ("nan.json", "the load of vertex 36 is null, not a finite number"),
                          ("none.json", "--load-pattern: none.json: ")]:
        errors = []
        for cmd in both:
            r = subprocess.run([*cmd, *args, "--load-pattern", bad], cwd=files,
                               capture_output=True, text=True)
            assert r.returncode == 2 and expected in r.stderr, r.stderr
            errors.append(r.stderr.strip().split(": ", 1)[1])
        assert errors[0] == errors[1], errors
    for cmd in both:
        r = subprocess.run([*cmd, *args[:4], "--intrados", "none.obj", "--extrados", "hi.obj",
                            "--load-pattern", "p.json"], cwd=files, capture_output=True, text=True)
        assert r.returncode == 2 and "--intrados: none.obj: " in r.stderr, r.stderr


def vertex_normals_z(v, f):
    """z-component of the unit vertex normals (area-weighted means of the face normals)."""
    cross = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    normals = np.zeros_like(v)
    for k in range(3):
        np.add.at(normals, f[:, k], cross)
    return normals[:, 2] / np.linalg.norm(normals, axis=1)


def test_a_linear_family_gives_the_least_thickness_analysis_answer():
    """Bounds z -+ t / (2 n_z) with uniform t, springing joints at the lower bound with reach
    t / 2, scale linearly about their middle, so the family's least thickness is t times the
    least scale of the same envelope given as intrados and extrados surfaces."""
    v, f, rim = dome(rings=4, angle=math.radians(85))
    mesh = voussoir.Mesh(v, f, anchored=rim)
    nz = vertex_normals_z(v, f)
    calls = []

    def envelope_at(t):
        calls.append(t)
        return v[:, 2] - t / (2 * nz), v[:, 2] + t / (2 * nz)

    lower, upper = envelope_at(0.1)
    below, above = v.copy(), v.copy()
    below[:, 2], above[:, 2] = lower, upper
    direct = voussoir.assess(mesh, intrados=(below, f), extrados=(above, f),
                             objective="min-thickness")
    calls.clear()
    check_certificate(direct, rim)
    r = voussoir.min_thickness_of_family(mesh, envelope_at, 0.1)
    check_certificate(r, rim)
    assert r.objective == "min-thickness" and r.family_converged
    assert r.rounds == len(calls) - 1  # and one more call for the answer's envelope
    expected = 0.1 * direct.thickness_scale
    assert abs(r.thickness_min - expected) <= 3e-3 * expected
    assert 1 - 1e-3 <= r.thickness_scale <= 1
    assert np.allclose(r.envelope_lower, v[:, 2] - r.thickness_min / (2 * nz))


def test_a_bad_family_is_named_and_its_exceptions_propagate():
    v, f, rim = dome()
    mesh = voussoir.Mesh(v, f, anchored=rim)
    with pytest.raises(voussoir.VoussoirError, match="envelope_at"):
        voussoir.min_thickness_of_family(mesh, 3.0, 0.1)
    with pytest.raises(voussoir.VoussoirError, match="pair"):
        voussoir.min_thickness_of_family(mesh, lambda t: 1.0, 0.1)
    with pytest.raises(voussoir.VoussoirError, match="vertex"):
        voussoir.min_thickness_of_family(mesh, lambda t: (v[:, 2] + t, v[:, 2] - t), 0.1)
    with pytest.raises(voussoir.VoussoirError, match="thickness"):
        voussoir.min_thickness_of_family(mesh, lambda t: (v[:, 2] - t, v[:, 2] + t), -1.0)

    def failing(t):
        raise ZeroDivisionError("no shell")

    with pytest.raises(ZeroDivisionError, match="no shell"):
        voussoir.min_thickness_of_family(mesh, failing, 0.1)


def test_springing_and_reach_set_the_joints_of_free_supports():
    """A narrow joint lowers the greatest thrust, no joint (an infinite reach: the vertical
    reading) raises it; each certificate, the joint's condition with the given plane and reach
    included, recomputed from the outputs."""
    v, f, rim = dome()
    mesh = voussoir.Mesh(v, f, rim)
    default = voussoir.assess(mesh, 0.1, objective="max-thrust")
    check_certificate(default, rim)
    reach = np.zeros(len(v))
    reach[default.joint_vertices] = 0.2 * default.joints[:, 1]
    springing = v[:, 2] - 0.01
    narrow = voussoir.assess(mesh, 0.1, objective="max-thrust", springing=springing, reach=reach)
    check_certificate(narrow, rim)
    assert narrow.thickness_scale == 1.0
    assert np.array_equal(narrow.joint_vertices, default.joint_vertices)
    # As given (to the rounding of the solver's unit of length).
    assert np.allclose(narrow.joints[:, 0], springing[narrow.joint_vertices], rtol=1e-13)
    assert np.allclose(narrow.joints[:, 1], reach[narrow.joint_vertices], rtol=1e-13)
    assert narrow.thrust_horizontal < default.thrust_horizontal * (1 - 1e-3)
    free = voussoir.assess(mesh, 0.1, objective="max-thrust", reach=math.inf)
    check_certificate(free, rim)
    assert len(free.joint_vertices) == 0 and free.worst_joint == 0.0
    assert free.thrust_horizontal > default.thrust_horizontal * (1 + 1e-3)
    # Without a joint the plane is not read: any springing gives the same surface.
    other = voussoir.assess(mesh, 0.1, objective="max-thrust", springing=-5.0, reach=math.inf)
    assert np.array_equal(other.positions, free.positions)
    # The default joint keeps the least thrust's supports at the middle surface or above;
    # without it they may drop towards the intrados, and the least thrust falls.
    least = voussoir.assess(mesh, 0.1, objective="min-thrust")
    lower = voussoir.assess(mesh, 0.1, objective="min-thrust", reach=math.inf)
    check_certificate(lower, rim)
    assert lower.positions[rim, 2].min() < v[rim, 2].min() - 1e-3
    assert lower.thrust_horizontal < least.thrust_horizontal * (1 - 1e-3)


@pytest.mark.parametrize(
    "joints, argument, detail",
    [
        ({"springing": [0.0, 0.0, 0.0]}, "springing", "has 3 entries"),
        ({"reach": np.zeros((37, 2))}, "reach", "expected (n,)"),
        ({"reach": -0.1}, "reach", "vertex 25"),  # the first support: a number holds there
        ({"reach": float("nan")}, "reach", "not a number >= 0"),
        ({"springing": float("nan")}, "springing", "must be finite"),
        ({"springing": 5.0}, "springing", "upper bound"),
    ],
)
def test_bad_springing_joints_name_the_argument(joints, argument, detail):
    v, f, rim = dome()
    mesh = voussoir.Mesh(v, f, rim)
    with pytest.raises(voussoir.VoussoirError) as e:
        voussoir.assess(mesh, 0.1, **joints)
    message = str(e.value)
    assert f"argument `{argument}`" in message and detail in message, message
    assert "\n" not in message


def test_a_family_may_give_its_springing_joints():
    """(lower, upper, springing, reach) with the defaults spelled out (the plane at the
    intrados, reach t / 2) gives what (lower, upper) gives; without joints the family's least
    thickness falls."""
    v, f, rim = dome(rings=4, angle=math.radians(85))
    mesh = voussoir.Mesh(v, f, anchored=rim)
    nz = vertex_normals_z(v, f)

    def bounds(t):
        return v[:, 2] - t / (2 * nz), v[:, 2] + t / (2 * nz)

    plain = voussoir.min_thickness_of_family(mesh, bounds, 0.1)
    spelled = voussoir.min_thickness_of_family(
        mesh, lambda t: (*bounds(t), bounds(t)[0], t / 2), 0.1
    )
    # Equal to rounding: the default reach is the area-weighted mean of t / 2 over the faces.
    assert spelled.thickness_min == pytest.approx(plain.thickness_min, rel=1e-9)
    check_certificate(spelled, rim)
    free = voussoir.min_thickness_of_family(mesh, lambda t: (*bounds(t), None, math.inf), 0.1)
    check_certificate(free, rim)
    assert len(free.joint_vertices) == 0
    assert free.thickness_min < plain.thickness_min * (1 - 1e-3), (free.thickness_min,
                                                                   plain.thickness_min)
    with pytest.raises(voussoir.VoussoirError, match="`reach`"):
        voussoir.min_thickness_of_family(mesh, lambda t: (*bounds(t), None, -1.0), 0.1)
    with pytest.raises(voussoir.VoussoirError, match="pair"):
        voussoir.min_thickness_of_family(mesh, lambda t: (*bounds(t), None), 0.1)


def test_a_free_corner_is_refused_at_once():
    """A vault over a square anchored along two sides has a free corner between its free
    sides: every edge leaves it on one side, so compression cannot hold it in any envelope.
    The answer comes without a search, names the corner and lists the stranded vertices;
    anchored all round, it fits."""
    n = 4
    v = np.array([(i / n, j / n, 0.1 + 0.1 * (i / n) * (1 - i / n) + 0.1 * (j / n) * (1 - j / n))
                  for j in range(n + 1) for i in range(n + 1)])
    vid = lambda i, j: j * (n + 1) + i  # noqa: E731
    f = np.array([t for j in range(n) for i in range(n)
                  for t in ((vid(i, j), vid(i + 1, j), vid(i + 1, j + 1)),
                            (vid(i, j), vid(i + 1, j + 1), vid(i, j + 1)))], dtype=np.int64)
    two_sides = [k for k, p in enumerate(v) if p[0] == 0 or p[1] == 0]
    r = voussoir.assess(voussoir.Mesh(v, f, two_sides), 1.0, objective="min-thickness")
    assert not r.feasible and r.termination == "infeasible" and r.iterations == 0
    assert f"vertex {vid(n, n)} is a free corner" in r.termination_message
    # The corner strands its free edges' rows in turn: every free vertex, none anchored.
    free = [k for k in range(len(v)) if k not in two_sides]
    assert r.stranded.tolist() == free
    all_round = [k for k, p in enumerate(v) if p[0] in (0, 1) or p[1] in (0, 1)]
    fits = voussoir.assess(voussoir.Mesh(v, f, all_round), 1.0)
    assert fits.feasible and len(fits.stranded) == 0
