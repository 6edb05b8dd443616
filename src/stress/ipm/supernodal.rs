//! Solves with a supernodal LDLᵀ factor, one right-hand side, in place: plain loops over each
//! supernode's columns, because faer's solve dispatches dense kernels per supernode, which on
//! the few-column supernodes of small QPs costs more than the arithmetic. Factors too large
//! for the cache are read downwards by the backward solve (`DOWNWARDS_FROM`), and those of
//! more than `SPLIT_FROM` values are solved on two threads (`Split`).

use faer::sparse::linalg::cholesky::{SymbolicCholesky, SymbolicCholeskyRaw};

/// x ← (L D Lᵀ)⁻¹ x for the factor `values` of `symbolic`, which must be supernodal and
/// without a permutation (the normal matrix is factored in its elimination order); false,
/// with x untouched, otherwise. `work` is working storage; with a `split` of this
/// factor's tree the two branches are solved on two threads.
pub(super) fn solve_in_place(
    symbolic: &SymbolicCholesky<usize>,
    values: &[f64],
    x: &mut [f64],
    work: &mut Vec<f64>,
    split: Option<&Split>,
) -> bool {
    let downwards = values.len() > DOWNWARDS_FROM;
    solve_in_place_reading(symbolic, values, x, work, downwards, split)
}

/// `solve_in_place`, its backward solve reading each column downwards (`dot_downwards`) or
/// upwards (`dot`).
pub(super) fn solve_in_place_reading(
    symbolic: &SymbolicCholesky<usize>,
    values: &[f64],
    x: &mut [f64],
    work: &mut Vec<f64>,
    downwards: bool,
    split: Option<&Split>,
) -> bool {
    let Some(factor) = Factor::new(symbolic, values) else {
        return false;
    };
    let dot = if downwards { dot_downwards } else { dot };
    match split {
        Some(split) => factor.solve_split(split, x, dot),
        None => {
            let all = 0..factor.n_supernodes;
            all.clone().for_each(|s| factor.forward(s, x, work));
            factor.scale(x);
            all.rev().for_each(|s| factor.backward(s, x, work, dot));
        }
    }
    true
}

/// A supernodal factor without a permutation, as `solve_in_place` takes it.
struct Factor<'a> {
    n_supernodes: usize,
    begin: &'a [usize],
    end: &'a [usize],
    row_ptr: &'a [usize],
    val_ptr: &'a [usize],
    row_idx: &'a [usize],
    values: &'a [f64],
}

type Dot = fn(&[f64], &[f64]) -> f64;

