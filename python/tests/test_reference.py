"""Bit for bit against the Rust API: the formfind example (the Rust library's `form_find` with
default settings, reading files as `Mesh.from_file` does) on every shared model. Its OBJ output
and JSON report keep every bit (shortest round-trip decimals), so equality here is exact."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

import voussoir
from conftest import MODEL_NAMES

PER_VERTEX = ("airy", "weights", "loads", "residuals", "tau")
NUMBERS = ("eps_inf", "objective", "hausdorff", "l2", "rms_change", "max_change")


def read_obj_vertices(path):
    rows = [line.split()[1:4] for line in path.read_text().splitlines() if line.startswith("v ")]
    return np.array(rows, dtype=np.float64)


@pytest.mark.parametrize("name", MODEL_NAMES)
def test_form_finding_equals_the_rust_api(name, models, formfind, tmp_path):
    obj, supports = models / f"{name}.obj", models / f"{name}.json"
    rust = subprocess.run(
        [formfind, obj, "--supports", supports, "--out", "out.obj", "--report", "report.json"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
    )
    # 0: converged; 3: finished without converging (outputs written all the same).
    assert rust.returncode in (0, 3), rust.stderr
    report = json.loads((tmp_path / "report.json").read_text())
    expected_positions = read_obj_vertices(tmp_path / "out.obj")

    mesh = voussoir.Mesh.from_file(obj, supports)
    result = voussoir.form_find(mesh)

    assert result.termination == report["termination"]
    assert result.iterations == report["iterations"]
    assert result.step_solvers == report["step_solvers"]
    assert np.array_equal(result.positions, expected_positions)
    assert np.array_equal(result.edges, np.array(report["edges"], dtype=np.uint32))
    assert np.array_equal(mesh.anchored, np.array(report["anchored"], dtype=np.uint32))
    assert np.array_equal(result.force_densities, np.array(report["force_densities"]))
    assert np.array_equal(result.history, np.array(report["history"]))
    for key in PER_VERTEX:
        assert np.array_equal(getattr(result, key), np.array(report[key])), key
    for key in NUMBERS:
        assert getattr(result, key) == report[key], key


FORMATS = ("obj", "off", "ply", "ply-ascii", "stl", "stl-ascii")


def write_as(mesh, path, fmt):
    """`mesh` to `path` in `fmt`: `Mesh.write` for the formats it writes (binary PLY and STL),
    text written here for the ASCII variants (shortest round-trip decimals; single precision
    for STL, as its binary form)."""
    if not fmt.endswith("-ascii"):
        mesh.write(path)
        return
    v, f = mesh.vertices, mesh.faces
    if fmt == "ply-ascii":
        head = ["ply", "format ascii 1.0", f"element vertex {len(v)}", "property double x",
                "property double y", "property double z", f"element face {len(f)}",
                "property list uchar int vertex_indices", "end_header"]
        rows = [" ".join(repr(float(c)) for c in p) for p in v]
        rows += ["3 " + " ".join(str(int(i)) for i in t) for t in f]
        path.write_text("\n".join(head + rows) + "\n")
        return
    lines = ["solid vault"]
    for t in f:
        lines += ["facet normal 0 0 0", "outer loop"]
        lines += ["vertex " + " ".join(str(np.float32(c)) for c in v[i]) for i in t]
        lines += ["endloop", "endfacet"]
    path.write_text("\n".join(lines + ["endsolid vault"]) + "\n")


@pytest.mark.parametrize("name", MODEL_NAMES)
def test_every_format_reads_as_the_rust_api_reads_it(name, models, formfind, tmp_path):
    """`Mesh.from_file` and the formfind example read a file through the same library call
    (`io::read_model`): the same mesh, supports and stress in every format, with supports
    from a file, the boundary or the lowest vertices."""
    obj, supports = models / f"{name}.obj", models / f"{name}.json"
    source = voussoir.Mesh.from_file(obj, supports)
    ways = [(["--supports", supports], {"supports": supports})]
    if name == "free_vault":
        ways += [
            (["--anchor-boundary"], {"anchor_boundary": True}),
            (["--anchor-lowest", "0.02"], {"anchor_lowest": 0.02}),
        ]
    for fmt in FORMATS:
        path = tmp_path / f"{name}-{fmt}.{fmt.removesuffix('-ascii')}"
        write_as(source, path, fmt)
        for flags, keywords in ways:
            rust = subprocess.run(
                [formfind, path, *flags, "--stress-only", "--out", "out.obj", "--report", "r.json",
                 "--pictures", "pics"],
                cwd=tmp_path,
                capture_output=True,
                text=True,
            )
            assert rust.returncode in (0, 3), rust.stderr
            report = json.loads((tmp_path / "r.json").read_text())
            mesh = voussoir.Mesh.from_file(path, **keywords)
            what = f"{name}.{fmt} {flags[0]}"
            assert np.array_equal(mesh.vertices, read_obj_vertices(tmp_path / "out.obj")), what
            assert np.array_equal(mesh.anchored, np.array(report["anchored"], dtype=np.uint32)), what
            assert np.array_equal(mesh.edges, np.array(report["edges"], dtype=np.uint32)), what
            if fmt == "obj" or len(mesh.vertices) < 400:
                result = voussoir.analyse(mesh)
                assert np.array_equal(result.force_densities, np.array(report["force_densities"])), what
                assert np.array_equal(result.residuals, np.array(report["residuals"])), what


def test_both_command_lines_write_one_report(models, formfind, tmp_path):
    """`python -m voussoir` and the formfind example write the library's report: the same
    keys and, but for timings, the same values."""
    obj, supports = models / "four_holes.obj", models / "four_holes.json"
    common = [obj, "--supports", supports, "--stress-only", "--solver", "edge_based",
              "--load", "plan_area", "--tau", "zero", "--out", "out.obj"]
    rust = subprocess.run([formfind, *common, "--report", "rust.json", "--pictures", "pics"],
                          cwd=tmp_path, capture_output=True, text=True)
    assert rust.returncode in (0, 3), rust.stderr
    python = subprocess.run([sys.executable, "-m", "voussoir", *map(str, common), "--report",
                             "python.json"], cwd=tmp_path, capture_output=True, text=True)
    assert python.returncode in (0, 3), python.stderr
    a = json.loads((tmp_path / "rust.json").read_text())
    b = json.loads((tmp_path / "python.json").read_text())
    assert set(a) == set(b) and set(a["settings"]) == set(b["settings"])
    for report in (a, b):
        report.pop("timings_s")
    assert a["settings"]["formulation"] == "edge_based"
    assert a["settings"]["load_rule"] == "plan_area" and a["settings"]["tau"] == "zero"
    assert a == b
