"""Warm re-solve after an edit: ``form_find(mesh, start=previous)``.

A dome's free vertex raised by 1% of the plan diagonal, and one more support: the warm answer
converges, in equilibrium by residuals recomputed here from its positions and forces, with the
supports where the edited mesh has them, as near the edited input as a cold form finding
(RMS change within 8%), in fewer stress steps. What does not fit is refused naming ``start``.
"""

from __future__ import annotations

import numpy as np
import pytest

import voussoir

RINGS, SECTORS = 6, 16


def dome(raise_vertex: float = 0.0, extra_support: bool = False) -> voussoir.Mesh:
    """A dome over the unit disk with a gentle bump, quads split along alternating diagonals,
    outer ring anchored; vertex 0 (the crown) raised by `raise_vertex`."""
    points = [[0.0, 0.0, 0.5 + raise_vertex]]
    for r in range(1, RINGS + 1):
        for s in range(SECTORS):
            a, rr = 2 * np.pi * s / SECTORS, r / RINGS
            z = 0.5 * (1 - rr * rr) + 0.02 * np.sin(3 * a) * rr * (1 - rr)
            points.append([rr * np.cos(a), rr * np.sin(a), z])

    def vid(r: int, s: int) -> int:
        return 1 + (r - 1) * SECTORS + s % SECTORS

    faces = [[0, vid(1, s), vid(1, s + 1)] for s in range(SECTORS)]
    for r in range(1, RINGS):
        for s in range(SECTORS):
            if (r + s) % 2 == 0:
                faces += [[vid(r, s), vid(r + 1, s), vid(r + 1, s + 1)],
                          [vid(r, s), vid(r + 1, s + 1), vid(r, s + 1)]]
            else:
                faces += [[vid(r, s), vid(r + 1, s), vid(r, s + 1)],
                          [vid(r + 1, s), vid(r + 1, s + 1), vid(r, s + 1)]]
    anchored = [vid(RINGS, s) for s in range(SECTORS)]
    if extra_support:
        anchored.append(vid(RINGS - 1, 0))
    return voussoir.Mesh(np.array(points), np.array(faces), anchored)


def residual_eps(mesh: voussoir.Mesh, r: voussoir.FormFindResult) -> float:
    """eps_inf recomputed from the result's positions and force densities: loads a third of
    each 3-D triangle's area, vertical residuals at the non-anchored vertices."""
    p, faces = r.positions, mesh.faces
    a, b, c = p[faces[:, 0]], p[faces[:, 1]], p[faces[:, 2]]
    area = np.linalg.norm(np.cross(b - a, c - a), axis=1) / 2
    load = np.zeros(len(p))
    for k in range(3):
        np.add.at(load, faces[:, k], area / 3)
    res = np.zeros(len(p))
    i, j = mesh.edges[:, 0], mesh.edges[:, 1]
    dz = p[i, 2] - p[j, 2]
    np.add.at(res, i, r.force_densities * dz)
    np.add.at(res, j, -r.force_densities * dz)
    free = np.setdiff1d(np.arange(len(p)), mesh.anchored)
    return float(np.max(np.abs(res[free] - load[free])) / np.mean(load[free]))


def rms_change(mesh: voussoir.Mesh, positions: np.ndarray) -> float:
    free = np.setdiff1d(np.arange(len(positions)), mesh.anchored)
    return float(np.sqrt(np.mean((positions[free, 2] - mesh.vertices[free, 2]) ** 2)))


@pytest.mark.parametrize("edit", ["one vertex raised", "one support added"])
def test_a_warm_resolve_after_an_edit(edit: str) -> None:
    previous = voussoir.form_find(dome())
    assert previous.converged
    edited = dome(0.02) if edit == "one vertex raised" else dome(extra_support=True)
    warm = voussoir.form_find(edited, start=previous)
    cold = voussoir.form_find(edited)
    assert warm.converged and cold.converged, (warm.termination_message, cold.termination_message)
    assert residual_eps(edited, warm) < 1e-6
    anchored = edited.anchored
    np.testing.assert_array_equal(warm.positions[anchored, 2], edited.vertices[anchored, 2])
    assert warm.iterations < cold.iterations, (warm.iterations, cold.iterations)
    assert rms_change(edited, warm.positions) <= 1.08 * rms_change(edited, cold.positions)


def test_what_does_not_fit_is_refused() -> None:
    previous = voussoir.form_find(dome())
    square = voussoir.Mesh(
        [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 0.3]],
        [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]],
        [0, 1, 2, 3],
    )
    with pytest.raises(voussoir.VoussoirError, match="argument `start`: has 97 vertices"):
        voussoir.form_find(square, start=previous)
    with pytest.raises(voussoir.VoussoirError, match="argument `start`"):
        voussoir.form_find(dome(), start=voussoir.analyse(dome()))
    with pytest.raises(voussoir.VoussoirError, match="argument `method`"):
        voussoir.form_find(dome(), start=previous, method="paper")


def test_a_result_copies_and_pickles_with_its_warm_state_or_without_it():
    """Copies (``copy``, ``dataclasses.asdict``) share the immutable warm state and still
    start a warm re-solve; a pickled result keeps its fields but not the process's solver
    state, and is refused as a start naming ``start``."""
    import copy
    import dataclasses
    import pickle

    mesh = dome()
    first = voussoir.form_find(mesh)
    for twin in (copy.copy(first), copy.deepcopy(first)):
        again = voussoir.form_find(mesh, start=twin)
        assert again.termination == "converged"
    fields = dataclasses.asdict(first)
    assert np.array_equal(fields["positions"], first.positions)
    back = pickle.loads(pickle.dumps(first))
    assert np.array_equal(back.positions, first.positions) and back._warm is None
    with pytest.raises(voussoir.VoussoirError, match="argument `start`: .*unpickled"):
        voussoir.form_find(mesh, start=back)
