//! The active-set polish: the optimum of the edge-based QP found from an approximate answer by
//! a primal–dual active-set method, each active set's equality-constrained QP solved exactly
//! (`kkt`). Unknowns on (or beyond) their bounds are held there; the multipliers of the held
//! ones decide which are released. The optimum of the right active set is the QP's optimum
//! itself, to the last digits the data allow.

use super::kkt::{self, dot2, EdgeQp, Side2};

/// Rounds of the active-set method at most (each a factorisation and its refinement).
const ROUNDS: usize = 40;
/// An unknown within this share of its typical size of a bound starts held on it.
const ACTIVE_GUESS: f64 = 1e-7;
/// A held unknown is released when its multiplier has the wrong sign by more than this share
/// of its terms (smaller ones are rounding: the unknown is degenerate, held or not).
const DUAL_TOL: f64 = 1e-9;
/// A free unknown counts as beyond its bound when it passes it by more than this share of
/// its size; within that it is put on the bound.
const PRIMAL_TOL: f64 = 1e-13;

/// The best answer the polish reached: x and whether it is the optimum (no wrong unknown in
/// the last round, and the last solve refined to rounding).
pub(super) struct Polished {
    pub(super) x: Vec<f64>,
    pub(super) optimal: bool,
}

/// ½ ‖A x − t‖² + ½ Σ w_k (b_k·x − s_k)², from its definition by compensated sums.
pub(super) fn objective(qp: &EdgeQp, x: &[f64]) -> f64 {
    let rows = |m: &super::Csr, rhs: &[f64], i: usize| {
        dot2(m.row(i).map(|(c, v)| (v, x[c])).chain([(rhs[i], -1.0)]))
    };
    let a: f64 = (0..qp.a.nrows())
        .map(|i| rows(&qp.a, &qp.t, i).powi(2))
        .sum();
    let b: f64 = (0..qp.b.nrows())
        .map(|i| qp.w[i] * rows(&qp.b, &qp.s, i).powi(2))
        .sum();
    0.5 * (a + b)
}

/// The first guess of the active set from `x0`.
fn guess(qp: &EdgeQp, x0: &[f64]) -> Vec<Side2> {
    let mut sizes: Vec<f64> = x0.iter().map(|v| v.abs()).filter(|v| *v > 0.0).collect();
    let k = sizes.len() / 2;
    let typical = if sizes.is_empty() {
        1.0
    } else {
        *sizes.select_nth_unstable_by(k, f64::total_cmp).1
    };
    (0..qp.n())
        .map(|k| {
            let near = ACTIVE_GUESS * (typical + x0[k].abs());
            if x0[k] - qp.lo[k] <= near {
                Side2::Lower
            } else if qp.up[k] - x0[k] <= near {
                Side2::Upper
            } else {
                Side2::Free
            }
        })
        .collect()
}

/// The polished answer from `x0`, each active set's QP factored with the regularisation
/// `delta` (`kkt::DELTAS`); None when no active set's solve succeeded.
pub(super) fn polish(qp: &EdgeQp, x0: &[f64], delta: f64) -> Option<Polished> {
    let tr = qp.transposes();
    let mut side = guess(qp, x0);
    let mut x = x0.to_vec();
    let mut best: Option<(f64, Polished)> = None;
    for _ in 0..ROUNDS {
        crate::interrupt::poll();
        let sol = kkt::solve(qp, &tr, &side, &x, delta)?;
        let z = qp.multipliers(&tr, &sol);
        // Unknowns beyond their bounds are held on them first; only from a feasible answer
        // are held unknowns whose multiplier has the wrong sign released (normwise: by more
        // than `DUAL_TOL` of the largest term of any multiplier).
        let z_scale = z.iter().fold(0.0f64, |m, v| m.max(v[1]));
        let mut next = side.clone();
        let mut beyond = 0;
        for k in 0..qp.n() {
            let (lo, up, v) = (qp.lo[k], qp.up[k], sol.x[k]);
            let slack = PRIMAL_TOL * (v.abs() + lo.abs().min(up.abs()));
            if side[k] == Side2::Free && (v < lo - slack || v > up + slack) {
                next[k] = if v < lo { Side2::Lower } else { Side2::Upper };
                beyond += 1;
            }
        }
        let mut released = 0;
        if beyond == 0 {
            for k in 0..qp.n() {
                let wrong_sign = match side[k] {
                    Side2::Lower => z[k][0] < -DUAL_TOL * z_scale,
                    Side2::Upper => z[k][0] > DUAL_TOL * z_scale,
                    Side2::Free => false,
                };
                if wrong_sign {
                    next[k] = Side2::Free;
                    released += 1;
                }
            }
        }
        let wrong = beyond + released;
        let feasible = beyond == 0;
        let candidate: Vec<f64> = (0..qp.n())
            .map(|k| sol.x[k].clamp(qp.lo[k], qp.up[k]))
            .collect();
        if feasible {
            let value = objective(qp, &candidate);
            let optimal = wrong == 0 && sol.error < 1e-10;
            if best.as_ref().is_none_or(|b| value < b.0) {
                best = Some((
                    value,
                    Polished {
                        x: candidate,
                        optimal,
                    },
                ));
            }
        }
        if wrong == 0 {
            break;
        }
        (side, x) = (next, sol.x);
    }
    best.map(|b| b.1)
}
