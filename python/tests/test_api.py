"""The Python API: shapes and dtypes of every result array, settings and their defaults,
files in every format, loads, and the command line."""

from __future__ import annotations

import dataclasses
import json
import os
import subprocess
import sys
import typing

import numpy as np
import pytest

import voussoir
from conftest import REPO, SQUARE_ANCHORED, SQUARE_FACES, SQUARE_POSITIONS

from voussoir import _voussoir as _native
from voussoir._settings import SETTING_NAMES, Settings


def square(**loads) -> voussoir.Mesh:
    return voussoir.Mesh(SQUARE_POSITIONS, SQUARE_FACES, SQUARE_ANCHORED, **loads)


def test_import_has_the_library_version_and_error_is_a_value_error():
    manifest = (REPO / "Cargo.toml").read_text()
    assert f'\nversion = "{voussoir.__version__}"\n' in manifest
    assert issubclass(voussoir.VoussoirError, ValueError)


def test_settings_list_every_default_and_nothing_else():
    d = voussoir.defaults()
    assert set(d) == set(SETTING_NAMES)
    assert d["method"] == "nearest" and d["q_max"] is None and d["dual_length_bounds"] is None


def test_the_typed_choices_are_the_library_names():
    """`Settings`' Literal types list the names the library parses and reports."""
    hints = typing.get_type_hints(Settings)
    # `up` is a read option and `objective` the assessment's, not solve settings.
    choices = {k: v for k, v in _native.choices().items() if k not in ("up", "objective")}
    for key, names in choices.items():
        assert list(typing.get_args(hints[key])) == names, key
    for key, names in choices.items():
        for name in names:
            voussoir.analyse(square(), **{key: name})
    assert _native.choices()["objective"] == [
        "fit", "min-thickness", "min-thrust", "max-thrust", "max-load"
    ]


def test_a_default_given_explicitly_changes_nothing():
    mesh = square()
    plain = voussoir.form_find(mesh)
    explicit = voussoir.form_find(mesh, **voussoir.defaults())
    assert np.array_equal(plain.positions, explicit.positions)
    assert np.array_equal(plain.force_densities, explicit.force_densities)


def test_settings_reach_the_solver(models):
    vault = voussoir.Mesh.from_file(models / "free_vault.obj", models / "free_vault.json")
    base = voussoir.analyse(vault)
    plain_compression = voussoir.analyse(vault, q_min=0.0)
    assert base.force_densities.min() > plain_compression.force_densities.min()
    mesh = square()
    edge_based = voussoir.analyse(mesh, formulation="edge_based", qp_solver="clarabel")
    assert edge_based.formulation == "edge_based" and edge_based.qp_solver == "clarabel"
    one_step = voussoir.form_find(mesh, method="paper", max_iterations=1, tolerance=1e-300)
    assert one_step.iterations == 1 and one_step.termination == "max_iterations"
    bounded = voussoir.analyse(mesh, q_max=1e-3, q_max_kind="absolute", q_min=0.0)
    assert bounded.force_densities.max() <= 1e-3 * (1 + 1e-6)
    assert bounded.eps_inf > voussoir.analyse(mesh).eps_inf


def expected_shapes(n, m, e, h, s):
    return {
        "positions": ((n, 3), np.float64),
        "edges": ((e, 2), np.uint32),
        "force_densities": ((e,), np.float64),
        "airy": ((n,), np.float64),
        "weights": ((n,), np.float64),
        "hole_coefficients": ((h, 3), np.float64),
        "tau": ((n,), np.float64),
        "external_horizontal": ((n, 2), np.float64),
        "loads": ((n,), np.float64),
        "residuals": ((n,), np.float64),
        "horizontal_imbalance": ((n, 2), np.float64),
        "force_diagram_centres": ((m, 2), np.float64),
        "force_diagram_segments": ((s, 2, 2), np.float64),
        "force_diagram_segment_edges": ((s,), np.uint32),
    }


def check_arrays(result, n, m, e, h):
    s = len(result.force_diagram_segment_edges)
    for name, (shape, dtype) in expected_shapes(n, m, e, h, s).items():
        array = getattr(result, name)
        assert isinstance(array, np.ndarray), name
        assert array.shape == shape, (name, array.shape, shape)
        assert array.dtype == dtype, (name, array.dtype)


def test_result_arrays_have_the_documented_shapes_and_dtypes(models):
    mesh = voussoir.Mesh.from_file(models / "hex.obj", models / "hex.json")
    n, m, e, h = len(mesh.vertices), len(mesh.faces), len(mesh.edges), mesh.n_holes
    assert h == 3
    stress = voussoir.analyse(mesh)
    check_arrays(stress, n, m, e, h)
    found = voussoir.form_find(mesh, max_iterations=3)
    check_arrays(found, n, m, e, h)
    assert found.history.dtype == np.float64 and found.history.ndim == 1
    assert found.termination_vertices.dtype == np.uint32
    assert len(found.step_solvers) == found.iterations
    assert isinstance(found.termination_message, str) and found.termination_message


