"""``python -m voussoir MESH --supports S.json [options]``: the formfind command line in Python.

Reads OBJ, OFF, STL or PLY; writes the form-found mesh (the format of ``--out``) and a JSON
report, all or nothing: bad input or output paths get a one-line message on stderr, a non-zero
exit status and no output files. Exit status: 0 converged (or ``--stress-only`` solved), 3
finished without converging (outputs written), 2 bad input or options, 1 other failure.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, Tuple


import voussoir
from voussoir import _voussoir as _native

BAD_INPUT = 2
NOT_CONVERGED = 3
OUT_DIR = Path("formfind-out")
MESH_SUFFIXES = (".obj", ".off", ".stl", ".ply")


class Failure(Exception):
    """A one-line message and the exit status it ends the run with."""

    def __init__(self, message: str, code: int = BAD_INPUT) -> None:
        super().__init__(message)
        self.code = code


def _bound(flag: str, text: str) -> Tuple[float, str]:
    """``X`` (relative to mean load / half plan diagonal) or ``Xabs`` (absolute)."""
    value, kind = (text[:-3], "absolute") if text.endswith("abs") else (text, "relative")
    try:
        number = float(value)
    except ValueError:
        raise Failure(f"{flag}: expected a number or NUMBERabs, got `{text}`") from None
    if not math.isfinite(number):
        raise Failure(f"{flag}: expected a number or NUMBERabs, got `{text}`")
    return number, kind


def parser() -> argparse.ArgumentParser:
    d = voussoir.defaults()
    # The library's names of each choice (those of the formfind example and the report);
    # the command line cannot give per-vertex values, so no `--tau prescribed`.
    names = _native.choices()
    taus = [t for t in names["tau"] if t != "prescribed"]
    p = argparse.ArgumentParser(
        prog="python -m voussoir",
        description="The nearest self-supporting (compression-only) shape to a triangulated "
        "vault. Defaults in brackets are the library's.",
    )
    p.add_argument("mesh", type=Path, help=".obj, .off, .stl or .ply (x, y plan; z up)")
    anchors = p.add_mutually_exclusive_group(required=True)
    anchors.add_argument("--supports", type=Path, help="JSON file of anchored vertex ids")
    anchors.add_argument("--anchor-boundary", action="store_true", help="anchor every boundary vertex")
    anchors.add_argument("--anchor-lowest", metavar="TOL",
                         help="anchor every vertex within TOL (x bounding-box diagonal, or TOLabs) of the lowest height")
    p.add_argument("--weld", type=float, default=voussoir.WELD_TOLERANCE,
                   help=f"merge vertices closer than TOL x bounding-box diagonal [{voussoir.WELD_TOLERANCE:g}]")
    p.add_argument("--no-weld", action="store_true", help="keep the file's vertices as they are")
    p.add_argument("--up", choices=names["up"], default="z",
                   help="the axis that points up in MESH; y for Y-up files (outputs keep MESH's axes) [z]")
    p.add_argument("--strict", action="store_true", help="reject plan slivers instead of mending them")
    p.add_argument("--out", type=Path, help="form-found mesh [formfind-out/NAME-formfound.obj]")
    p.add_argument("--report", type=Path, help="everything computed, as JSON [formfind-out/report.json]")
    p.add_argument("--stress-only", action="store_true", help="analyse the input shape only")
    p.add_argument("--method", choices=names["method"], default=d["method"], help=f"[{d['method']}]")
    p.add_argument("--fairness", type=float, help=f"nearest method: smoothness weight [{d['fairness']}]")
    p.add_argument("--max-height-change", type=float,
                   help=f"nearest method: largest height change, plan diagonals [{d['max_height_change']}]")
    p.add_argument("--solver", choices=names["formulation"], help=f"[{d['formulation']}]")
    p.add_argument("--qp", choices=names["qp_solver"], help=f"QP solver [{d['qp_solver']}]")
    p.add_argument("--tol", type=float, help=f"stop when eps_inf < T [{d['tolerance']:g}]")
    p.add_argument("--max-iter", type=int, help=f"at most N stress steps [{d['max_iterations']}]")
    p.add_argument("--qmin", help=f"lower bound on force densities, X (relative) or Xabs [{d['q_min']}]")
    p.add_argument("--qmin-scope", choices=names["q_min_scope"], help=f"[{d['q_min_scope']}]")
    p.add_argument("--qmax", help="upper bound on force densities as --qmin, or none [none]")
    p.add_argument("--tau", choices=taus, help=f"normal push at free edges [{d['tau']}]")
    p.add_argument("--holes", choices=names["holes"], help=f"[{d['holes']}]")
    p.add_argument("--dual-smoothing", type=float, help=f"force-diagram smoothing weight [{d['dual_length_smoothing']}]")
    p.add_argument("--smoothing-decay", type=float, help=f"decay of --dual-smoothing per step [{d['smoothing_decay']}]")
    p.add_argument("--odt", type=int, help=f"ODT sweeps of the plan [{d['odt_iterations']}]")
    p.add_argument("--density", type=float, default=1.0, help="weight per unit area of every face [1]")
    p.add_argument("--load", choices=names["load_rule"], help=f"[{d['load_rule']}]")
    return p


def settings_of(a: argparse.Namespace) -> Dict[str, Any]:
    """The options given, as keyword settings of `voussoir.form_find`."""
    s: Dict[str, Any] = {"method": a.method}
    plain = {
        "fairness": a.fairness,
        "max_height_change": a.max_height_change,
        "tolerance": a.tol,
        "max_iterations": a.max_iter,
        "q_min_scope": a.qmin_scope,
        "holes": a.holes,
        "formulation": a.solver,
        "tau": a.tau,
        "load_rule": a.load,
        "dual_length_smoothing": a.dual_smoothing,
        "smoothing_decay": a.smoothing_decay,
        "odt_iterations": a.odt,
        "qp_solver": a.qp,
    }
    s.update({k: v for k, v in plain.items() if v is not None})
    if a.qmin is not None:
        s["q_min"], s["q_min_kind"] = _bound("--qmin", a.qmin)
    if a.qmax is not None and a.qmax != "none":
        s["q_max"], s["q_max_kind"] = _bound("--qmax", a.qmax)
    return s


def read_model(a: argparse.Namespace, density: float) -> voussoir.Mesh:
    """The mesh of the command line, read by the library's one read path."""
    lowest: Optional[Tuple[float, str]] = None
    if a.anchor_lowest is not None:
        lowest = _bound("--anchor-lowest", a.anchor_lowest)
        if lowest[0] < 0:
            raise Failure(f"--anchor-lowest: expected a number >= 0 or NUMBERabs, got `{a.anchor_lowest}`")
    return voussoir.Mesh.from_file(
        a.mesh,
        a.supports,
        anchor_boundary=a.anchor_boundary,
        anchor_lowest=None if lowest is None else lowest[0],
        anchor_lowest_absolute=lowest is not None and lowest[1] == "absolute",
        weld=not a.no_weld,
        weld_tolerance=a.weld,
        repair_tolerance=0.0 if a.strict else None,
        up=a.up,
        face_density=density,
    )


