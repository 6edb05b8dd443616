"""The least thickness of a semicircular arch and a hemispherical dome in the continuum, under
the convention of `cargo bench --bench assess -- --heyman` (docs/benchmarks.md, "The least
thickness over Heyman's shells").

The convention: shells R ± t/2 (R = 1) read on verticals, the springing plane z = 0 below the
intrados' footprint, the weight t × the area of the vertical reading's middle surface (or, with
--true-middle, of the middle circle or sphere itself), supports at plan radius 1 whose reaction
line reaches z = 0 within t/2 (the springing joint; --no-joint drops it).

Arch: z(x) = z0 - k M(x), k = 1/H, M'' = w; feasibility is linear in (z0, k).
Dome: z'(r) = -W(r) g(r) / 2pi with g = 1/h, h the meridional horizontal thrust per radian;
compressive hoops mean h non-decreasing outward (g non-increasing); linear in (z0, g).
Each t is a linear feasibility problem (scipy's HiGHS); t_min is bisected.
With --rings N N..., the dome on N rings equal in the meridian's angle instead (the rings of
`cargo bench --bench assess -- --heyman`): straight meridian segments between rings, the
bounds at the rings only, each band's weight (its frustum of the read middle surface × t)
lumped half to either ring, compressive hoops, the joint at the support ring.

    python benches/heyman_continuum.py [--true-middle] [--no-joint] [--rings N N...]
"""

import sys

import numpy as np
from scipy.optimize import linprog

ARCH_GRID = 4000
DOME_GRID = 600  # the dome's constraint matrix is dense


def shells(x, t):
    a, b = 1.0 - t / 2.0, 1.0 + t / 2.0
    lower = np.sqrt(np.clip(a * a - x * x, 0.0, None))
    upper = np.sqrt(b * b - x * x)
    return lower, upper


def middle_slope_length(x, t, true_middle):
    """Length of the middle curve per plan length, at the grid's interval midpoints."""
    if true_middle:
        xm = 0.5 * (x[1:] + x[:-1])
        return 1.0 / np.sqrt(np.clip(1.0 - xm * xm, 1e-12, None))
    lower, upper = shells(x, t)
    m = 0.5 * (lower + upper)
    return np.hypot(np.diff(x), np.diff(m)) / np.diff(x)


def arch_fits(t, joint, true_middle):
    x = np.linspace(0.0, 1.0, ARCH_GRID + 1)
    w = t * middle_slope_length(x, t, true_middle)
    dx = np.diff(x)
    shear = np.concatenate([[0.0], np.cumsum(w * dx)])  # ∫0^x w
    moment = np.concatenate([[0.0], np.cumsum(0.5 * (shear[1:] + shear[:-1]) * dx)])
    lower, upper = shells(x, t)
    # z = z0 - k M(x): lower <= z <= upper; z(1) >= 0; joint z(1) <= (t/2) k W.
    a_ub = [np.stack([-np.ones_like(x), moment], 1), np.stack([np.ones_like(x), -moment], 1)]
    b_ub = [-lower, upper]
    if joint:
        a_ub.append(np.array([[1.0, -moment[-1] - 0.5 * t * shear[-1]]]))
        b_ub.append(np.array([0.0]))
    return feasible(np.vstack(a_ub), np.concatenate(b_ub), 2, [(None, None), (0, None)])