impl<'a> Factor<'a> {
    fn new(symbolic: &'a SymbolicCholesky<usize>, values: &'a [f64]) -> Option<Factor<'a>> {
        let SymbolicCholeskyRaw::Supernodal(sym) = symbolic.raw() else {
            return None;
        };
        if symbolic.perm().is_some() {
            return None;
        }
        Some(Factor {
            n_supernodes: sym.n_supernodes(),
            begin: sym.supernode_begin(),
            end: sym.supernode_end(),
            row_ptr: sym.col_ptr_for_row_idx(),
            val_ptr: sym.col_ptr_for_val(),
            row_idx: sym.row_idx(),
            values,
        })
    }

    /// Supernode s: columns start..start + ncols, stored column-major as a block of
    /// ncols + |pattern| rows (the unit lower triangle with D on its diagonal, then the rows
    /// `pattern` below it).
    fn block(&self, s: usize) -> (usize, usize, &'a [usize], &'a [f64], usize) {
        let (start, ncols) = (self.begin[s], self.end[s] - self.begin[s]);
        let pattern = &self.row_idx[self.row_ptr[s]..self.row_ptr[s + 1]];
        let l = &self.values[self.val_ptr[s]..self.val_ptr[s + 1]];
        (start, ncols, pattern, l, ncols + pattern.len())
    }

    /// Supernode s's part of L y = b: the triangle, then the rows below, gathered in
    /// `work` and subtracted once.
    fn forward(&self, s: usize, x: &mut [f64], work: &mut Vec<f64>) {
        let (start, ncols, pattern, l, nrows) = self.block(s);
        work.clear();
        work.resize(pattern.len(), 0.0);
        for j in 0..ncols {
            let col = &l[j * nrows..(j + 1) * nrows];
            let xj = x[start + j];
            for (xi, &v) in x[start + j + 1..start + ncols]
                .iter_mut()
                .zip(&col[j + 1..ncols])
            {
                *xi -= v * xj;
            }
            for (t, &v) in work.iter_mut().zip(&col[ncols..]) {
                *t += v * xj;
            }
        }
        for (&r, &t) in pattern.iter().zip(work.iter()) {
            x[r] -= t;
        }
    }

    /// D z = y.
    fn scale(&self, x: &mut [f64]) {
        for s in 0..self.n_supernodes {
            let (start, ncols, _, l, nrows) = self.block(s);
            for j in 0..ncols {
                x[start + j] /= l[j * nrows + j];
            }
        }
    }

    /// Supernode s's part of Lᵀ x = z (supernodes in reverse): the rows below are final,
    /// then the triangle upwards.
    fn backward(&self, s: usize, x: &mut [f64], work: &mut Vec<f64>, dot: Dot) {
        let (start, ncols, pattern, l, nrows) = self.block(s);
        work.clear();
        work.extend(pattern.iter().map(|&r| x[r]));
        for j in (0..ncols).rev() {
            let col = &l[j * nrows..(j + 1) * nrows];
            let mut xj = x[start + j];
            xj -= dot(&col[ncols..], work);
            xj -= dot(&col[j + 1..ncols], &x[start + j + 1..start + ncols]);
            x[start + j] = xj;
        }
    }

    /// The solve with the two branches of `split` on two threads. Each branch works on its
    /// own copy of x: forwards, its updates of the stem's rows collect in the copy (those
    /// rows start at 0) and are added to x after both; backwards, it reads the stem's final
    /// values. Only the order of those additions differs from the sequential solve.
    fn solve_split(&self, split: &Split, x: &mut [f64], dot: Dot) {
        let forward_branch = |members: &[usize], x: &[f64]| {
            let mut own = x.to_vec();
            split.stem_columns(self).for_each(|c| own[c] = 0.0);
            let mut work = Vec::new();
            members
                .iter()
                .for_each(|&s| self.forward(s, &mut own, &mut work));
            own
        };
        let [first, second] = on_two_threads(|branch| forward_branch(&split.branches[branch], x));
        for (branch, own) in [&first, &second].into_iter().enumerate() {
            for c in split.columns(self, &split.branches[branch]) {
                x[c] = own[c];
            }
        }
        for c in split.stem_columns(self) {
            x[c] += first[c] + second[c];
        }
        let mut work = Vec::new();
        split
            .stem
            .iter()
            .for_each(|&s| self.forward(s, x, &mut work));
        self.scale(x);
        for &s in split.stem.iter().rev() {
            self.backward(s, x, &mut work, dot);
        }
        let backward_branch = |members: &[usize], x: &[f64]| {
            let mut own = x.to_vec();
            let mut work = Vec::new();
            for &s in members.iter().rev() {
                self.backward(s, &mut own, &mut work, dot);
            }
            own
        };
        let solved = on_two_threads(|branch| backward_branch(&split.branches[branch], x));
        for (branch, own) in solved.iter().enumerate() {
            for c in split.columns(self, &split.branches[branch]) {
                x[c] = own[c];
            }
        }
    }
}

/// `work(0)` on a second thread and `work(1)` on this one (both here, in turn, if no
/// thread can be started).
fn on_two_threads<T: Send>(work: impl Fn(usize) -> T + Sync) -> [T; 2] {
    let (first, second) = both(|| work(0), || work(1));
    [first, second]
}

