//! The numeric LDLᵀ factorisation of large normal matrices, supernode by supernode
//! (left-looking, as faer's own), so that the two branches of a `Split` of the elimination
//! tree, independent subtrees, are factored on two threads before the stem. faer's
//! factorisation runs its supernodes in one sequence and parallelises only the dense kernels
//! inside each, which on these factors was slower than one thread. The dense kernels here
//! are faer's: the LDLᵀ of each supernode's diagonal block (with faer's dynamic
//! regularisation), the triangular solve below it and the products of the updates.
//! Smaller factors (`FACTOR_SPLIT_FROM`) keep faer's factorisation.

use super::supernodal::{both, owners, Split};
use crate::stress::sparse::bucketed;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::cholesky::ldlt::factor::{cholesky_in_place, cholesky_in_place_scratch};
use faer::linalg::matmul::matmul;
use faer::linalg::matmul::triangular::{self, BlockStructure};
use faer::linalg::triangular_solve::solve_unit_lower_triangular_in_place;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::sparse::linalg::cholesky::{SymbolicCholesky, SymbolicCholeskyRaw};
use faer::{Accum, MatMut, MatRef, Par};

/// Pivots at most this are replaced by `HUGE_PIVOT` (faer's dynamic regularisation, here and
/// in faer's factorisation of smaller factors).
pub(super) const TINY_PIVOT: f64 = 1e-14;
pub(super) const HUGE_PIVOT: f64 = 1e20;

/// Updates with fewer multiply-adds than this are done by plain loops: faer's matrix product
/// costs more to dispatch than the arithmetic of the many small supernodes.
const LOOPS_BELOW: usize = 4096;

/// The supernodal structure the factorisation reads, and for every supernode the earlier
/// supernodes whose rows reach it (which update it), built once per symbolic factorisation.
pub(super) struct Plan {
    begin: Vec<usize>,
    end: Vec<usize>,
    row_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    val_ptr: Vec<usize>,
    updater_ptr: Vec<usize>,
    updaters: Vec<usize>,
    n: usize,
    /// None: one thread, in supernode order.
    split: Option<Split>,
    /// Columns from this one on have negative pivots (the split rows' unknowns, see `dense`).
    negative_from: usize,
}

impl Plan {
    /// The plan of a factor large enough to be factored on two threads (`Split::for_factor`),
    /// supernodal and without a permutation; None otherwise (faer factors it). Pivots of the
    /// columns from `negative_from` on are negative.
    pub(super) fn new(symbolic: &SymbolicCholesky<usize>, negative_from: usize) -> Option<Plan> {
        Plan::with_split(symbolic, Some(Split::for_factor(symbolic)?), negative_from)
    }

    /// The plan with this split of the tree (None: one thread, in supernode order), pivots
    /// negative from column `negative_from` on; None if `symbolic` is not supernodal or has a
    /// permutation.
    pub(super) fn with_split(
        symbolic: &SymbolicCholesky<usize>,
        split: Option<Split>,
        negative_from: usize,
    ) -> Option<Plan> {
        let SymbolicCholeskyRaw::Supernodal(sym) = symbolic.raw() else {
            return None;
        };
        if symbolic.perm().is_some() {
            return None;
        }
        let ns = sym.n_supernodes();
        let (begin, end) = (sym.supernode_begin().to_vec(), sym.supernode_end().to_vec());
        let (row_ptr, row_idx) = (sym.col_ptr_for_row_idx(), sym.row_idx());
        let owner = owners(&begin, &end, symbolic.nrows());
        // (updated, updater) pairs: rows are sorted, so a supernode's owners come in runs.
        let mut pairs = Vec::new();
        for d in 0..ns {
            let mut last = usize::MAX;
            for &r in &row_idx[row_ptr[d]..row_ptr[d + 1]] {
                if owner[r] != last {
                    last = owner[r];
                    pairs.push((last, d));
                }
            }
        }
        // Pairs come by updater, so each supernode's updaters stay in increasing order.
        let (updater_ptr, updaters) = bucketed(ns, pairs.len(), || pairs.iter().copied());
        Some(Plan {
            begin,
            end,
            row_ptr: row_ptr.to_vec(),
            row_idx: row_idx.to_vec(),
            val_ptr: sym.col_ptr_for_val().to_vec(),
            updater_ptr,
            updaters,
            n: symbolic.nrows(),
            split,
            negative_from,
        })
    }

    fn n_supernodes(&self) -> usize {
        self.begin.len()
    }

    fn pattern(&self, s: usize) -> &[usize] {
        &self.row_idx[self.row_ptr[s]..self.row_ptr[s + 1]]
    }

