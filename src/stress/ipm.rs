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
//! The unknowns are relabelled once in a fill-reducing (AMD) order, so that no factorisation
//! permutes the matrix again. Gondzio's centrality correctors lengthen steps that a few
//! products s_i z_i would otherwise cut short; they reuse the factor with coarse solves. Near
//! the optimum the active set is solved for directly ("polishing"): with an objective that is
//! nearly zero at the optimum, the gap alone would creep towards the tolerance in rounding.
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
use faer::sparse::linalg::{amd, SupernodalThreshold};
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
    /// Inequality rows known to be dependent when all of a group are active (see
    /// `RowGroups`); empty when none are known.
    pub groups: &'a RowGroups,
}

/// Groups of inequality rows with two independent vanishing combinations each:
/// Σ_k c_k row_k = 0 with c_k ∈ R² (the lower bounds of the edges around an interior vertex in
/// reduced coordinates, whose forces balance horizontally there for every Airy function, with
/// c the edge vectors). When a whole group is active, its rows are dependent and the right-hand
/// side's rounding along the combinations is amplified by 1/δ: polishing then releases two
/// rows per such group, which the others imply.
#[derive(Debug, Clone, Default)]
pub struct RowGroups {
    /// Group g is `row[start[g]..start[g + 1]]` with coefficients `coef[..]` alike; `start` is
    /// empty or begins with 0.
    pub start: Vec<usize>,
    pub row: Vec<usize>,
    pub coef: Vec<[f64; 2]>,
}

impl RowGroups {
    fn len(&self) -> usize {
        self.start.len().saturating_sub(1)
    }

    fn group(&self, g: usize) -> (&[usize], &[[f64; 2]]) {
        let range = self.start[g]..self.start[g + 1];
        (&self.row[range.clone()], &self.coef[range])
    }

    fn any_wholly_active(&self, active: &[bool]) -> bool {
        (0..self.len()).any(|g| self.group(g).0.iter().all(|&r| active[r]))
    }

    /// The same groups for rows scaled by `row_scale` (coefficients divided by it).
    fn for_scaled_rows(&self, row_scale: &[f64]) -> RowGroups {
        let coef = self
            .row
            .iter()
            .zip(&self.coef)
            .map(|(&r, c)| [c[0] / row_scale[r], c[1] / row_scale[r]])
            .collect();
        RowGroups {
            start: self.start.clone(),
            row: self.row.clone(),
            coef,
        }
    }

    /// The rows to release from the active set `active`: two of every group whose rows are
    /// all active (and not yet released for another group). With multipliers z, the pair is
    /// chosen so that shifting z along the group's combinations to zero them keeps the
    /// group's other multipliers non-negative (a vertex of {a : z_k + a·c_k ≥ 0}), the best
    /// conditioned such pair; with z = 0 every pair qualifies.
    fn released(&self, active: &[bool], z: &[f64]) -> Vec<bool> {
        let mut released = vec![false; active.len()];
        for g in 0..self.len() {
            let (rows, coef) = self.group(g);
            if rows.len() < 3 || !rows.iter().all(|&r| active[r]) {
                continue;
            }
            let mut best: Option<(f64, usize, usize)> = None;
            for i in 0..rows.len() {
                for j in i + 1..rows.len() {
                    if released[rows[i]] || released[rows[j]] {
                        continue;
                    }
                    let (a, b) = (coef[i], coef[j]);
                    let det = a[0] * b[1] - a[1] * b[0];
                    let norms = a[0].hypot(a[1]) * b[0].hypot(b[1]);
                    if det.abs() <= 1e-6 * norms {
                        continue;
                    }
                    // a·c_i = −z_i, a·c_j = −z_j.
                    let (zi, zj) = (z[rows[i]], z[rows[j]]);
                    let shift = [
                        (-zi * b[1] + zj * a[1]) / det,
                        (-zj * a[0] + zi * b[0]) / det,
                    ];
                    let feasible = rows.iter().zip(coef).all(|(&r, c)| {
                        z[r] + shift[0] * c[0] + shift[1] * c[1] >= -1e-9 * z[r].abs().max(1e-300)
                    });
                    let conditioning = det.abs() / norms;
                    if feasible && best.is_none_or(|(q, ..)| conditioning > q) {
                        best = Some((conditioning, rows[i], rows[j]));
                    }
                }
            }
            if let Some((_, ri, rj)) = best {
                (released[ri], released[rj]) = (true, true);
            }
        }
        released
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IpmStatus {
    Solved,
    /// The method stopped (iteration limit, no progress or numerical trouble) at a point that
    /// meets the tolerances relaxed by `Tolerances::almost`.
    AlmostSolved,
    /// The iteration limit was reached, or beyond it stopped making progress (see
    /// `Progress`), short of even the relaxed tolerances.
    MaxIterations,
    /// Factorisation failed or the iterates diverged (typically an infeasible or degenerate
    /// problem).
    NumericalError,
}

pub struct IpmOutput {
    pub x: Vec<f64>,
    pub status: IpmStatus,
    pub iterations: u32,
    /// Per inequality row, whether it is active at `x` (empty unless solved).
    pub active: Vec<bool>,
}

/// Tolerances: the gap sᵀz must fall below `gap_abs + gap_rel |objective|`, the primal
/// residuals below `feas` and the dual one below `dual_feas`, each relative to its data.
#[derive(Debug, Clone, Copy)]
pub struct Tolerances {
    pub gap_abs: f64,
    pub gap_rel: f64,
    pub feas: f64,
    /// The same for the dual residual P x + c − Eᵀλ − Gᵀz, or its rounding floor when that
    /// is larger (see `for_size` and `DUAL_ROUNDING`).
    pub dual_feas: f64,
    /// Factor by which all tolerances are relaxed for `AlmostSolved`.
    pub almost: f64,
    pub max_iter: u32,
}

impl Tolerances {
    /// The defaults adapted to `n` unknowns.
    /// - The dual tolerance grows as √(n / 10⁴) from 10⁴ unknowns on, besides its rounding
    ///   floor (`DUAL_ROUNDING`): at 100k unknowns form-finding steps whose residual hovered
    ///   1–3× above 1e-10 of its scale stayed above the floor as well, and without the growth
    ///   they fell back to clarabel. A flat 1e-9 let four_holes stop 0.2% above its optimum.
    /// - The iteration budget: the fallback (clarabel) costs about what 100 native iterations
    ///   do at a thousand unknowns but thousands at 20k and more (a 20k-vertex QP: 2 s
    ///   native, 120 s clarabel), so large problems get more (see `fallback_is_costly`).
    pub fn for_size(n: usize) -> Tolerances {
        let base = Tolerances::default();
        Tolerances {
            dual_feas: base.dual_feas * (n as f64 / 1e4).sqrt().max(1.0),
            max_iter: if fallback_is_costly(n) { 150 } else { 80 },
            ..base
        }
    }
}

/// Whether clarabel, the fallback, costs thousands of native iterations on a QP with `n`
/// unknowns (a 20k-vertex QP: 2 s native, 120 s clarabel; at 100k a form-finding step ran
/// for more than 10 minutes in clarabel where the native method had taken 20–75 s).
pub fn fallback_is_costly(n: usize) -> bool {
    n > 20_000
}

impl Default for Tolerances {
    fn default() -> Self {
        // As tight as the clarabel settings in qp.rs: residuals must be reproducible to ~1e-6
        // of the mean load, and the objective (Σ r²) is often ~0 at the optimum.
        Tolerances {
            gap_abs: 1e-12,
            gap_rel: 1e-11,
            feas: 1e-10,
            dual_feas: 1e-10,
            almost: 10.0,
            // Well-posed problems converge in 11–40 iterations (form-finding steps at 100k
            // unknowns took up to 130); beyond, the caller's fallback is cheaper than crawling
            // on: see `for_size`.
            max_iter: 80,
        }
    }
}

/// The structure of the normal matrix P + Cᵀ W C (lower triangle, compressed columns): its
/// fill-reducing relabelling (`label[i]` is the new index of unknown i, so that no numeric
/// factorisation has to permute it again), its symbolic factorisation and the value slot of
/// every product q_ka q_kb and c_ia c_ib. It depends only on where P's rows and C have entries,
/// which form finding keeps from step to step, so a `PatternCache` carries it across steps.
struct Pattern {
    /// Row starts and columns of P's rows and of C: with `n` and `m_eq`, the structure this
    /// pattern was built from.
    built_from: [Vec<usize>; 4],
    n: usize,
    m_eq: usize,
    label: Vec<usize>,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Slot of each product of P's rows, in the order `products` visits them.
    quad_slot: Vec<usize>,
    /// Per constraint row, from `row_start[r]`: the slot of each of its products.
    row_start: Vec<usize>,
    row_slot: Vec<usize>,
    diag: Vec<usize>,
    symbolic: SymbolicCholesky<usize>,
}

/// The normal matrix's structure, kept between QPs of the same structure (the steps of one
/// form finding): its ordering and symbolic analysis are then done once per loop instead of
/// once per step. Empty by default; a QP of another structure replaces what it holds.
#[derive(Default)]
pub struct PatternCache {
    pattern: Option<Pattern>,
    /// The last answer on this pattern, in the caller's units, and its active set.
    last: Option<(Vec<f64>, Vec<bool>)>,
}

impl PatternCache {
    /// The pattern of P + Cᵀ W C for these matrices: the one held if it was built from the
    /// same structure (true), else a new one (false; None if the ordering or analysis failed).
    fn pattern(&mut self, quad: &Csr, cons: &Csr, m_eq: usize) -> Option<(&Pattern, bool)> {
        let reused = self
            .pattern
            .as_ref()
            .is_some_and(|p| p.fits(quad, cons, m_eq));
        if !reused {
            self.pattern = None;
            self.pattern = Some(Pattern::new(quad, cons, m_eq)?);
        }
        self.pattern.as_ref().map(|p| (p, reused))
    }
}

/// The normal matrix: the values of P and of each constraint row's products, on a `Pattern`.
struct Normal<'p> {
    pattern: &'p Pattern,
    /// Values of P alone, in the pattern's slots.
    p_values: Vec<f64>,
    /// c_ia c_ib for the slots `pattern.row_slot`.
    row_prod: Vec<f64>,
}

/// Every pair of entries (a, v_a), (b, v_b) with b ≤ a of each row r of `m`, as
/// (r, a, b, v_a, v_b), row by row: the order of `Pattern::quad_slot` and `row_slot`.
fn products(m: &Csr) -> impl Iterator<Item = (usize, usize, usize, f64, f64)> + '_ {
    (0..m.nrows()).flat_map(move |r| {
        m.row(r).flat_map(move |(a, va)| {
            m.row(r)
                .filter(move |&(b, _)| b <= a)
                .map(move |(b, vb)| (r, a, b, va, vb))
        })
    })
}

