//! The certificate polish: the answer of a stress step's attempts finished in edge
//! coordinates (one force density per edge, docs/solver.md §5).
//!
//! Where a shape nearly stands the QP's optimum is flat and tiny, and the solvers' tolerances
//! (an absolute gap of 1e-12 on Σ r²) bound the residuals only loosely; in reduced
//! coordinates a force density is moreover a difference of Airy values far larger than itself.
//! The polish solves the same QP again in edge coordinates with the native solver and an
//! absolute gap of `GAP_ABS`, and takes its forces only if they keep every bound and the
//! horizontal balance rows and lower the objective, both recomputed from their definition
//! (no cancellation of ½ xᵀPx + cᵀx): the polish never makes an answer worse.

use super::qp::{self, QpInput};
use super::sparse::Csr;
use super::{ipm, StressStatus};

/// The absolute gap (frame units: Σ (r/p̄)²) of the polishing solve, and its relative gap.
const GAP_ABS: f64 = 1e-16;
const GAP_REL: f64 = 1e-12;
/// Its iteration budget.
const MAX_ITER: u32 = 200;

/// The polished force densities per edge and τ per vertex (frame units).
pub(super) struct Certified {
    pub(super) q: Vec<f64>,
    pub(super) tau: Vec<f64>,
}

/// The least-squares rows of the objective Σ_k w_k (a_k·x − t_k)² over x = (q, τ).
struct Objective {
    a: Csr,
    target: Vec<f64>,
    weight: Vec<f64>,
}

impl Objective {
    fn new(inp: &QpInput, incident: &[Vec<usize>], n: usize) -> Objective {
        let (mut a, mut target, mut weight) = (Csr::new(n), Vec::new(), Vec::new());
        for &i in inp.residual_vertices {
            let i = i as usize;
            let mut row = Vec::new();
            for &e in &incident[i] {
                let dz = inp.z[i] - inp.z[qp::other_end(inp, e, i)];
                row.extend(inp.s.row(e).map(|(c, v)| (c, dz * v)));
            }
            a.push_row(row);
            target.push(inp.load[i]);
            weight.push(1.0);
        }
        if inp.regularisation > 0.0 {
            for (e, bound) in inp.bounds.iter().enumerate() {
                if bound.is_some() {
                    a.push_row(inp.s.row(e).collect());
                    target.push(inp.prior.map_or(0.0, |p| p[e]));
                    weight.push(inp.regularisation * inp.length[e] * inp.length[e]);
                }
            }
        }
        if inp.smoothing > 0.0 {
            for row in qp::smoothing_rows(inp, inp.s) {
                a.push_row(row);
                target.push(0.0);
                weight.push(inp.smoothing);
            }
        }
        Objective { a, target, weight }
    }

    /// Per row: a_k·x − t_k, recomputed from x.
    fn residuals(&self, x: &[f64]) -> Vec<f64> {
        let ax = self.a.mul(x);
        ax.iter().zip(&self.target).map(|(v, t)| v - t).collect()
    }

    fn value(&self, x: &[f64]) -> f64 {
        let r = self.residuals(x);
        r.iter().zip(&self.weight).map(|(r, w)| w * r * r).sum()
    }
}

fn mul_t(a: &Csr, y: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; a.ncols];
    for (r, &yr) in y.iter().enumerate() {
        for (c, v) in a.row(r) {
            out[c] += v * yr;
        }
    }
    out
}

