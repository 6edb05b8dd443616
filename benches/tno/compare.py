#!/usr/bin/env python3
"""Voussoir's masonry assessment side by side with compas_tno 0.4 (docs/benchmarks.md).

    python3 benches/tno/compare.py            # installs, builds, runs every case
    python3 benches/tno/compare.py --quick    # the small cases only

Not a test: it prints one Markdown table and asserts nothing. It makes a virtual environment
under target/tno/venv with compas_tna 0.9 and compas_tno 0.4 from PyPI (as .ci/hosts does),
builds `examples/assess_json.rs` in release mode, and runs every case with one BLAS thread.

For each case compas_tno builds its form diagram, envelope, self-weight (`apply_selfweight`:
middle-surface tributary area x t x unit weight, normalised to the envelope's weight) and
bounds (`apply_envelope`: zlb, zub read vertically); then it solves with SLSQP (its starting
point: load path). The same plan, loads (pz) and bounds go to Voussoir: the form diagram's
faces fan-triangulated, its supports anchored, the supports' heights free within the bounds
(compas_tno's `zb` variable), the loads alone (unit weight 0).
"""

import json
import os
import re
import resource
import subprocess
import sys
import time
from pathlib import Path

for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS"):
    os.environ[var] = "1"

ROOT = Path(__file__).resolve().parents[2]
WORK = ROOT / "target" / "tno"
VENV = WORK / "venv"
PY = VENV / "bin" / "python"
EXE = ROOT / "target" / "release" / "examples" / "assess_json"


def setup():
    """The venv with compas_tno (from PyPI) and the release example."""
    if not PY.exists():
        subprocess.run([sys.executable, "-m", "venv", str(VENV)], check=True)
    probe = [str(PY), "-c", "import compas_tno, compas_tna"]
    if subprocess.run(probe, capture_output=True).returncode != 0:
        pip = [str(VENV / "bin" / "pip"), "install", "--quiet", "--disable-pip-version-check"]
        # numpy 2.4 turns compas_tna 0.9's float() of a one-element array into an error.
        subprocess.run(pip + ["compas_tna==0.9.*", "compas_tno==0.4.*", "numpy<2.4"], check=True)
    cargo = ["cargo", "build", "--release", "--locked", "--example", "assess_json"]
    subprocess.run(cargo, cwd=ROOT, check=True)


# --- inside the venv: one compas_tno case -------------------------------------------------

def tno_case(case):
    """Solves `case` with compas_tno; returns its result and the problem for Voussoir."""
    import numpy as np
    from compas_tna.diagrams import FormDiagram
    from compas_tna.envelope import CrossVaultEnvelope, DomeEnvelope
    from compas_tno.analysis import Analysis

    kind, analysis_name = case["kind"], case["analysis"]
    t = case["thickness"]
    if kind == "dome":
        envelope = DomeEnvelope(center=(5.0, 5.0), radius=5.0, thickness=t, min_lb=0.0,
                                n_hoops=2 * case["hoops"], n_parallels=2 * case["parallels"])
        form = FormDiagram.create_circular_radial(center=(5.0, 5.0), radius=5.0,
                                                  n_hoops=case["hoops"],
                                                  n_parallels=case["parallels"])
        for edge in form.edges_on_boundary():
            form.edge_attribute(edge, "_is_edge", False)
    else:
        envelope = CrossVaultEnvelope(x_span=(0.0, 10.0), y_span=(0.0, 10.0), thickness=t)
        form = FormDiagram.create_cross(x_span=(0.0, 10.0), y_span=(0.0, 10.0), n=case["n"])

    keys = list(form.vertices())
    index = {k: i for i, k in enumerate(keys)}
    pattern = None
    if analysis_name == "min-thrust":
        analysis = Analysis.create_minthrust_analysis(form, envelope, solver="SLSQP")
    elif analysis_name == "max-thrust":
        analysis = Analysis.create_maxthrust_analysis(form, envelope, solver="SLSQP")
    elif analysis_name == "min-thickness":
        analysis = Analysis.create_minthk_analysis(form, envelope, solver="SLSQP")
    else:  # max-load: a point load at the vertex nearest (7.5, 5) (a quarter span)
        xy = np.array(form.vertices_attributes("xy"))
        target = np.argmin(np.hypot(xy[:, 0] - 7.5, xy[:, 1] - 5.0))
        pattern = np.zeros((len(keys), 1))
        pattern[target] = -case["point_load"]
        analysis = Analysis.create_max_load_analysis(form, envelope, solver="SLSQP",
                                                     load_direction=pattern, max_lambd=1e3)
    analysis.apply_selfweight()
    analysis.apply_envelope()
    lower = [form.vertex_attribute(k, "lb") for k in keys]
    upper = [form.vertex_attribute(k, "ub") for k in keys]
    pz = [form.vertex_attribute(k, "pz") for k in keys]
    # compas_tno moves z to its starting point; Voussoir reads z only at fixed supports.
    xyz0 = [form.vertex_coordinates(k) for k in keys]

    start = time.process_time()
    wall = time.perf_counter()
    analysis.set_up_optimiser()
    result = analysis.solve()
    cpu = time.process_time() - start
    wall = time.perf_counter() - wall
    xopt = np.asarray(result.xopt).ravel()
    if analysis_name in ("min-thrust", "max-thrust"):
        value = abs(result.fopt)
    elif analysis_name == "min-thickness":
        value = float(xopt[-1])  # the thickness variable t
    else:
        value = float(xopt[-1])  # lambda

    faces = []
    for f in form.faces():
        if not form.face_attribute(f, "_is_loaded"):
            continue
        ids = [index[k] for k in form.face_vertices(f)]
        faces += [[ids[0], ids[i], ids[i + 1]] for i in range(1, len(ids) - 1)]
    supports = [index[k] for k in form.vertices_where(is_support=True)]
    voussoir = {
        "vertices": [[x, y, 0.5 * (lo + hi)] for (x, y, _), lo, hi in zip(xyz0, lower, upper)],
        "faces": faces,
        "anchored": supports,
        "lower": lower,
        "upper": upper,
        "loads": [-p for p in pz],
        "objective": analysis_name,
        "fixed_supports": False,
    }
    if pattern is not None:
        voussoir["load_pattern"] = [-float(p) for p in pattern.ravel()]
    quads = sum(1 for f in form.faces() if len(form.face_vertices(f)) > 3)
    return {
        "value": value,
        "success": bool(result.success),
        "message": str(result.message),
        "iterations": result.niter,
        "cpu": cpu,
        "wall": wall,
        "solver_time": result.time,
        "vertices": len(keys),
        "edges": len(list(form.edges_where(_is_edge=True))),
        "quads": quads,
        "total_load": -sum(pz),
        "voussoir": voussoir,
    }


