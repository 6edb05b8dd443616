//! The equality-constrained QP of one active set, solved to the last digits: its KKT system in
//! augmented form (the vertical residuals kept as unknowns, so that nothing is squared),
//! factored once with a small regularisation and refined against the exact system, every residual recomputed from its definition with compensated products and sums.

use super::super::sparse::Csr;
use faer::linalg::solvers::SolveCore;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMat, Triplet};
use faer::{Conj, MatMut};

/// The edge-based QP in the polish's terms, over x = (q of the edges with a force, τ):
///
///   minimise  ½ ‖A x − t‖² + ½ Σ_k w_k (b_k·x − s_k)²   subject to  E x = f,  lo ≤ x ≤ up
///
/// (A: the vertical residual rows, b_k: the regulariser's and the smoothing's rows).
pub(super) struct EdgeQp {
    pub(super) a: Csr,
    pub(super) t: Vec<f64>,
    pub(super) b: Csr,
    pub(super) s: Vec<f64>,
    pub(super) w: Vec<f64>,
    pub(super) eq: Csr,
    pub(super) f: Vec<f64>,
    pub(super) lo: Vec<f64>,
    pub(super) up: Vec<f64>,
}

/// Per unknown: free, or held on its lower or its upper bound.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Side2 {
    Free,
    Lower,
    Upper,
}

/// The solution of one active set's QP: x (active unknowns on their bounds), the residuals
/// r = A x − t, the multipliers λ of E x = f, and the largest refined KKT residual relative
/// to its terms.
pub(super) struct Eqp {
    pub(super) x: Vec<f64>,
    pub(super) r: Vec<f64>,
    pub(super) lambda: Vec<f64>,
    pub(super) error: f64,
}

/// Σ a_i b_i as if computed in twice the working precision, then rounded (Ogita, Rump and
/// Oishi's Dot2: error-free products by fused multiply-add, error-free sums).
pub(super) fn dot2(terms: impl Iterator<Item = (f64, f64)>) -> f64 {
    let (mut sum, mut carry) = (0.0f64, 0.0f64);
    for (a, b) in terms {
        let p = a * b;
        let product_error = a.mul_add(b, -p);
        let t = sum + p;
        let z = t - sum;
        carry += (sum - (t - z)) + (p - z) + product_error;
        sum = t;
    }
    sum + carry
}

/// The transpose of `m` (columns as rows).
/// Per row of `m`: 1 over its largest |entry| in the columns `keep` takes (1 where none),
/// which gives each row unit ∞-norm over those columns.
pub(super) fn unit_row_scales(m: &Csr, keep: impl Fn(usize) -> bool) -> Vec<f64> {
    (0..m.nrows())
        .map(|i| {
            let largest =
                (m.row(i).filter(|(c, _)| keep(*c))).fold(0.0f64, |a, (_, v)| a.max(v.abs()));
            if largest > 0.0 {
                1.0 / largest
            } else {
                1.0
            }
        })
        .collect()
}

pub(super) fn transpose(m: &Csr) -> Csr {
    let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); m.ncols];
    for r in 0..m.nrows() {
        for (c, v) in m.row(r) {
            rows[c].push((r, v));
        }
    }
    let mut t = Csr::new(m.nrows());
    for row in rows {
        t.push_row(row);
    }
    t
}

/// Row-wise M x − rhs, each row by `dot2`.
pub(super) fn residual(m: &Csr, x: &[f64], rhs: &[f64]) -> Vec<f64> {
    (0..m.nrows())
        .map(|r| dot2(m.row(r).map(|(c, v)| (v, x[c])).chain([(rhs[r], -1.0)])))
        .collect()
}

impl EdgeQp {
    pub(super) fn n(&self) -> usize {
        self.lo.len()
    }

    /// The gradient's parts per unknown from given residual vectors: Aᵀ r + Σ_k w_k b_k ρ_k
    /// + Eᵀ λ, by `dot2`, with the sum of the terms' sizes.
    fn stationarity(&self, tr: &[Csr; 3], r: &[f64], rho: &[f64], lambda: &[f64]) -> Vec<[f64; 2]> {
        let wr: Vec<f64> = rho.iter().zip(&self.w).map(|(p, w)| p * w).collect();
        (0..self.n())
            .map(|k| {
                let terms: Vec<(f64, f64)> = (tr[0].row(k).map(|(i, v)| (v, r[i])))
                    .chain(tr[1].row(k).map(|(i, v)| (v, wr[i])))
                    .chain(tr[2].row(k).map(|(i, v)| (v, lambda[i])))
                    .collect();
                let size: f64 = terms.iter().map(|(a, b)| (a * b).abs()).sum();
                [dot2(terms.into_iter()), size]
            })
            .collect()
    }

