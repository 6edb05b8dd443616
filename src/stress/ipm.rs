//! A primal–dual interior-point method (Mehrotra predictor–corrector) for sparse convex QPs of
//! the stress step's shape:
//!
//!   minimise    ½ xᵀ P x + cᵀ x,   P = Σ_k ρ_k a_kᵀ a_k   (rows a_k of `quad`)
//!   subject to  E x = f,   G x ≥ h
//!
//! Each Newton step is solved through the normal matrix P + Cᵀ W C, C = [E; G], with
//! W = 1 / (s/z + δ) on inequality rows and 1 / δ on equality rows: one sparse positive
//! definite factorisation whose symbolic analysis (fill-reducing ordering, supernodes) is
//! done once, since only W changes. δ caps the weights (their rounding would otherwise swamp
//! the small curvatures) and iterative refinement against the exact augmented system removes
//! its effect. In weight space every row a_k and c_i touches a vertex's one-ring, so the
//! matrix has the two-ring pattern of the mesh: much smaller than a generic conic solver's
//! KKT system (MATH §8).
//!
//! The method has no infeasibility certificates: it reports failure and the caller falls back
//! to clarabel, which decides.

use super::sparse::Csr;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LdltRef, SymbolicCholesky,
    SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par};

/// A QP in the form above.
pub struct Qp<'a> {
    pub quad: &'a Csr,
    pub quad_weight: &'a [f64],
    pub c: &'a [f64],
    /// Constant added to ½ xᵀPx + cᵀx so that the objective is the true one (for the
    /// relative gap).
    pub constant: f64,
    pub eq: &'a Csr,
    pub f: &'a [f64],
    pub ineq: &'a Csr,
    pub h: &'a [f64],
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IpmStatus {
    Solved,
    /// The method stopped (iteration limit or numerical trouble) at a point that meets the
    /// tolerances relaxed by `Tolerances::almost`.
    AlmostSolved,
    MaxIterations,
    /// Factorisation failed or the iterates diverged (typically an infeasible or degenerate
    /// problem).
    NumericalError,
}

pub struct IpmOutput {
    pub x: Vec<f64>,
    pub status: IpmStatus,
    pub iterations: u32,
}

/// Tolerances: the gap sᵀz must fall below `gap_abs + gap_rel |objective|` and every
/// residual below `feas` relative to its data.
#[derive(Debug, Clone, Copy)]
pub struct Tolerances {
    pub gap_abs: f64,
    pub gap_rel: f64,
    pub feas: f64,
    /// Factor by which all tolerances are relaxed for `AlmostSolved`.
    pub almost: f64,
    pub max_iter: u32,
}

impl Default for Tolerances {
    fn default() -> Self {
        // As tight as the clarabel settings in qp.rs: residuals must be reproducible to ~1e-6
        // of the mean load, and the objective (Σ r²) is often ~0 at the optimum.
        Tolerances {
            gap_abs: 1e-12,
            gap_rel: 1e-11,
            feas: 1e-10,
            almost: 10.0,
            // Well-posed problems converge in 15–60 iterations; beyond, the caller's fallback
            // is cheaper than crawling on.
            max_iter: 80,
        }
    }
}

/// The normal matrix P + Cᵀ W C (lower triangle, compressed columns) with the value slot of
/// every product c_ia c_ib of each constraint row precomputed, and its symbolic factorisation.
struct Normal {
    n: usize,
    m_eq: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Values of P alone.
    p_values: Vec<f64>,
    /// Per constraint row: (slot, c_ia c_ib) for its products.
    row_start: Vec<usize>,
    row_slot: Vec<(usize, f64)>,
    diag: Vec<usize>,
    symbolic: SymbolicCholesky<usize>,
}