def worker(case_json, out_path):
    import contextlib
    import io

    case = json.loads(case_json)
    log = io.StringIO()
    with contextlib.redirect_stdout(log):
        result = tno_case(case)
    Path(out_path).write_text(json.dumps(result))


# --- outside: run both, print the table ---------------------------------------------------

CASES = [
    {"name": "dome (tutorial)", "kind": "dome", "hoops": 8, "parallels": 20, "thickness": 0.5,
     "analysis": "min-thrust"},
    {"name": "dome (tutorial)", "kind": "dome", "hoops": 8, "parallels": 20, "thickness": 0.5,
     "analysis": "max-thrust"},
    {"name": "cross vault (tutorial)", "kind": "cross", "n": 10, "thickness": 0.5,
     "analysis": "min-thrust"},
    {"name": "cross vault (tutorial)", "kind": "cross", "n": 10, "thickness": 0.5,
     "analysis": "max-load", "point_load": 1.0},
    {"name": "cross vault (tutorial)", "kind": "cross", "n": 10, "thickness": 0.5,
     "analysis": "min-thickness"},
    {"name": "dome", "kind": "dome", "hoops": 16, "parallels": 24, "thickness": 0.5,
     "analysis": "min-thrust", "large": True},
]


def run_case(case):
    out = WORK / "case.json"
    code = f"import sys; sys.path.insert(0, {str(Path(__file__).parent)!r}); import compare; " \
           f"compare.worker({json.dumps(json.dumps(case))}, {str(out)!r})"
    subprocess.run([str(PY), "-c", code], check=True)
    tno = json.loads(out.read_text())
    slug = re.sub(r"[^a-z0-9]+", "-", f"{case['name']} {case['analysis']}".lower()).strip("-")
    problem = WORK / f"problem-{slug}.json"
    problem.write_text(json.dumps(tno["voussoir"]))
    start, before = time.perf_counter(), resource.getrusage(resource.RUSAGE_CHILDREN)
    ours = json.loads(subprocess.run([str(EXE), str(problem)], check=True,
                                     capture_output=True, text=True).stdout)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    ours["wall"] = time.perf_counter() - start
    # CPU seconds of the whole process (reading the JSON included), as compas_tno's.
    ours["cpu"] = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return tno, ours


def ours_value(case, ours, tno):
    a = case["analysis"]
    if a in ("min-thrust", "max-thrust"):
        return ours["thrust_horizontal"]
    if a == "max-load":
        return ours["load_factor"]
    return ours["thickness_scale"] * case["thickness"]


def main():
    quick = "--quick" in sys.argv
    setup()
    print("| case | V | analysis | TNO objective | ours | rel. diff | TNO CPU s | ours s | ratio "
          "| TNO ok | ours certified |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for case in CASES:
        if quick and case.get("large"):
            continue
        tno, ours = run_case(case)
        mine = ours_value(case, ours, tno)
        rel = (mine - tno["value"]) / abs(tno["value"]) if tno["value"] else float("nan")
        print(f"| {case['name']} | {tno['vertices']} | {case['analysis']} | {tno['value']:.4g} "
              f"| {mine:.4g} | {rel:+.2%} | {tno['cpu']:.2f} | {ours['cpu']:.3f} "
              f"| {tno['cpu'] / max(ours['cpu'], 1e-9):.1f}x | {tno['success']} "
              f"| {ours['feasible']} |", flush=True)
        detail = {k: tno[k] for k in ("iterations", "wall", "solver_time", "edges", "quads",
                                      "total_load", "message")}
        detail.update({f"ours_{k}": ours[k] for k in ("iterations", "termination", "eps_inf",
                                                        "thrust_horizontal", "wall", "seconds")})
        print("<!-- " + json.dumps(detail) + " -->", file=sys.stderr, flush=True)


if __name__ == "__main__":
    main()