def dome_fits(t, joint, true_middle):
    r = np.linspace(0.0, 1.0, DOME_GRID + 1)
    n = DOME_GRID
    dr = np.diff(r)
    rm = 0.5 * (r[1:] + r[:-1])
    area = 2.0 * np.pi * rm * middle_slope_length(r, t, true_middle) * dr
    weight_mid = np.cumsum(t * area) - 0.5 * t * area  # W at each interval's midpoint
    weight_end = np.sum(t * area)
    # Unknowns: z0, g_0..g_{n-1}. z(r_i) = z0 - sum_{j<i} W_j g_j dr_j / 2pi.
    drop = np.tril(np.ones((n + 1, n)), -1) * (weight_mid * dr / (2.0 * np.pi))
    lower, upper = shells(r, t)
    ones = np.ones((n + 1, 1))
    rows = [np.hstack([-ones, drop]), np.hstack([ones, -drop])]
    rhs = [-lower, upper]
    # Compressive hoops: g_{j+1} - g_j <= 0.
    mono = np.zeros((n - 1, n + 1))
    mono[np.arange(n - 1), np.arange(1, n)] = -1.0
    mono[np.arange(n - 1), np.arange(2, n + 1)] = 1.0
    rows.append(mono)
    rhs.append(np.zeros(n - 1))
    if joint:
        # z(1) <= (t/2) W(1) g_last / 2pi.
        row = np.hstack([[1.0], -drop[-1]])
        row[-1] -= 0.5 * t * weight_end / (2.0 * np.pi)
        rows.append(row[None, :])
        rhs.append(np.array([0.0]))
    bounds = [(None, None)] + [(0, None)] * n
    return feasible(np.vstack(rows), np.concatenate(rhs), n + 1, bounds)


def rings_fit(t, rings, joint):
    r = np.sin(0.5 * np.pi * np.arange(rings + 1) / rings)
    lower, upper = shells(r, t)
    m = 0.5 * (lower + upper)
    band = np.pi * (r[1:] + r[:-1]) * np.hypot(np.diff(r), np.diff(m)) * t
    p = np.zeros(rings + 1)
    p[:-1] += 0.5 * band
    p[1:] += 0.5 * band
    carried = np.cumsum(p)[:-1]  # the weight crossing segment k (rings 0..k)
    n = rings
    # Unknowns z0, g_0..g_{n-1}: z_i = z0 - sum_{k<i} dr_k W_k g_k / 2pi.
    drop = np.tril(np.ones((n + 1, n)), -1) * (np.diff(r) * carried / (2.0 * np.pi))
    ones = np.ones((n + 1, 1))
    rows = [np.hstack([-ones, drop]), np.hstack([ones, -drop])]
    rhs = [-lower, upper]
    mono = np.zeros((n - 1, n + 1))
    mono[np.arange(n - 1), np.arange(1, n)] = -1.0
    mono[np.arange(n - 1), np.arange(2, n + 1)] = 1.0
    rows.append(mono)
    rhs.append(np.zeros(n - 1))
    if joint:
        # The support's reaction: H = h_last, V = the weight carried plus its own load.
        row = np.hstack([[1.0], -drop[-1]])
        row[-1] -= 0.5 * t * (carried[-1] + p[-1]) / (2.0 * np.pi)
        rows.append(row[None, :])
        rhs.append(np.array([0.0]))
    bounds = [(None, None)] + [(0, None)] * n
    return feasible(np.vstack(rows), np.concatenate(rhs), n + 1, bounds)


def feasible(a_ub, b_ub, n, bounds):
    result = linprog(np.zeros(n), A_ub=a_ub, b_ub=b_ub, bounds=bounds, method="highs")
    return result.status == 0


def least(fits, lo=0.005, hi=0.3, tol=1e-5):
    assert fits(hi) and not fits(lo), "bracket"
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if fits(mid) else (mid, hi)
    return hi


def main():
    joint = "--no-joint" not in sys.argv
    true_middle = "--true-middle" in sys.argv
    if "--rings" in sys.argv:
        for rings in [int(a) for a in sys.argv[sys.argv.index("--rings") + 1:]]:
            dome = least(lambda t: rings_fit(t, rings, joint), lo=0.001)
            print(f"dome on {rings} rings, joint {joint}: t_min/R {dome:.4f}")
        return
    arch = least(lambda t: arch_fits(t, joint, true_middle))
    dome = least(lambda t: dome_fits(t, joint, true_middle))
    print(f"joint {joint}, weight of the {'true' if true_middle else 'read'} middle surface")
    print(f"arch t_min/R {arch:.4f}\ndome t_min/R {dome:.4f}")


if __name__ == "__main__":
    main()
