"""formfind's printable solid (--solid) in OpenSCAD: `openscad` imports the STL, 3MF and OFF
files and renders them through CGAL's Nef polyhedra (a difference with a far cube, which
refuses a solid that is not closed and manifold); the mesh it exports encloses the volume of
ours within 1%. Both volumes are computed here from the files (divergence theorem), ours from
the format formfind wrote, OpenSCAD's from its OFF export. examples/openscad/vault_section.scad
renders too.
"""

from __future__ import annotations

import re
import subprocess
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
import pytest

from conftest import REPO, host_program, read_obj

MODELS = ("neumunster", "four_holes", "three_pillar")
FORMATS = ("stl", "3mf", "off")
SECTION = REPO / "examples" / "openscad" / "vault_section.scad"
RENDER = (
    'difference() {{ import("{path}", convexity = 10); translate([1e6, 1e6, 1e6]) cube(1); }}\n'
)


def read_stl(path):
    data = path.read_bytes()
    if data[:5] == b"solid" and b"facet" in data[:300]:
        numbers = re.findall(rb"vertex\s+(\S+)\s+(\S+)\s+(\S+)", data)
        return np.array(numbers, dtype=np.float64).reshape(-1, 3, 3)
    count = int(np.frombuffer(data, "<u4", 1, 80)[0])
    record = np.dtype([("normal", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    return np.frombuffer(data, record, count, 84)["v"].astype(np.float64)


def read_off(path):
    tokens = re.sub(r"#[^\n]*", "", path.read_text()).split()
    assert tokens[0] == "OFF", path
    n, m = int(tokens[1]), int(tokens[2])
    points = np.array(tokens[4 : 4 + 3 * n], dtype=np.float64).reshape(n, 3)
    triangles, at = [], 4 + 3 * n
    for _ in range(m):
        k = int(tokens[at])
        ids = [int(t) for t in tokens[at + 1 : at + 1 + k]]
        triangles += [[ids[0], ids[i], ids[i + 1]] for i in range(1, k - 1)]
        at += 1 + k
    return points[np.array(triangles)]


def read_3mf(path):
    with zipfile.ZipFile(path) as z:
        root = ET.fromstring(z.read("3D/3dmodel.model"))
    ns = {"m": root.tag[1 : root.tag.index("}")]}
    points = np.array(
        [[float(v.get(a)) for a in "xyz"] for v in root.iterfind(".//m:vertex", ns)]
    )
    ids = np.array(
        [[int(t.get(a)) for a in ("v1", "v2", "v3")] for t in root.iterfind(".//m:triangle", ns)]
    )
    return points[ids]


READERS = {"stl": read_stl, "off": read_off, "3mf": read_3mf}


def volume(triangles):
    """The signed volume a closed triangle mesh (t, 3, 3) encloses: positive when outward."""
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6)


def surface_area(vertices, faces):
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    return float(np.linalg.norm(np.cross(b - a, c - a), axis=1).sum() / 2)


@pytest.fixture(scope="module")
def openscad():
    return host_program("openscad", "openscad")


def run_openscad(openscad, scad, out, defines=()):
    args = [openscad, "-o", str(out)]
    for d in defines:
        args += ["-D", d]
    run = subprocess.run(args + [str(scad)], capture_output=True, text=True, errors="replace")
    assert run.returncode == 0 and out.is_file(), f"openscad exited {run.returncode}:\n{run.stderr}"
    assert "ERROR" not in run.stderr and "WARNING" not in run.stderr, run.stderr
    return run


# The solid's thickness in each model's units: about half the most that formfind accepts
# (its error names that bound: the thinnest the shell's curvature allows).
THICKNESS = {"neumunster": 2.5, "four_holes": 0.007, "three_pillar": 0.05}


@pytest.fixture(scope="module")
def solids(models, formfind, tmp_path_factory):
    """formfind's --solid output of each model in each format, with the form-found surface."""
    tmp = tmp_path_factory.mktemp("solids")
    made = {}
    for name in MODELS:
        t = THICKNESS[name]
        for fmt in FORMATS:
            out = tmp / f"{name}-solid.{fmt}"
            run = subprocess.run(
                [formfind, models / f"{name}.obj", "--supports", models / f"{name}.json",
                 "--out", tmp / f"{name}.obj", "--report", tmp / f"{name}.json",
                 "--pictures", tmp / "pictures", "--solid", str(t), out],
                capture_output=True, text=True,
            )  # fmt: skip
            assert run.returncode == 0, run.stderr
            made[name, fmt] = out
        made[name, "surface"] = tmp / f"{name}.obj"
    return made


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("name", MODELS)
def test_openscad_renders_the_solid_with_our_volume(name, fmt, models, solids, openscad, tmp_path):
    solid = solids[name, fmt]
    ours = volume(READERS[fmt](solid))
    # The solid is the form-found surface thickened by T: its volume is about area x T.
    vertices, faces = read_obj(solids[name, "surface"])
    t = THICKNESS[name]
    assert ours == pytest.approx(surface_area(vertices, faces) * t, rel=0.05)

    scad = tmp_path / "render.scad"
    scad.write_text(RENDER.format(path=solid))
    run = run_openscad(openscad, scad, tmp_path / "rendered.off")
    # One closed volume (CGAL counts the outer one too).
    assert re.search(r"Volumes:\s+2\b", run.stderr), run.stderr
    theirs = volume(read_off(tmp_path / "rendered.off"))
    assert theirs == pytest.approx(ours, rel=0.01)


def test_the_section_example_renders(models, solids, openscad, tmp_path):
    solid = solids["three_pillar", "stl"]
    whole = volume(read_stl(solid))
    out = tmp_path / "section.off"
    run_openscad(openscad, SECTION, out, [f'solid="{solid}"', "cut_y=0"])
    section = read_off(out)
    assert section[:, :, 1].max() <= 1e-5
    assert 0.1 * whole < volume(section) < 0.9 * whole