    /// The multipliers of the bounds at a solution: the stationarity residual of each
    /// unknown (0 on free ones, ≥ 0 on lower bounds and ≤ 0 on upper ones at the optimum),
    /// with the size of its terms.
    pub(super) fn multipliers(&self, tr: &[Csr; 3], sol: &Eqp) -> Vec<[f64; 2]> {
        let rho = residual(&self.b, &sol.x, &self.s);
        self.stationarity(tr, &sol.r, &rho, &sol.lambda)
    }

    /// Transposes of A, B and E for `stationarity`.
    pub(super) fn transposes(&self) -> [Csr; 3] {
        [transpose(&self.a), transpose(&self.b), transpose(&self.eq)]
    }
}

/// Regularisations of the factored system in scaled unknowns, +δ on x and −δ on λ, against
/// dependent rows and directions the objective does not see; refinement against the exact
/// system removes its effect where the system's curvature is well above δ. The first is
/// stable on plan slivers (four_holes: a 0.0037° corner); in directions that only the
/// regulariser ε ‖l q‖² bends (curvature ~1e-16 of the scaled system's) refinement with it
/// stalls, and the second reaches them (a generated vault with three anchored hole rims:
/// stationarity 2e-6 → its optimum).
pub(super) const DELTAS: [f64; 2] = [1e-9, 1e-14];
/// Refinement steps at most; refinement stops earlier once the residual no longer halves.
const REFINE: usize = 40;

/// The optimum of `qp` with the unknowns of `side` held on their bounds, refined from x0
/// (whose active unknowns are set to their bounds) on the system factored with the
/// regularisation `delta`; None when the factorisation fails.
pub(super) fn solve(
    qp: &EdgeQp,
    tr: &[Csr; 3],
    side: &[Side2],
    x0: &[f64],
    delta: f64,
) -> Option<Eqp> {
    let n = qp.n();
    let mut x: Vec<f64> = (0..n)
        .map(|k| match side[k] {
            Side2::Free => x0[k],
            Side2::Lower => qp.lo[k],
            Side2::Upper => qp.up[k],
        })
        .collect();
    let free: Vec<usize> = (0..n).filter(|&k| side[k] == Side2::Free).collect();
    let system = System::new(qp, &free, delta)?;
    let (m_a, m_e) = (qp.a.nrows(), qp.eq.nrows());
    let mut r = residual(&qp.a, &x, &qp.t);
    let mut lambda = vec![0.0; m_e];
    let mut best = f64::INFINITY;
    let mut error = f64::INFINITY;
    for _ in 0..REFINE {
        crate::interrupt::poll();
        // The exact system's residuals, recomputed from their definitions.
        let rho = residual(&qp.b, &x, &qp.s);
        let st = qp.stationarity(tr, &r, &rho, &lambda);
        let ra: Vec<f64> = (0..m_a)
            .map(|i| {
                dot2(
                    qp.a.row(i)
                        .map(|(c, v)| (v, x[c]))
                        .chain([(qp.t[i], -1.0), (r[i], -1.0)]),
                )
            })
            .collect();
        let re = residual(&qp.eq, &x, &qp.f);
        // Normwise per block: the largest residual over the largest sum of term sizes.
        let e_x = normwise(free.iter().map(|&k| st[k]));
        let e_r =
            normwise((0..m_a).map(|i| [ra[i], qp.t[i].abs() + r[i].abs() + abs_dot(&qp.a, i, &x)]));
        let e_e = normwise((0..m_e).map(|i| [re[i], qp.f[i].abs() + abs_dot(&qp.eq, i, &x)]));
        error = e_x.max(e_r).max(e_e);
        if error.is_nan() || error >= 0.5 * best || error < 1e-15 {
            break;
        }
        best = error;
        let rhs: Vec<f64> = (free.iter().map(|&k| -st[k][0]))
            .chain(ra.iter().map(|v| -v))
            .chain(re.iter().map(|v| -v))
            .collect();
        let d = system.solve(rhs);
        for (j, &k) in free.iter().enumerate() {
            x[k] += system.scale[j] * d[j];
        }
        for i in 0..m_a {
            r[i] += d[free.len() + i];
        }
        for i in 0..m_e {
            lambda[i] += system.scale[free.len() + m_a + i] * d[free.len() + m_a + i];
        }
    }
    Some(Eqp {
        x,
        r,
        lambda,
        error,
    })
}

/// max |residual| / max size over (residual, size of its terms) pairs.
fn normwise(rows: impl Iterator<Item = [f64; 2]>) -> f64 {
    let (r, size) = rows.fold((0.0f64, 0.0f64), |(r, s), [v, t]| {
        (r.max(v.abs()), s.max(t))
    });
    if size > 0.0 {
        r / size
    } else {
        0.0
    }
}