/// `first()` on a second thread and `second()` on this one; if no thread can be started,
/// both here, `first` first.
pub(super) fn both<A: Send, B>(
    first: impl FnOnce() -> A + Send,
    second: impl FnOnce() -> B,
) -> (A, B) {
    // The spawn takes the closure even when it fails: it is handed over through a slot.
    let slot = std::sync::Mutex::new(Some(first));
    let take = || slot.lock().ok().and_then(|mut f| f.take());
    std::thread::scope(|scope| {
        let spawned = std::thread::Builder::new().spawn_scoped(scope, || take().map(|f| f()));
        let b = second();
        let a = match spawned {
            Ok(handle) => handle
                .join()
                .unwrap_or_else(|panic| std::panic::resume_unwind(panic)),
            Err(_) => None,
        };
        let a = a.or_else(|| take().map(|f| f()));
        (
            a.expect("the first closure ran on one thread or the other"),
            b,
        )
    })
}

/// Factors with more values than this are solved on two threads where the machine has them
/// (`Split`): from about 40k vertices; below, the threads' start and the copies of x cost
/// more than they save.
pub(super) const SPLIT_FROM: usize = 1 << 22;

/// Factors with more values than this are factored on two threads (`factorise`): from about
/// 10k vertices, where the second thread saves more than it costs to start.
pub(super) const FACTOR_SPLIT_FROM: usize = 1 << 20;

/// At most this many subtrees are expanded into their children in search of a balanced
/// `Split`.
const MAX_EXPANSIONS: usize = 64;

/// A division of a factor's supernodes into two branches, each a set of whole subtrees of
/// its elimination tree, and the stem, the rest: the branches can be solved or factored at
/// the same time. The solves with large factors are limited by reading them from memory,
/// which two cores do faster than one.
pub(super) struct Split {
    pub(super) branches: [Vec<usize>; 2],
    pub(super) stem: Vec<usize>,
}

/// The supernode holding each of a factor's `n` columns (supernode s: begin[s]..end[s]).
pub(super) fn owners(begin: &[usize], end: &[usize], n: usize) -> Vec<usize> {
    let mut owner = vec![0; n];
    for (s, (&b, &e)) in begin.iter().zip(end).enumerate() {
        owner[b..e].fill(s);
    }
    owner
}

/// Whether the machine runs two threads at once, asked once per process because the answer
/// reads cgroup files, too slow to ask on every small QP.
fn two_threads() -> bool {
    static TWO: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *TWO.get_or_init(|| std::thread::available_parallelism().is_ok_and(|n| n.get() >= 2))
}

/// The multiply-adds of factoring a supernode of `ncols` columns and `nrows` rows (its
/// diagonal block's included): Σ_j (nrows − j)² over its columns j.
pub(super) fn factor_work(ncols: usize, nrows: usize) -> u64 {
    (0..ncols).map(|j| ((nrows - j) as u64).pow(2)).sum()
}

impl Split {
    /// The split for solves (`SPLIT_FROM`), balancing the factor values each part reads.
    pub(super) fn for_solve(symbolic: &SymbolicCholesky<usize>) -> Option<Split> {
        let values = |ncols: usize, nrows: usize| (ncols * nrows) as u64;
        two_threads().then(|| Split::new(symbolic, SPLIT_FROM, values))?
    }

    /// The split for the factorisation (`FACTOR_SPLIT_FROM`), balancing the multiply-adds of
    /// each part's supernodes (`factor_work`).
    pub(super) fn for_factor(symbolic: &SymbolicCholesky<usize>) -> Option<Split> {
        two_threads().then(|| Split::new(symbolic, FACTOR_SPLIT_FROM, factor_work))?
    }

