//! Solves with a supernodal LDLᵀ factor, one right-hand side, in place. faer's solve
//! dispatches a dense triangular solve and a matrix–vector product for every supernode; on
//! the small supernodes of QPs with up to a few thousand unknowns that dispatch costs more
//! than the arithmetic, and plain loops over each supernode's columns are faster (scratch
//! medians, own against faer's: barrel 6.97 against 7.70 ms, lilium 26.9 against 28.0 ms,
//! cheese 141 against 154 ms). Factors too large for the cache are read downwards by the
//! backward solve (`DOWNWARDS_FROM`), which makes these loops faster at every size (50k
//! unknowns: 8.7 against 13.1 ms a solve, 100k: about 21 against 30 ms). Until the gauge was
//! spread (`stress::gauge`), their other rounding took the 100k step onto a trajectory that
//! froze a pivot, so faer's solve was kept beyond 20k unknowns.

use faer::sparse::linalg::cholesky::{SymbolicCholesky, SymbolicCholeskyRaw};

/// x ← (L D Lᵀ)⁻¹ x for the factor `values` of `symbolic`, which must be supernodal and
/// without a permutation (the normal matrix is factored in its elimination order); false,
/// with x untouched, otherwise. `scratch` is working storage.
pub(super) fn solve_in_place(
    symbolic: &SymbolicCholesky<usize>,
    values: &[f64],
    x: &mut [f64],
    scratch: &mut Vec<f64>,
) -> bool {
    let downwards = values.len() > DOWNWARDS_FROM;
    solve_in_place_reading(symbolic, values, x, scratch, downwards)
}

/// `solve_in_place`, its backward solve reading each column downwards (`dot_downwards`) or
/// upwards (`dot`).
pub(super) fn solve_in_place_reading(
    symbolic: &SymbolicCholesky<usize>,
    values: &[f64],
    x: &mut [f64],
    scratch: &mut Vec<f64>,
    downwards: bool,
) -> bool {
    let SymbolicCholeskyRaw::Supernodal(sym) = symbolic.raw() else {
        return false;
    };
    if symbolic.perm().is_some() {
        return false;
    }
    let (begin, end) = (sym.supernode_begin(), sym.supernode_end());
    let (row_ptr, val_ptr, row_idx) = (
        sym.col_ptr_for_row_idx(),
        sym.col_ptr_for_val(),
        sym.row_idx(),
    );
    // Supernode s: columns start..start + ncols, stored column-major as a block of
    // ncols + |pattern| rows (the unit lower triangle with D on its diagonal, then the rows
    // `pattern` below it).
    let block = |s: usize| {
        let (start, ncols) = (begin[s], end[s] - begin[s]);
        let pattern = &row_idx[row_ptr[s]..row_ptr[s + 1]];
        let l = &values[val_ptr[s]..val_ptr[s + 1]];
        (start, ncols, pattern, l, ncols + pattern.len())
    };
    // L y = b, supernode by supernode: the triangle, then the rows below, gathered in
    // `scratch` and subtracted once.
    for s in 0..sym.n_supernodes() {
        let (start, ncols, pattern, l, nrows) = block(s);
        scratch.clear();
        scratch.resize(pattern.len(), 0.0);
        for j in 0..ncols {
            let col = &l[j * nrows..(j + 1) * nrows];
            let xj = x[start + j];
            for (xi, &v) in x[start + j + 1..start + ncols]
                .iter_mut()
                .zip(&col[j + 1..ncols])
            {
                *xi -= v * xj;
            }
            for (t, &v) in scratch.iter_mut().zip(&col[ncols..]) {
                *t += v * xj;
            }
        }
        for (&r, &t) in pattern.iter().zip(scratch.iter()) {
            x[r] -= t;
        }
    }
    // D z = y.
    for s in 0..sym.n_supernodes() {
        let (start, ncols, _, l, nrows) = block(s);
        for j in 0..ncols {
            x[start + j] /= l[j * nrows + j];
        }
    }
    // Lᵀ x = z, supernodes in reverse: the rows below are final, then the triangle upwards.
    let dot = if downwards { dot_downwards } else { dot };
    for s in (0..sym.n_supernodes()).rev() {
        let (start, ncols, pattern, l, nrows) = block(s);
        scratch.clear();
        scratch.extend(pattern.iter().map(|&r| x[r]));
        for j in (0..ncols).rev() {
            let col = &l[j * nrows..(j + 1) * nrows];
            let mut xj = x[start + j];
            xj -= dot(&col[ncols..], scratch);
            xj -= dot(&col[j + 1..ncols], &x[start + j + 1..start + ncols]);
            x[start + j] = xj;
        }
    }
    true
}

/// Σ a_i b_i in four interleaved partial sums, which the compiler keeps in one vector
/// register (one running sum must add in order, one term at a time).
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let (a4, b4) = (a.chunks_exact(4), b.chunks_exact(4));
    four_sums((a4.remainder(), b4.remainder()), a4.zip(b4))
}

/// The sums of `dot`: the terms of `tail`, then four partial sums over `chunks` of four.
fn four_sums<'a>(
    tail: (&[f64], &[f64]),
    chunks: impl Iterator<Item = (&'a [f64], &'a [f64])>,
) -> f64 {
    let tail: f64 = tail.0.iter().zip(tail.1).map(|(x, y)| x * y).sum();
    let mut acc = [0.0; 4];
    for (x, y) in chunks {
        for k in 0..4 {
            acc[k] += x[k] * y[k];
        }
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// Factors with more values than this are read downwards by the backward solve
/// (`dot_downwards`), one descending stream the prefetcher follows. The backward solve visits
/// supernodes downwards and, with `dot`, reads each column upwards: on the 100k dome's factor
/// (17M values) that took 20 ms against 9 ms for the forward pass over the same memory, and
/// 11 ms read downwards. Measured on the generated domes (one step each, three interleaved
/// runs): 10k unknowns (1.07M values) 0.48–0.53 → 0.46–0.49 s, 20k (2.4M) 1.34–1.49 →
/// 1.17–1.31 s, with the same iterations. Smaller factors stay in cache and gain nothing
/// (6k unknowns, 0.57M values); they keep `dot`'s rounding, to which the small shared
/// models' degenerate QPs are sensitive (read downwards, free_vault's form finding took 0.32
/// s instead of 0.20, three_pillar's 0.54 instead of 0.29).
const DOWNWARDS_FROM: usize = 1 << 20;

/// `dot` from the last terms to the first (the same four partial sums, taken from the end).
fn dot_downwards(a: &[f64], b: &[f64]) -> f64 {
    let (a4, b4) = (a.rchunks_exact(4), b.rchunks_exact(4));
    four_sums((a4.remainder(), b4.remainder()), a4.zip(b4))
}
