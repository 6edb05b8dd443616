"""``python -m voussoir MESH --supports S.json [options]``: the formfind command line in Python,
form finding or (``--assess``) masonry assessment.

Reads OBJ, OFF, STL or PLY; writes the form-found mesh (the format of ``--out``) and a JSON
report, all or nothing: bad input or output paths get a one-line message on stderr, a non-zero
exit status and no output files. Exit status: 0 converged (or ``--stress-only`` solved), 3
finished without converging (outputs written), 2 bad input or options, 1 other failure.
"""

from __future__ import annotations

import argparse
import math
import os
import re
import stat
import sys
import tempfile
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

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


class _Once:
    """An option's action that refuses a second use of the option (or of the other spelling of
    the same setting: `--weld` and `--no-weld`), which would otherwise keep the last value
    unseen; the formfind example's rule and messages."""

    SAME = {"no_weld": "weld"}

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace,
                 values: Any, option_string: Optional[str] = None) -> None:
        if self.option_strings:
            flag = self.option_strings[0]
            given: Dict[str, str] = namespace.__dict__.setdefault("_given", {})
            first = given.setdefault(self.SAME.get(self.dest, self.dest), flag)
            if first == flag and getattr(namespace, "_seen_" + self.dest, False):
                raise Failure(f"{flag} is given twice; give it once")
            if first != flag:
                raise Failure(f"{first} and {flag} are both given; give one of them")
            setattr(namespace, "_seen_" + self.dest, True)
        super().__call__(parser, namespace, values, option_string)  # type: ignore[misc]


class _OnceStore(_Once, argparse._StoreAction):
    pass


class _OnceStoreTrue(_Once, argparse._StoreTrueAction):
    pass


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
    # Every option at most once (argument groups share the parser's registry).
    p.register("action", None, _OnceStore)
    p.register("action", "store", _OnceStore)
    p.register("action", "store_true", _OnceStoreTrue)
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
                   help=f"largest height change, plan diagonals [{d['max_height_change']}]")
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
    p.add_argument("--odt", type=int,
                   help="at most N ODT sweeps of the plan: the nearest method runs them on the input "
                   "first; the paper method one before each of its first N stress steps; the first "
                   f"sweep that does not improve the plan's triangles is undone and ends them "
                   f"[{d['odt_iterations']}]")
    p.add_argument("--density", type=float, default=1.0, help="weight per unit area of every face [1]")
    p.add_argument("--load", choices=names["load_rule"], help=f"[{d['load_rule']}]")
    a = p.add_argument_group("assessment (instead of form finding; MESH is the middle surface)")
    a.add_argument("--assess", choices=names["objective"],
                   help="a compression-only thrust surface inside the masonry: the one nearest the "
                   "middle surface, the least thickness, the least or greatest thrust, the largest "
                   "factor on --load-pattern")
    a.add_argument("--thickness", help="thickness along MESH's normals, or `density` (--density / W)")
    a.add_argument("--intrados", type=Path, help="instead of --thickness: the intrados as a mesh file")
    a.add_argument("--extrados", type=Path, help="and the extrados as a mesh file")
    a.add_argument("--unit-weight", type=float, help="weight per unit volume [1]")
    a.add_argument("--fixed-supports", action="store_true", help="keep the supports at MESH's heights")
    a.add_argument("--springing", type=float,
                   help="free supports: the springing plane's height at every support [the "
                   "intrados; the middle surface's height with --thickness]")
    a.add_argument("--reach",
                   help="free supports: the springing joint's reach (half its width) at every "
                   "support, or `inf` (no joint) [half the vertex's thickness, horizontally]")
    a.add_argument("--load-pattern", type=Path,
                   help='max-load: {"loads": [..]}, [..] or {"loads": {"ID": load}}, ids of MESH\'s own vertices')
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
    try:
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
    except voussoir.VoussoirError as e:
        # The ranges are the library's (`ReadOptions::validate`), named by their option.
        named = re.match(r"argument `([^`]*)`: ", str(e))
        if named and named.group(1) in READ_FLAGS:
            raise _flagged(READ_FLAGS[named.group(1)], e) from None
        raise


READ_FLAGS = {"anchor_lowest": "--anchor-lowest", "weld_tolerance": "--weld"}


