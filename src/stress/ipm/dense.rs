//! Dense rows of P and C, factored apart. A row a with k entries (weight w) adds w a aᵀ to the
//! normal matrix: k² couplings. The residual row of a vertex with many edges (a fan's hub, a
//! UV sphere's pole) has about as many entries as the vertex has neighbours, so a wheel of n
//! spokes makes the normal matrix dense: O(n²) memory and O(n³) work per factorisation,
//! whatever the ordering. Such a row gets an unknown u = w a·x of its own instead:
//!
//!   [ M_s   aᵀ  ] [x]   [b]
//!   [ a   −1/w  ] [u] = [0]
//!
//! whose Schur complement on x is M_s + w a aᵀ, the normal matrix M (M_s: M without the
//! row). The split unknowns are ordered after all others: each costs one row of the factor
//! (at most one entry per unknown) and a negative pivot, −1/w − a M_s⁻¹ aᵀ. The matrix is
//! quasi-definite, so LDLᵀ factors it in this order without pivoting; what it loses to
//! rounding where M_s is nearly singular along M_s⁻¹ aᵀ, the refinement against the exact
//! system recovers.

use crate::stress::sparse::{bucketed, dense_row_limit, Csr};

/// Marks a row that is not split.
const KEPT: usize = usize::MAX;

/// Where a split row comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Source {
    /// A row of P (`quad`).
    Quad,
    /// A row of C = [E; G].
    Cons,
}

/// The dense rows of one QP's structure and their place in the factored matrix: split row
/// k is unknown n + k.
#[derive(Debug, Default)]
pub(super) struct DenseRows {
    /// Per row of P and of C: its split unknown's index k, or `KEPT`.
    quad: Vec<usize>,
    cons: Vec<usize>,
    /// Per split unknown: the row it stands for.
    pub(super) rows: Vec<(Source, usize)>,
    /// Per split unknown k, from `slot_start[k]`: the slot of its coupling to each entry of its
    /// row, in the row's order.
    pub(super) slot_start: Vec<usize>,
    pub(super) slot: Vec<usize>,
    /// Per split unknown: the slot of its diagonal.
    pub(super) diag: Vec<usize>,
}

impl DenseRows {
    /// The rows of `quad` and `cons` (over n unknowns) with too many entries to be kept.
    pub(super) fn find(quad: &Csr, cons: &Csr) -> DenseRows {
        let n = cons.ncols;
        let limit = dense_row_limit(n);
        let mut rows = Vec::new();
        let mut mark = |m: &Csr, source: Source| -> Vec<usize> {
            (0..m.nrows())
                .map(|r| {
                    if m.start[r + 1] - m.start[r] > limit {
                        rows.push((source, r));
                        rows.len() - 1
                    } else {
                        KEPT
                    }
                })
                .collect()
        };
        let quad_marks = mark(quad, Source::Quad);
        let cons_marks = mark(cons, Source::Cons);
        DenseRows {
            quad: quad_marks,
            cons: cons_marks,
            rows,
            ..Default::default()
        }
    }

    /// How many rows are split.
    pub(super) fn count(&self) -> usize {
        self.rows.len()
    }

    /// Whether row r of P (`Source::Quad`) or of C is split.
    pub(super) fn is_split(&self, source: Source, r: usize) -> bool {
        let marks = match source {
            Source::Quad => &self.quad,
            Source::Cons => &self.cons,
        };
        marks.get(r).is_some_and(|&k| k != KEPT)
    }

    /// `m` (P's rows or C, as `source` says) without its split rows.
    pub(super) fn kept(&self, m: &Csr, source: Source) -> Csr {
        let mut out = Csr::new(m.ncols);
        for r in (0..m.nrows()).filter(|&r| !self.is_split(source, r)) {
            let range = m.start[r]..m.start[r + 1];
            out.col.extend_from_slice(&m.col[range.clone()]);
            out.val.extend_from_slice(&m.val[range]);
            out.start.push(out.col.len());
        }
        out
    }