fn abs_dot(m: &Csr, row: usize, x: &[f64]) -> f64 {
    m.row(row).map(|(c, v)| (v * x[c]).abs()).sum()
}

/// The regularised KKT matrix of one active set in scaled unknowns (x = D x̄, λ = S λ̄):
///
///   [ D B_Fᵀ W B_F D + δ I   D A_Fᵀ    D E_Fᵀ S ]
///   [ A_F D                  −I        0        ]
///   [ S E_F D                0         −δ I     ]
///
/// factored as L U with partial pivoting (a symmetric factorisation without pivoting loses
/// the digits the refinement needs when the regularisation is this small), with the scale of
/// every unknown (D, 1, S).
struct System {
    lu: Lu<usize, f64>,
    scale: Vec<f64>,
}

impl System {
    fn new(qp: &EdgeQp, free: &[usize], delta: f64) -> Option<System> {
        let (n_f, m_a, m_e) = (free.len(), qp.a.nrows(), qp.eq.nrows());
        let dim = n_f + m_a + m_e;
        let mut col_of = vec![usize::MAX; qp.n()];
        for (j, &k) in free.iter().enumerate() {
            col_of[k] = j;
        }
        // Row scales of E (unit ∞-norm over the free unknowns), then column scales of x
        // (unit 2-norm of the column of [A; S E; √w B]).
        let row_scale = unit_row_scales(&qp.eq, |c| col_of[c] != usize::MAX);
        let mut norm2 = vec![0.0; n_f];
        let mut add = |m: &Csr, i: usize, s: f64| {
            for (c, v) in m.row(i) {
                if col_of[c] != usize::MAX {
                    norm2[col_of[c]] += s * v * v;
                }
            }
        };
        (0..m_a).for_each(|i| add(&qp.a, i, 1.0));
        (0..m_e).for_each(|i| add(&qp.eq, i, row_scale[i] * row_scale[i]));
        (0..qp.b.nrows()).for_each(|i| add(&qp.b, i, qp.w[i]));
        let d: Vec<f64> = norm2
            .iter()
            .map(|s| if *s > 0.0 { 1.0 / s.sqrt() } else { 1.0 })
            .collect();
        let mut triplets = Vec::new();
        for j in 0..n_f {
            triplets.push(Triplet::new(j, j, delta));
        }
        for i in 0..qp.b.nrows() {
            let row: Vec<(usize, f64)> = (qp.b.row(i).filter(|(c, _)| col_of[*c] != usize::MAX))
                .map(|(c, v)| (col_of[c], v * d[col_of[c]]))
                .collect();
            for &(c1, v1) in &row {
                for &(c2, v2) in row.iter().filter(|e| e.0 >= c1) {
                    triplets.push(Triplet::new(c2, c1, qp.w[i] * v1 * v2));
                }
            }
        }
        for i in 0..m_a {
            for (c, v) in qp.a.row(i).filter(|(c, _)| col_of[*c] != usize::MAX) {
                triplets.push(Triplet::new(n_f + i, col_of[c], v * d[col_of[c]]));
            }
            triplets.push(Triplet::new(n_f + i, n_f + i, -1.0));
        }
        for (i, scale) in row_scale.iter().enumerate() {
            for (c, v) in qp.eq.row(i).filter(|(c, _)| col_of[*c] != usize::MAX) {
                triplets.push(Triplet::new(
                    n_f + m_a + i,
                    col_of[c],
                    scale * v * d[col_of[c]],
                ));
            }
            triplets.push(Triplet::new(n_f + m_a + i, n_f + m_a + i, -delta));
        }
        // Both triangles: the LU factorisation with partial pivoting reads the whole matrix.
        let upper: Vec<_> = (triplets.iter().filter(|t| t.row != t.col))
            .map(|t| Triplet::new(t.col, t.row, t.val))
            .collect();
        triplets.extend(upper);
        let matrix = SparseColMat::<usize, f64>::try_new_from_triplets(dim, dim, &triplets).ok()?;
        let symbolic = SymbolicLu::try_new(matrix.symbolic()).ok()?;
        let lu = Lu::try_new_with_symbolic(symbolic, matrix.as_ref()).ok()?;
        let scale = d
            .into_iter()
            .chain(std::iter::repeat_n(1.0, m_a))
            .chain(row_scale)
            .collect();
        Some(System { lu, scale })
    }

    /// The regularised system's solution for the unscaled right side (x rows, r rows, λ
    /// rows), in scaled unknowns.
    fn solve(&self, mut rhs: Vec<f64>) -> Vec<f64> {
        // Rows of the x and λ blocks are scaled like their unknowns (symmetric scaling).
        for (v, s) in rhs.iter_mut().zip(&self.scale) {
            *v *= s;
        }
        let dim = rhs.len();
        self.lu.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(&mut rhs, dim, 1),
        );
        rhs
    }
}