/// Lower-triangle pattern (column pointers, row indices) of the products of every row's
/// entries with each other, for `n` unknowns. Built column by column with a marker array:
/// sorting all products at once dominated the setup.
fn product_pattern(rows: [&Csr; 2], n: usize) -> (Vec<usize>, Vec<usize>) {
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
/// all the row's later labels: a binary search per product mispredicted most of its branches
/// (20 of the 35 ms the 6k-vertex row's pattern took).
fn product_slots(m: &Csr, label: &[usize], col_ptr: &[usize], row_idx: &[usize]) -> Vec<usize> {
    let mut out = Vec::new();
    // The row's entries in label order, and the k × k table of their products' slots.
    let (mut by_label, mut table) = (Vec::new(), Vec::new());
    for r in 0..m.nrows() {
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

/// The new label of every unknown in the approximate-minimum-degree order of a symmetric
/// pattern (its lower triangle, rows sorted in each column).
fn amd_labels(n: usize, col_ptr: &[usize], row_idx: &[usize]) -> Option<Vec<usize>> {
    let (mut order, mut label) = (vec![0; n], vec![0; n]);
    let mut buffer = MemBuffer::try_new(amd::order_scratch::<usize>(n, row_idx.len())).ok()?;
    amd::order(
        &mut order,
        &mut label,
        SymbolicSparseColMatRef::new_checked(n, n, col_ptr, None, row_idx),
        amd::Control::default(),
        MemStack::new(&mut buffer),
    )
    .ok()?;
    Some(label)
}

/// The lower triangle of a symmetric pattern (given by its lower triangle) with its unknowns
/// relabelled, rows sorted in each column.
fn relabelled_lower(
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
fn transpose(n: usize, col_ptr: &[usize], row_idx: &[usize]) -> (Vec<usize>, Vec<usize>) {
    bucketed(n, row_idx.len(), || entries(col_ptr, row_idx))
}

/// The (row, column) entries of a compressed-column pattern, column by column.
fn entries<'a>(
    col_ptr: &'a [usize],
    row_idx: &'a [usize],
) -> impl Iterator<Item = (usize, usize)> + 'a {
    (0..col_ptr.len() - 1).flat_map(move |c| {
        row_idx[col_ptr[c]..col_ptr[c + 1]]
            .iter()
            .map(move |&r| (r, c))
    })
}

/// A compressed-column pattern of n columns from `nnz` (column, row) entries, rows in the
/// order the entries come (`entries` is called twice: to count, then to fill).
fn bucketed<I: Iterator<Item = (usize, usize)>>(
    n: usize,
    nnz: usize,
    entries: impl Fn() -> I,
) -> (Vec<usize>, Vec<usize>) {
    let mut ptr = vec![0; n + 1];
    for (col, _) in entries() {
        ptr[col + 1] += 1;
    }
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

/// The symbolic factorisation of a pattern already in its elimination order (given as an
/// upper triangle: without an ordering faer reads it so, whatever the side).
fn symbolic_cholesky(
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
    /// them (compared in place: no copy per step).
    fn fits(&self, quad: &Csr, cons: &Csr, m_eq: usize) -> bool {
        let [quad_start, quad_col, cons_start, cons_col] = &self.built_from;
        (self.n, self.m_eq) == (cons.ncols, m_eq)
            && (quad_start, quad_col) == (&quad.start, &quad.col)
            && (cons_start, cons_col) == (&cons.start, &cons.col)
    }

    /// `cons` = [E; G] with `m_eq` equality rows first.
    fn new(quad: &Csr, cons: &Csr, m_eq: usize) -> Option<Pattern> {
        let n = cons.ncols;
        let (col_ptr, row_idx) = product_pattern([quad, cons], n);
        // One symbolic analysis in the new labels: the ordering alone comes from AMD, so
        // that the pattern is not analysed twice.
        let label = amd_labels(n, &col_ptr, &row_idx)?;
        let (col_ptr, row_idx) = relabelled_lower(n, &col_ptr, &row_idx, &label);
        let (up_ptr, up_idx) = transpose(n, &col_ptr, &row_idx);
        let symbolic = symbolic_cholesky(n, &up_ptr, &up_idx)?;
        let quad_slot = product_slots(quad, &label, &col_ptr, &row_idx);
        let row_slot = product_slots(cons, &label, &col_ptr, &row_idx);
        // A row's columns are distinct (`Csr::push_row` merges repeats): k entries, k(k+1)/2
        // products.
        let mut row_start = vec![0];
        for r in 0..cons.nrows() {
            let k = cons.start[r + 1] - cons.start[r];
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
            symbolic,
        })
    }
}

impl<'p> Normal<'p> {
    /// The values of P (rows of `quad` weighted by `quad_weight`) and of C's products on
    /// `pattern`, which was built from the same structure.
    fn new(pattern: &'p Pattern, quad: &Csr, quad_weight: &[f64], cons: &Csr) -> Normal<'p> {
        let mut p_values = vec![0.0; pattern.row_idx.len()];
        for (&slot, (r, _, _, va, vb)) in pattern.quad_slot.iter().zip(products(quad)) {
            p_values[slot] += quad_weight[r] * va * vb;
        }
        let mut row_prod = Vec::with_capacity(pattern.row_slot.len());
        row_prod.extend(products(cons).map(|(.., va, vb)| va * vb));
        Normal {
            pattern,
            p_values,
            row_prod,
        }
    }

    /// y = |P| |x| (entrywise absolute values): the size of the terms summed in P x.
    fn mul_p_abs(&self, x: &[f64]) -> Vec<f64> {
        self.sum_p_terms(x, |p, x| (p * x).abs())
    }

    /// y = P x from the stored lower triangle (x and y in the new labels).
    fn mul_p(&self, x: &[f64]) -> Vec<f64> {
        self.sum_p_terms(x, |p, x| p * x)
    }

    /// y_r = Σ_c term(P_rc, x_c) over the full symmetric P, from its lower triangle.
    fn sum_p_terms(&self, x: &[f64], term: impl Fn(f64, f64) -> f64) -> Vec<f64> {
        let mut y = vec![0.0; self.pattern.n];
        let Pattern {
            col_ptr, row_idx, ..
        } = self.pattern;
        for c in 0..self.pattern.n {
            let mut acc = 0.0;
            let range = col_ptr[c]..col_ptr[c + 1];
            for (&r, &v) in row_idx[range.clone()].iter().zip(&self.p_values[range]) {
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
fn relabel_columns(m: &Csr, label: &[usize]) -> Csr {
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
fn stacked(eq: &Csr, ineq: &Csr) -> Csr {
    let mut cons = eq.clone();
    let offset = eq.col.len();
    cons.start
        .extend(ineq.start[1..].iter().map(|s| s + offset));
    cons.col.extend_from_slice(&ineq.col);
    cons.val.extend_from_slice(&ineq.val);
    cons
}

/// `x` with entry i moved to `label[i]`.
fn relabel_vector(x: &[f64], label: &[usize]) -> Vec<f64> {
    let mut out = vec![0.0; x.len()];
    for (i, &l) in label.iter().enumerate() {
        out[l] = x[i];
    }
    out
}

/// Regularisation δ of the constraint rows (scaled units): inequality weights z/s are capped
/// near 1/δ, equality rows weigh 1/δ_eq. Larger weights would lose the small curvatures to
/// rounding; refinement removes the regularisation's effect on the solution. With 1e-8 the
/// 100k-vertex dome stalled at a dual residual near 1e-8 (and fell back to clarabel); 1e-10
/// failed already at 6k.
const DELTA: f64 = 1e-7;
const DELTA_EQ: f64 = 1e-6;

/// Gondzio's centrality correctors: at most this many per iteration, each aiming at a step
/// `stretch α + add` (α the step already reached) and kept only if it gains a tenth of that.
const CORRECTORS: usize = 3;
const CORRECTOR_STRETCH: f64 = 1.5;
const CORRECTOR_ADD: f64 = 0.1;

/// Fraction of the way to the boundary of the positive orthant taken by each step (0.995
/// lost the last digits the 50k-vertex dome needs and fell back to clarabel).
const STEP_FRACTION: f64 = 0.99;

/// Static regularisations of the normal matrix tried in turn until the factor is sound.
const REGULARISATION: [f64; 3] = [1e-12, 1e-9, 1e-6];

/// The Newton system in augmented form, for unknowns (dx, w):
///
///   P dx + Cᵀ w = b1,   C dx − D w = b2      (C = [E; G], D = 0 on E, s / z on G)
///
/// solved with the factor of P + Cᵀ (D + δ)⁻¹ C, then refined against the exact system.
struct Newton<'a> {
    normal: &'a Normal<'a>,
    cons: &'a Csr,
    /// D per constraint row, and the weights 1 / (D + δ) the factor uses.
    d: Vec<f64>,
    w_reg: Vec<f64>,
    space: &'a mut FactorSpace,
}

/// Storage of the numeric factor and its scratch, allocated once per QP: every Newton step
/// refactors the same pattern.
struct FactorSpace {
    values: Vec<f64>,
    /// Expected pivot signs (all positive) for faer's dynamic regularisation.
    signs: Vec<i8>,
    l_values: Vec<f64>,
    buffer: MemBuffer,
}

impl FactorSpace {
    fn new(symbolic: &SymbolicCholesky<usize>, n_values: usize) -> Option<FactorSpace> {
        let par = Par::Seq;
        let scratch = symbolic
            .factorize_numeric_ldlt_scratch::<f64>(par, Default::default())
            .or(symbolic.solve_in_place_scratch::<f64>(1, par));
        Some(FactorSpace {
            values: vec![0.0; n_values],
            signs: vec![1; symbolic.nrows()],
            l_values: vec![0.0; symbolic.len_val()],
            buffer: MemBuffer::try_new(scratch).ok()?,
        })
    }
}

impl<'a> Newton<'a> {
    fn new(
        normal: &'a Normal<'a>,
        cons: &'a Csr,
        d: Vec<f64>,
        reg: f64,
        space: &'a mut FactorSpace,
    ) -> Option<Newton<'a>> {
        let pattern = normal.pattern;
        let n = pattern.n;
        let w_reg: Vec<f64> = d
            .iter()
            .enumerate()
            .map(|(r, d)| 1.0 / (d + if r < pattern.m_eq { DELTA_EQ } else { DELTA }))
            .collect();
        let values = &mut space.values;
        values.copy_from_slice(&normal.p_values);
        for (r, &w) in w_reg.iter().enumerate() {
            let range = pattern.row_start[r]..pattern.row_start[r + 1];
            for (&slot, &prod) in pattern.row_slot[range.clone()]
                .iter()
                .zip(&normal.row_prod[range])
            {
                values[slot] += w * prod;
            }
        }
        // A static regularisation keeps columns that only inactive bounds hold (pivots
        // ~ z/s → 0) away from zero; refinement removes its effect.
        for &k in &pattern.diag {
            values[k] += reg;
        }
        let matrix = SparseColMatRef::new(
            SymbolicSparseColMatRef::new_checked(n, n, &pattern.col_ptr, None, &pattern.row_idx),
            &values[..],
        );
        // Pivots that rounding makes non-positive are replaced by a huge value: that
        // direction then stays put for this solve instead of being amplified.
        let factored = pattern.symbolic.factorize_numeric_ldlt(
            &mut space.l_values,
            matrix,
            faer::Side::Lower,
            LdltRegularization {
                dynamic_regularization_signs: Some(&space.signs),
                dynamic_regularization_delta: 1e20,
                dynamic_regularization_epsilon: 1e-14,
            },
            Par::Seq,
            MemStack::new(&mut space.buffer),
            Default::default(),
        );
        factored.ok()?;
        Some(Newton {
            normal,
            cons,
            d,
            w_reg,
            space,
        })
    }

    /// One solve with the regularised factor.
    fn approximate(&mut self, b1: &[f64], b2: &[f64]) -> [Vec<f64>; 2] {
        let n = self.normal.pattern.n;
        let t: Vec<f64> = b2.iter().zip(&self.w_reg).map(|(b, w)| b * w).collect();
        let mut dx = mul_t(self.cons, &t, n);
        dx.iter_mut().zip(b1).for_each(|(x, b)| *x += b);
        let space = &mut *self.space;
        let ldlt = LdltRef::new(&self.normal.pattern.symbolic, &space.l_values);
        ldlt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(&mut dx, n, 1),
            Par::Seq,
            MemStack::new(&mut space.buffer),
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
    fn solve(&mut self, b1: &[f64], b2: &[f64], tol: f64, x_rows: bool) -> Option<[Vec<f64>; 2]> {
        let sol = self.approximate(b1, b2);
        self.refine(sol, b1, b2, tol, x_rows)
    }

    /// Iterative refinement of an approximate solution `sol` against the exact augmented
    /// system, as in `solve`.
    /// `x_rows`: go on while the x rows' error falls by a quarter a round, even once the
    /// weighted error has stalled (for a final answer, whose dual residual is that error).
    fn refine(
        &mut self,
        mut sol: [Vec<f64>; 2],
        b1: &[f64],
        b2: &[f64],
        tol: f64,
        x_rows: bool,
    ) -> Option<[Vec<f64>; 2]> {
        let n = self.normal.pattern.n;
        // Equality rows count as they are (their violation is what matters), inequality rows
        // as they enter dx (times their weight): inactive ones carry huge right-hand sides
        // whose rounding does not matter.
        let m_eq = self.normal.pattern.m_eq;
        let w_reg = self.w_reg.clone();
        let weighted = |b1: &[f64], b2: &[f64]| {
            b2.iter()
                .zip(&w_reg)
                .enumerate()
                .fold(inf_norm(b1), |a, (r, (b, w))| {
                    a.max(if r < m_eq { b.abs() } else { (b * w).abs() })
                })
        };
        let b_norm = weighted(b1, b2);
        let (mut last, mut last_x) = (f64::INFINITY, f64::INFINITY);
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
            let e_norm = weighted(&e1, &e2);
            e_x = inf_norm(&e1);
            terms = inf_norm(&px).max(inf_norm(&ct_w));
            let x_progress = x_rows && e_norm <= last && e_x <= 0.75 * last_x;
            if e_norm <= tol * b_norm || (e_norm > 0.5 * last && !x_progress) {
                break;
            }
            (last, last_x) = (e_norm, e_x);
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
    sum_t_terms(a, y, n, |a, y| a * y)
}

/// |A|ᵀ |y| for a Csr A with `n` columns.
fn abs_mul_t(a: &Csr, y: &[f64], n: usize) -> Vec<f64> {
    sum_t_terms(a, y, n, |a, y| (a * y).abs())
}

/// out_c = Σ_r term(a_rc, y_r) for a Csr A with `n` columns.
fn sum_t_terms(a: &Csr, y: &[f64], n: usize, term: impl Fn(f64, f64) -> f64) -> Vec<f64> {
    let mut out = vec![0.0; n];
    for (bounds, &yr) in a.start.windows(2).zip(y) {
        let range = bounds[0]..bounds[1];
        for (&c, &v) in a.col[range.clone()].iter().zip(&a.val[range]) {
            out[c] += term(v, yr);
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

/// Per inequality row, the factor that turns its scaled slack back into the caller's units,
/// up to one common factor (the median row scale). The starting point is built in those units:
/// the stress QPs' rows bound force densities (and τ), commensurate as the caller states them,
/// while the unit-norm scaling measures a boundary edge's force density (its own unknown) about 1/ℓ²
/// times larger than an interior edge's (a combination of Airy values). Mehrotra's uniform
/// shift in the scaled units then started the boundary edges' slacks hundreds of times below
/// their optimum (Cas-size dome: 65 against 3600; 50k: against 55 000), and the iterations
/// spent 15 steps of 0.2–0.7 letting them grow. The iterates are otherwise invariant to the
/// row scaling, which stays for the linear algebra.
fn caller_units(row_scale: &[f64]) -> Vec<f64> {
    let mut sorted = row_scale.to_vec();
    sorted.sort_by(f64::total_cmp);
    let Some(&median) = sorted.get(sorted.len() / 2) else {
        return Vec::new();
    };
    row_scale.iter().map(|r| median / r).collect()
}

/// Solves the QP after equilibration: variables scaled so that the normal matrix at W = I has
/// a unit diagonal, constraint rows scaled to unit norm. Weights and Airy values, boundary-edge
/// forces and hole coefficients differ by orders of magnitude; unscaled, the factorisation
/// loses the accuracy the last iterations need. `cache` holds the normal matrix's structure
/// from an earlier QP of the same structure, and is left holding this one's.
pub fn solve(qp: &Qp, tol: &Tolerances, cache: &mut PatternCache) -> IpmOutput {
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
    let start_units = caller_units(&ri);
    let warm = cache.last.take().map(|(x, active)| {
        let x: Vec<f64> = x.iter().zip(&d).map(|(x, d)| x / d).collect();
        (x, active)
    });
    let quad = scaled(qp.quad, &d, &ones_q);
    let eq = scaled(qp.eq, &d, &re);
    let ineq = scaled(qp.ineq, &d, &ri);
    let c: Vec<f64> = qp.c.iter().zip(&d).map(|(c, d)| c * d).collect();
    let f: Vec<f64> = qp.f.iter().zip(&re).map(|(f, r)| f * r).collect();
    let h: Vec<f64> = qp.h.iter().zip(&ri).map(|(h, r)| h * r).collect();
    let groups = qp.groups.for_scaled_rows(&ri);
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
            groups: &groups,
        },
        &start_units,
        tol,
        cache,
        warm,
    );
    out.x.iter_mut().zip(&d).for_each(|(x, d)| *x *= d);
    if out.status == IpmStatus::Solved {
        cache.last = Some((out.x.clone(), out.active.clone()));
    }
    out
}

/// The residuals of the KKT conditions at a point, each with the size of the terms that make
/// it up (a backward error: at the optimum E x ≈ f is often 0 while its terms are not).
struct Kkt {
    r_d: Vec<f64>,
    r_e: Vec<f64>,
    r_i: Vec<f64>,
    gap: f64,
    objective: f64,
    dual_scale: f64,
    /// The rounding floor of the dual residual: `DUAL_ROUNDING` ulps of its largest sum of
    /// term sizes.
    dual_floor: f64,
    eq_scale: f64,
    ineq_scale: f64,
}

impl Kkt {
    fn new(qp: &Qp, normal: &Normal, x: &[f64], lambda: &[f64], s: &[f64], z: &[f64]) -> Kkt {
        let n = x.len();
        let px = normal.mul_p(x);
        let et_l = mul_t(qp.eq, lambda, n);
        let gt_z = mul_t(qp.ineq, z, n);
        let r_d = (0..n)
            .map(|i| px[i] + qp.c[i] - et_l[i] - gt_z[i])
            .collect();
        let r_e = qp.eq.mul(x).iter().zip(qp.f).map(|(a, b)| a - b).collect();
        let gx = qp.ineq.mul(x);
        let r_i = (0..s.len()).map(|i| gx[i] - qp.h[i] - s[i]).collect();
        Kkt {
            r_d,
            r_e,
            r_i,
            gap: dot(s, z),
            objective: 0.5 * dot(x, &px) + dot(qp.c, x) + qp.constant,
            dual_scale: 1.0
                + inf_norm(qp.c)
                    .max(inf_norm(&px))
                    .max(inf_norm(&gt_z))
                    .max(inf_norm(&et_l)),
            dual_floor: DUAL_ROUNDING
                * f64::EPSILON
                * inf_norm(
                    &normal
                        .mul_p_abs(x)
                        .iter()
                        .zip(abs_mul_t(qp.eq, lambda, n))
                        .zip(abs_mul_t(qp.ineq, z, n))
                        .zip(qp.c)
                        .map(|(((p, e), g), c)| p + e + g + c.abs())
                        .collect::<Vec<f64>>(),
                ),
            eq_scale: 1.0 + inf_norm(qp.f).max(abs_row_norm(qp.eq, x)),
            ineq_scale: 1.0 + inf_norm(qp.h).max(abs_row_norm(qp.ineq, x)),
        }
    }

    fn feasible(&self, tol: &Tolerances, k: f64) -> bool {
        inf_norm(&self.r_d) <= k * (tol.dual_feas * self.dual_scale).max(self.dual_floor)
            && inf_norm(&self.r_e) <= k * tol.feas * self.eq_scale
            && inf_norm(&self.r_i) <= k * tol.feas * self.ineq_scale
    }

    /// How many times their tolerances the residuals (the largest of the three) and the gap
    /// are.
    fn excess(&self, tol: &Tolerances) -> [f64; 2] {
        let residuals = (inf_norm(&self.r_d)
            / (tol.dual_feas * self.dual_scale).max(self.dual_floor))
        .max(inf_norm(&self.r_e) / (tol.feas * self.eq_scale))
        .max(inf_norm(&self.r_i) / (tol.feas * self.ineq_scale));
        [
            residuals,
            self.gap / (tol.gap_abs + tol.gap_rel * self.objective.abs()),
        ]
    }

    /// Meets the tolerances relaxed k times.
    fn within(&self, tol: &Tolerances, k: f64) -> bool {
        self.feasible(tol, k) && self.gap <= k * (tol.gap_abs + tol.gap_rel * self.objective.abs())
    }

    /// Close enough to the optimum for the active set to be guessed.
    fn near(&self, tol: &Tolerances) -> bool {
        self.feasible(tol, POLISH_FEAS) && self.gap <= POLISH_GAP * (1.0 + self.objective.abs())
    }
}

/// The dual residual is accepted within this many ulps of the largest sum of absolute terms
/// in a row of P x + c − Eᵀλ − Gᵀz: below that it is rounding. Weights and Airy values can be
/// 10⁶–10⁷ in the scaled unknowns while P x is O(1) (100k-vertex form finding: Σ|P||x| 1.75e7
/// against |P x| 2.7), and the residual then hovered at 0.5–1.5 ulps of those terms, 2–4×
/// above the relative tolerance, for 50 iterations.
const DUAL_ROUNDING: f64 = 10.0;

/// Iterations without progress after which `Progress` declares a stall.
const STALL_WINDOW: u32 = 20;

/// Whether the iterations still make progress: the residuals halving or the gap falling
/// tenfold (against where they stood at the last such progress) within `STALL_WINDOW`
/// iterations. Only beyond 20k unknowns is a stall an exit (`fallback_is_costly`: the caller
/// then keeps the answer at hand): there form-finding steps whose directions had gone inexact
/// kept the dual residual near 1e-4, 2700× its tolerance, from their 12th iteration to the
/// 150-iteration limit, with no tenfold fall of the gap in the 60 iterations after the 36th.
/// Stopped by a stall at 55 iterations, the 100k dome's 13th step balanced the shape as well
/// as at 150 (ε∞ 0.1614) in 28 s instead of 71 s.
struct Progress {
    reference: [f64; 2],
    since: u32,
}

impl Progress {
    fn new() -> Progress {
        Progress {
            reference: [f64::INFINITY; 2],
            since: 0,
        }
    }

    /// Records an iterate's `Kkt::excess`; true once it has made no progress for
    /// `STALL_WINDOW` iterations.
    fn stalled(&mut self, iteration: u32, [residuals, gap]: [f64; 2]) -> bool {
        let [r, g] = self.reference;
        if residuals < 0.5 * r || gap < 0.1 * g {
            self.reference = [r.min(residuals), g.min(gap)];
            self.since = iteration;
        }
        iteration - self.since >= STALL_WINDOW
    }
}

/// When `Kkt::near` holds: residuals within this many times the tolerance, relative gap
/// below `POLISH_GAP`.
const POLISH_FEAS: f64 = 1e3;
const POLISH_GAP: f64 = 1e-5;

/// The iterate polishing starts from (its slacks only enter through the active-set guess).
#[derive(Clone, Copy)]
struct Point<'a> {
    x: &'a [f64],
    lambda: &'a [f64],
    z: &'a [f64],
}

/// How many wrong rows `polish` corrects, and for how many rounds (rows the step violates
/// join the active set, rows whose multiplier comes out negative leave it).
#[derive(Clone, Copy)]
enum Corrections {
    /// From an iterate's guess: a few rows, up to `POLISH_ROUNDS` times; more wrong rows
    /// than a share 1 / `POLISH_CORRECTABLE` of the active ones mean dependent active rows
    /// or an early guess, and further rounds only chased them (cheese: each round made more
    /// rows wrong).
    Few,
    /// From the previous form-finding step's active set (a primal–dual active-set method):
    /// every wrong row, up to `WARM_ROUNDS` times, while their number at least halves each
    /// round. Between late steps tens to hundreds of rows change, mostly bounds to release:
    /// on the Cas-size dome and lilium the last 6–7 steps converged this way in 1–4 rounds
    /// (Cas: 234 → 25 → 10 → 1 wrong rows), while on early steps the count fell by less
    /// than half or grew from the second round on, and an attempt then costs two
    /// factorisations.
    AllWhileFewer,
}
const POLISH_ROUNDS: usize = 3;
const POLISH_CORRECTABLE: usize = 200;
const WARM_ROUNDS: usize = 8;

/// Why `polish` did not reach the optimum, which decides when it is worth another attempt
/// (each costs a factorisation and several solves).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum PolishFailure {
    /// The guess had more wrong rows than a round may correct, or kept finding new ones. One
    /// more iteration usually settles it (lilium, groin), and where the gap stalls at its
    /// rounding floor (the last form-finding steps on cheese, objective ~0) a later guess
    /// is the way out: retried at the next iteration.
    EarlyGuess,
    /// No row was wrong, yet the step missed the tolerances (or its solve failed), also when
    /// retried without the rows that wholly active groups imply: the active set is right but
    /// the factor cannot resolve it that finely. At 100k unknowns, before that retry, this
    /// repeated at every iteration from the 21st to the 27th: retried only once the gap has
    /// fallen by `INEXACT_RETRY`.
    Inexact,
}

/// After an `Inexact` failure, the factor by which the gap must fall before the next attempt
/// (at 100k, from the gaps measured there: attempts at iterations 20, 21, 23, 25 and 27
/// instead of every one from 20 to 27; 41 → 37 factorisations, as counted).
const INEXACT_RETRY: f64 = 1e-2;

/// The optimum for the active set `guess` (see `active_guess`: inequalities with z > s held
/// as equalities, the others dropped), accepted only if it meets every KKT condition: the
/// inactive inequalities hold and the active ones have non-negative multipliers. It is a
/// Newton step from the iterate, so it corrects the iterate's multipliers rather than
/// computing new ones: when the active rows are dependent any combination would balance,
/// and a fresh one need not be non-negative.
///
/// A guess with wrong rows is corrected as `corrections` says. An iterate's plain guess goes
/// wrong on degenerate rows (s and z both tending to 0): on the generated
/// groin vault one row with s = 7e-4, z = 2e-8 was violated by 1e-2 at every attempt, and
/// the gap needed five more iterations to close.
fn polish(
    qp: &Qp,
    normal: &Normal,
    cons: &Csr,
    point: &Point,
    (guess, corrections): (&[bool], Corrections),
    tol: &Tolerances,
    space: &mut FactorSpace,
) -> Result<(Vec<f64>, Vec<bool>), PolishFailure> {
    let m = guess.len();
    let mut active = guess.to_vec();
    let from = PolishFrom::new(qp, normal, point);
    let rounds = match corrections {
        Corrections::Few => POLISH_ROUNDS,
        Corrections::AllWhileFewer => WARM_ROUNDS,
    };
    let mut last_wrong = usize::MAX;
    // The answer is the point with the active rows on their bounds: their computed slack
    // (rounding of differences of large Airy values) is an inequality residual, held to its
    // tolerance, not complementarity. Counted in the gap it kept right active sets from
    // being accepted (50k-vertex dome: the gap 3-11x its tolerance, the dual residual within).
    let kkt_of = |step: &PolishStep, active: &[bool]| {
        let s_new: Vec<f64> = (step.slack.iter().zip(active))
            .map(|(&s, &a)| if a { 0.0 } else { s.max(0.0) })
            .collect();
        let z_new: Vec<f64> = step.multiplier.iter().map(|v| v.max(0.0)).collect();
        Kkt::new(qp, normal, &step.x, &step.lambda, &s_new, &z_new)
    };
    for _ in 0..rounds {
        let step = polish_step(qp, normal, cons, &from, (&active, false), tol, space)
            .ok_or(PolishFailure::Inexact)?;
        let kkt = kkt_of(&step, &active);
        if kkt.within(tol, 1.0) {
            return Ok((step.x, active));
        }
        let (violation, negative) = (tol.feas * kkt.ineq_scale, tol.dual_feas * kkt.dual_scale);
        let wrong: Vec<usize> = (0..m)
            .filter(|&i| {
                if active[i] {
                    step.multiplier[i] < -negative
                } else {
                    step.slack[i] < -violation
                }
            })
            .collect();
        if wrong.is_empty() {
            // The right active set, missed by the factor's accuracy: where whole groups of
            // dependent rows are active, held without two rows each (at 100k the polished
            // dual residual then came out 8-90x smaller, and the step ended at 26 iterations
            // instead of 28).
            if qp.groups.any_wholly_active(&active) {
                let step = polish_step(qp, normal, cons, &from, (&active, true), tol, space)
                    .ok_or(PolishFailure::Inexact)?;
                if kkt_of(&step, &active).within(tol, 1.0) {
                    return Ok((step.x, active));
                }
            }
            return Err(PolishFailure::Inexact);
        }
        let correctable = match corrections {
            Corrections::Few => {
                let n_active = active.iter().filter(|&&a| a).count();
                3.max(n_active / POLISH_CORRECTABLE)
            }
            Corrections::AllWhileFewer => last_wrong / 2,
        };
        if wrong.len() > correctable {
            return Err(PolishFailure::EarlyGuess);
        }
        last_wrong = wrong.len();
        for i in wrong {
            active[i] = !active[i];
        }
    }
    Err(PolishFailure::EarlyGuess)
}

/// The active set an iterate suggests: the inequality rows whose multiplier exceeds their
/// slack.
fn active_guess(s: &[f64], z: &[f64]) -> Vec<bool> {
    s.iter().zip(z).map(|(s, z)| z > s).collect()
}

/// The Newton step of `polish` for one guess of the active set. Slacks and multipliers are
/// left unclipped: their signs show where the guess was wrong.
struct PolishStep {
    x: Vec<f64>,
    lambda: Vec<f64>,
    /// G x − h per inequality row.
    slack: Vec<f64>,
    /// The multiplier of each active row before clipping (0 on inactive rows).
    multiplier: Vec<f64>,
}

/// The iterate `polish` starts from, with the parts of its Newton right-hand side that do not
/// depend on the active-set guess, computed once for all its rounds.
struct PolishFrom<'a> {
    point: Point<'a>,
    /// P x + c − Eᵀλ: the dual residual before the active rows' Gᵀz.
    dual_before_g: Vec<f64>,
    /// The constraint rows: f − E x, then h − G x.
    b2: Vec<f64>,
}

impl<'a> PolishFrom<'a> {
    fn new(qp: &Qp, normal: &Normal, point: &Point<'a>) -> PolishFrom<'a> {
        let Point { x, lambda, .. } = *point;
        let n = x.len();
        let px = normal.mul_p(x);
        let et_l = mul_t(qp.eq, lambda, n);
        let dual_before_g = (0..n).map(|i| px[i] + qp.c[i] - et_l[i]).collect();
        let mut b2: Vec<f64> = qp.eq.mul(x).iter().zip(qp.f).map(|(a, b)| b - a).collect();
        b2.extend(qp.ineq.mul(x).iter().zip(qp.h).map(|(a, b)| b - a));
        PolishFrom {
            point: *point,
            dual_before_g,
            b2,
        }
    }
}

fn polish_step(
    qp: &Qp,
    normal: &Normal,
    cons: &Csr,
    from: &PolishFrom,
    (active, release): (&[bool], bool),
    tol: &Tolerances,
    space: &mut FactorSpace,
) -> Option<PolishStep> {
    let Point { x, lambda, z, .. } = from.point;
    let (n, m_eq, m) = (x.len(), qp.eq.nrows(), z.len());
    // With `release`, rows of wholly active groups that the others imply are held only
    // through them.
    let active: Vec<bool> = if release {
        let released = qp.groups.released(active, z);
        (0..m).map(|i| active[i] && !released[i]).collect()
    } else {
        active.to_vec()
    };
    let z_active: Vec<f64> = (0..m).map(|i| if active[i] { z[i] } else { 0.0 }).collect();
    let gt_z = mul_t(qp.ineq, &z_active, n);
    let b1: Vec<f64> = (0..n).map(|i| -(from.dual_before_g[i] - gt_z[i])).collect();
    let b2 = &from.b2;
    // D = 0 holds a row as an equality; a huge D drops it (its multiplier is D⁻¹ × residual).
    let mut d = vec![0.0; m_eq];
    d.extend(active.iter().map(|&a| if a { 0.0 } else { 1e30 }));
    let [dx, w] = REGULARISATION.iter().find_map(|&reg| {
        Newton::new(normal, cons, d.clone(), reg, space)?.solve(&b1, b2, 1e-2 * tol.feas, true)
    })?;
    let x_new: Vec<f64> = x.iter().zip(&dx).map(|(x, d)| x + d).collect();
    let lambda_new: Vec<f64> = (0..m_eq).map(|i| lambda[i] - w[i]).collect();
    let gx = qp.ineq.mul(&x_new);
    let slack: Vec<f64> = (0..m).map(|i| gx[i] - qp.h[i]).collect();
    let multiplier: Vec<f64> = (0..m)
        .map(|i| {
            if active[i] {
                z_active[i] - w[m_eq + i]
            } else {
                0.0
            }
        })
        .collect();
    Some(PolishStep {
        x: x_new,
        lambda: lambda_new,
        slack,
        multiplier,
    })
}

fn solve_scaled(
    qp: &Qp,
    start_units: &[f64],
    tol: &Tolerances,
    cache: &mut PatternCache,
    warm: Option<(Vec<f64>, Vec<bool>)>,
) -> IpmOutput {
    let n = qp.c.len();
    let cons = stacked(qp.eq, qp.ineq);
    let Some((pattern, reused)) = cache.pattern(qp.quad, &cons, qp.eq.nrows()) else {
        return IpmOutput {
            x: vec![0.0; n],
            status: IpmStatus::NumericalError,
            iterations: 0,
            active: Vec::new(),
        };
    };
    let normal = Normal::new(pattern, qp.quad, qp.quad_weight, &cons);
    // The iterations work in the factor's labels: no vector is permuted per solve.
    let relabelled = Relabelled::new(qp, &normal.pattern.label);
    let warm = warm
        .filter(|_| reused)
        .map(|(x, active)| (relabel_vector(&x, &normal.pattern.label), active));
    let mut out = iterate(
        &relabelled.qp(qp),
        &normal,
        &relabelled.cons,
        start_units,
        tol,
        warm.as_ref().map(|(x, a)| (&x[..], &a[..])),
    );
    out.x = normal.pattern.label.iter().map(|&l| out.x[l]).collect();
    out
}

/// The constraints and linear term of a QP with its unknowns relabelled (`quad` is left as
/// it is: the iterations use P only through `Normal`), and C = [E; G] in the new labels.
struct Relabelled {
    eq: Csr,
    ineq: Csr,
    cons: Csr,
    c: Vec<f64>,
}

impl Relabelled {
    fn new(qp: &Qp, label: &[usize]) -> Relabelled {
        let (eq, ineq) = (
            relabel_columns(qp.eq, label),
            relabel_columns(qp.ineq, label),
        );
        let cons = stacked(&eq, &ineq);
        let c = relabel_vector(qp.c, label);
        Relabelled { eq, ineq, cons, c }
    }

    fn qp<'a>(&'a self, qp: &Qp<'a>) -> Qp<'a> {
        Qp {
            c: &self.c,
            eq: &self.eq,
            ineq: &self.ineq,
            ..*qp
        }
    }
}

/// Weight 1 / START_PENALTY of the constraint term of the starting point's problem. CVXOPT's
/// weight 1 pulls every force density towards its bound, so that nearly every constraint
/// starts out looking active; measured on generated domes with a hole (with the start still in
/// the unit-norm row scaling, before `caller_units`), 100 took the iterations
/// from 29 to 22 at 6k unknowns, 34 to 31 at 20k, 46 to 34 at 50k and 79 to 39 at 100k, and
/// cost the shared models 0 to 6 more (11–25 in all). 10 and 1000 did less well at 100k; 30
/// left free_vault's dual residual 5× above its tolerance (it fell back to clarabel).
const START_PENALTY: f64 = 100.0;

/// The interior-point iterations on a QP whose unknowns are in `normal`'s labels; the
/// starting point is built with inequality row i's slack multiplied by `start_units[i]` (see
/// `caller_units`).
fn iterate(
    qp: &Qp,
    normal: &Normal,
    cons: &Csr,
    start_units: &[f64],
    tol: &Tolerances,
    warm: Option<(&[f64], &[bool])>,
) -> IpmOutput {
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
            active: Vec::new(),
        },
        None => IpmOutput {
            x,
            status: IpmStatus::NumericalError,
            iterations,
            active: Vec::new(),
        },
    };
    let with_eq_zeros = |d: &[f64]| -> Vec<f64> {
        let mut out = vec![0.0; m_eq];
        out.extend_from_slice(d);
        out
    };

    // Starting point (as CVXOPT, with the constraint term weighted down by START_PENALTY):
    // minimise ½xᵀPx + cᵀx + ½‖U(Gx − h)‖² / START_PENALTY subject to Ex = f, take the slacks
    // s = Gx − h and the duals z = −s, then shift both into the positive orthant; all in the
    // caller's units (U = diag(start_units)), converted back at the end.
    let minus_c: Vec<f64> = qp.c.iter().map(|c| -c).collect();
    let mut rhs = qp.f.to_vec();
    rhs.extend_from_slice(qp.h);
    // The numeric factor's storage, shared by every Newton system of this QP (one at a time).
    let Some(mut space) = FactorSpace::new(&normal.pattern.symbolic, normal.p_values.len()) else {
        return fail(vec![0.0; n], 0, None);
    };
    // A form-finding step first tries the previous step's active set: where it is nearly
    // right, a few active-set corrections reach the optimum for a fraction of the
    // iterations' cost. Only x and the active set are carried over: the step computes the
    // multipliers afresh, from zero.
    if let Some((x0, guess)) = warm {
        let (lambda0, z0) = (vec![0.0; m_eq], vec![0.0; m]);
        let point = Point {
            x: x0,
            lambda: &lambda0,
            z: &z0,
        };
        let warm = polish(
            qp,
            normal,
            cons,
            &point,
            (guess, Corrections::AllWhileFewer),
            tol,
            &mut space,
        );
        if let Ok((x, active)) = warm {
            return IpmOutput {
                x,
                status: IpmStatus::Solved,
                iterations: 0,
                active,
            };
        }
    }
    let penalty: Vec<f64> = start_units
        .iter()
        .map(|u| START_PENALTY / (u * u))
        .collect();
    let start = REGULARISATION.iter().find_map(|&reg| {
        Newton::new(normal, cons, with_eq_zeros(&penalty), reg, &mut space)?
            .solve(&minus_c, &rhs, 1e-8, false)
    });
    let Some([mut x, mut w]) = start else {
        return fail(vec![0.0; n], 0, None);
    };
    // The solve returns w = (Gx − h) / penalty on the inequality rows.
    let s_hat: Vec<f64> = w
        .split_off(m_eq)
        .iter()
        .zip(&penalty)
        .zip(start_units)
        .map(|((w, p), u)| w * p * u)
        .collect();
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
    s.iter_mut()
        .zip(start_units)
        .for_each(|(v, u)| *v = (*v + ds.max(1e-8)) / u);
    z.iter_mut()
        .zip(start_units)
        .for_each(|(v, u)| *v = (*v + dz.max(1e-8)) * u);

    // Polishing is tried only while the gap is below this (see `PolishFailure`).
    let mut polish_below = f64::INFINITY;
    // The guess of the last attempt that failed with an early guess: the same guess from
    // another iterate leads to the same step (a QP's Newton step lands on the optimum for its
    // active set wherever it starts), so it fails again (dome with doors: iterations 14, 15).
    let mut failed_guess: Option<Vec<bool>> = None;
    let (mut progress, stall_exits) = (Progress::new(), fallback_is_costly(n));
    let mut iterations = tol.max_iter;
    for iteration in 0..tol.max_iter {
        let kkt = Kkt::new(qp, normal, &x, &lambda, &s, &z);
        if !kkt.objective.is_finite() || inf_norm(&x) > 1e15 {
            return fail(x, iteration, almost);
        }
        if kkt.within(tol, tol.almost) {
            almost = Some(x.clone());
        }
        if kkt.within(tol, 1.0) {
            return IpmOutput {
                x,
                status: IpmStatus::Solved,
                iterations: iteration,
                active: active_guess(&s, &z),
            };
        }
        if progress.stalled(iteration, kkt.excess(tol)) && stall_exits {
            iterations = iteration;
            break;
        }
        // Close to the optimum the active set is plain to see: solving for it directly ends
        // the iterations the gap would otherwise need to creep down to the tolerance, which
        // near a zero objective is at the edge of double precision.
        let guess = (kkt.near(tol) && kkt.gap <= polish_below).then(|| active_guess(&s, &z));
        if let Some(guess) = guess.filter(|g| failed_guess.as_ref() != Some(g)) {
            let point = Point {
                x: &x,
                lambda: &lambda,
                z: &z,
            };
            match polish(
                qp,
                normal,
                cons,
                &point,
                (&guess, Corrections::Few),
                tol,
                &mut space,
            ) {
                Ok((x, active)) => {
                    return IpmOutput {
                        x,
                        status: IpmStatus::Solved,
                        iterations: iteration + 1,
                        active,
                    }
                }
                Err(PolishFailure::EarlyGuess) => {
                    polish_below = f64::INFINITY;
                    failed_guess = Some(guess);
                }
                Err(PolishFailure::Inexact) => {
                    polish_below = INEXACT_RETRY * kkt.gap;
                    failed_guess = None;
                }
            }
        }
        let Kkt {
            r_d,
            r_e,
            r_i,
            gap,
            dual_scale,
            ..
        } = kkt;
        let mu = if m > 0 { gap / m as f64 } else { 0.0 };

        let minus_rd: Vec<f64> = r_d.iter().map(|v| -v).collect();
        // Direction for a complementarity target r_c (Z ds + S dz = r_c): in augmented form
        // P dx + Eᵀ(−dλ) + Gᵀ(−dz) = −r_d,  E dx = −r_e,  G dx − (s/z)(−dz) = r_c/z − r_i.
        let rhs = |r_c: &[f64]| {
            let mut b2: Vec<f64> = r_e.iter().map(|v| -v).collect();
            b2.extend((0..m).map(|i| r_c[i] / z[i] - r_i[i]));
            b2
        };
        let split = |[dx, mut w]: [Vec<f64>; 2], r_c: &[f64]| {
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
            (dx, dl, ds, dz)
        };
        let step_length = |ds: &[f64], dz: &[f64]| max_step(&s, ds).min(max_step(&z, dz));
        // Predictor (affine scaling), then the centred, second-order corrected step, with the
        // least regularisation whose factor is sound.
        let r_aff: Vec<f64> = (0..m).map(|i| -s[i] * z[i]).collect();
        let d: Vec<f64> = (0..m).map(|i| s[i] / z[i]).collect();
        // The corrector needs an accuracy just ahead of the iterate's own.
        let precision = (1e-3 * inf_norm(&r_d) / dual_scale).clamp(1e-2 * tol.feas, 1e-6);
        let mut step = |reg: f64| {
            let mut newton = Newton::new(normal, cons, with_eq_zeros(&d), reg, &mut space)?;
            let sol = newton.approximate(&minus_rd, &rhs(&r_aff));
            let (_, _, ds_a, dz_a) = split(sol, &r_aff);
            let alpha_a = step_length(&ds_a, &dz_a);
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
            let mut r_c: Vec<f64> = (0..m)
                .map(|i| -s[i] * z[i] + sigma * mu - ds_a[i] * dz_a[i])
                .collect();
            // Gondzio's centrality correctors, tried with coarse solves: a few blocking
            // products s_i z_i otherwise hold the step to a fraction of the way.
            let mut b2 = rhs(&r_c);
            let mut sol = newton.approximate(&minus_rd, &b2);
            let mut dir = split(sol.clone(), &r_c);
            let mut alpha = step_length(&dir.2, &dir.3);
            let target = sigma * mu;
            for _ in 0..CORRECTORS {
                if alpha >= 0.9 || target <= 0.0 {
                    break;
                }
                let trial = (CORRECTOR_STRETCH * alpha + CORRECTOR_ADD).min(1.0);
                let mut r_try = r_c.clone();
                for i in 0..m {
                    let v = (s[i] + trial * dir.2[i]) * (z[i] + trial * dir.3[i]);
                    let want = v.clamp(0.1 * target, 10.0 * target);
                    r_try[i] += (want - v).max(-10.0 * target);
                }
                let b_try = rhs(&r_try);
                let sol_try = newton.approximate(&minus_rd, &b_try);
                let dir_try = split(sol_try.clone(), &r_try);
                let a = step_length(&dir_try.2, &dir_try.3);
                if a < alpha + 0.1 * (trial - alpha) {
                    break;
                }
                (alpha, r_c, b2, sol, dir) = (a, r_try, b_try, sol_try, dir_try);
            }
            drop(dir);
            let sol = newton.refine(sol, &minus_rd, &b2, precision, false)?;
            Some(split(sol, &r_c))
        };
        let Some((dx, dl, ds, dz)) = REGULARISATION.iter().find_map(|&reg| step(reg)) else {
            return fail(x, iteration, almost);
        };
        let alpha = (STEP_FRACTION * max_step(&s, &ds).min(max_step(&z, &dz))).min(1.0);
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
            iterations,
            active: Vec::new(),
        },
        None => IpmOutput {
            x,
            status: IpmStatus::MaxIterations,
            iterations,
            active: Vec::new(),
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

    /// Two rows of a wholly active group are released, not collinear, and such that moving the
    /// multipliers along the group's combinations to zero them leaves its others non-negative
    /// (a vertex of {a : z_k + a·c_k ≥ 0}); a group with an inactive row releases none.
    #[test]
    fn released_rows_are_a_vertex_of_the_multiplier_shifts() {
        let star: Vec<[f64; 2]> = [0.1f64, 1.2, 2.0, 3.3, 4.1, 5.4]
            .iter()
            .map(|a| [a.cos() * (1.0 + 0.3 * a), a.sin() * (1.0 + 0.3 * a)])
            .collect();
        let mut coef = star.clone();
        coef.extend_from_slice(&star[..3]);
        let groups = RowGroups {
            start: vec![0, 6, 9],
            row: (0..9).collect(),
            coef,
        };
        let mut active = vec![true; 9];
        active[8] = false;
        for seed in 0..50u32 {
            let z: Vec<f64> = (0..9)
                .map(|k| 0.05 + ((seed * 7 + k * 13) % 17) as f64 / 4.0)
                .collect();
            let released = groups.released(&active, &z);
            let rows: Vec<usize> = (0..9).filter(|&r| released[r]).collect();
            assert_eq!(rows.len(), 2, "seed {seed}: {rows:?}");
            let ([i, j], [a, b]) = ([rows[0], rows[1]], [star[rows[0]], star[rows[1]]]);
            assert!(j < 6);
            let det = a[0] * b[1] - a[1] * b[0];
            assert!(det.abs() > 1e-3);
            let shift = [
                (-z[i] * b[1] + z[j] * a[1]) / det,
                (-z[j] * a[0] + z[i] * b[0]) / det,
            ];
            for (k, c) in star.iter().enumerate() {
                let shifted = z[k] + shift[0] * c[0] + shift[1] * c[1];
                assert!(
                    shifted >= -1e-9,
                    "seed {seed}: row {k} shifted to {shifted}"
                );
            }
        }
    }

    /// Every product of a row's entries lands in the slot of its (row, column) pair in the
    /// relabelled lower triangle, for rows of several lengths over a shuffled set of columns.
    #[test]
    fn product_slots_point_at_their_entries() {
        let n = 40;
        // A deterministic scramble of columns: rows of 1–12 distinct entries.
        let mut seed = 12345u64;
        let mut next = |k: usize| {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 33) as usize % k
        };
        let mut rows = |count: usize| {
            let mut m = Csr::new(n);
            for _ in 0..count {
                let len = 1 + next(12);
                m.push_row((0..len).map(|_| (next(n), 1.0 + next(5) as f64)).collect());
            }
            m
        };
        let (quad, cons) = (rows(30), rows(25));
        let pattern = Pattern::new(&quad, &cons, 3).expect("pattern");
        for (m, slots) in [(&quad, &pattern.quad_slot), (&cons, &pattern.row_slot)] {
            let pairs: Vec<(usize, usize)> = products(m).map(|(_, a, b, ..)| (a, b)).collect();
            assert_eq!(pairs.len(), slots.len());
            for (&(a, b), &slot) in pairs.iter().zip(slots.iter()) {
                let (col, row) = (pattern.label[a], pattern.label[b]);
                let (col, row) = (col.min(row), col.max(row));
                assert!((pattern.col_ptr[col]..pattern.col_ptr[col + 1]).contains(&slot));
                assert_eq!(pattern.row_idx[slot], row, "product ({a}, {b})");
            }
        }
        for (i, &slot) in pattern.diag.iter().enumerate() {
            assert_eq!(pattern.row_idx[slot], pattern.label[i]);
        }
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
                groups: &RowGroups::default(),
            },
            &Tolerances::default(),
            &mut PatternCache::default(),
        );
        assert_eq!(out.status, IpmStatus::Solved);
        assert!((out.x[0] - 1.8).abs() < 1e-8, "{:?}", out.x);
        assert!((out.x[1] - 2.3).abs() < 1e-8, "{:?}", out.x);
    }

    /// `polish` from the iterate (x, s, z) (no equality rows), in the caller's labels.
    fn polish_at(
        qp: &Qp,
        x: &[f64],
        s: &[f64],
        z: &[f64],
        tol: &Tolerances,
    ) -> Result<Vec<f64>, PolishFailure> {
        let cons = stacked(qp.eq, qp.ineq);
        let mut cache = PatternCache::default();
        let (pattern, _) = cache.pattern(qp.quad, &cons, 0).expect("normal matrix");
        let normal = Normal::new(pattern, qp.quad, qp.quad_weight, &cons);
        let label = &normal.pattern.label;
        let relabelled = Relabelled::new(qp, label);
        let (qp, cons) = (relabelled.qp(qp), &relabelled.cons);
        let mut space = FactorSpace::new(&normal.pattern.symbolic, normal.p_values.len())
            .expect("factor space");
        let x = relabel_vector(x, label);
        let point = Point {
            x: &x,
            lambda: &[],
            z,
        };
        let guess = active_guess(s, z);
        let (polished, _) = polish(
            &qp,
            &normal,
            cons,
            &point,
            (&guess, Corrections::Few),
            tol,
            &mut space,
        )?;
        Ok(label.iter().map(|&l| polished[l]).collect())
    }

    /// min (x0 − 2)² + (x1 + 10⁻⁶)² subject to x1 ≥ 0: the bound is active at the optimum
    /// (2, 0) with the tiny multiplier 2·10⁻⁶. At an iterate that has not told it apart yet
    /// (s = 10⁻³ > z = 10⁻⁷) the plain guess drops it and its step lands at x1 = −10⁻⁶,
    /// violating it; the corrected guess must find the optimum.
    #[test]
    fn polishing_corrects_a_wrongly_dropped_row() {
        let quad = csr(2, &[&[(0, 1.0)], &[(1, 1.0)]]);
        let qp = Qp {
            quad: &quad,
            quad_weight: &[2.0, 2.0],
            c: &[-4.0, 2e-6],
            constant: 4.0 + 1e-12,
            eq: &csr(2, &[]),
            f: &[],
            ineq: &csr(2, &[&[(1, 1.0)]]),
            h: &[0.0],
            groups: &RowGroups::default(),
        };
        let x = polish_at(&qp, &[2.0, 1e-3], &[1e-3], &[1e-7], &Tolerances::default())
            .expect("the corrected guess is optimal");
        assert!((x[0] - 2.0).abs() < 1e-12 && x[1].abs() < 1e-12, "{x:?}");
    }

    /// min Σ (x_i + 1)² subject to x ≥ 0 (four rows): every bound is active at the optimum
    /// x = 0, with multiplier 2.
    fn four_active_bounds<R>(run: impl FnOnce(&Qp) -> R) -> R {
        let identity: Vec<Vec<(usize, f64)>> = (0..4).map(|i| vec![(i, 1.0)]).collect();
        let rows: Vec<&[(usize, f64)]> = identity.iter().map(|r| r.as_slice()).collect();
        let quad = csr(4, &rows);
        run(&Qp {
            quad: &quad,
            quad_weight: &[2.0; 4],
            c: &[2.0; 4],
            constant: 4.0,
            eq: &csr(4, &[]),
            f: &[],
            ineq: &quad,
            h: &[0.0; 4],
            groups: &RowGroups::default(),
        })
    }

    /// A guess that drops all four active bounds has more wrong rows than a round may correct
    /// (at most three here): the iterate was early, and the caller may retry next iteration.
    #[test]
    fn polishing_a_guess_with_too_many_wrong_rows_reports_an_early_guess() {
        let failure = four_active_bounds(|qp| {
            polish_at(qp, &[0.1; 4], &[0.1; 4], &[1e-3; 4], &Tolerances::default())
        });
        assert_eq!(failure, Err(PolishFailure::EarlyGuess));
    }

    /// The right guess with a tolerance no step can meet (a negative gap) has no wrong row,
    /// so it is the precision that failed: the caller waits for the gap to fall before
    /// retrying. The same guess meets the default tolerances.
    #[test]
    fn polishing_the_right_guess_beyond_reach_reports_inexact() {
        let at = |tol: Tolerances| {
            four_active_bounds(|qp| polish_at(qp, &[0.1; 4], &[1e-3; 4], &[1.0; 4], &tol))
        };
        let unreachable = Tolerances {
            gap_abs: -1.0,
            ..Tolerances::default()
        };
        assert_eq!(at(unreachable), Err(PolishFailure::Inexact));
        let x = at(Tolerances::default()).expect("the right guess is optimal");
        assert!(x.iter().all(|v| v.abs() < 1e-12), "{x:?}");
    }

    /// min (x_0 − 10⁷)² + Σ (x_{i+1} − x_i − t_i)² subject to x_{i+1} − x_i ≥ 0.1, with
    /// t_i = −1 on every other difference (bound active, multiplier 2.2) and +1 on the rest.
    /// Polishing from a perturbed iterate lands on the optimum, but the slack of an active row,
    /// x_{i+1} − x_i − 0.1 with x near 10⁷, comes out as rounding (~1e-9) rather than 0. Those
    /// rows are held on their bounds, so that is an inequality residual (within its tolerance)
    /// and not complementarity: counted in the gap, the positive ones times z = 2.2 exceed the
    /// gap's tolerance (1e-12 + 1e-11 × 60.5) and would fail the step as inexact.
    #[test]
    fn polished_active_rows_count_on_their_bounds_in_the_gap() {
        let n = 101;
        let bound = 0.1;
        let target: Vec<f64> = (0..n - 1)
            .map(|i| if i % 2 == 0 { -1.0 } else { 1.0 })
            .collect();
        let mut rows: Vec<Vec<(usize, f64)>> = vec![vec![(0, 1.0)]];
        rows.extend((0..n - 1).map(|i| vec![(i, -1.0), (i + 1, 1.0)]));
        let quad = csr(n, &rows.iter().map(|r| r.as_slice()).collect::<Vec<_>>());
        let ineq = csr(
            n,
            &rows[1..].iter().map(|r| r.as_slice()).collect::<Vec<_>>(),
        );
        let weight = vec![2.0; n];
        // c = −2 Aᵀ b with b = (10⁷, t).
        let mut c = vec![0.0; n];
        c[0] = -2e7;
        for (i, t) in target.iter().enumerate() {
            c[i] += 2.0 * t;
            c[i + 1] -= 2.0 * t;
        }
        let constant = 1e14 + target.iter().map(|t| t * t).sum::<f64>();
        let qp = Qp {
            quad: &quad,
            quad_weight: &weight,
            c: &c,
            constant,
            eq: &csr(n, &[]),
            f: &[],
            ineq: &ineq,
            h: &vec![bound; n - 1],
            groups: &RowGroups::default(),
        };
        let active = |i: usize| target[i] < bound;
        let mut optimum = vec![1e7];
        for t in &target {
            optimum.push(optimum.last().expect("x_0") + t.max(bound));
        }
        let x: Vec<f64> = (0..n)
            .map(|i| optimum[i] + 1e-3 * (((i * 7) % 5) as f64 - 2.0))
            .collect();
        let s: Vec<f64> = (0..n - 1)
            .map(|i| if active(i) { 1e-6 } else { 1.0 })
            .collect();
        let z: Vec<f64> = (0..n - 1)
            .map(|i| if active(i) { 2.2 } else { 1e-6 })
            .collect();
        let polished = polish_at(&qp, &x, &s, &z, &Tolerances::default())
            .expect("the right active set polishes to the optimum");
        for (i, t) in target.iter().enumerate() {
            let d = polished[i + 1] - polished[i];
            assert!(
                (d - t.max(bound)).abs() < 1e-6,
                "difference {i} = {d} for target {t}"
            );
        }
        let above = (0..n - 1)
            .filter(|&i| active(i) && polished[i + 1] - polished[i] - bound > 0.0)
            .count();
        assert!(
            above > 0,
            "no active slack rounds above 0: the test shows nothing"
        );
    }

    /// min Σ (x_{i+1} − x_i − t_i)² subject to x_{i+1} ≥ x_i and x_0 = 10⁷: the differences
    /// come out at max(t_i, 0) while every unknown is near 10⁷, so P x sums terms of 10⁷ to
    /// O(1) results and its rounding (~1e-9) exceeds 1e-10 of the dual residual's scale. The
    /// method must still report the optimum as solved (the rounding floor), not stall.
    #[test]
    fn large_unknowns_with_small_differences_converge_at_the_rounding_floor() {
        let n = 200;
        let target: Vec<f64> = (0..n - 1)
            .map(|i| ((i * 37) % 11) as f64 / 5.0 - 1.0)
            .collect();
        let diffs: Vec<Vec<(usize, f64)>> =
            (0..n - 1).map(|i| vec![(i, -1.0), (i + 1, 1.0)]).collect();
        let rows: Vec<&[(usize, f64)]> = diffs.iter().map(|r| r.as_slice()).collect();
        let quad = csr(n, &rows);
        let weight = vec![2.0; n - 1];
        // c = −2 Aᵀ t.
        let mut c = vec![0.0; n];
        for (i, t) in target.iter().enumerate() {
            c[i] += 2.0 * t;
            c[i + 1] -= 2.0 * t;
        }
        let constant = target.iter().map(|t| t * t).sum();
        let out = solve(
            &Qp {
                quad: &quad,
                quad_weight: &weight,
                c: &c,
                constant,
                eq: &csr(n, &[&[(0, 1.0)]]),
                f: &[1e7],
                ineq: &quad,
                h: &vec![0.0; n - 1],
                groups: &RowGroups::default(),
            },
            &Tolerances::default(),
            &mut PatternCache::default(),
        );
        assert_eq!(out.status, IpmStatus::Solved);
        for (i, t) in target.iter().enumerate() {
            let d = out.x[i + 1] - out.x[i];
            assert!(
                (d - t.max(0.0)).abs() < 1e-6,
                "difference {i} = {d} for target {t}"
            );
        }
    }

    /// min Σ (x_i − t_i)² subject to x ≥ 0 and x constant over blocks of four: with targets of
    /// both signs many bounds are active, and each block must come out at the positive part
    /// of its mean (never 0: no degenerate bound), to the accuracy the tolerances imply
    /// (values are O(1); a wrong active set would be off by O(0.1)).
    #[test]
    fn bound_constrained_least_squares_finds_the_active_set() {
        let n = 400;
        let target: Vec<f64> = (0..n).map(|i| ((i * 7919) % 13) as f64 - 5.9).collect();
        // The identity: the objective's rows and the bounds x ≥ 0.
        let identity = csr(
            n,
            &(0..n)
                .map(|i| vec![(i, 1.0)])
                .collect::<Vec<_>>()
                .iter()
                .map(|r| r.as_slice())
                .collect::<Vec<_>>(),
        );
        let weight = vec![2.0; n];
        let c: Vec<f64> = target.iter().map(|t| -2.0 * t).collect();
        let constant = target.iter().map(|t| t * t).sum();
        let chain: Vec<Vec<(usize, f64)>> = (0..n - 1)
            .filter(|i| i % 4 != 3)
            .map(|i| vec![(i, 1.0), (i + 1, -1.0)])
            .collect();
        let eq = csr(n, &chain.iter().map(|r| r.as_slice()).collect::<Vec<_>>());
        let out = solve(
            &Qp {
                quad: &identity,
                quad_weight: &weight,
                c: &c,
                constant,
                eq: &eq,
                f: &vec![0.0; chain.len()],
                ineq: &identity,
                h: &vec![0.0; n],
                groups: &RowGroups::default(),
            },
            &Tolerances::default(),
            &mut PatternCache::default(),
        );
        assert_eq!(out.status, IpmStatus::Solved);
        for block in 0..n / 4 {
            let mean = target[4 * block..4 * block + 4].iter().sum::<f64>() / 4.0;
            for i in 4 * block..4 * block + 4 {
                assert!(
                    (out.x[i] - mean.max(0.0)).abs() < 1e-7,
                    "x{i} = {} for block mean {mean}",
                    out.x[i]
                );
            }
        }
    }

    /// A stall is a window of `STALL_WINDOW` iterations in which neither the residuals halved
    /// nor the gap fell tenfold; progress on either, however slow, keeps the iterations going.
    #[test]
    fn a_stall_is_a_window_without_halved_residuals_or_a_tenfold_gap() {
        let first_stall = |excess: &dyn Fn(u32) -> [f64; 2]| {
            let mut progress = Progress::new();
            (0..300).find(|&k| progress.stalled(k, excess(k)))
        };
        // Nothing moves: a stall as the window ends.
        assert_eq!(first_stall(&|_| [10.0, 1e3]), Some(STALL_WINDOW));
        // Slow but steady: the gap tenfold every 15 iterations, or the residuals halved
        // every 19, the other flat.
        let falling = |k: u32, per: f64, factor: f64| factor.powf(-(k as f64) / per);
        assert_eq!(first_stall(&|k| [10.0, 1e3 * falling(k, 15.0, 10.0)]), None);
        assert_eq!(first_stall(&|k| [10.0 * falling(k, 19.0, 2.0), 1e3]), None);
        // Too slow: the residuals falling by 40% a window, the gap bouncing within a factor
        // of 5: a stall as the first window ends.
        assert_eq!(
            first_stall(&|k| [
                10.0 * 0.6f64.powf(k as f64 / 20.0),
                if k % 2 == 0 { 1e3 } else { 2e2 }
            ]),
            Some(STALL_WINDOW)
        );
        // Progress restarts the window: the residuals halved at iteration 15, then flat.
        let halved_at_15 = |k: u32| [if k < 15 { 10.0 } else { 4.9 }, 1e3];
        assert_eq!(first_stall(&halved_at_15), Some(15 + STALL_WINDOW));
    }
}