impl Normal {
    /// `cons` = [E; G] with `m_eq` equality rows first.
    fn new(quad: &Csr, quad_weight: &[f64], cons: &Csr, m_eq: usize) -> Option<Normal> {
        let n = cons.ncols;
        // Pattern as (col, row) with row ≥ col.
        let mut entries: Vec<(usize, usize)> = (0..n).map(|i| (i, i)).collect();
        for m in [quad, cons] {
            for r in 0..m.nrows() {
                let cols = &m.col[m.start[r]..m.start[r + 1]];
                for &a in cols {
                    entries.extend(cols.iter().filter(|&&b| b <= a).map(|&b| (b, a)));
                }
            }
        }
        entries.sort_unstable();
        entries.dedup();
        let mut col_ptr = vec![0; n + 1];
        for &(c, _) in &entries {
            col_ptr[c + 1] += 1;
        }
        for c in 0..n {
            col_ptr[c + 1] += col_ptr[c];
        }
        let row_idx: Vec<usize> = entries.iter().map(|&(_, r)| r).collect();
        drop(entries);
        let slot = |row: usize, col: usize| -> usize {
            let range = col_ptr[col]..col_ptr[col + 1];
            col_ptr[col]
                + row_idx[range]
                    .binary_search(&row)
                    .expect("entry in the pattern")
        };
        let mut p_values = vec![0.0; row_idx.len()];
        for (r, &w) in quad_weight.iter().enumerate() {
            for (a, va) in quad.row(r) {
                for (b, vb) in quad.row(r).filter(|&(b, _)| b <= a) {
                    p_values[slot(a, b)] += w * va * vb;
                }
            }
        }
        let mut row_start = vec![0];
        let mut row_slot = Vec::new();
        for r in 0..cons.nrows() {
            for (a, va) in cons.row(r) {
                for (b, vb) in cons.row(r).filter(|&(b, _)| b <= a) {
                    row_slot.push((slot(a, b), va * vb));
                }
            }
            row_start.push(row_slot.len());
        }
        let diag = (0..n).map(|i| slot(i, i)).collect();
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
        let symbolic = factorize_symbolic_cholesky(
            pattern,
            faer::Side::Lower,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams {
                // The simplicial variant is several times slower on these two-ring matrices
                // even at a thousand unknowns.
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            },
        )
        .ok()?;
        Some(Normal {
            n,
            m_eq,
            col_ptr,
            row_idx,
            p_values,
            row_start,
            row_slot,
            diag,
            symbolic,
        })
    }

    /// y = P x from the stored lower triangle.
    fn mul_p(&self, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; self.n];
        for c in 0..self.n {
            let mut acc = 0.0;
            for k in self.col_ptr[c]..self.col_ptr[c + 1] {
                let r = self.row_idx[k];
                let v = self.p_values[k];
                y[r] += v * x[c];
                if r != c {
                    acc += v * x[r];
                }
            }
            y[c] += acc;
        }
        y
    }
}

/// Regularisation δ of the constraint rows (scaled units): inequality weights z/s are capped
/// near 1/δ, equality rows weigh 1/δ_eq. Larger weights would lose the small curvatures to
/// rounding; refinement removes the regularisation's effect on the solution.
const DELTA: f64 = 1e-8;
const DELTA_EQ: f64 = 1e-6;

/// Static regularisations of the normal matrix tried in turn until the factor is sound.
const REGULARISATION: [f64; 3] = [1e-12, 1e-9, 1e-6];

/// The Newton system in augmented form, for unknowns (dx, w):
///
///   P dx + Cᵀ w = b1,   C dx − D w = b2      (C = [E; G], D = 0 on E, s / z on G)
///
/// solved with the factor of P + Cᵀ (D + δ)⁻¹ C, then refined against the exact system.
struct Newton<'a> {
    normal: &'a Normal,
    cons: &'a Csr,
    /// D per constraint row, and the weights 1 / (D + δ) the factor uses.
    d: Vec<f64>,
    w_reg: Vec<f64>,
    l_values: Vec<f64>,
    buffer: MemBuffer,
}

