//! Dense rows of K, a fan's hub with one entry per spoke, kept out of KᵀK: k spokes would add
//! a k × k block to its pattern (O(k²) memory and O(k³) work per factorisation, whatever the
//! ordering). They come back by Woodbury's identity: with M_s the normal matrix without them
//! and U their rows as columns, (M_s + U Uᵀ)⁻¹ = M_s⁻¹ − M_s⁻¹ U C⁻¹ Uᵀ M_s⁻¹ with
//! C = I + Uᵀ M_s⁻¹ U, at d + 1 solves with M_s's factor for d dense rows.

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::Llt;
use faer::Mat;

/// One dense row of K: its entries with each column once.
pub(super) type DenseRow = Vec<(usize, f64)>;

/// At most this many refinement steps against the exact system: M_s may be nearly singular
/// along a column of U (K without its hub's row can lose rank), where the identity loses
/// digits that a step or two win back.
const MOST_REFINEMENTS: usize = 4;

/// How many columns `cols` holds, each counted once.
pub(super) fn distinct(cols: &[usize]) -> usize {
    let mut cols = cols.to_vec();
    cols.sort_unstable();
    cols.dedup();
    cols.len()
}

/// The entries `cols`, `vals` of a row of K (a column repeated per edge) merged by column.
pub(super) fn merged(cols: &[usize], vals: &[f64]) -> DenseRow {
    let mut entries: Vec<(usize, f64)> = cols.iter().copied().zip(vals.iter().copied()).collect();
    entries.sort_by_key(|&(c, _)| c);
    let mut row: DenseRow = Vec::with_capacity(entries.len());
    for (c, v) in entries {
        match row.last_mut() {
            Some(last) if last.0 == c => last.1 += v,
            _ => row.push((c, v)),
        }
    }
    row
}

/// M_s in its lower triangle, compressed by columns.
pub(super) struct Lower<'a> {
    pub col_ptr: &'a [usize],
    pub row_idx: &'a [usize],
    pub values: &'a [f64],
}

impl Lower<'_> {
    /// M_s x.
    fn mul(&self, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; x.len()];
        for j in 0..x.len() {
            for k in self.col_ptr[j]..self.col_ptr[j + 1] {
                let (i, v) = (self.row_idx[k], self.values[k]);
                y[i] += v * x[j];
                if i != j {
                    y[j] += v * x[i];
                }
            }
        }
        y
    }
}

/// (M_s + U Uᵀ) z = rhs by the identity, with M_s factored.
pub(super) struct Woodbury<'a> {
    llt: &'a Llt<usize, f64>,
    lower: Lower<'a>,
    rows: &'a [DenseRow],
    /// M_s⁻¹ U, one column per dense row.
    v: Mat<f64>,
    /// C's Cholesky factor, row-major lower triangle.
    c: Vec<f64>,
}

impl<'a> Woodbury<'a> {
    /// None where C is not positive definite to rounding.
    pub fn new(llt: &'a Llt<usize, f64>, lower: Lower<'a>, rows: &'a [DenseRow]) -> Option<Self> {
        let (m, d) = (lower.col_ptr.len() - 1, rows.len());
        let mut v = Mat::<f64>::zeros(m, d);
        for (h, row) in rows.iter().enumerate() {
            for &(c, x) in row {
                v[(c, h)] = x;
            }
        }
        llt.solve_in_place(v.as_mut());
        let mut c = vec![0.0; d * d];
        for a in 0..d {
            for b in 0..=a {
                let dot: f64 = rows[a].iter().map(|&(i, x)| x * v[(i, b)]).sum();
                c[a * d + b] = dot + if a == b { 1.0 } else { 0.0 };
            }
        }
        cholesky_in_place(&mut c, d)?;
        Some(Woodbury {
            llt,
            lower,
            rows,
            v,
            c,
        })
    }