def _file_kind(mode: int) -> str:
    for test, name in ((stat.S_ISDIR, "a folder"), (stat.S_ISCHR, "a character device"),
                       (stat.S_ISBLK, "a block device"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
                       (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return name
    return "a special file"


def _output_target(option: str, path: Path, inputs: Sequence[Tuple[str, Path]]) -> Path:
    """The file an output replaces (through symbolic links, as the library writes), checked:
    a regular file or none yet, and none of `inputs` (option, path)."""
    try:
        mode = os.stat(path).st_mode
    except OSError:
        mode = None
    if mode is not None and not stat.S_ISREG(mode):
        raise Failure(f"{option}: {path}: is {_file_kind(mode)}, not a regular file: outputs "
                      "replace regular files only")
    target = Path(os.path.realpath(path))
    for name, given in inputs:
        if mode is not None and os.path.exists(given) and os.path.samefile(target, given):
            raise Failure(f"{option} {path} names the input file of {name}: writing it would "
                          "destroy the input; give the output another path")
    return target


def _write_all(files: Sequence[Tuple[Path, Any]]) -> None:
    """Writes every (path, writer) beside its target under a temporary name, then renames
    them all: on any failure no target is touched. Targets are the files symbolic links name
    (see `_output_target`)."""
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


ASSESS_ONLY = ("thickness", "intrados", "extrados", "unit_weight", "load_pattern", "springing",
               "reach")
FORM_FINDING_ONLY = ("stress_only", "fairness", "max_height_change", "solver", "qp", "qmin_scope",
                     "qmax", "tau", "holes", "dual_smoothing", "smoothing_decay", "odt")


def _check_assess(a: argparse.Namespace) -> None:
    """The combinations formfind rejects, with its messages."""
    flag = lambda name: "--" + name.replace("_", "-")  # noqa: E731
    if not a.assess:
        given = [n for n in ASSESS_ONLY if getattr(a, n) is not None] + (
            ["fixed_supports"] if a.fixed_supports else [])
        if given:
            raise Failure(f"{flag(given[0])} needs --assess ANALYSIS")
        return
    for name in FORM_FINDING_ONLY:
        if getattr(a, name) not in (None, False):
            raise Failure(f"{flag(name)} is an option of form finding, not of --assess")
    joint = next((n for n in ("springing", "reach") if getattr(a, n) is not None), None)
    if a.fixed_supports and joint:
        raise Failure(f"{flag(joint)} sets the joint of free supports: it does not go with "
                      "--fixed-supports")
    if a.thickness is None and (a.intrados is None or a.extrados is None):
        raise Failure("--assess needs the masonry's envelope: --thickness T, or --intrados A --extrados B")
    if a.thickness is not None and (a.intrados or a.extrados):
        raise Failure("give --thickness or --intrados and --extrados, not both")
    # --unit-weight's range is the library's (0: no self-weight); density mode divides by it.
    if a.thickness == "density" and a.unit_weight is None:
        raise Failure("--thickness density needs --unit-weight W (thickness = --density / W)")
    if a.thickness == "density" and not a.unit_weight > 0:
        raise Failure(f"--unit-weight: {a.unit_weight:g} must be > 0 with --thickness density "
                      "(thickness = --density / W)")
    if (a.assess == "max-load") != (a.load_pattern is not None):
        raise Failure("--assess max-load needs --load-pattern L.json (the load to multiply)"
                      if a.assess == "max-load" else
                      f"--load-pattern goes with --assess max-load, not with --assess {a.assess}")


def _reach(a: argparse.Namespace) -> Optional[float]:
    """--reach: a length (its range is the library's) or `inf`."""
    if a.reach is None:
        return None
    try:
        b = float(a.reach)
    except ValueError:
        b = math.nan
    if math.isnan(b):
        raise Failure(f"--reach: expected a length or `inf`, got `{a.reach}`")
    return b


def _thickness(a: argparse.Namespace) -> float:
    if a.thickness == "density":
        return a.density / a.unit_weight
    try:
        t = float(a.thickness)
    except ValueError:
        t = math.nan
    if not (math.isfinite(t) and t > 0):
        raise Failure(f"--thickness: expected a thickness > 0 or `density`, got `{a.thickness}`")
    return t


def _flagged(flag: str, e: voussoir.VoussoirError) -> Failure:
    """A library error about the file of `flag`, in the command line's words (as formfind's)."""
    return Failure(f"{flag}: {re.sub(r'^argument `[^`]*`: ', '', str(e))}")


def _load_pattern(path: Path, mesh: voussoir.Mesh) -> np.ndarray:
    """The loads of a JSON file per mesh vertex (the library's `io::read_load_pattern`: loads
    of file vertices welded into one add)."""
    try:
        return _native.read_load_pattern(mesh._native, os.fspath(path))
    except voussoir.VoussoirError as e:
        raise _flagged("--load-pattern", e) from None


def _surface(flag: str, path: Path, up: str) -> Tuple[np.ndarray, np.ndarray]:
    """An intrados or extrados file, Z-up (the library's `io::read_surface`)."""
    try:
        vertices, faces = _native.read_surface(os.fspath(path), up)
    except voussoir.VoussoirError as e:
        raise _flagged(flag, e) from None
    return vertices, faces.astype(np.int64)


def run_assess(a: argparse.Namespace) -> int:
    """`--assess`: the thrust surface as OUT, the report with its "assessment"."""
    name = a.mesh.stem
    out = a.out or OUT_DIR / f"{name}-thrust.obj"
    report_path = a.report or OUT_DIR / "report.json"
    if out.suffix.lower() not in MESH_SUFFIXES:
        raise Failure(f"--out: {out}: unknown mesh format (use .obj, .off, .stl or .ply)")
    thickness = None if a.thickness is None else _thickness(a)
    settings: Dict[str, Any] = {"objective": a.assess, "fixed_supports": a.fixed_supports,
                                "unit_weight": 1.0 if a.unit_weight is None else a.unit_weight}
    if a.load:
        settings["load_rule"] = a.load
    if a.tol is not None:
        settings["tolerance"] = a.tol
    if a.max_iter is not None:
        settings["max_iterations"] = a.max_iter
    if a.qmin is not None:
        settings["q_min"], settings["q_min_kind"] = _bound("--qmin", a.qmin)
    # The input files the report's settings name, as given.
    files = tuple(None if p is None else os.fspath(p)
                  for p in (a.intrados, a.extrados, a.load_pattern))
    try:
        mesh = read_model(a, 1.0)
        if a.load_pattern is not None:
            settings["load_pattern"] = _load_pattern(a.load_pattern, mesh)
        envelope = ((np.array([thickness]), None, None) if thickness is not None
                    else (None, _surface("--intrados", a.intrados, a.up), _surface("--extrados", a.extrados, a.up)))
        # The natives, asked for the library's report (the formfind example's schema).
        joint = {name: None if value is None else np.array(value)
                 for name, value in (("springing", a.springing), ("reach", _reach(a)))}
        fields = _native.assess(mesh._native, *envelope, settings, None, files, **joint)
    except voussoir.VoussoirError as e:
        raise Failure(str(e), 1 if "numerical failure" in str(e) else BAD_INPUT) from None
    least = None if thickness is None or not fields["feasible"] else fields["thickness_scale"] * thickness
    r = voussoir.AssessmentResult._from_native(fields, least)
    text = fields["report"]
    try:
        _write_all([(out, lambda p: mesh.write(p, r.positions)),
                    (report_path, lambda p: Path(p).write_text(text))])
    except (OSError, voussoir.VoussoirError) as e:
        raise Failure(str(e), 1) from None
    verdict = "a thrust surface fits" if r.feasible else "no certified thrust surface"
    print(f"{name}: {len(mesh.vertices)} vertices, {len(mesh.faces)} faces, {len(mesh.anchored)} anchored")
    # A safety factor is proven only by a certified surface.
    safety = f"safety factor {r.safety_factor:.4g}, " if r.feasible else ""
    print(f"assessment {r.objective}: {verdict} ({r.termination.replace('_', ' ')} after "
          f"{r.iterations} steps); {safety}thrust {r.thrust_horizontal:.6g}")
    if r.unbounded:
        what = "the load factor" if r.objective == "max-load" else "the greatest thrust"
        print(f"{what} has no bound: this surface's force densities scaled up by any factor "
              "from some s0 on still fit")
    print(f"wrote: {out} (thrust surface), {report_path} (report)")
    if not r.converged:
        print("voussoir: no certified optimum: the outputs hold the best state reached", file=sys.stderr)
        return NOT_CONVERGED
    return 0


def run(argv: Optional[Sequence[str]] = None) -> int:
    a = parser().parse_args(argv)
    _check_assess(a)
    if a.assess:
        return run_assess(a)
    settings = settings_of(a)
    name = a.mesh.stem
    out = a.out or OUT_DIR / f"{name}-formfound.obj"
    report_path = a.report or OUT_DIR / "report.json"
    if out.suffix.lower() not in MESH_SUFFIXES:
        raise Failure(f"--out: {out}: unknown mesh format (use .obj, .off, .stl or .ply)")
    if a.density <= 0:
        raise Failure(f"--density: must be > 0, got {a.density}")
    inputs = [("MESH", a.mesh)] + ([("--supports", Path(a.supports))] if a.supports else [])
    out_target = _output_target("--out", out, inputs)
    report_target = _output_target("--report", report_path, inputs)
    if out_target == report_target:
        raise Failure(f"--out and --report name the same file {out}; give each its own path")
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
        _write_all([(out_target, lambda p: mesh.write(p, result.positions)),
                    (report_target, write_report)])
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
