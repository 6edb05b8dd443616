//! The normal matrix P + Cᵀ W C: its structure (fill-reducing relabelling, symbolic
//! factorisation, the value slot of every product), built once per mesh connectivity and kept
//! in a `PatternCache`, and its values for one QP.

use super::dense::{fill_couplings, DenseQuad, DenseRows, Source};
use super::factorise::Plan;
use super::graph::{amd_labels, entries};
use super::ordering::nested_dissection_labels;
use super::supernodal::Split;
use crate::stress::sparse::{bucketed, Csr};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky, SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::SymbolicSparseColMatRef;

/// The structure of the normal matrix P + Cᵀ W C (lower triangle, compressed columns): its
/// fill-reducing relabelling (`label[i]` is the new index of unknown i, so that no numeric
/// factorisation has to permute it again), its symbolic factorisation and the value slot of
/// every product q_ka q_kb and c_ia c_ib. It depends only on where P's rows and C have entries,
/// which form finding keeps from step to step, so a `PatternCache` carries it across steps.
pub(super) struct Pattern {
    /// Row starts and columns of P's rows and of C: with `n` and `m_eq`, the structure this
    /// pattern was built from.
    pub(super) built_from: [Vec<usize>; 4],
    pub(super) n: usize,
    pub(super) m_eq: usize,
    pub(super) label: Vec<usize>,
    pub(super) col_ptr: Vec<usize>,
    pub(super) row_idx: Vec<usize>,
    /// Slot of each product of P's rows, in the order `products` visits them.
    pub(super) quad_slot: Vec<usize>,
    /// Per constraint row, from `row_start[r]`: the slot of each of its products.
    pub(super) row_start: Vec<usize>,
    pub(super) row_slot: Vec<usize>,
    pub(super) diag: Vec<usize>,
    /// The rows of P and C factored apart, as unknowns n, n + 1, … of the factored matrix
    /// (`dense`); the pattern's rows and columns beyond n are theirs.
    pub(super) dense: DenseRows,
    pub(super) symbolic: SymbolicCholesky<usize>,
    /// Large factors' solves on two threads (`supernodal::Split::for_solve`).
    pub(super) solve_split: Option<Split>,
    /// Large factors' factorisation on two threads (`factorise::Plan::new`).
    pub(super) plan: Option<Plan>,
}

/// The normal matrix's structure, kept between QPs of the same structure (the steps of one
/// form finding): its ordering and symbolic analysis are then done once per loop instead of
/// once per step. Empty by default; a QP of another structure replaces what it holds.
#[derive(Default)]
pub struct PatternCache {
    pub(super) pattern: Option<Pattern>,
    /// The last answer on this pattern, in the caller's units, with its active set and
    /// multipliers.
    pub(super) last: Option<super::WarmPoint>,
    /// The shape is far from balance: beyond 20k unknowns the next QP does not try the last
    /// answer's active set (see `PatternCache::far_from_balance`).
    pub(super) far_from_balance: bool,
}

impl PatternCache {
    /// Whether the next QP's shape is far from balance (see `StressCache::far_from_balance`).
    /// Only beyond 20k unknowns is the last active set then skipped: below, a failed attempt
    /// costs milliseconds and a successful one can spare a fallback to clarabel.
    pub fn far_from_balance(&mut self, far: bool) {
        self.far_from_balance = far;
    }

    /// The pattern of P + Cᵀ W C for these matrices: the one held if it was built from the
    /// same structure (true), else a new one (false; None if the ordering or analysis failed).
    pub(super) fn pattern(
        &mut self,
        quad: &Csr,
        cons: &Csr,
        m_eq: usize,
        positions: Option<&[[f64; 2]]>,
    ) -> Option<(&Pattern, bool)> {
        let reused = self
            .pattern
            .as_ref()
            .is_some_and(|p| p.fits(quad, cons, m_eq));
        if !reused {
            self.pattern = None;
            self.pattern = Some(Pattern::new(quad, cons, m_eq, positions)?);
        }
        self.pattern.as_ref().map(|p| (p, reused))
    }
}

