//! A minimal compressed-row matrix: the force map q = S y is built row by row (one row per
//! edge) and consumed row by row when the QP is assembled; compressed patterns built from
//! their entries (`bucketed`); and the (row, column, value) lists clarabel's matrices are
//! built from (`Triplets`).

/// Entries of a sparse matrix as (row, column, value) lists, zeros left out; repeated
/// positions add up when clarabel compresses them.
#[derive(Debug, Clone, Default)]
pub(crate) struct Triplets {
    pub i: Vec<usize>,
    pub j: Vec<usize>,
    pub v: Vec<f64>,
}

impl Triplets {
    pub fn push(&mut self, i: usize, j: usize, v: f64) {
        if v != 0.0 {
            self.i.push(i);
            self.j.push(j);
            self.v.push(v);
        }
    }
}

/// Compressed sparse rows; duplicate entries within a row are summed on construction.
#[derive(Debug, Clone, Default)]
pub struct Csr {
    pub ncols: usize,
    pub start: Vec<usize>,
    pub col: Vec<usize>,
    pub val: Vec<f64>,
}

impl Csr {
    pub fn new(ncols: usize) -> Csr {
        Csr {
            ncols,
            start: vec![0],
            col: Vec::new(),
            val: Vec::new(),
        }
    }

    pub fn nrows(&self) -> usize {
        self.start.len() - 1
    }

    /// Appends a row from (column, value) pairs, summing repeated columns, dropping zeros.
    pub fn push_row(&mut self, mut entries: Vec<(usize, f64)>) {
        entries.sort_unstable_by_key(|e| e.0);
        let row_start = self.col.len();
        for (c, v) in entries {
            debug_assert!(c < self.ncols);
            if self.col.len() > row_start && *self.col.last().unwrap() == c {
                *self.val.last_mut().unwrap() += v;
            } else {
                self.col.push(c);
                self.val.push(v);
            }
        }
        // Drop exact zeros left by cancellation, keeping the pattern minimal.
        let mut w = row_start;
        for r in row_start..self.col.len() {
            if self.val[r] != 0.0 {
                self.col[w] = self.col[r];
                self.val[w] = self.val[r];
                w += 1;
            }
        }
        self.col.truncate(w);
        self.val.truncate(w);
        self.start.push(w);
    }

    #[inline]
    pub fn row(&self, r: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let range = self.start[r]..self.start[r + 1];
        self.col[range.clone()]
            .iter()
            .copied()
            .zip(self.val[range].iter().copied())
    }

    pub fn mul(&self, x: &[f64]) -> Vec<f64> {
        // Row slices rather than `row`: the solvers' hottest loop outside the factor.
        self.start
            .windows(2)
            .map(|bounds| {
                let range = bounds[0]..bounds[1];
                self.col[range.clone()]
                    .iter()
                    .zip(&self.val[range])
                    .map(|(&c, &v)| v * x[c])
                    .sum()
            })
            .collect()
    }
}

/// A compressed-column pattern of n columns from `nnz` (column, row) entries, rows in the
/// order the entries come (`entries` is called twice: to count, then to fill).
pub(crate) fn bucketed<I: Iterator<Item = (usize, usize)>>(
    n: usize,
    nnz: usize,
    entries: impl Fn() -> I,
) -> (Vec<usize>, Vec<usize>) {
    crate::interrupt::poll();
    let mut ptr = vec![0; n + 1];
    for (col, _) in entries() {
        ptr[col + 1] += 1;
    }
    crate::interrupt::poll();
    for c in 0..n {
        ptr[c + 1] += ptr[c];
    }
    let mut next = ptr.clone();
    let mut idx = vec![0; nnz];
    for (col, row) in entries() {
        idx[next[col]] = row;
        next[col] += 1;
    }
    (ptr, idx)
}

/// A row of a least-squares system is dense beyond max(`DENSE_FROM`, `DENSE_SQRT` √n) entries
/// (n unknowns): its k entries add a k × k block to the normal matrix. Below the limit that
/// block costs less than handling the row apart (a block of 2√n columns costs about as much
/// work as factoring a planar mesh's n unknowns); above it, a fan's hub would make the normal
/// matrix dense.
pub(crate) fn dense_row_limit(n: usize) -> usize {
    const DENSE_FROM: usize = 64;
    const DENSE_SQRT: f64 = 2.0;
    DENSE_FROM.max((DENSE_SQRT * (n as f64).sqrt()) as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_sum_duplicates_and_drop_zeros() {
        let mut m = Csr::new(4);
        m.push_row(vec![(2, 1.0), (0, 2.0), (2, 3.0)]);
        m.push_row(vec![(1, 1.0), (1, -1.0), (3, 5.0)]);
        assert_eq!(m.row(0).collect::<Vec<_>>(), vec![(0, 2.0), (2, 4.0)]);
        assert_eq!(m.row(1).collect::<Vec<_>>(), vec![(3, 5.0)]);
        assert_eq!(m.mul(&[1.0, 1.0, 1.0, 2.0]), vec![6.0, 10.0]);
    }
}