    /// The factor L D Lᵀ (D on L's diagonal) of the symmetric matrix whose lower triangle is
    /// `col_ptr`, `row_idx`, `values` (rows sorted in each column), into `l_values`, its two
    /// branches on two threads. False if a pivot is not finite (the dynamic regularisation
    /// replaces the small ones).
    pub(super) fn factorise(
        &self,
        matrix: (&[usize], &[usize], &[f64]),
        l_values: &mut [f64],
    ) -> bool {
        // Every supernode's block of values, to hand out to the threads.
        let mut blocks: Vec<&mut [f64]> = Vec::with_capacity(self.n_supernodes());
        let mut rest = l_values;
        for s in 0..self.n_supernodes() {
            let (block, tail) = rest.split_at_mut(self.val_ptr[s + 1] - self.val_ptr[s]);
            blocks.push(block);
            rest = tail;
        }
        let Some(split) = &self.split else {
            return self.factor_in_order(0..self.n_supernodes(), matrix, &mut blocks, |s| s);
        };
        // Each branch takes its supernodes' blocks, in order (their updaters are descendants,
        // in the same branch); the stem's follow once both are factored.
        let mut branch_of = vec![None; self.n_supernodes()];
        let mut position = vec![0; self.n_supernodes()];
        for (b, members) in split.branches.iter().enumerate() {
            for (p, &s) in members.iter().enumerate() {
                (branch_of[s], position[s]) = (Some(b), p);
            }
        }
        let (mut taken, mut stem): ([Vec<&mut [f64]>; 2], Vec<&mut [f64]>) = Default::default();
        for (s, block) in blocks.into_iter().enumerate() {
            match branch_of[s] {
                Some(b) => taken[b].push(block),
                None => stem.push(block),
            }
        }
        let position = &position;
        let branch = |b: usize, blocks: &mut Vec<&mut [f64]>| {
            let members = split.branches[b].iter().copied();
            self.factor_in_order(members, matrix, blocks, |s| position[s])
        };
        let [mut first, mut second] = taken;
        let (first_done, second_done) = both(|| branch(0, &mut first), || branch(1, &mut second));
        let factored = first_done && second_done;
        // Back in supernode order for the stem.
        let (mut first, mut second, mut stem) =
            (first.into_iter(), second.into_iter(), stem.into_iter());
        let blocks: Option<Vec<&mut [f64]>> = branch_of
            .iter()
            .map(|b| match b {
                Some(0) => first.next(),
                Some(_) => second.next(),
                None => stem.next(),
            })
            .collect();
        match blocks {
            Some(mut blocks) if factored => {
                self.factor_in_order(split.stem.iter().copied(), matrix, &mut blocks, |s| s)
            }
            _ => false,
        }
    }

    /// Factors `supernodes` in order; `blocks[at(s)]` is supernode s's block, and every
    /// updater's block comes before it.
    fn factor_in_order(
        &self,
        supernodes: impl Iterator<Item = usize>,
        matrix: (&[usize], &[usize], &[f64]),
        blocks: &mut [&mut [f64]],
        at: impl Fn(usize) -> usize,
    ) -> bool {
        let mut work = Work::new(self.n);
        for s in supernodes {
            let (done, rest) = blocks.split_at_mut(at(s));
            let done: &[&mut [f64]] = done;
            if !self.supernode(s, matrix, rest[0], |d| &*done[at(d)], &mut work) {
                return false;
            }
        }
        true
    }