/// The normal matrix: the values of P and of each constraint row's products, on a `Pattern`.
pub(super) struct Normal<'p> {
    pub(super) pattern: &'p Pattern,
    /// Values of P alone, in the pattern's slots, and the couplings of the split rows (see
    /// `dense`), which P x does not read.
    pub(super) p_values: Vec<f64>,
    /// c_ia c_ib for the slots `pattern.row_slot`.
    pub(super) row_prod: Vec<f64>,
    /// P's split rows, which P x adds apart.
    pub(super) dense_quad: DenseQuad,
}

/// Every pair of entries (a, v_a), (b, v_b) with b ≤ a of each row r of `m`, as
/// (r, a, b, v_a, v_b), row by row: the order of `Pattern::quad_slot` and `row_slot`.
#[cfg(test)]
pub(super) fn products(m: &Csr) -> impl Iterator<Item = (usize, usize, usize, f64, f64)> + '_ {
    products_of(m, |_| true)
}

/// `products` of the rows r of `m` with `keep(r)` (the others are not paired at all: a split
/// row's pairs are as many as its entries squared).
#[cfg(test)]
pub(super) fn products_of<'a>(
    m: &'a Csr,
    keep: impl Fn(usize) -> bool + 'a,
) -> impl Iterator<Item = (usize, usize, usize, f64, f64)> + 'a {
    (0..m.nrows()).filter(move |&r| keep(r)).flat_map(move |r| {
        m.row(r).flat_map(move |(a, va)| {
            m.row(r)
                .filter(move |&(b, _)| b <= a)
                .map(move |(b, vb)| (r, a, b, va, vb))
        })
    })
}

/// `products_of(m, …)` over the rows of `m` that `pattern` does not split, as plain loops
/// (the numeric assembly of every QP of a form finding; the iterator chain cost as much as a
/// factorisation): `f(r, v_a, v_b)` in the same order.
fn for_each_product(
    m: &Csr,
    source: Source,
    pattern: &Pattern,
    mut f: impl FnMut(usize, f64, f64),
) {
    for r in (0..m.nrows()).filter(|&r| !pattern.dense.is_split(source, r)) {
        let range = m.start[r]..m.start[r + 1];
        let (cols, vals) = (&m.col[range.clone()], &m.val[range]);
        for (&a, &va) in cols.iter().zip(vals) {
            for (&b, &vb) in cols.iter().zip(vals) {
                if b <= a {
                    f(r, va, vb);
                }
            }
        }
    }
}

/// Lower-triangle pattern (column pointers, row indices) of the products of every row's
/// entries with each other, for `n` unknowns. Built column by column with a marker array:
/// sorting all products at once dominated the setup.
pub(super) fn product_pattern(rows: [&Csr; 2], n: usize) -> (Vec<usize>, Vec<usize>) {
    // The rows holding each unknown, as compressed columns; the second matrix's rows are
    // numbered after the first's.
    let first_rows = rows[0].nrows();
    let row_entries = |k: usize| {
        let m = rows[k];
        (0..m.nrows()).flat_map(move |r| {
            m.col[m.start[r]..m.start[r + 1]]
                .iter()
                .map(move |&a| (a, r + k * first_rows))
        })
    };
    let (holder_ptr, holders) = bucketed(n, rows[0].col.len() + rows[1].col.len(), || {
        row_entries(0).chain(row_entries(1))
    });
    let mut col_ptr = vec![0];
    let mut row_idx = Vec::new();
    let mut seen = vec![usize::MAX; n];
    for c in 0..n {
        let first = row_idx.len();
        seen[c] = c;
        row_idx.push(c);
        for &h in &holders[holder_ptr[c]..holder_ptr[c + 1]] {
            let (m, r) = match h.checked_sub(first_rows) {
                Some(r) => (rows[1], r),
                None => (rows[0], h),
            };
            for &b in &m.col[m.start[r]..m.start[r + 1]] {
                if b > c && seen[b] != c {
                    seen[b] = c;
                    row_idx.push(b);
                }
            }
        }
        row_idx[first..].sort_unstable();
        col_ptr.push(row_idx.len());
    }
    (col_ptr, row_idx)
}

