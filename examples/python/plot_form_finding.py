"""Form-find a shared model and plot it with matplotlib: the input and the self-supporting
shape side by side, coloured by height change, and the convergence history.

    python examples/python/plot_form_finding.py [MODEL.obj SUPPORTS.json] [--out picture.png]

Without arguments it reads lilium from ../shared/data/models beside the repository.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Optional, Sequence

import matplotlib

import voussoir

MODELS = Path(__file__).resolve().parents[3] / "shared" / "data" / "models"


def plot(mesh: voussoir.Mesh, result: voussoir.FormFindResult, title: str):
    """A figure: input, form-found shape coloured by height change, and eps_inf per step."""
    import matplotlib.pyplot as plt

    before, after = mesh.vertices, result.positions
    change = after[:, 2] - before[:, 2]
    figure = plt.figure(figsize=(13, 4.5))
    for k, (points, colour, label) in enumerate(
        [(before, before[:, 2], "input (height)"), (after, change, "form found (height change)")]
    ):
        axes = figure.add_subplot(1, 3, k + 1, projection="3d")
        surface = axes.plot_trisurf(
            points[:, 0], points[:, 1], points[:, 2], triangles=mesh.faces, cmap="viridis",
            linewidth=0.1, edgecolor="grey",
        )
        surface.set_array(colour[mesh.faces].mean(axis=1))
        surface.autoscale()
        axes.set_title(label)
        axes.set_box_aspect(tuple(points.max(axis=0) - points.min(axis=0) + 1e-9))
        figure.colorbar(surface, ax=axes, shrink=0.6)
    history = figure.add_subplot(1, 3, 3)
    history.semilogy(result.history, marker=".")
    history.set_xlabel("step")
    history.set_ylabel("eps_inf (max residual / mean load)")
    history.set_title(f"{result.termination} after {result.iterations} stress steps")
    figure.suptitle(title)
    figure.tight_layout()
    return figure


def main(argv: Optional[Sequence[str]] = None) -> Path:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("mesh", nargs="?", type=Path, default=MODELS / "lilium.obj")
    p.add_argument("supports", nargs="?", type=Path, default=MODELS / "lilium.json")
    p.add_argument("--out", type=Path, default=Path("form_finding.png"))
    p.add_argument("--show", action="store_true", help="open a window as well")
    a = p.parse_args(argv)
    if not a.show:
        matplotlib.use("Agg")
    mesh = voussoir.Mesh.from_file(a.mesh, a.supports)
    result = voussoir.form_find(mesh)
    figure = plot(mesh, result, f"{a.mesh.stem}: {result.termination_message}")
    figure.savefig(a.out, dpi=110)
    print(f"{a.mesh.stem}: {result.termination}, eps_inf {result.eps_inf:.2e}; wrote {a.out}")
    if a.show:
        import matplotlib.pyplot as plt

        plt.show()
    return a.out


if __name__ == "__main__":
    main()