/// The polished answer for the edge-based QP `inp` (S a selection, balance rows at every
/// vertex that needs them), from force densities `q0` per edge and τ `tau0` per vertex; None
/// when it does not lower the objective with every bound and balance row kept.
pub(super) fn certify(inp: &QpInput, q0: &[f64], tau0: &[f64]) -> Option<Certified> {
    let n_q = inp.s.ncols;
    let (tau_col, n_tau) = qp::tau_columns(inp, n_q);
    let n = n_q + n_tau;
    let incident = qp::incident_edges(inp);
    let obj = Objective::new(inp, &incident, n);
    let (eq, f) = qp::native_balance_rows(inp, &incident, &tau_col, n);
    let (mut lo, mut up, mut x0): (Vec<f64>, Vec<f64>, Vec<f64>) =
        (vec![0.0; n], vec![f64::INFINITY; n], vec![0.0; n]);
    for (e, bound) in inp.bounds.iter().enumerate() {
        if let (Some((l, u)), Some((c, _))) = (bound, inp.s.row(e).next()) {
            (lo[c], up[c], x0[c]) = (*l, *u, q0[e]);
        }
    }
    for (v, c) in tau_col.iter().enumerate() {
        if let Some(c) = *c {
            x0[c] = tau0[v];
        }
    }
    let tol = ipm::Tolerances {
        gap_abs: GAP_ABS,
        gap_rel: GAP_REL,
        max_iter: MAX_ITER,
        ..ipm::Tolerances::for_size(n)
    };
    let out = qp::solve_native_with(inp, &mut ipm::PatternCache::default(), &tol);
    if out.status == StressStatus::NumericalError {
        return None;
    }
    // An answer at the iteration limit is as welcome as any: it is judged below.
    let mut x = out.y;
    x.resize(n, 0.0);
    for (v, c) in tau_col.iter().enumerate() {
        if let Some(c) = *c {
            x[c] = out.tau[v].max(0.0);
        }
    }
    for k in 0..n {
        x[k] = x[k].clamp(lo[k], up[k]);
    }
    let before = (obj.value(&x0), inf_norm(&balance(&eq, &f, &x0)));
    let after = (obj.value(&x), inf_norm(&balance(&eq, &f, &x)));
    let terms = (0..eq.nrows())
        .map(|r| eq.row(r).map(|(c, v)| (v * x[c]).abs()).sum::<f64>() + f[r].abs())
        .fold(0.0, f64::max);
    let kept = after.1 <= before.1.max(1e-12 * terms);
    if !(after.0 < before.0 && kept) {
        return None;
    }
    let q = (0..inp.bounds.len())
        .map(|e| inp.s.row(e).next().map_or(0.0, |(c, _)| x[c]))
        .collect();
    let tau = tau_col.iter().map(|c| c.map_or(0.0, |c| x[c])).collect();
    Some(Certified { q, tau })
}

fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// H x − f, recomputed from x.
fn balance(eq: &Csr, f: &[f64], x: &[f64]) -> Vec<f64> {
    let hx = eq.mul(x);
    hx.iter().zip(f).map(|(h, f)| h - f).collect()
}

/// The least-squares solution Δy of S Δy = dq (normal equations, with the diagonal raised by
/// 1e-12 of itself against a rank-deficient S), refined once against the residual recomputed
/// from its definition; None if the factorisation fails.
pub(super) fn least_squares(s: &Csr, dq: &[f64]) -> Option<Vec<f64>> {
    use faer::linalg::solvers::Solve;
    use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
    use faer::sparse::SparseColMat;
    use faer::{Mat, Side};
    let n = s.ncols;
    let mut triplets = Vec::new();
    let mut diag = vec![0.0; n];
    for e in 0..s.nrows() {
        for (c1, v1) in s.row(e) {
            diag[c1] += v1 * v1;
            for (c2, v2) in s.row(e).filter(|x| x.0 > c1) {
                triplets.push(faer::sparse::Triplet::new(c2, c1, v1 * v2));
            }
        }
    }
    for (k, d) in diag.iter().enumerate() {
        triplets.push(faer::sparse::Triplet::new(
            k,
            k,
            d * (1.0 + 1e-12) + f64::MIN_POSITIVE,
        ));
    }
    let matrix = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &triplets).ok()?;
    let symbolic = SymbolicLlt::try_new(matrix.symbolic(), Side::Lower).ok()?;
    let llt = Llt::try_new_with_symbolic(symbolic, matrix.as_ref(), Side::Lower).ok()?;
    let mut dy = vec![0.0; n];
    for _ in 0..2 {
        let sd = s.mul(&dy);
        let r: Vec<f64> = dq.iter().zip(&sd).map(|(a, b)| a - b).collect();
        let mut rhs = Mat::from_fn(n, 1, |i, _| 0.0 * i as f64);
        for (i, v) in mul_t(s, &r).into_iter().enumerate() {
            rhs[(i, 0)] = v;
        }
        llt.solve_in_place(rhs.as_mut());
        for (i, d) in dy.iter_mut().enumerate() {
            *d += rhs[(i, 0)];
        }
    }
    Some(dy)
}