impl<'a> Newton<'a> {
    fn new(normal: &'a Normal, cons: &'a Csr, d: Vec<f64>, reg: f64) -> Option<Newton<'a>> {
        let n = normal.n;
        let w_reg: Vec<f64> = d
            .iter()
            .enumerate()
            .map(|(r, d)| 1.0 / (d + if r < normal.m_eq { DELTA_EQ } else { DELTA }))
            .collect();
        let mut values = normal.p_values.clone();
        for (r, &w) in w_reg.iter().enumerate() {
            for &(slot, prod) in &normal.row_slot[normal.row_start[r]..normal.row_start[r + 1]] {
                values[slot] += w * prod;
            }
        }
        // A static regularisation keeps columns that only inactive bounds hold (pivots
        // ~ z/s → 0) away from zero; refinement removes its effect.
        for &k in &normal.diag {
            values[k] += reg;
        }
        let par = Par::Seq;
        let mut l_values = vec![0.0; normal.symbolic.len_val()];
        let scratch = normal
            .symbolic
            .factorize_numeric_ldlt_scratch::<f64>(par, Default::default())
            .or(normal.symbolic.solve_in_place_scratch::<f64>(1, par));
        let mut buffer = MemBuffer::try_new(scratch).ok()?;
        let signs = vec![1i8; n];
        let matrix = SparseColMatRef::new(
            SymbolicSparseColMatRef::new_checked(n, n, &normal.col_ptr, None, &normal.row_idx),
            &values,
        );
        // Pivots that rounding makes non-positive are replaced by a huge value: that
        // direction then stays put for this solve instead of being amplified.
        normal
            .symbolic
            .factorize_numeric_ldlt(
                &mut l_values,
                matrix,
                faer::Side::Lower,
                LdltRegularization {
                    dynamic_regularization_signs: Some(&signs),
                    dynamic_regularization_delta: 1e20,
                    dynamic_regularization_epsilon: 1e-14,
                },
                par,
                MemStack::new(&mut buffer),
                Default::default(),
            )
            .ok()?;
        Some(Newton {
            normal,
            cons,
            d,
            w_reg,
            l_values,
            buffer,
        })
    }

    /// One solve with the regularised factor.
    fn approximate(&mut self, b1: &[f64], b2: &[f64]) -> [Vec<f64>; 2] {
        let n = self.normal.n;
        let t: Vec<f64> = b2.iter().zip(&self.w_reg).map(|(b, w)| b * w).collect();
        let mut dx = mul_t(self.cons, &t, n);
        dx.iter_mut().zip(b1).for_each(|(x, b)| *x += b);
        let ldlt = LdltRef::new(&self.normal.symbolic, &self.l_values);
        ldlt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(&mut dx, n, 1),
            Par::Seq,
            MemStack::new(&mut self.buffer),
        );
        let cdx = self.cons.mul(&dx);
        let w = (0..b2.len())
            .map(|i| self.w_reg[i] * (cdx[i] - b2[i]))
            .collect();
        [dx, w]
    }

    /// Solves the exact augmented system: the regularised solve, then iterative refinement.
    /// Refinement stops at a relative error `tol` (or when it stops converging); None when the
    /// factor is unfit (a pivot was lost) and needs more regularisation.
    fn solve(&mut self, b1: &[f64], b2: &[f64], tol: f64) -> Option<[Vec<f64>; 2]> {
        let n = self.normal.n;
        // Equality rows count as they are (their violation is what matters), inequality rows
        // as they enter dx (times their weight): inactive ones carry huge right-hand sides
        // whose rounding does not matter.
        let m_eq = self.normal.m_eq;
        let w_reg = self.w_reg.clone();
        let weighted = |b1: &[f64], b2: &[f64], with_eq: bool| {
            b2.iter()
                .zip(&w_reg)
                .enumerate()
                .fold(inf_norm(b1), |a, (r, (b, w))| {
                    a.max(match r < m_eq {
                        true if with_eq => b.abs(),
                        true => 0.0,
                        false => (b * w).abs(),
                    })
                })
        };
        let mut sol = self.approximate(b1, b2);
        let b_norm = weighted(b1, b2, true);
        let mut last = f64::INFINITY;
        let (mut e_x, mut terms) = (0.0, 0.0);
        for _ in 0..10 {
            let [dx, w] = &sol;
            let px = self.normal.mul_p(dx);
            let ct_w = mul_t(self.cons, w, n);
            let e1: Vec<f64> = (0..n).map(|i| b1[i] - px[i] - ct_w[i]).collect();
            let cdx = self.cons.mul(dx);
            let e2: Vec<f64> = (0..b2.len())
                .map(|i| b2[i] - cdx[i] + self.d[i] * w[i])
                .collect();
            let e_norm = weighted(&e1, &e2, true);
            e_x = inf_norm(&e1);
            terms = inf_norm(&px).max(inf_norm(&ct_w));
            if e_norm <= tol * b_norm || e_norm > 0.5 * last {
                break;
            }
            last = e_norm;
            let corr = self.approximate(&e1, &e2);
            for (s, c) in sol.iter_mut().zip(&corr) {
                s.iter_mut().zip(c).for_each(|(s, c)| *s += c);
            }
        }
        // Refined, an error in the x rows (the dual residual) still as large as the right-hand
        // side, and beyond rounding of the terms that make it up: a lost pivot. Constraint rows
        // converge at a rate set by δ / (s/z + δ), slowly where constraints are strongly
        // active, whatever the factor: an inexact direction there is still a good one.
        (e_x <= 0.5 * b_norm || e_x <= 1e-10 * terms).then_some(sol)
    }
}