/// The slot in a relabelled lower-triangle pattern of every product `products(m)` visits, in
/// its order. Per row, the labels are sorted so that one forward scan of each column finds
/// all the row's later labels, where a binary search per product would mispredict most of
/// its branches.
pub(super) fn product_slots(
    m: &Csr,
    label: &[usize],
    col_ptr: &[usize],
    row_idx: &[usize],
) -> Vec<usize> {
    let mut out = Vec::new();
    // The row's entries in label order, and the k × k table of their products' slots.
    let (mut by_label, mut table) = (Vec::new(), Vec::new());
    for r in 0..m.nrows() {
        if r % 1024 == 0 {
            crate::interrupt::poll();
        }
        let cols = &m.col[m.start[r]..m.start[r + 1]];
        let k = cols.len();
        by_label.clear();
        by_label.extend(0..k);
        by_label.sort_unstable_by_key(|&i| label[cols[i]]);
        table.clear();
        table.resize(k * k, 0);
        for (i, &a) in by_label.iter().enumerate() {
            let col = label[cols[a]];
            let mut slot = col_ptr[col];
            debug_assert_eq!(row_idx[slot], col);
            table[a * k + a] = slot;
            for &b in &by_label[i + 1..] {
                let row = label[cols[b]];
                while row_idx[slot] != row {
                    slot += 1;
                }
                debug_assert!(slot < col_ptr[col + 1]);
                (table[a * k + b], table[b * k + a]) = (slot, slot);
            }
        }
        // `products` order: a row's columns are sorted, so b ≤ a is position ib ≤ ia.
        for ia in 0..k {
            out.extend_from_slice(&table[ia * k..ia * k + ia + 1]);
        }
    }
    out
}

/// QPs with this many unknowns or more are ordered by nested dissection when their
/// unknowns' positions are known (`ordering`). Below, AMD's order needs less work and two
/// threads still factor it well.
const DISSECT_FROM: usize = 40_000;

/// The lower triangle of a symmetric pattern (given by its lower triangle) with its unknowns
/// relabelled, rows sorted in each column.
pub(super) fn relabelled_lower(
    n: usize,
    col_ptr: &[usize],
    row_idx: &[usize],
    label: &[usize],
) -> (Vec<usize>, Vec<usize>) {
    let (ptr, mut idx) = bucketed(n, row_idx.len(), || {
        entries(col_ptr, row_idx).map(|(r, c)| {
            let (a, b) = (label[r], label[c]);
            (a.min(b), a.max(b))
        })
    });
    for c in 0..n {
        idx[ptr[c]..ptr[c + 1]].sort_unstable();
    }
    (ptr, idx)
}

/// The pattern of the transpose of an n × n compressed-column pattern (rows stay sorted: the
/// entries come column by column).
pub(super) fn transpose(
    n: usize,
    col_ptr: &[usize],
    row_idx: &[usize],
) -> (Vec<usize>, Vec<usize>) {
    bucketed(n, row_idx.len(), || entries(col_ptr, row_idx))
}

/// The symbolic factorisation of a pattern already in its elimination order (given as an
/// upper triangle: without an ordering faer reads it so, whatever the side).
pub(super) fn symbolic_cholesky(
    n: usize,
    col_ptr: &[usize],
    row_idx: &[usize],
) -> Option<SymbolicCholesky<usize>> {
    factorize_symbolic_cholesky(
        SymbolicSparseColMatRef::new_checked(n, n, col_ptr, None, row_idx),
        faer::Side::Lower,
        SymmetricOrdering::Identity,
        CholeskySymbolicParams {
            // The simplicial variant is several times slower on these two-ring matrices
            // even at a thousand unknowns.
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        },
    )
    .ok()
}