def test_mesh_round_trips_through_every_format(tmp_path):
    mesh = square(face_density=[1, 2, 3, 4])
    for suffix in (".obj", ".off", ".ply", ".stl"):
        path = tmp_path / f"square{suffix}"
        mesh.write(path)
        again = voussoir.Mesh.from_file(path, anchored=[0, 1, 2, 3])
        if suffix == ".stl":
            # STL keeps single precision and one vertex per triangle corner, welded on reading.
            assert len(again.vertices) == 5
            assert len(again.welded_ids) == 12
        else:
            assert np.array_equal(again.vertices, mesh.vertices), suffix
            assert np.array_equal(again.faces, mesh.faces), suffix


def test_loads_are_kept_and_change_the_answer():
    light = square()
    heavy = square(face_density=[1, 1, 1, 5], extra_loads=[0, 0, 0, 0, 0.5])
    assert np.array_equal(heavy.face_density, [1, 1, 1, 5])
    assert heavy.extra_loads[4] == 0.5
    assert voussoir.analyse(heavy).loads[4] > voussoir.analyse(light).loads[4]


def test_a_hanging_mesh_is_read_upside_down_and_says_so():
    hanging = np.array(SQUARE_POSITIONS, dtype=np.float64)
    hanging[4, 2] = -0.3
    found = voussoir.form_find(voussoir.Mesh(hanging, SQUARE_FACES, SQUARE_ANCHORED))
    assert found.mirrored and found.converged
    assert found.positions[4, 2] > 0
    assert not voussoir.form_find(square()).mirrored


def test_faces_keep_their_orientation():
    clockwise = [f[::-1] for f in SQUARE_FACES]
    mesh = voussoir.Mesh(SQUARE_POSITIONS, clockwise, SQUARE_ANCHORED)
    assert np.array_equal(mesh.faces, clockwise)


def test_results_are_frozen_dataclasses():
    found = voussoir.form_find(square())
    assert dataclasses.is_dataclass(found)
    with pytest.raises(dataclasses.FrozenInstanceError):
        found.eps_inf = 0.0  # type: ignore[misc]
    assert found.converged


def run_cli(*args, cwd):
    return subprocess.run(
        [sys.executable, "-m", "voussoir", *map(str, args)],
        cwd=cwd,
        capture_output=True,
        text=True,
    )


def test_command_line_writes_the_mesh_and_report(tmp_path, models):
    done = run_cli(
        models / "neumunster.obj",
        "--supports",
        models / "neumunster.json",
        "--out",
        "out.ply",
        "--report",
        "r.json",
        cwd=tmp_path,
    )
    assert done.returncode == 0, done.stderr
    report = json.loads((tmp_path / "r.json").read_text())
    assert report["termination"] == "converged"
    written = voussoir.Mesh.from_file(tmp_path / "out.ply", anchored=report["anchored"])
    assert np.array_equal(written.vertices, np.array(report["positions"]))


def test_command_line_rejects_bad_input_and_writes_nothing(tmp_path):
    (tmp_path / "bad.off").write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n")
    done = run_cli("bad.off", "--anchor-boundary", cwd=tmp_path)
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1 and "bad.off:6:" in done.stderr
    assert not (tmp_path / "formfind-out").exists()
    done = run_cli("bad.off", cwd=tmp_path)
    assert done.returncode == 2 and "--supports" in done.stderr


def test_command_line_outputs_go_through_links_and_spare_inputs_and_fifos(tmp_path):
    # Issue 48: outputs replaced whatever their path named (a link, a FIFO, the input).
    square().write(tmp_path / "sq.obj")
    (tmp_path / "s.json").write_text("[0, 1, 2, 3]")
    os.mkfifo(tmp_path / "fifo.json")
    os.symlink("sq.obj", tmp_path / "to-input.obj")
    before = sorted(p.name for p in tmp_path.iterdir())
    for args, message in [
        (["--out", "sq.obj"], "--out sq.obj names the input file of MESH"),
        (["--out", "to-input.obj"], "--out to-input.obj names the input file of MESH"),
        (["--report", "s.json"], "--report s.json names the input file of --supports"),
        (["--report", "fifo.json"], "--report: fifo.json: is a FIFO (named pipe), not a regular"),
    ]:
        done = run_cli("sq.obj", "--supports", "s.json", "--stress-only", *args, cwd=tmp_path)
        assert done.returncode == 2, done.stderr
        assert message in done.stderr and done.stderr.count("\n") == 1, done.stderr
        assert sorted(p.name for p in tmp_path.iterdir()) == before
    (tmp_path / "real.json").write_text("old")
    os.symlink("real.json", tmp_path / "link.json")
    done = run_cli("sq.obj", "--supports", "s.json", "--stress-only", "--out", "o.obj",
                   "--report", "link.json", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "link.json").is_symlink()
    assert json.loads((tmp_path / "real.json").read_text())["anchored"] == [0, 1, 2, 3]