fn inf_norm(x: &[f64]) -> f64 {
    x.iter().fold(0.0f64, |a, v| a.max(v.abs()))
}

/// max_i Σ_j |a_ij x_j|.
fn abs_row_norm(a: &Csr, x: &[f64]) -> f64 {
    (0..a.nrows())
        .map(|r| a.row(r).map(|(c, v)| (v * x[c]).abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

/// Aᵀ y for a Csr A with `n` columns.
fn mul_t(a: &Csr, y: &[f64], n: usize) -> Vec<f64> {
    let mut out = vec![0.0; n];
    for (r, &yr) in y.iter().enumerate() {
        for k in a.start[r]..a.start[r + 1] {
            out[a.col[k]] += a.val[k] * yr;
        }
    }
    out
}

/// Largest α ≤ 1 with v + α dv ≥ 0.
fn max_step(v: &[f64], dv: &[f64]) -> f64 {
    v.iter()
        .zip(dv)
        .filter(|(_, d)| **d < 0.0)
        .map(|(v, d)| -v / d)
        .fold(1.0, f64::min)
}

/// `m` with column j scaled by `col[j]` and row i by `row[i]`.
fn scaled(m: &Csr, col: &[f64], row: &[f64]) -> Csr {
    let mut out = m.clone();
    for (r, &rs) in row.iter().enumerate() {
        for k in m.start[r]..m.start[r + 1] {
            out.val[k] *= rs * col[m.col[k]];
        }
    }
    out
}

/// Row scale that gives every row of `m` (after the column scaling) unit ∞-norm.
fn unit_rows(m: &Csr, col: &[f64]) -> Vec<f64> {
    (0..m.nrows())
        .map(|r| {
            let norm = m.row(r).fold(0.0f64, |a, (c, v)| a.max((v * col[c]).abs()));
            if norm > 0.0 {
                1.0 / norm
            } else {
                1.0
            }
        })
        .collect()
}

/// Solves the QP after equilibration: variables scaled so that the normal matrix at W = I has
/// a unit diagonal, constraint rows scaled to unit norm. Weights and Airy values, boundary-edge
/// forces and hole coefficients differ by orders of magnitude; unscaled, the factorisation
/// loses the accuracy the last iterations need.
pub fn solve(qp: &Qp, tol: &Tolerances) -> IpmOutput {
    let n = qp.c.len();
    let mut diag = vec![0.0; n];
    for (r, &w) in qp.quad_weight.iter().enumerate() {
        qp.quad.row(r).for_each(|(c, v)| diag[c] += w * v * v);
    }
    for m in [qp.eq, qp.ineq] {
        for r in 0..m.nrows() {
            let norm2: f64 = m.row(r).map(|(_, v)| v * v).sum();
            m.row(r)
                .for_each(|(c, v)| diag[c] += v * v / norm2.max(1e-300));
        }
    }
    let d: Vec<f64> = diag
        .iter()
        .map(|&v| if v > 0.0 { 1.0 / v.sqrt() } else { 1.0 })
        .collect();
    let ones_q = vec![1.0; qp.quad.nrows()];
    let re = unit_rows(qp.eq, &d);
    let ri = unit_rows(qp.ineq, &d);
    let quad = scaled(qp.quad, &d, &ones_q);
    let eq = scaled(qp.eq, &d, &re);
    let ineq = scaled(qp.ineq, &d, &ri);
    let c: Vec<f64> = qp.c.iter().zip(&d).map(|(c, d)| c * d).collect();
    let f: Vec<f64> = qp.f.iter().zip(&re).map(|(f, r)| f * r).collect();
    let h: Vec<f64> = qp.h.iter().zip(&ri).map(|(h, r)| h * r).collect();
    let mut out = solve_scaled(
        &Qp {
            quad: &quad,
            quad_weight: qp.quad_weight,
            c: &c,
            constant: qp.constant,
            eq: &eq,
            f: &f,
            ineq: &ineq,
            h: &h,
        },
        tol,
    );
    out.x.iter_mut().zip(&d).for_each(|(x, d)| *x *= d);
    out
}

fn solve_scaled(qp: &Qp, tol: &Tolerances) -> IpmOutput {
    let n = qp.c.len();
    let m_eq = qp.eq.nrows();
    let m = qp.ineq.nrows();
    // The last iterate that met the relaxed tolerances, returned if the method stops early.
    let mut almost: Option<Vec<f64>> = None;
    let fail = |x: Vec<f64>, iterations, almost: Option<Vec<f64>>| match almost {
        Some(x) => IpmOutput {
            x,
            status: IpmStatus::AlmostSolved,
            iterations,
        },
        None => IpmOutput {
            x,
            status: IpmStatus::NumericalError,
            iterations,
        },
    };
    // C = [E; G]: equality rows are constraints whose slack is pinned to zero.
    let mut cons = qp.eq.clone();
    for r in 0..m {
        cons.push_row(qp.ineq.row(r).collect());
    }
    let Some(normal) = Normal::new(qp.quad, qp.quad_weight, &cons, m_eq) else {
        return fail(vec![0.0; n], 0, None);
    };
    let with_eq_zeros = |d: &[f64]| -> Vec<f64> {
        let mut out = vec![0.0; m_eq];
        out.extend_from_slice(d);
        out
    };

    // Starting point (as CVXOPT): minimise ½xᵀPx + cᵀx + ½‖Gx − h‖² subject to Ex = f, then
    // shift the slacks and duals into the positive orthant.
    let minus_c: Vec<f64> = qp.c.iter().map(|c| -c).collect();
    let mut rhs = qp.f.to_vec();
    rhs.extend_from_slice(qp.h);
    let start = REGULARISATION.iter().find_map(|&reg| {
        Newton::new(&normal, &cons, with_eq_zeros(&vec![1.0; m]), reg)?.solve(&minus_c, &rhs, 1e-8)
    });
    let Some([mut x, mut w]) = start else {
        return fail(vec![0.0; n], 0, None);
    };
    let s_hat = w.split_off(m_eq);
    let mut lambda: Vec<f64> = w.iter().map(|v| -v).collect();
    // Mehrotra's shift: into the positive orthant, then balanced so that s ∘ z starts centred.
    let mut z: Vec<f64> = s_hat.iter().map(|v| -v).collect();
    let mut s = s_hat;
    let lowest = |v: &[f64]| v.iter().fold(f64::INFINITY, |a, &b| a.min(b));
    let ds = (-1.5 * lowest(&s)).max(0.0);
    let dz = (-1.5 * lowest(&z)).max(0.0);
    s.iter_mut().for_each(|v| *v += ds);
    z.iter_mut().for_each(|v| *v += dz);
    let sz = dot(&s, &z);
    let (sum_s, sum_z) = (s.iter().sum::<f64>(), z.iter().sum::<f64>());
    let ds = if sum_z > 0.0 { 0.5 * sz / sum_z } else { 1.0 };
    let dz = if sum_s > 0.0 { 0.5 * sz / sum_s } else { 1.0 };
    s.iter_mut().for_each(|v| *v += ds.max(1e-8));
    z.iter_mut().for_each(|v| *v += dz.max(1e-8));

    let c_norm = inf_norm(qp.c);
    let f_norm = inf_norm(qp.f);
    let h_norm = inf_norm(qp.h);
    for iteration in 0..tol.max_iter {
        // Residuals of the KKT conditions.
        let px = normal.mul_p(&x);
        let et_l = mul_t(qp.eq, &lambda, n);
        let gt_z = mul_t(qp.ineq, &z, n);
        let r_d: Vec<f64> = (0..n)
            .map(|i| px[i] + qp.c[i] - et_l[i] - gt_z[i])
            .collect();
        let r_e: Vec<f64> = qp.eq.mul(&x).iter().zip(qp.f).map(|(a, b)| a - b).collect();
        let gx = qp.ineq.mul(&x);
        let r_i: Vec<f64> = (0..m).map(|i| gx[i] - qp.h[i] - s[i]).collect();
        let gap = dot(&s, &z);
        let objective = 0.5 * dot(&x, &px) + dot(qp.c, &x) + qp.constant;
        if !objective.is_finite() || inf_norm(&x) > 1e15 {
            return fail(x, iteration, almost);
        }
        // Residuals are measured against the size of the terms that make them up (a backward
        // error): at the optimum E x ≈ f is often 0 while its terms are not.
        let dual_scale = 1.0
            + c_norm
                .max(inf_norm(&px))
                .max(inf_norm(&gt_z))
                .max(inf_norm(&et_l));
        let eq_scale = 1.0 + f_norm.max(abs_row_norm(qp.eq, &x));
        let ineq_scale = 1.0 + h_norm.max(abs_row_norm(qp.ineq, &x));
        let within = |k: f64| {
            inf_norm(&r_d) <= k * tol.feas * dual_scale
                && inf_norm(&r_e) <= k * tol.feas * eq_scale
                && inf_norm(&r_i) <= k * tol.feas * ineq_scale
                && gap <= k * (tol.gap_abs + tol.gap_rel * objective.abs())
        };
        if within(tol.almost) {
            almost = Some(x.clone());
        }
        if within(1.0) {
            return IpmOutput {
                x,
                status: IpmStatus::Solved,
                iterations: iteration,
            };
        }
        let mu = if m > 0 { gap / m as f64 } else { 0.0 };

        let minus_rd: Vec<f64> = r_d.iter().map(|v| -v).collect();
        // Direction for a complementarity target r_c (Z ds + S dz = r_c): in augmented form
        // P dx + Eᵀ(−dλ) + Gᵀ(−dz) = −r_d,  E dx = −r_e,  G dx − (s/z)(−dz) = r_c/z − r_i.
        let direction = |newton: &mut Newton, r_c: &[f64], tol: f64| {
            let mut b2: Vec<f64> = r_e.iter().map(|v| -v).collect();
            b2.extend((0..m).map(|i| r_c[i] / z[i] - r_i[i]));
            let [dx, mut w] = newton.solve(&minus_rd, &b2, tol)?;
            let w_in = w.split_off(m_eq);
            let dl: Vec<f64> = w.iter().map(|w| -w).collect();
            // Of ds and dz, the one of the larger variable comes from the linear system, the
            // other from complementarity: dividing by the tiny one would amplify errors.
            let gdx = qp.ineq.mul(&dx);
            let (mut ds, mut dz) = (vec![0.0; m], vec![0.0; m]);
            for i in 0..m {
                if s[i] >= z[i] {
                    ds[i] = gdx[i] + r_i[i];
                    dz[i] = (r_c[i] - z[i] * ds[i]) / s[i];
                } else {
                    dz[i] = -w_in[i];
                    ds[i] = (r_c[i] - s[i] * dz[i]) / z[i];
                }
            }
            Some((dx, dl, ds, dz))
        };
        // Predictor (affine scaling), then the centred, second-order corrected step, with the
        // least regularisation whose factor is sound.
        let r_aff: Vec<f64> = (0..m).map(|i| -s[i] * z[i]).collect();
        let d: Vec<f64> = (0..m).map(|i| s[i] / z[i]).collect();
        // The corrector needs an accuracy just ahead of the iterate's own.
        let precision = (1e-3 * inf_norm(&r_d) / dual_scale).clamp(1e-13, 1e-6);
        let step = |reg: f64| {
            let mut newton = Newton::new(&normal, &cons, with_eq_zeros(&d), reg)?;
            let (_, _, ds_a, dz_a) = direction(&mut newton, &r_aff, 1e-6)?;
            let alpha_a = max_step(&s, &ds_a).min(max_step(&z, &dz_a));
            let mu_aff = if m > 0 {
                (0..m)
                    .map(|i| (s[i] + alpha_a * ds_a[i]) * (z[i] + alpha_a * dz_a[i]))
                    .sum::<f64>()
                    / m as f64
            } else {
                0.0
            };
            let sigma = if mu > 0.0 {
                (mu_aff / mu).clamp(0.0, 1.0).powi(3)
            } else {
                0.0
            };
            let r_c: Vec<f64> = (0..m)
                .map(|i| -s[i] * z[i] + sigma * mu - ds_a[i] * dz_a[i])
                .collect();
            direction(&mut newton, &r_c, precision)
        };
        let Some((dx, dl, ds, dz)) = REGULARISATION.iter().find_map(|&reg| step(reg)) else {
            return fail(x, iteration, almost);
        };
        let alpha = (0.99 * max_step(&s, &ds).min(max_step(&z, &dz))).min(1.0);
        if alpha.is_nan() || alpha <= 0.0 {
            return fail(x, iteration, almost);
        }
        x.iter_mut().zip(&dx).for_each(|(a, d)| *a += alpha * d);
        lambda
            .iter_mut()
            .zip(&dl)
            .for_each(|(a, d)| *a += alpha * d);
        s.iter_mut().zip(&ds).for_each(|(a, d)| *a += alpha * d);
        z.iter_mut().zip(&dz).for_each(|(a, d)| *a += alpha * d);
    }
    match almost {
        Some(x) => IpmOutput {
            x,
            status: IpmStatus::AlmostSolved,
            iterations: tol.max_iter,
        },
        None => IpmOutput {
            x,
            status: IpmStatus::MaxIterations,
            iterations: tol.max_iter,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn csr(ncols: usize, rows: &[&[(usize, f64)]]) -> Csr {
        let mut m = Csr::new(ncols);
        for r in rows {
            m.push_row(r.to_vec());
        }
        m
    }

    /// min (x0 − 1)² + (x1 − 2)² + (x0 + x1 − 4)²  s.t. x0 − x1 = −0.5, x0 ≥ 1.8: on the
    /// line x1 = x0 + 0.5 the objective is least at x0 = 19/12 < 1.8, so the bound binds.
    #[test]
    fn small_qp_with_active_bound_and_equality() {
        let quad = csr(2, &[&[(0, 1.0)], &[(1, 1.0)], &[(0, 1.0), (1, 1.0)]]);
        let weight = [2.0, 2.0, 2.0];
        // c = −2 Σ_k b_k a_k with targets b = (1, 2, 4).
        let c = [-10.0, -12.0];
        let eq = csr(2, &[&[(0, 1.0), (1, -1.0)]]);
        let ineq = csr(2, &[&[(0, 1.0)]]);
        let out = solve(
            &Qp {
                quad: &quad,
                quad_weight: &weight,
                c: &c,
                constant: 1.0 + 4.0 + 16.0,
                eq: &eq,
                f: &[-0.5],
                ineq: &ineq,
                h: &[1.8],
            },
            &Tolerances::default(),
        );
        assert_eq!(out.status, IpmStatus::Solved);
        assert!((out.x[0] - 1.8).abs() < 1e-8, "{:?}", out.x);
        assert!((out.x[1] - 2.3).abs() < 1e-8, "{:?}", out.x);
    }
}