    /// The split of `symbolic`'s tree whose more loaded branch plus stem has the least
    /// `weight(ncols, nrows)` summed over its supernodes, if the factor has more than
    /// `min_values` values and the split saves at least a tenth of the weight done in
    /// sequence.
    pub(super) fn new(
        symbolic: &SymbolicCholesky<usize>,
        min_values: usize,
        weight_of: impl Fn(usize, usize) -> u64,
    ) -> Option<Split> {
        let SymbolicCholeskyRaw::Supernodal(sym) = symbolic.raw() else {
            return None;
        };
        if symbolic.len_val() <= min_values {
            return None;
        }
        let (begin, end, row_ptr, row_idx) = (
            sym.supernode_begin(),
            sym.supernode_end(),
            sym.col_ptr_for_row_idx(),
            sym.row_idx(),
        );
        let ns = sym.n_supernodes();
        let owner = owners(begin, end, symbolic.nrows());
        // A supernode's parent owns the first row below its columns; ns stands for a root
        // above the roots of a forest.
        let parent: Vec<usize> = (0..ns)
            .map(|s| row_idx[row_ptr[s]..row_ptr[s + 1]].first())
            .map(|first| first.map_or(ns, |&r| owner[r]))
            .collect();
        let mut children = vec![Vec::new(); ns + 1];
        let mut weight: Vec<u64> = (0..ns)
            .map(|s| {
                let ncols = end[s] - begin[s];
                weight_of(ncols, ncols + row_ptr[s + 1] - row_ptr[s])
            })
            .collect();
        weight.push(0);
        for s in 0..ns {
            children[parent[s]].push(s);
            weight[parent[s]] += weight[s];
        }
        let total = weight[ns];
        // Independent subtrees (a frontier across the tree) go to two threads, the heaviest
        // first to the less loaded; the supernodes above them are the stem. From the roots'
        // subtrees, the heaviest subtree is replaced by its children, its root joining the
        // stem, up to MAX_EXPANSIONS times or until the heaviest is one supernode; the
        // frontier with the shortest wall (stem plus the more loaded thread) is kept.
        let mut frontier = children[ns].clone();
        let mut stem = 0;
        let mut best: Option<(u64, Vec<usize>, Vec<u8>)> = None;
        for _ in 0..MAX_EXPANSIONS {
            frontier.sort_unstable_by_key(|&k| std::cmp::Reverse((weight[k], k)));
            let mut load = [0, 0];
            let thread: Vec<u8> = (frontier.iter())
                .map(|&k| {
                    let t = usize::from(load[1] < load[0]);
                    load[t] += weight[k];
                    t as u8
                })
                .collect();
            let wall = stem + load[0].max(load[1]);
            if best.as_ref().is_none_or(|(w, ..)| wall < *w) {
                best = Some((wall, frontier.clone(), thread));
            }
            let heaviest = frontier[0];
            if children[heaviest].is_empty() {
                break;
            }
            stem += weight[heaviest] - children[heaviest].iter().map(|&k| weight[k]).sum::<u64>();
            frontier.swap_remove(0);
            frontier.extend_from_slice(&children[heaviest]);
        }
        let (wall, frontier, thread) = best?;
        if wall * 10 > total * 9 {
            return None;
        }
        // Parents come after their children: mark downwards from the roots.
        let mut part = vec![2u8; ns + 1];
        for (&k, &t) in frontier.iter().zip(&thread) {
            part[k] = t;
        }
        for s in (0..ns).rev() {
            if part[s] == 2 {
                part[s] = part[parent[s]];
            }
        }
        let members = |p: u8| (0..ns).filter(|&s| part[s] == p).collect::<Vec<_>>();
        Some(Split {
            branches: [members(0), members(1)],
            stem: members(2),
        })
    }

    fn columns<'a>(
        &self,
        factor: &'a Factor,
        members: &'a [usize],
    ) -> impl Iterator<Item = usize> + 'a {
        members.iter().flat_map(|&s| factor.begin[s]..factor.end[s])
    }

    fn stem_columns<'a>(&'a self, factor: &'a Factor) -> impl Iterator<Item = usize> + 'a {
        self.columns(factor, &self.stem)
    }
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
/// (`dot_downwards`), one descending stream the prefetcher follows, where reading each column
/// upwards would be limited by memory; smaller factors stay in cache and keep `dot`'s
/// rounding, to which the small models' degenerate QPs are sensitive.
const DOWNWARDS_FROM: usize = 1 << 20;

/// `dot` from the last terms to the first (the same four partial sums, taken from the end).
fn dot_downwards(a: &[f64], b: &[f64]) -> f64 {
    let (a4, b4) = (a.rchunks_exact(4), b.rchunks_exact(4));
    four_sums((a4.remainder(), b4.remainder()), a4.zip(b4))
}