def test_command_line_refuses_a_repeated_option(tmp_path):
    # Issue 48: a repeated option silently kept its last value; formfind refuses it (exit 2,
    # naming the option) and so does the Python command line, with formfind's words.
    square().write(tmp_path / "sq.obj")
    for args, message in [
        (["--max-iter", "3", "--max-iter", "4"], "--max-iter is given twice; give it once"),
        (["--max-it", "3", "--max-iter=4"], "--max-iter is given twice; give it once"),
        (["--stress-only", "--stress-only"], "--stress-only is given twice; give it once"),
        (["--out", "a.obj", "--out", "b.obj"], "--out is given twice; give it once"),
        (["--weld", "0.1", "--no-weld"], "--weld and --no-weld are both given; give one of them"),
    ]:
        done = run_cli("sq.obj", "--anchor-boundary", *args, cwd=tmp_path)
        assert done.returncode == 2, done.stderr
        assert done.stderr == f"voussoir: error: {message}\n"
        assert sorted(p.name for p in tmp_path.iterdir()) == ["sq.obj"]


def test_both_command_lines_leave_read_ranges_to_the_library(tmp_path, formfind):
    # The range of --anchor-lowest and --weld is `ReadOptions::validate`'s alone: both command
    # lines give its reason under the option's name (`--opt=-0.5abs`: argparse takes a
    # leading `-` that is not a number for an option).
    square().write(tmp_path / "sq.obj")
    for args, message in [
        (["--anchor-lowest", "-1"], "--anchor-lowest: -1 is not a finite number >= 0"),
        (["--anchor-lowest=-0.5abs"], "--anchor-lowest: -0.5 is not a finite number >= 0"),
        (["--anchor-boundary", "--weld", "-1"], "--weld: -1 is not a finite number >= 0"),
        (["--anchor-lowest", "x"], "--anchor-lowest: expected a number or NUMBERabs, got `x`"),
    ]:
        python = run_cli("sq.obj", *args, cwd=tmp_path)
        rust = subprocess.run([formfind, "sq.obj", *args], cwd=tmp_path, capture_output=True,
                              text=True)
        for done, program in ((python, "voussoir"), (rust, "formfind")):
            assert done.returncode == 2, done.stderr
            assert done.stderr.strip().splitlines()[-1] == f"{program}: error: {message}"


def test_command_line_anchors_the_boundary_of_the_welded_mesh(tmp_path):
    # An STL file repeats every vertex per triangle: the boundary is the welded mesh's.
    square().write(tmp_path / "square.stl")
    done = run_cli("square.stl", "--anchor-boundary", "--stress-only", "--report", "r.json",
                   "--out", "out.obj", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    report = json.loads((tmp_path / "r.json").read_text())
    assert len(report["anchored"]) == 4 and len(report["positions"]) == 5


def quad_dome(path, rings=4, sectors=16):
    """A latitude-longitude dome in quads (split along one diagonal per ring when read); its
    rim's vertex ids."""
    lines = ["v 0 0 0.6"]
    for r in range(1, rings + 1):
        for s in range(sectors):
            a, rr = 2 * np.pi * s / sectors, r / rings
            lines.append(f"v {float(rr * np.cos(a))!r} {float(rr * np.sin(a))!r} {0.6 * (1 - rr)!r}")
    vid = lambda r, s: 2 + (r - 1) * sectors + s % sectors  # noqa: E731 (1-based)
    lines += [f"f 1 {vid(1, s)} {vid(1, s + 1)}" for s in range(sectors)]
    for r in range(1, rings):
        for s in range(sectors):
            lines.append(f"f {vid(r, s)} {vid(r + 1, s)} {vid(r + 1, s + 1)} {vid(r, s + 1)}")
    path.write_text("\n".join(lines) + "\n")
    return [vid(rings, s) - 1 for s in range(sectors)]


def test_polygon_diagonals_from_arrays_solve_as_those_of_a_file(tmp_path):
    rim = quad_dome(tmp_path / "dome.obj")
    read = voussoir.Mesh.from_file(tmp_path / "dome.obj", anchored=rim)
    assert read.polygon_diagonals.shape == (3 * 16, 2)
    arrays = voussoir.Mesh(read.vertices, read.faces, read.anchored,
                           polygon_diagonals=read.polygon_diagonals[:, ::-1])
    assert np.array_equal(arrays.polygon_diagonals, read.polygon_diagonals)
    expected = voussoir.analyse(read).force_densities
    assert np.array_equal(voussoir.analyse(arrays).force_densities, expected)
    plain = voussoir.Mesh(read.vertices, read.faces, read.anchored)
    assert plain.polygon_diagonals.shape == (0, 2)
    assert not np.array_equal(voussoir.analyse(plain).force_densities, expected)
