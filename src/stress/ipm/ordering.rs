//! A nested-dissection ordering of the normal matrix for large QPs, from the plan positions
//! of its unknowns. Cut by straight lines, the mesh falls into halves, quarters and so on:
//! independent subtrees of the elimination tree, which two threads factor at once
//! (`factorise`), in a factor that needs less work than with AMD's order; written here
//! rather than taken from METIS so that the library has no C dependency.
//!
//! A part is cut by the line that leaves the fewest unknowns next to it among a few
//! directions and offsets; its near side's unknowns coupled to the far side are the
//! separator, ordered after both sides. Parts of up to `LEAF` unknowns are ordered by minimum
//! degree, counting their couplings to the separators around them.

use super::graph::{amd_labels, entries};
use crate::stress::sparse::bucketed;

/// Parts of up to this many unknowns are ordered by minimum degree (`order_leaf`): the leaf
/// size that gave the least factorisation work on large domes.
const LEAF: usize = 256;

/// Parts of at least this many unknowns try `DIRECTIONS` directions of cut and `OFFSETS` + 1
/// offsets in each, from `BALANCE` of the part to 1 − `BALANCE`; smaller parts are cut across
/// their principal axis at the median. The search pays on large parts, where a better cut
/// saves much factorisation work.
const SEARCH_FROM: usize = 500;
const DIRECTIONS: usize = 8;
const OFFSETS: usize = 10;
const BALANCE: f64 = 0.4;

/// Parts still above `LEAF` after this many cuts (only where cuts keep leaving nearly all of
/// a part on one side) are ordered by AMD.
const MAX_LEVELS: usize = 64;

/// Unknowns coupled to more than this many times the mean number of others (a hole's
/// coefficient, coupled to every vertex around the hole) are ordered last: in a part they
/// would join every separator near them.
const DENSE_FACTOR: f64 = 8.0;

/// The new label of every unknown in a nested-dissection order of a symmetric pattern (its
/// lower triangle, rows sorted in each column), from the unknowns' plan positions.
pub(super) fn nested_dissection_labels(
    col_ptr: &[usize],
    row_idx: &[usize],
    positions: &[[f64; 2]],
) -> Vec<usize> {
    let mut dissection = Dissection::new(col_ptr, row_idx, positions);
    let mean_degree = dissection.adj.len() as f64 / positions.len().max(1) as f64;
    let (dense, rest): (Vec<usize>, Vec<usize>) = (0..positions.len())
        .partition(|&v| dissection.neighbours(v).len() as f64 > DENSE_FACTOR * mean_degree);
    dissection.dissect(rest, 0);
    dissection.order.extend(dense);
    postordered(&dissection.order, &dissection.adj_ptr, &dissection.adj)
}

/// The labels of the elimination order `order` (unknowns in order), renumbered in a
/// postorder of its elimination tree: the same fill, with each subtree's columns contiguous,
/// so that chains of columns merge into supernodes (the leaves' minimum-degree orders are
/// not postordered).
fn postordered(order: &[usize], adj_ptr: &[usize], adj: &[usize]) -> Vec<usize> {
    let n = order.len();
    let mut label = vec![0; n];
    for (k, &v) in order.iter().enumerate() {
        label[v] = k;
    }
    // Liu's elimination tree, with path compression through `ancestor`.
    const NONE: usize = usize::MAX;
    let (mut parent, mut ancestor) = (vec![NONE; n], vec![NONE; n]);
    for (j, &v) in order.iter().enumerate() {
        for &w in &adj[adj_ptr[v]..adj_ptr[v + 1]] {
            let mut r = label[w];
            if r >= j {
                continue;
            }
            while ancestor[r] != NONE && ancestor[r] != j {
                let next = ancestor[r];
                ancestor[r] = j;
                r = next;
            }
            if ancestor[r] == NONE {
                (ancestor[r], parent[r]) = (j, j);
            }
        }
    }
    // Children in increasing order; roots likewise, as children of n.
    let mut child_ptr = vec![0; n + 2];
    for &p in &parent {
        child_ptr[if p == NONE { n } else { p } + 1] += 1;
    }
    for k in 0..=n {
        child_ptr[k + 1] += child_ptr[k];
    }
    let mut next = child_ptr.clone();
    let mut children = vec![0; n];
    for (j, &p) in parent.iter().enumerate() {
        let p = if p == NONE { n } else { p };
        children[next[p]] = j;
        next[p] += 1;
    }
    // Depth-first, children before their parent.
    let mut position = vec![0; n];
    let mut count = 0;
    let mut stack = vec![(n, child_ptr[n])];
    while let Some((node, k)) = stack.pop() {
        if k < child_ptr[node + 1] {
            stack.push((node, k + 1));
            let c = children[k];
            stack.push((c, child_ptr[c]));
        } else if node < n {
            position[node] = count;
            count += 1;
        }
    }
    label.iter().map(|&l| position[l]).collect()
}