def _write_all(files: Sequence[Tuple[Path, Any]]) -> None:
    """Writes every (path, writer) beside its target under a temporary name, then renames
    them all: on any failure no target is touched."""
    staged: List[Tuple[Path, str]] = []
    try:
        for target, write in files:
            target.parent.mkdir(parents=True, exist_ok=True)
            fd, temp = tempfile.mkstemp(dir=target.parent, suffix=target.suffix, prefix=".voussoir-")
            os.close(fd)
            staged.append((target, temp))
            write(temp)
        for target, temp in staged:
            os.replace(temp, target)
    finally:
        for _, temp in staged:
            if os.path.exists(temp):
                os.remove(temp)


def run(argv: Optional[Sequence[str]] = None) -> int:
    a = parser().parse_args(argv)
    settings = settings_of(a)
    name = a.mesh.stem
    out = a.out or OUT_DIR / f"{name}-formfound.obj"
    report_path = a.report or OUT_DIR / "report.json"
    if out.suffix.lower() not in MESH_SUFFIXES:
        raise Failure(f"--out: {out}: unknown mesh format (use .obj, .off, .stl or .ply)")
    if a.density <= 0:
        raise Failure(f"--density: must be > 0, got {a.density}")
    try:
        mesh = read_model(a, a.density)
        # The natives, asked for the library's report (the formfind example's schema).
        if a.stress_only:
            fields = _native.analyse(mesh._native, settings, True)
            result: voussoir.StressResult = voussoir.StressResult._from_native(fields)
            done = result.status in ("solved", "almost_solved")
            summary = f"stress only ({result.status}): eps_inf = {result.eps_inf:.2e}"
        else:
            fields = _native.form_find(mesh._native, settings, None, True)
            found = voussoir.FormFindResult._from_native(fields)
            result, done = found, found.converged
            summary = (
                f"{found.termination.replace('_', ' ')} after {found.iterations} iterations: "
                f"eps_inf = {found.eps_inf:.2e}; height change max {100 * found.max_change:.3f}%"
                f" of the plan diagonal"
            )
    except voussoir.VoussoirError as e:
        raise Failure(str(e), 1 if "numerical failure" in str(e) else BAD_INPUT) from None
    text = fields["report"]

    def write_report(path: str) -> None:
        Path(path).write_text(text)

    try:
        _write_all([(out, lambda p: mesh.write(p, result.positions)), (report_path, write_report)])
    except (OSError, voussoir.VoussoirError) as e:
        raise Failure(str(e), 1) from None
    print(f"{name}: {len(mesh.vertices)} vertices, {len(mesh.faces)} faces, {len(mesh.anchored)} anchored")
    print(summary)
    print(f"wrote: {out} (form-found mesh), {report_path} (report)")
    if not done:
        print("voussoir: not converged: the outputs hold the best state reached", file=sys.stderr)
        return NOT_CONVERGED
    return 0


def main(argv: Optional[Sequence[str]] = None) -> int:
    try:
        return run(argv)
    except Failure as f:
        print(f"voussoir: error: {' '.join(str(f).split())}", file=sys.stderr)
        return f.code
    except KeyboardInterrupt:
        print("voussoir: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