impl Pattern {
    /// Whether the pattern was built from matrices with entries where `quad` and `cons` have
    /// them (compared in place: no copy per step). The unknowns' positions only chose the
    /// order, which stays valid (and is kept) whatever positions later QPs bring.
    pub(super) fn fits(&self, quad: &Csr, cons: &Csr, m_eq: usize) -> bool {
        let [quad_start, quad_col, cons_start, cons_col] = &self.built_from;
        (self.n, self.m_eq) == (cons.ncols, m_eq)
            && (quad_start, quad_col) == (&quad.start, &quad.col)
            && (cons_start, cons_col) == (&cons.start, &cons.col)
    }

    /// `cons` = [E; G] with `m_eq` equality rows first; `positions`: see `Qp::positions`.
    pub(super) fn new(
        quad: &Csr,
        cons: &Csr,
        m_eq: usize,
        positions: Option<&[[f64; 2]]>,
    ) -> Option<Pattern> {
        let n = cons.ncols;
        let mut dense = DenseRows::find(quad, cons);
        let kept = [
            dense.kept(quad, Source::Quad),
            dense.kept(cons, Source::Cons),
        ];
        let (col_ptr, row_idx) = product_pattern([&kept[0], &kept[1]], n);
        crate::interrupt::poll();
        // One symbolic analysis in the new labels: the ordering alone comes from AMD or the
        // dissection, so that the pattern is not analysed twice.
        let label = match positions {
            Some(positions)
                if n >= DISSECT_FROM
                    && positions.len() == n
                    && positions.iter().flatten().all(|x| x.is_finite()) =>
            {
                nested_dissection_labels(&col_ptr, &row_idx, positions)
            }
            _ => amd_labels(n, &col_ptr, &row_idx)?,
        };
        let lower = relabelled_lower(n, &col_ptr, &row_idx, &label);
        let (col_ptr, row_idx) = dense.augmented(lower, &label, quad, cons);
        let n_factor = n + dense.count();
        let (up_ptr, up_idx) = transpose(n_factor, &col_ptr, &row_idx);
        let symbolic = symbolic_cholesky(n_factor, &up_ptr, &up_idx)?;
        let quad_slot = product_slots(&kept[0], &label, &col_ptr, &row_idx);
        let row_slot = product_slots(&kept[1], &label, &col_ptr, &row_idx);
        // A row's columns are distinct (`Csr::push_row` merges repeats): k entries, k(k+1)/2
        // products.
        let mut row_start = vec![0];
        for r in 0..cons.nrows() {
            let k = if dense.is_split(Source::Cons, r) {
                0
            } else {
                cons.start[r + 1] - cons.start[r]
            };
            row_start.push(row_start[r] + k * (k + 1) / 2);
        }
        debug_assert_eq!(row_start[cons.nrows()], row_slot.len());
        // Rows are sorted in each column of the lower triangle: the diagonal comes first.
        let diag = label.iter().map(|&l| col_ptr[l]).collect();
        Some(Pattern {
            built_from: [
                quad.start.clone(),
                quad.col.clone(),
                cons.start.clone(),
                cons.col.clone(),
            ],
            n,
            m_eq,
            label,
            col_ptr,
            row_idx,
            quad_slot,
            row_start,
            row_slot,
            diag,
            dense,
            solve_split: Split::for_solve(&symbolic),
            plan: Plan::new(&symbolic, n),
            symbolic,
        })
    }
}