struct Dissection<'a> {
    adj_ptr: Vec<usize>,
    adj: Vec<usize>,
    positions: &'a [[f64; 2]],
    /// Marks of the unknowns of one set at a time (`stamp[v] == next_stamp`).
    stamp: Vec<usize>,
    next_stamp: usize,
    /// Position of each unknown of a leaf in that leaf.
    local: Vec<usize>,
    /// The elimination order so far.
    order: Vec<usize>,
}

impl<'a> Dissection<'a> {
    /// The dissection of the symmetric pattern given by its lower triangle, nothing ordered.
    fn new(col_ptr: &[usize], row_idx: &[usize], positions: &'a [[f64; 2]]) -> Dissection<'a> {
        let n = positions.len();
        let off_diagonal = || entries(col_ptr, row_idx).filter(|(r, c)| r != c);
        let (adj_ptr, adj) = bucketed(n, 2 * off_diagonal().count(), || {
            off_diagonal().flat_map(|(r, c)| [(r, c), (c, r)])
        });
        Dissection {
            adj_ptr,
            adj,
            positions,
            stamp: vec![0; n],
            next_stamp: 0,
            local: vec![0; n],
            order: Vec::with_capacity(n),
        }
    }

    fn neighbours(&self, v: usize) -> &[usize] {
        &self.adj[self.adj_ptr[v]..self.adj_ptr[v + 1]]
    }

    /// Marks `set`, returning its mark.
    fn mark(&mut self, set: &[usize]) -> usize {
        self.next_stamp += 1;
        for &v in set {
            self.stamp[v] = self.next_stamp;
        }
        self.next_stamp
    }

    /// Appends `part` to the order: both sides first, recursively, then the separator.
    /// `level` counts the cuts above it.
    fn dissect(&mut self, part: Vec<usize>, level: usize) {
        crate::interrupt::poll();
        if part.len() <= LEAF {
            return self.order_leaf(&part);
        }
        if level >= MAX_LEVELS {
            return self.order_by_amd(&part);
        }
        let (near, separator, far) = self.split(part);
        if near.is_empty() || far.is_empty() {
            // Nothing separated (the part's unknowns all at one point, or along the cut).
            return self.order_by_amd(&[near, separator, far].concat());
        }
        self.dissect(near, level + 1);
        self.dissect(far, level + 1);
        self.order.extend(separator);
    }

    /// (near, separator, far): `part` split by a straight line, the separator being the
    /// near side's unknowns coupled to the far side. The line is the shortest of several
    /// directions and offsets that leave at least `BALANCE` of the part on either side; each
    /// candidate's separator is estimated by the unknowns in a band as deep as the separator
    /// of the cut across the principal axis at the median.
    fn split(&mut self, part: Vec<usize>) -> (Vec<usize>, Vec<usize>, Vec<usize>) {
        let p = self.positions;
        let k = part.len() as f64;
        let mean = part
            .iter()
            .fold([0.0, 0.0], |m, &v| [m[0] + p[v][0] / k, m[1] + p[v][1] / k]);
        let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
        for &v in &part {
            let (x, y) = (p[v][0] - mean[0], p[v][1] - mean[1]);
            (sxx, sxy, syy) = (sxx + x * x, sxy + x * y, syy + y * y);
        }
        // The principal axis of the positions' covariance [[sxx, sxy], [sxy, syy]].
        let principal = 0.5 * (2.0 * sxy).atan2(sxx - syy);
        let along = |angle: f64| {
            let axis = [angle.cos(), angle.sin()];
            part.iter()
                .map(|&v| p[v][0] * axis[0] + p[v][1] * axis[1])
                .collect::<Vec<f64>>()
        };
        let t = along(principal);
        let mut sorted = t.clone();
        sorted.sort_unstable_by(f64::total_cmp);
        let median = sorted[part.len() / 2];
        let first = self.cut(&part, &t, median);
        let depth = (first.1.iter())
            .map(|&v| (t[self.local_of(v, &part)] - median).abs())
            .fold(0.0, f64::max);
        if part.len() < SEARCH_FROM || depth <= 0.0 {
            return first;
        }
        let mut best = (f64::INFINITY, principal, median);
        for i in 0..DIRECTIONS {
            let angle = principal + i as f64 * std::f64::consts::PI / DIRECTIONS as f64;
            let t = along(angle);
            let mut sorted = t;
            sorted.sort_unstable_by(f64::total_cmp);
            let count_below = |x: f64| sorted.partition_point(|&y| y < x);
            for step in 0..=OFFSETS {
                let q = BALANCE + (1.0 - 2.0 * BALANCE) * step as f64 / OFFSETS as f64;
                let at = sorted[(q * k) as usize];
                let band = (count_below(at) - count_below(at - depth)) as f64;
                if band < best.0 {
                    best = (band, angle, at);
                }
            }
        }
        let (_, angle, at) = best;
        if angle == principal && at == median {
            return first;
        }
        let t = along(angle);
        let other = self.cut(&part, &t, at);
        if other.1.len() < first.1.len() && !other.0.is_empty() {
            other
        } else {
            first
        }
    }

    /// `part[i]` is the unknown at `t[i]` along some axis: (near, separator, far) of the cut
    /// at `at`, far being from `at` on or below it. The separator is the smaller of the two
    /// sides' sets of unknowns coupled to the other side (its side is then the near one);
    /// those of it coupled to no other near unknown join the far side.
    fn cut(&mut self, part: &[usize], t: &[f64], at: f64) -> (Vec<usize>, Vec<usize>, Vec<usize>) {
        for (i, &v) in part.iter().enumerate() {
            self.local[v] = i;
        }
        let (low, high): (Vec<usize>, Vec<usize>) = (0..part.len()).partition(|&i| t[i] < at);
        let [low, high] =
            [low, high].map(|side| side.into_iter().map(|i| part[i]).collect::<Vec<_>>());
        let coupled_to = |this: &Self, v: usize, mark: usize| {
            this.neighbours(v).iter().any(|&w| this.stamp[w] == mark)
        };
        let low_mark = self.mark(&low);
        let high_next_to_low: Vec<usize> = (high.iter().copied())
            .filter(|&v| coupled_to(self, v, low_mark))
            .collect();
        let high_mark = self.mark(&high);
        let low_next_to_high: Vec<usize> = (low.iter().copied())
            .filter(|&v| coupled_to(self, v, high_mark))
            .collect();
        let (mut near, mut far, separator) = if low_next_to_high.len() <= high_next_to_low.len() {
            (low, high, low_next_to_high)
        } else {
            (high, low, high_next_to_low)
        };
        // The separator is on the near side: those of its unknowns coupled to no other near
        // unknown join the far side.
        let in_separator = self.mark(&separator);
        let near_rest: Vec<usize> = near
            .iter()
            .copied()
            .filter(|&v| self.stamp[v] != in_separator)
            .collect();
        let near_mark = self.mark(&near_rest);
        let (mut kept, mut moved) = (Vec::new(), Vec::new());
        for &v in &separator {
            if coupled_to(self, v, near_mark) {
                kept.push(v);
            } else {
                moved.push(v);
            }
        }
        near = near_rest;
        far.extend(moved);
        (near, kept, far)
    }

    /// The index in `part` of its unknown v (set by the last `cut` of `part`).
    fn local_of(&self, v: usize, part: &[usize]) -> usize {
        debug_assert_eq!(part[self.local[v]], v);
        self.local[v]
    }

    /// Appends `part` in AMD's order of the pattern it induces (a part no line divides).
    fn order_by_amd(&mut self, part: &[usize]) {
        let in_part = self.mark(part);
        for (i, &v) in part.iter().enumerate() {
            self.local[v] = i;
        }
        let (mut col_ptr, mut row_idx) = (vec![0], Vec::new());
        for &v in part {
            let (first, c) = (row_idx.len(), self.local[v]);
            row_idx.push(c);
            for &w in self.neighbours(v) {
                if self.stamp[w] == in_part && self.local[w] > c {
                    row_idx.push(self.local[w]);
                }
            }
            row_idx[first..].sort_unstable();
            col_ptr.push(row_idx.len());
        }
        match amd_labels(part.len(), &col_ptr, &row_idx) {
            Some(label) => {
                let mut ordered = vec![0; part.len()];
                for (i, &v) in part.iter().enumerate() {
                    ordered[label[i]] = v;
                }
                self.order.extend(ordered);
            }
            // AMD's workspace could not be had: any order is a valid one.
            None => self.order.extend_from_slice(part),
        }
    }

    /// Appends `part` in a minimum-degree order that counts its couplings to unknowns
    /// outside it (the separators around it, ordered later): its unknowns next to a separator
    /// then come last, as they would in an order of the whole matrix. (AMD on the part alone
    /// sees those as its least coupled and takes them first, which fills the separators'
    /// rows.)
    fn order_leaf(&mut self, part: &[usize]) {
        let in_part = self.mark(part);
        for (i, &v) in part.iter().enumerate() {
            self.local[v] = i;
        }
        // The halo: unknowns outside the part coupled to it, numbered after it.
        self.next_stamp += 1;
        let in_halo = self.next_stamp;
        let mut size = part.len();
        for &v in part {
            for k in self.adj_ptr[v]..self.adj_ptr[v + 1] {
                let w = self.adj[k];
                if self.stamp[w] != in_part && self.stamp[w] != in_halo {
                    self.stamp[w] = in_halo;
                    self.local[w] = size;
                    size += 1;
                }
            }
        }
        // Each part unknown's neighbours in the elimination graph, as a bit set.
        let words = size.div_ceil(64);
        let mut adj = vec![0u64; part.len() * words];
        for (i, &v) in part.iter().enumerate() {
            for &w in self.neighbours(v) {
                if self.stamp[w] == in_part || self.stamp[w] == in_halo {
                    let l = self.local[w];
                    adj[i * words + l / 64] |= 1 << (l % 64);
                }
            }
        }
        let degree = |adj: &[u64], i: usize| -> u32 {
            adj[i * words..(i + 1) * words]
                .iter()
                .map(|w| w.count_ones())
                .sum()
        };
        let mut deg: Vec<u32> = (0..part.len()).map(|i| degree(&adj, i)).collect();
        let mut left = vec![true; part.len()];
        let mut row = vec![0u64; words];
        for _ in 0..part.len() {
            let Some(v) = (0..part.len())
                .filter(|&i| left[i])
                .min_by_key(|&i| (deg[i], i))
            else {
                break;
            };
            left[v] = false;
            self.order.push(part[v]);
            // v's neighbours become a clique, without v.
            row.copy_from_slice(&adj[v * words..(v + 1) * words]);
            for u in (0..part.len()).filter(|&u| row[u / 64] >> (u % 64) & 1 == 1) {
                for (a, r) in adj[u * words..(u + 1) * words].iter_mut().zip(&row) {
                    *a |= r;
                }
                adj[u * words + u / 64] &= !(1 << (u % 64));
                adj[u * words + v / 64] &= !(1 << (v % 64));
                deg[u] = degree(&adj, u);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stress::ipm::pattern::product_pattern;
    use crate::stress::sparse::Csr;

    /// Every cut of a dome-like disc with a hole leaves no coupling between its two sides,
    /// and near, separator and far are the part: the searched cut of a large part and the
    /// median cut of a small one.
    #[test]
    fn cuts_separate_their_sides() {
        // A k × k grid of two-ring couplings (five-point rows), the unknowns outside a
        // radius or inside a hole left uncoupled.
        let k = 48;
        let at = |i: usize, j: usize| [i as f64 - 23.5, j as f64 - 23.5];
        let inside = |p: [f64; 2]| {
            let (r, h) = (p[0].hypot(p[1]), (p[0] - 8.0).hypot(p[1] - 3.0));
            r < 23.0 && h > 5.0
        };
        let mut rows = Csr::new(k * k);
        for i in 0..k {
            for j in 0..k {
                if !inside(at(i, j)) {
                    continue;
                }
                let mut row = vec![(i * k + j, 1.0)];
                for (a, b) in [(i + 1, j), (i, j + 1)] {
                    if a < k && b < k && inside(at(a, b)) {
                        row.push((a * k + b, 1.0));
                    }
                }
                rows.push_row(row);
            }
        }
        let (col_ptr, row_idx) = product_pattern([&rows, &Csr::new(k * k)], k * k);
        let positions: Vec<[f64; 2]> = (0..k * k).map(|v| at(v / k, v % k)).collect();
        let disc: Vec<usize> = (0..k * k).filter(|&v| inside(positions[v])).collect();
        let mut dissection = Dissection::new(&col_ptr, &row_idx, &positions);
        for part in [disc.clone(), disc[..300].to_vec()] {
            let (near, separator, far) = dissection.split(part.clone());
            assert!(!near.is_empty() && !far.is_empty() && !separator.is_empty());
            let mut all = [near.clone(), separator, far.clone()].concat();
            all.sort_unstable();
            let mut expected = part.clone();
            expected.sort_unstable();
            assert_eq!(all, expected);
            let far_mark = dissection.mark(&far);
            for &v in &near {
                assert!(
                    dissection
                        .neighbours(v)
                        .iter()
                        .all(|&w| dissection.stamp[w] != far_mark),
                    "{v} on the near side is coupled to the far side"
                );
            }
        }
    }
}