    /// z, refined while the exact system's residual falls.
    pub fn solve(&self, rhs: &[f64]) -> Vec<f64> {
        let mut z = self.apply(rhs);
        let mut last = f64::INFINITY;
        for _ in 0..MOST_REFINEMENTS {
            let r = self.residual(rhs, &z);
            let size = r.iter().fold(0.0f64, |a, x| a.max(x.abs()));
            if size == 0.0 || size > 0.5 * last {
                break;
            }
            last = size;
            let dz = self.apply(&r);
            z.iter_mut().zip(dz).for_each(|(z, d)| *z += d);
        }
        z
    }

    /// rhs − (M_s + U Uᵀ) z.
    fn residual(&self, rhs: &[f64], z: &[f64]) -> Vec<f64> {
        let mut r: Vec<f64> = (rhs.iter().zip(self.lower.mul(z)))
            .map(|(b, m)| b - m)
            .collect();
        for row in self.rows {
            let dot: f64 = row.iter().map(|&(i, x)| x * z[i]).sum();
            row.iter().for_each(|&(i, x)| r[i] -= x * dot);
        }
        r
    }

    /// The identity applied to b.
    fn apply(&self, b: &[f64]) -> Vec<f64> {
        let mut y = Mat::from_fn(b.len(), 1, |i, _| b[i]);
        self.llt.solve_in_place(y.as_mut());
        let d = self.rows.len();
        let mut w: Vec<f64> = (self.rows.iter())
            .map(|row| row.iter().map(|&(i, x)| x * y[(i, 0)]).sum())
            .collect();
        cholesky_solve(&self.c, d, &mut w);
        (0..b.len())
            .map(|i| y[(i, 0)] - (0..d).map(|h| self.v[(i, h)] * w[h]).sum::<f64>())
            .collect()
    }
}

/// The lower Cholesky factor of the d × d matrix `a` (its lower triangle, row-major) in place;
/// None at a pivot that is not positive.
fn cholesky_in_place(a: &mut [f64], d: usize) -> Option<()> {
    for j in 0..d {
        let pivot = a[j * d + j] - (0..j).map(|k| a[j * d + k].powi(2)).sum::<f64>();
        // NaN fails too.
        if pivot.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        let l = pivot.sqrt();
        a[j * d + j] = l;
        for i in j + 1..d {
            let s = a[i * d + j] - (0..j).map(|k| a[i * d + k] * a[j * d + k]).sum::<f64>();
            a[i * d + j] = s / l;
        }
    }
    Some(())
}

/// x ← (L Lᵀ)⁻¹ x for the factor of `cholesky_in_place`.
fn cholesky_solve(l: &[f64], d: usize, x: &mut [f64]) {
    for i in 0..d {
        let s = x[i] - (0..i).map(|k| l[i * d + k] * x[k]).sum::<f64>();
        x[i] = s / l[i * d + i];
    }
    for i in (0..d).rev() {
        let s = x[i] - (i + 1..d).map(|k| l[k * d + i] * x[k]).sum::<f64>();
        x[i] = s / l[i * d + i];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn merged_sums_repeated_columns() {
        assert_eq!(
            merged(&[3, 1, 3, 0], &[1.0, 2.0, 4.0, -1.0]),
            vec![(0, -1.0), (1, 2.0), (3, 5.0)]
        );
    }

    #[test]
    fn cholesky_solves_a_small_system() {
        // A = [[4, 2], [2, 3]], b = A [1, -2] = [0, -4].
        let mut a = vec![4.0, 0.0, 2.0, 3.0];
        cholesky_in_place(&mut a, 2).unwrap();
        let mut x = vec![0.0, -4.0];
        cholesky_solve(&a, 2, &mut x);
        assert!(
            (x[0] - 1.0).abs() < 1e-14 && (x[1] + 2.0).abs() < 1e-14,
            "{x:?}"
        );
        let mut singular = vec![1.0, 0.0, 1.0, 1.0];
        assert!(cholesky_in_place(&mut singular, 2).is_none());
    }
}