impl<'p> Normal<'p> {
    /// The values of P (rows of `quad` weighted by `quad_weight`) and of C's products on
    /// `pattern`, which was built from the same structure.
    pub(super) fn new(
        pattern: &'p Pattern,
        quad: &Csr,
        quad_weight: &[f64],
        cons: &Csr,
    ) -> Normal<'p> {
        let mut p_values = vec![0.0; pattern.row_idx.len()];
        let mut slots = pattern.quad_slot.iter();
        for_each_product(quad, Source::Quad, pattern, |r, va, vb| {
            let slot = *slots.next().expect("one slot per product");
            p_values[slot] += quad_weight[r] * va * vb;
        });
        fill_couplings(&pattern.dense, (quad, quad_weight), cons, &mut p_values);
        let mut row_prod = Vec::with_capacity(pattern.row_slot.len());
        for_each_product(cons, Source::Cons, pattern, |_, va, vb| {
            row_prod.push(va * vb)
        });
        Normal {
            pattern,
            p_values,
            row_prod,
            dense_quad: DenseQuad::new(&pattern.dense, &pattern.label, quad, quad_weight),
        }
    }

    /// y = |P| |x| (entrywise absolute values): the size of the terms summed in P x.
    pub(super) fn mul_p_abs(&self, x: &[f64]) -> Vec<f64> {
        let mut y = self.sum_p_terms(x, |p, x| (p * x).abs());
        self.dense_quad.add_to(x, &mut y, true);
        y
    }

    /// y = P x from the stored lower triangle (x and y in the new labels).
    pub(super) fn mul_p(&self, x: &[f64]) -> Vec<f64> {
        let mut y = self.sum_p_terms(x, |p, x| p * x);
        self.dense_quad.add_to(x, &mut y, false);
        y
    }

    /// y_r = Σ_c term(P_rc, x_c) over the symmetric P held in the pattern (all but its split
    /// rows), from its lower triangle.
    pub(super) fn sum_p_terms(&self, x: &[f64], term: impl Fn(f64, f64) -> f64) -> Vec<f64> {
        let mut y = vec![0.0; self.pattern.n];
        let Pattern {
            col_ptr, row_idx, ..
        } = self.pattern;
        for c in 0..self.pattern.n {
            let mut acc = 0.0;
            let range = col_ptr[c]..col_ptr[c + 1];
            for (&r, &v) in row_idx[range.clone()].iter().zip(&self.p_values[range]) {
                // Rows beyond n: the split rows' couplings, not P's (the last in each column).
                if r >= self.pattern.n {
                    break;
                }
                y[r] += term(v, x[c]);
                if r != c {
                    acc += term(v, x[r]);
                }
            }
            y[c] += acc;
        }
        y
    }
}

/// `m` with column j renamed `label[j]` (each row re-sorted by the new labels).
pub(super) fn relabel_columns(m: &Csr, label: &[usize]) -> Csr {
    let mut out = Csr {
        ncols: m.ncols,
        start: m.start.clone(),
        col: Vec::with_capacity(m.col.len()),
        val: Vec::with_capacity(m.val.len()),
    };
    let mut row = Vec::new();
    for r in 0..m.nrows() {
        row.clear();
        row.extend(m.row(r).map(|(c, v)| (label[c], v)));
        // Distinct columns stay distinct: sorting is all `Csr::push_row` would do.
        row.sort_unstable_by_key(|e| e.0);
        out.col.extend(row.iter().map(|e| e.0));
        out.val.extend(row.iter().map(|e| e.1));
    }
    out
}

/// C = [E; G]: equality rows are constraints whose slack is pinned to zero. The rows are
/// copied as they are (`Csr::push_row` made them sorted, without repeats or zeros).
pub(super) fn stacked(eq: &Csr, ineq: &Csr) -> Csr {
    let mut cons = eq.clone();
    let offset = eq.col.len();
    cons.start
        .extend(ineq.start[1..].iter().map(|s| s + offset));
    cons.col.extend_from_slice(&ineq.col);
    cons.val.extend_from_slice(&ineq.val);
    cons
}

/// `x` with entry i moved to `label[i]`.
pub(super) fn relabel_vector(x: &[f64], label: &[usize]) -> Vec<f64> {
    let mut out = vec![0.0; x.len()];
    for (i, &l) in label.iter().enumerate() {
        out[l] = x[i];
    }
    out
}
