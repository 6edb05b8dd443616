//! Exact horizontal balance for an answer at hand: the smallest change of the force densities
//! and τ, each relative to its distance from its bound, that satisfies every horizontal
//! balance row to rounding.
//!
//! In reduced coordinates horizontal balance holds identically only in exact arithmetic: a
//! force density is a difference of Airy values far larger than itself (four_holes: a plan
//! sliver with a 0.0037° corner, Airy values ~1.7e5), and the rows it leaves unbalanced by
//! 1e-10 of the load can cost a fresh analysis of the same shape, which holds them exactly,
//! an order of magnitude in ε∞.

use super::kkt::{dot2, transpose, EdgeQp};
use super::Csr;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Side};

/// Refinement rounds of the projection.
const ROUNDS: usize = 4;

/// E x − f per row, by compensated sums.
pub(super) fn imbalance(qp: &EdgeQp, x: &[f64]) -> Vec<f64> {
    (0..qp.eq.nrows())
        .map(|i| {
            dot2(
                qp.eq
                    .row(i)
                    .map(|(c, v)| (v, x[c]))
                    .chain([(qp.f[i], -1.0)]),
            )
        })
        .collect()
}

fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// x moved by Δx = −W Eᵀ (E W Eᵀ)⁻¹ (E x − f), W the squared distances of the unknowns from
/// their nearer bound (unknowns on a bound stay), refined `ROUNDS` times; None when the
/// factorisation fails, a bound would be crossed or the imbalance does not fall.
pub(super) fn balanced(qp: &EdgeQp, x0: &[f64]) -> Option<Vec<f64>> {
    let n = qp.n();
    let et = transpose(&qp.eq);
    let before = inf_norm(&imbalance(qp, x0));
    let mut weight: Vec<f64> = (0..n)
        .map(|k| {
            let slack = (x0[k] - qp.lo[k]).min(qp.up[k] - x0[k]).max(0.0);
            slack * slack
        })
        .collect();
    let mut x = x0.to_vec();
    // Unknowns the projection would carry across their bound are put on it and held there,
    // and the projection is solved again.
    for _ in 0..HOLD_ROUNDS {
        let llt = factor(qp, &et, &weight)?;
        let m = qp.eq.nrows();
        for _ in 0..ROUNDS {
            let r = imbalance(qp, &x);
            let mut rhs = Mat::from_fn(m, 1, |i, _| r[i]);
            llt.solve_in_place(rhs.as_mut());
            for k in 0..n {
                let d = dot2(et.row(k).map(|(i, v)| (v, rhs[(i, 0)])));
                x[k] -= weight[k] * d;
            }
        }
        let mut crossed = false;
        for k in 0..n {
            if x[k] < qp.lo[k] || x[k] > qp.up[k] {
                (x[k], weight[k], crossed) = (x[k].clamp(qp.lo[k], qp.up[k]), 0.0, true);
            }
        }
        if !crossed {
            return (inf_norm(&imbalance(qp, &x)) < before).then_some(x);
        }
    }
    None
}

/// Times the projection is solved again with the unknowns it carried across their bounds
/// held on them.
const HOLD_ROUNDS: usize = 4;

/// The factor of E W Eᵀ (diagonal raised by 1e-12 of itself and 1e-14 of the largest).
fn factor(qp: &EdgeQp, et: &Csr, weight: &[f64]) -> Option<Llt<usize, f64>> {
    let m = qp.eq.nrows();
    let mut triplets = Vec::new();
    let mut diag = vec![0.0; m];
    for (k, w) in weight.iter().enumerate() {
        let col: Vec<(usize, f64)> = et.row(k).collect();
        for &(i, vi) in &col {
            diag[i] += w * vi * vi;
            for &(j, vj) in col.iter().filter(|e| e.0 > i) {
                triplets.push(Triplet::new(j, i, w * vi * vj));
            }
        }
    }
    let floor = 1e-14 * diag.iter().fold(0.0f64, |a, b| a.max(*b)) + f64::MIN_POSITIVE;
    for (i, d) in diag.iter().enumerate() {
        triplets.push(Triplet::new(i, i, d * (1.0 + 1e-12) + floor));
    }
    let matrix = SparseColMat::<usize, f64>::try_new_from_triplets(m, m, &triplets).ok()?;
    let symbolic = SymbolicLlt::try_new(matrix.symbolic(), Side::Lower).ok()?;
    Llt::try_new_with_symbolic(symbolic, matrix.as_ref(), Side::Lower).ok()
}