    /// Factors supernode s into `ls`, from A's columns and the updates of its updaters
    /// (already factored; `done(d)` is d's block).
    fn supernode<'b>(
        &self,
        s: usize,
        (a_ptr, a_rows, a_values): (&[usize], &[usize], &[f64]),
        ls: &mut [f64],
        done: impl Fn(usize) -> &'b [f64],
        work: &mut Work,
    ) -> bool {
        let (start, stop) = (self.begin[s], self.end[s]);
        let ncols = stop - start;
        let pattern = self.pattern(s);
        let nrows = ncols + pattern.len();
        for (i, &r) in pattern.iter().enumerate() {
            work.local[r] = ncols + i;
        }
        let local = |r: usize, local: &[usize]| if r < stop { r - start } else { local[r] };
        ls.fill(0.0);
        for j in start..stop {
            let col = j - start;
            for k in a_ptr[j]..a_ptr[j + 1] {
                let i = a_rows[k];
                if i >= j {
                    ls[col * nrows + local(i, &work.local)] += a_values[k];
                }
            }
        }
        for &d in &self.updaters[self.updater_ptr[s]..self.updater_ptr[s + 1]] {
            self.update(s, d, done(d), ls, nrows, work);
        }
        let mut block = MatMut::from_column_major_slice_mut(ls, nrows, ncols);
        let (mut top, mut bottom) = block.rb_mut().split_at_row_mut(ncols);
        work.signs.clear();
        work.signs
            .extend((start..stop).map(|j| if j < self.negative_from { 1 } else { -1 }));
        let stack = cholesky_in_place_scratch::<f64>(ncols, Par::Seq, Default::default());
        if work.buffer_len < stack.unaligned_bytes_required() {
            work.buffer = MemBuffer::new(stack);
            work.buffer_len = stack.unaligned_bytes_required();
        }
        let factored = cholesky_in_place(
            top.rb_mut(),
            LdltRegularization {
                dynamic_regularization_signs: Some(&work.signs[..ncols]),
                dynamic_regularization_delta: HUGE_PIVOT,
                dynamic_regularization_epsilon: TINY_PIVOT,
            },
            Par::Seq,
            MemStack::new(&mut work.buffer),
            Default::default(),
        );
        if factored.is_err() {
            return false;
        }
        for j in 0..ncols {
            for i in 0..j {
                top[(i, j)] = 0.0;
            }
        }
        solve_unit_lower_triangular_in_place(top.rb(), bottom.rb_mut().transpose_mut(), Par::Seq);
        for j in 0..ncols {
            let d = top[(j, j)].recip();
            for i in 0..pattern.len() {
                bottom[(i, j)] *= d;
            }
        }
        true
    }

    /// Subtracts supernode d's update from supernode s's block `ls` (`nrows` rows; the local
    /// row of each of s's pattern rows is in `work.local`).
    fn update(
        &self,
        s: usize,
        d: usize,
        ld: &[f64],
        ls: &mut [f64],
        nrows: usize,
        work: &mut Work,
    ) {
        let (start, stop) = (self.begin[s], self.end[s]);
        let d_cols = self.end[d] - self.begin[d];
        let d_pattern = self.pattern(d);
        let d_rows = d_cols + d_pattern.len();
        // d's pattern rows in s's columns, then those below.
        let first = d_pattern.partition_point(|&r| r < start);
        let mid = d_pattern[first..].partition_point(|&r| r < stop);
        let rows = &d_pattern[first..];
        let local = |r: usize| if r < stop { r - start } else { work.local[r] };
        // W = L_mid D (mid × d_cols).
        work.w.clear();
        for k in 0..d_cols {
            let dk = ld[k * d_rows + k];
            let col = &ld[k * d_rows + d_cols + first..][..mid];
            work.w.extend(col.iter().map(|v| v * dk));
        }
        if rows.len() * mid * d_cols < LOOPS_BELOW {
            for j in 0..mid {
                let c = rows[j] - start;
                for (i, &r) in rows.iter().enumerate().skip(j) {
                    let mut sum = 0.0;
                    for k in 0..d_cols {
                        sum += ld[k * d_rows + d_cols + first + i] * work.w[k * mid + j];
                    }
                    ls[c * nrows + local(r)] -= sum;
                }
            }
            return;
        }
        // T = L_rows W ᵀ (rows × mid), then scattered.
        let l_rows = MatRef::from_column_major_slice_with_stride(
            &ld[d_cols + first..],
            rows.len(),
            d_cols,
            d_rows,
        );
        let w = MatRef::from_column_major_slice(&work.w, mid, d_cols);
        // Only the lower triangle of T's top (the rows in s's columns) is needed.
        if work.t.len() < rows.len() * mid {
            work.t.resize(rows.len() * mid, 0.0);
        }
        let t =
            MatMut::from_column_major_slice_mut(&mut work.t[..rows.len() * mid], rows.len(), mid);
        let (t_top, t_bottom) = t.split_at_row_mut(mid);
        let (l_top, l_bottom) = l_rows.split_at_row(mid);
        triangular::matmul(
            t_top,
            BlockStructure::TriangularLower,
            Accum::Replace,
            l_top,
            BlockStructure::Rectangular,
            w.transpose(),
            BlockStructure::Rectangular,
            1.0,
            Par::Seq,
        );
        matmul(
            t_bottom,
            Accum::Replace,
            l_bottom,
            w.transpose(),
            1.0,
            Par::Seq,
        );
        for j in 0..mid {
            let c = rows[j] - start;
            let t = &work.t[j * rows.len()..(j + 1) * rows.len()];
            for i in j..rows.len() {
                ls[c * nrows + local(rows[i])] -= t[i];
            }
        }
    }
}

/// One thread's working storage.
struct Work {
    /// Local row of each global row in the supernode being factored.
    local: Vec<usize>,
    w: Vec<f64>,
    t: Vec<f64>,
    signs: Vec<i8>,
    buffer: MemBuffer,
    buffer_len: usize,
}

impl Work {
    fn new(n: usize) -> Work {
        Work {
            local: vec![0; n],
            w: Vec::new(),
            t: Vec::new(),
            signs: Vec::new(),
            buffer: MemBuffer::new(faer::dyn_stack::StackReq::EMPTY),
            buffer_len: 0,
        }
    }
}