    /// The split rows' entries (column, value) in `quad` and `cons`, split unknown by split
    /// unknown.
    pub(super) fn entries<'a>(
        &'a self,
        quad: &'a Csr,
        cons: &'a Csr,
    ) -> impl Iterator<Item = (usize, impl Iterator<Item = (usize, f64)> + 'a)> + 'a {
        self.rows.iter().enumerate().map(move |(k, &(source, r))| {
            let m = match source {
                Source::Quad => quad,
                Source::Cons => cons,
            };
            (k, m.row(r))
        })
    }

    /// The lower triangle (rows sorted in each column) of the factored matrix: that of the n
    /// unknowns in their new labels (`col_ptr`, `row_idx`), with split unknown k as n + k,
    /// coupled to the entries of its row and to nothing else. Records the slots of those
    /// couplings and of the split unknowns' diagonals.
    pub(super) fn augmented(
        &mut self,
        (col_ptr, row_idx): (Vec<usize>, Vec<usize>),
        label: &[usize],
        quad: &Csr,
        cons: &Csr,
    ) -> (Vec<usize>, Vec<usize>) {
        let n = label.len();
        if self.rows.is_empty() {
            return (col_ptr, row_idx);
        }
        let n_factor = n + self.count();
        let couplings = || {
            self.entries(quad, cons)
                .flat_map(move |(k, row)| row.map(move |(c, _)| (label[c], n + k)))
        };
        let diagonals = (n..n_factor).map(|j| (j, j));
        let extra = self.rows.iter().map(|&(source, r)| match source {
            Source::Quad => quad.start[r + 1] - quad.start[r] + 1,
            Source::Cons => cons.start[r + 1] - cons.start[r] + 1,
        });
        let nnz = row_idx.len() + extra.sum::<usize>();
        // Each column's new rows (n + k, k increasing) come after its old ones (all < n):
        // rows stay sorted.
        let (ptr, idx) = bucketed(n_factor, nnz, || {
            super::graph::entries(&col_ptr, &row_idx)
                .map(|(r, c)| (c, r))
                .chain(couplings())
                .chain(diagonals.clone())
        });
        debug_assert!((0..n_factor).all(|c| idx[ptr[c]..ptr[c + 1]].is_sorted()));
        let (mut slot_start, mut slot) = (vec![0], Vec::new());
        for (k, row) in self.entries(quad, cons) {
            for (c, _) in row {
                let col = label[c];
                let rows = &idx[ptr[col]..ptr[col + 1]];
                slot.push(ptr[col] + rows.partition_point(|&r| r < n + k));
            }
            slot_start.push(slot.len());
        }
        (self.slot_start, self.slot) = (slot_start, slot);
        self.diag = (n..n_factor).map(|j| ptr[j]).collect();
        (ptr, idx)
    }
}

/// The split rows of P, with their weights, in the new labels: P x adds w a (a·x) for each.
pub(super) struct DenseQuad {
    pub(super) rows: Vec<(f64, Vec<(usize, f64)>)>,
}

impl DenseQuad {
    /// The split rows of `dense` that are rows of P, their columns relabelled by `label`.
    pub(super) fn new(
        dense: &DenseRows,
        label: &[usize],
        quad: &Csr,
        quad_weight: &[f64],
    ) -> DenseQuad {
        let rows = (dense.rows.iter())
            .filter(|(source, _)| *source == Source::Quad)
            .map(|&(_, r)| {
                let entries = quad.row(r).map(|(c, v)| (label[c], v)).collect();
                (quad_weight[r], entries)
            })
            .collect();
        DenseQuad { rows }
    }

    /// Adds Σ w a (a·x) to y, or with `abs` the sizes of its terms, |w| |a| (|a|·|x|).
    pub(super) fn add_to(&self, x: &[f64], y: &mut [f64], abs: bool) {
        for (w, row) in &self.rows {
            if abs {
                let t = w.abs() * row.iter().map(|&(c, v)| (v * x[c]).abs()).sum::<f64>();
                row.iter().for_each(|&(c, v)| y[c] += v.abs() * t);
            } else {
                let t = w * row.iter().map(|&(c, v)| v * x[c]).sum::<f64>();
                row.iter().for_each(|&(c, v)| y[c] += v * t);
            }
        }
    }
}

/// The values of the split rows' couplings and diagonals in `values` (slots of the
/// factored matrix): a row of P couples by its entries and has the diagonal −1/w; one of
/// weight 0 is left uncoupled, its unknown pinned to 0 by the diagonal −1. C's split rows
/// couple by their entries; their diagonals, −1/w with the step's weight, are set per
/// Newton system.
pub(super) fn fill_couplings(
    dense: &DenseRows,
    (quad, quad_weight): (&Csr, &[f64]),
    cons: &Csr,
    values: &mut [f64],
) {
    for (k, row) in dense.entries(quad, cons) {
        let (source, r) = dense.rows[k];
        let w = if source == Source::Quad {
            quad_weight[r]
        } else {
            1.0
        };
        let slots = &dense.slot[dense.slot_start[k]..dense.slot_start[k + 1]];
        for (&slot, (_, v)) in slots.iter().zip(row) {
            values[slot] = if w > 0.0 { v } else { 0.0 };
        }
        if source == Source::Quad {
            values[dense.diag[k]] = if w > 0.0 { -1.0 / w } else { -1.0 };
        }
    }
}
