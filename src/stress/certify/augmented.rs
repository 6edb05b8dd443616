//! One working set's equality-constrained QP solved at its own conditioning: the problem as
//! an equality-constrained least-squares problem
//!
//!   minimise ‖M x − b‖²  subject to  E x = f  (unknowns of the working set held on their bounds)
//!
//! with M = [A; √w B] and b = [t; √w s], in Björck's scaled augmented form
//!
//!   [ α I    M D    0     ] [ u ]   [ b   ]
//!   [ D Mᵀ   0      D Eᵀ S] [ x̄ ] = [ 0   ]     r = b − M x = α u,  x = D x̄,  λ = −α S μ̄
//!   [ 0      S E D  0     ] [ μ̄ ]   [ S f ]
//!
//! (D unit column scales, S unit row scales of E). The regulariser's rows, one entry each,
//! are eliminated into a diagonal −w v² d² / α of the x block, of the size of α. Nothing is
//! squared and nothing is regularised: the regulariser enters as √w, or as w/α (the
//! directions only it bends have singular values ~√w of M D, where a KKT system with the
//! Hessian holds w), and the balance rows are kept exactly. With α the typical √w of the
//! scaled columns the system's condition is about that of M D itself, so refinement against
//! the exact system, every residual recomputed by compensated sums, converges to rounding.

use super::kkt::{dot2, transpose, unit_row_scales, EdgeQp, Side2};
use super::Csr;
use faer::linalg::solvers::SolveCore;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Conj, MatMut};

/// Refinement steps at most; refinement stops earlier once the error no longer halves.
const REFINE: usize = 20;
/// Refinement steps at least (unless the error is already at rounding).
const MIN_REFINE: usize = 3;

/// The least-squares rows of the QP, M = [A; √w B] and b = [t; √w s], with the transposes of
/// M and E. Rows of B with a single entry (the regulariser's) are not rows of M: each adds
/// w v² to the diagonal `h` of its column and w v s to `c` (their residual unknown eliminated,
/// which leaves a diagonal of the size of α in the x block).
pub(super) struct Rows {
    m: Csr,
    b: Vec<f64>,
    mt: Csr,
    et: Csr,
    h: Vec<f64>,
    c: Vec<f64>,
}

impl Rows {
    pub(super) fn new(qp: &EdgeQp) -> Rows {
        let mut m = Csr::new(qp.n());
        let mut b = qp.t.clone();
        let (mut h, mut c) = (vec![0.0; qp.n()], vec![0.0; qp.n()]);
        for i in 0..qp.a.nrows() {
            m.push_row(qp.a.row(i).collect());
        }
        for i in 0..qp.b.nrows() {
            let mut entries = qp.b.row(i);
            if let (Some((k, v)), None) = (entries.next(), entries.next()) {
                h[k] += qp.w[i] * v * v;
                c[k] += qp.w[i] * v * qp.s[i];
                continue;
            }
            let root = qp.w[i].sqrt();
            m.push_row(qp.b.row(i).map(|(c, v)| (c, root * v)).collect());
            b.push(root * qp.s[i]);
        }
        let (mt, et) = (transpose(&m), transpose(&qp.eq));
        Rows { m, b, mt, et, h, c }
    }
}

/// The solution of one working set's QP: x (held unknowns on their bounds), the multipliers
/// z of the bounds (∂L/∂x: ≥ 0 on a held lower bound at the optimum) with the size of their
/// terms, and the refined error relative to the terms of each block.
pub(super) struct Solution {
    pub(super) x: Vec<f64>,
    pub(super) z: Vec<[f64; 2]>,
    pub(super) error: f64,
}

/// The factored augmented system of one working set.
pub(super) struct Augmented {
    lu: Lu<usize, f64>,
    free: Vec<usize>,
    d: Vec<f64>,
    row_scale: Vec<f64>,
    alpha: f64,
}

