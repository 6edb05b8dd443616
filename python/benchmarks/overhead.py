"""The Python package's overhead on lilium's form finding, against the Rust call it wraps.

    python python/benchmarks/overhead.py [--runs 5] [--models DIR]

"Rust" is `FormFindResult.total_seconds`, the time the Rust `form_find` measures around its
own work; "Python" is the wall time of `voussoir.form_find` (settings, the GIL released and
re-taken for the progress hook, result arrays). Medians over the runs; the target is an
overhead under 5%. It prints a table and asserts nothing about time.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import voussoir

MODELS = Path(__file__).resolve().parents[3] / "shared" / "data" / "models"


def measure(mesh: voussoir.Mesh, runs: int, **kwargs):
    """(Python wall seconds, Rust seconds) medians over `runs` calls of form_find."""
    wall, rust = [], []
    for _ in range(runs):
        start = time.perf_counter()
        result = voussoir.form_find(mesh, **kwargs)
        wall.append(time.perf_counter() - start)
        rust.append(result.total_seconds)
    return statistics.median(wall), statistics.median(rust)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, default=5)
    p.add_argument("--models", type=Path, default=MODELS)
    a = p.parse_args()
    start = time.perf_counter()
    mesh = voussoir.Mesh.from_file(a.models / "lilium.obj", a.models / "lilium.json")
    read = time.perf_counter() - start
    rows = [
        ("form_find (no callback)", measure(mesh, a.runs)),
        ("form_find (progress callback)", measure(mesh, a.runs, progress=lambda k, e: None)),
    ]
    print(f"lilium: {len(mesh.vertices)} vertices; Mesh.from_file {1000 * read:.1f} ms; "
          f"median of {a.runs} runs")
    print(f"{'call':<32}{'Python (ms)':>12}{'Rust (ms)':>11}{'overhead':>10}")
    for name, (wall, rust) in rows:
        print(f"{name:<32}{1000 * wall:>12.1f}{1000 * rust:>11.1f}{100 * (wall - rust) / rust:>9.2f}%")


if __name__ == "__main__":
    main()
