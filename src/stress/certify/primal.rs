//! A primal active-set method from a feasible answer, each working set's QP solved at its own
//! conditioning (`augmented`).
//!
//! Where a shape nearly stands its QP has directions that only the regulariser ε Σ l² q²
//! bends, and the optimum lies far along them, settled by many bounds (docs/solver.md). The
//! method keeps every bound: from the answer at hand it steps towards the working set's
//! optimum as far as the bounds allow; an unknown that stops the step is held on its bound;
//! at a working set's optimum the held unknown whose multiplier has the most wrong sign is
//! released. Every step lowers the objective and keeps the balance rows (a step of length a
//! scales the imbalance by 1 − a).

use super::active::objective;
use super::augmented::{Augmented, Rows};
use super::kkt::{EdgeQp, Side2};

/// Steps at most (each a factorisation of the augmented system and its refinement).
const STEPS: usize = 800;
/// A held unknown is released when its multiplier has the wrong sign by more than this share
/// of the largest size of the multipliers' terms.
const DUAL_TOL: f64 = 1e-9;

/// The descent's answer: the lowest-objective point it reached, and whether it ended at a
/// working set's optimum with no multiplier of the wrong sign, refined to `1e-10`.
pub(super) struct Descended {
    pub(super) x: Vec<f64>,
    pub(super) optimal: bool,
}

/// The descent from `x0` (within its bounds, its balance rows held to rounding); None when no
/// step was taken.
pub(super) fn descend(qp: &EdgeQp, x0: &[f64]) -> Option<Descended> {
    let rows = Rows::new(qp);
    let mut x: Vec<f64> = (0..qp.n())
        .map(|k| x0[k].clamp(qp.lo[k], qp.up[k]))
        .collect();
    let mut side: Vec<Side2> = (0..qp.n())
        .map(|k| {
            if x[k] <= qp.lo[k] {
                Side2::Lower
            } else if x[k] >= qp.up[k] {
                Side2::Upper
            } else {
                Side2::Free
            }
        })
        .collect();
    let mut best: Option<(f64, Descended)> = None;
    let mut released: Option<usize> = None;
    for _ in 0..STEPS {
        crate::interrupt::poll();
        let system = Augmented::new(qp, &rows, &side)?;
        let sol = system.optimum(qp, &rows, &x)?;
        let (a, blocker) = ratio_test(qp, &side, &x, &sol.x);
        for k in 0..qp.n() {
            if side[k] == Side2::Free {
                x[k] = (x[k] + a * (sol.x[k] - x[k])).clamp(qp.lo[k], qp.up[k]);
            }
        }
        let mut optimal = false;
        if let Some(k) = blocker {
            side[k] = if sol.x[k] < x[k] {
                Side2::Lower
            } else {
                Side2::Upper
            };
            x[k] = if side[k] == Side2::Lower {
                qp.lo[k]
            } else {
                qp.up[k]
            };
            // Released and held again at once: the multipliers' signs are rounding.
            if released == Some(k) && a == 0.0 {
                break;
            }
            released = None;
        } else {
            released = most_wrong(&side, &sol.z);
            match released {
                Some(k) => side[k] = Side2::Free,
                None => optimal = sol.error < 1e-10,
            }
        }
        let value = objective(qp, &x);
        if best.as_ref().is_none_or(|b| value < b.0 || optimal) {
            let x = x.clone();
            best = Some((value, Descended { x, optimal }));
        }
        if optimal || (blocker.is_none() && released.is_none()) {
            break;
        }
    }
    best.map(|b| b.1)
}

/// The largest step a ≤ 1 from x towards `target` that keeps every free unknown within its
/// bounds, with the free unknown that limits it (None when the whole step is taken).
fn ratio_test(qp: &EdgeQp, side: &[Side2], x: &[f64], target: &[f64]) -> (f64, Option<usize>) {
    let mut best = (1.0, None);
    for k in (0..qp.n()).filter(|&k| side[k] == Side2::Free) {
        let p = target[k] - x[k];
        let room = if p < 0.0 {
            (x[k] - qp.lo[k]) / -p
        } else if p > 0.0 {
            (qp.up[k] - x[k]) / p
        } else {
            continue;
        };
        if room.max(0.0) < best.0 {
            best = (room.max(0.0), Some(k));
        }
    }
    best
}

/// The held unknown whose multiplier has the most wrong sign beyond `DUAL_TOL`, if any.
fn most_wrong(side: &[Side2], z: &[[f64; 2]]) -> Option<usize> {
    let scale = (0..side.len())
        .filter(|&k| side[k] != Side2::Free)
        .fold(0.0f64, |m, k| m.max(z[k][1]));
    let wrong = |k: usize| match side[k] {
        Side2::Lower => -z[k][0],
        Side2::Upper => z[k][0],
        Side2::Free => 0.0,
    };
    (0..side.len())
        .filter(|&k| wrong(k) > DUAL_TOL * scale)
        .max_by(|&a, &b| wrong(a).total_cmp(&wrong(b)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stress::sparse::Csr;

    /// ½ (x0 − x1 − 2)² + ½ w ‖x‖² subject to x0 + x1 + x2 = 3 and x ≥ `lo`, w = 1e-16: along
    /// the line where the residual vanishes only the regulariser bends the objective.
    fn line_qp(lo: f64) -> EdgeQp {
        let mut a = Csr::new(3);
        a.push_row(vec![(0, 1.0), (1, -1.0)]);
        let mut b = Csr::new(3);
        for k in 0..3 {
            b.push_row(vec![(k, 1.0)]);
        }
        let mut eq = Csr::new(3);
        eq.push_row(vec![(0, 1.0), (1, 1.0), (2, 1.0)]);
        EdgeQp {
            a,
            t: vec![2.0],
            b,
            s: vec![0.0; 3],
            w: vec![1e-16; 3],
            eq,
            f: vec![3.0],
            lo: vec![lo; 3],
            up: vec![f64::INFINITY; 3],
        }
    }

    #[test]
    fn reaches_the_optimum_the_regulariser_alone_settles() {
        // On the line x = (2 + s, s, 1 − 2s) the regulariser's minimum is s = 0.
        let d = descend(&line_qp(-10.0), &[1.0, 1.0, 1.0]).expect("descended");
        assert!(d.optimal);
        for (v, want) in d.x.iter().zip([2.0, 0.0, 1.0]) {
            assert!((v - want).abs() < 1e-9, "{:?}", d.x);
        }
    }

    #[test]
    fn holds_the_bounds_that_settle_the_optimum() {
        // With x ≥ 0.5 the residual cannot vanish: the optimum is (2, 0.5, 0.5).
        let d = descend(&line_qp(0.5), &[1.0, 1.0, 1.0]).expect("descended");
        assert!(d.optimal);
        for (v, want) in d.x.iter().zip([2.0, 0.5, 0.5]) {
            assert!((v - want).abs() < 1e-12, "{:?}", d.x);
        }
    }
}