impl Augmented {
    /// The system of the working set `side` (held unknowns leave it); None when its
    /// factorisation fails.
    pub(super) fn new(qp: &EdgeQp, rows: &Rows, side: &[Side2]) -> Option<Augmented> {
        let free: Vec<usize> = (0..qp.n()).filter(|&k| side[k] == Side2::Free).collect();
        let (n_f, m_m, m_e) = (free.len(), rows.m.nrows(), qp.eq.nrows());
        let is_free = |c: usize| side[c] == Side2::Free;
        let row_scale = unit_row_scales(&qp.eq, is_free);
        // Unit 2-norm of each free column of [M; S E], and the scaled regulariser's norm.
        let (mut d, mut reg) = (Vec::with_capacity(n_f), Vec::new());
        for &k in &free {
            let mm: f64 = rows.mt.row(k).map(|(_, v)| v * v).sum::<f64>() + rows.h[k];
            let ee: f64 = (rows.et.row(k))
                .map(|(i, v)| (v * row_scale[i]).powi(2))
                .sum();
            let scale = if mm + ee > 0.0 {
                1.0 / (mm + ee).sqrt()
            } else {
                1.0
            };
            d.push(scale);
            let rr: f64 = (rows.mt.row(k).filter(|(i, _)| *i >= qp.a.nrows()))
                .map(|(_, v)| v * v)
                .sum::<f64>()
                + rows.h[k];
            if rr > 0.0 {
                reg.push(rr.sqrt() * scale);
            }
        }
        // α near the smallest singular values of M D (Björck): the typical scaled √w.
        let alpha = if reg.is_empty() {
            1.0
        } else {
            let k = reg.len() / 2;
            reg.select_nth_unstable_by(k, f64::total_cmp)
                .1
                .clamp(1e-12, 1.0)
        };
        let mut col_of = vec![usize::MAX; qp.n()];
        for (j, &k) in free.iter().enumerate() {
            col_of[k] = j;
        }
        let mut triplets = Vec::new();
        for (j, &k) in free.iter().enumerate() {
            triplets.push(Triplet::new(
                m_m + j,
                m_m + j,
                -rows.h[k] * d[j] * d[j] / alpha,
            ));
        }
        for i in 0..m_m {
            triplets.push(Triplet::new(i, i, alpha));
            for (c, v) in rows.m.row(i).filter(|(c, _)| is_free(*c)) {
                let j = col_of[c];
                triplets.push(Triplet::new(i, m_m + j, v * d[j]));
                triplets.push(Triplet::new(m_m + j, i, v * d[j]));
            }
        }
        for (i, s) in row_scale.iter().enumerate() {
            for (c, v) in qp.eq.row(i).filter(|(c, _)| is_free(*c)) {
                let j = col_of[c];
                triplets.push(Triplet::new(m_m + n_f + i, m_m + j, s * v * d[j]));
                triplets.push(Triplet::new(m_m + j, m_m + n_f + i, s * v * d[j]));
            }
        }
        let dim = m_m + n_f + m_e;
        let matrix = SparseColMat::<usize, f64>::try_new_from_triplets(dim, dim, &triplets).ok()?;
        let symbolic = SymbolicLu::try_new(matrix.symbolic()).ok()?;
        let lu = Lu::try_new_with_symbolic(symbolic, matrix.as_ref()).ok()?;
        Some(Augmented {
            lu,
            free,
            d,
            row_scale,
            alpha,
        })
    }

    fn solve(&self, mut rhs: Vec<f64>) -> Vec<f64> {
        let dim = rhs.len();
        self.lu.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(&mut rhs, dim, 1),
        );
        rhs
    }

    /// The working set's optimum, refined from `x0` (held unknowns set to their bounds by
    /// the caller); None when the refinement does not yield finite values.
    pub(super) fn optimum(&self, qp: &EdgeQp, rows: &Rows, x0: &[f64]) -> Option<Solution> {
        let (m_m, n_f, m_e) = (rows.m.nrows(), self.free.len(), qp.eq.nrows());
        let mut x = x0.to_vec();
        let mut u: Vec<f64> = (0..m_m)
            .map(|i| {
                dot2(
                    rows.m
                        .row(i)
                        .map(|(c, v)| (v, -x[c]))
                        .chain([(rows.b[i], 1.0)]),
                )
            })
            .map(|r| r / self.alpha)
            .collect();
        let mut mu = vec![0.0; m_e];
        let (mut best, mut error) = (f64::INFINITY, f64::INFINITY);
        for step in 0..REFINE {
            crate::interrupt::poll();
            let (rhs, e) = self.residual(qp, rows, &x, &u, &mu);
            error = e;
            // The error is relative to the terms, which fall by orders of magnitude in the
            // first corrections where x0 is far from the optimum: it is judged from the third.
            let stalled = step >= MIN_REFINE && error >= 0.5 * best;
            if !error.is_finite() || stalled || error < 1e-16 {
                break;
            }
            best = best.min(error);
            let z = self.solve(rhs);
            u.iter_mut().zip(&z).for_each(|(v, dz)| *v += dz);
            for (j, &k) in self.free.iter().enumerate() {
                x[k] += self.d[j] * z[m_m + j];
            }
            for i in 0..m_e {
                mu[i] += self.row_scale[i] * z[m_m + n_f + i];
            }
        }
        if !error.is_finite() || x.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let z = (0..qp.n())
            .map(|k| {
                let (value, size) = self.gradient_terms(rows, k, &x, &u, &mu);
                [-self.alpha * value, self.alpha * size]
            })
            .collect();
        Some(Solution { x, z, error })
    }

    /// (Mᵀ u + Eᵀ μ − (h x − c) / α)_k by compensated sums, with the sum of its terms' sizes.
    fn gradient_terms(
        &self,
        rows: &Rows,
        k: usize,
        x: &[f64],
        u: &[f64],
        mu: &[f64],
    ) -> (f64, f64) {
        let diagonal = [
            (-rows.h[k] / self.alpha, x[k]),
            (rows.c[k] / self.alpha, 1.0),
        ];
        let terms = || {
            (rows.mt.row(k).map(|(i, v)| (v, u[i])))
                .chain(rows.et.row(k).map(|(i, v)| (v, mu[i])))
                .chain(diagonal)
        };
        (dot2(terms()), terms().map(|(a, b)| (a * b).abs()).sum())
    }

    /// The scaled right side of the correction (the exact system's residuals) and the
    /// largest residual of each block relative to its largest terms.
    fn residual(
        &self,
        qp: &EdgeQp,
        rows: &Rows,
        x: &[f64],
        u: &[f64],
        mu: &[f64],
    ) -> (Vec<f64>, f64) {
        let mut rhs = Vec::with_capacity(u.len() + self.free.len() + mu.len());
        let (mut worst, mut size) = ([0.0f64; 3], [0.0f64; 3]);
        for (i, ui) in u.iter().enumerate() {
            let terms = || {
                (rows.m.row(i).map(|(c, v)| (v, -x[c])))
                    .chain([(rows.b[i], 1.0), (*ui, -self.alpha)])
            };
            let r = dot2(terms());
            worst[0] = worst[0].max(r.abs());
            size[0] = size[0].max(terms().map(|(a, b)| (a * b).abs()).sum());
            rhs.push(r);
        }
        for (j, &k) in self.free.iter().enumerate() {
            let (g, s) = self.gradient_terms(rows, k, x, u, mu);
            worst[1] = worst[1].max(g.abs());
            size[1] = size[1].max(s);
            rhs.push(-self.d[j] * g);
        }
        for i in 0..qp.eq.nrows() {
            let terms = || (qp.eq.row(i).map(|(c, v)| (v, -x[c]))).chain([(qp.f[i], 1.0)]);
            let r = dot2(terms());
            worst[2] = worst[2].max(r.abs());
            size[2] = size[2].max(terms().map(|(a, b)| (a * b).abs()).sum());
            rhs.push(self.row_scale[i] * r);
        }
        let error = (0..3)
            .map(|b| {
                if size[b] > 0.0 {
                    worst[b] / size[b]
                } else {
                    0.0
                }
            })
            .fold(0.0, f64::max);
        (rhs, error)
    }
}
