//! Groups of inequality rows that are dependent when all of a group is active, and the rows
//! polishing releases from such groups.

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
    pub(super) fn len(&self) -> usize {
        self.start.len().saturating_sub(1)
    }

    pub(super) fn group(&self, g: usize) -> (&[usize], &[[f64; 2]]) {
        let range = self.start[g]..self.start[g + 1];
        (&self.row[range.clone()], &self.coef[range])
    }

    pub(super) fn any_wholly_active(&self, active: &[bool]) -> bool {
        (0..self.len()).any(|g| self.group(g).0.iter().all(|&r| active[r]))
    }

    /// The same groups for rows scaled by `row_scale` (coefficients divided by it).
    pub(super) fn for_scaled_rows(&self, row_scale: &[f64]) -> RowGroups {
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
    /// conditioned such pair; with z = 0 every pair qualifies. Groups of up to
    /// `ALL_PAIRS_UP_TO` rows try every pair; larger ones (the star of a high-valence vertex)
    /// only the pairs at the polygon's vertices (`vertex_pairs`), since testing every pair
    /// against every row costs the cube of the group's size.
    pub(super) fn released(&self, active: &[bool], z: &[f64]) -> Vec<bool> {
        let mut released = vec![false; active.len()];
        for g in 0..self.len() {
            let (rows, coef) = self.group(g);
            if rows.len() < 3 || !rows.iter().all(|&r| active[r]) {
                continue;
            }
            let star = Star { rows, coef, z };
            let free = |i: usize| !released[rows[i]];
            let best = if rows.len() <= ALL_PAIRS_UP_TO {
                let pairs = (0..rows.len()).flat_map(|i| (i + 1..rows.len()).map(move |j| (i, j)));
                star.best_feasible(pairs.filter(|&(i, j)| free(i) && free(j)), usize::MAX)
            } else {
                let pairs = star.vertex_pairs();
                star.best_feasible(
                    pairs.into_iter().filter(|&(i, j)| free(i) && free(j)),
                    LARGE_GROUP_TESTS,
                )
            };
            if let Some((i, j)) = best {
                (released[rows[i]], released[rows[j]]) = (true, true);
            }
        }
        released
    }
}

/// Groups of up to this many rows choose their released pair among all pairs.
const ALL_PAIRS_UP_TO: usize = 64;

/// A larger group tests this many of its candidate pairs at most, best conditioned first: the
/// first is a vertex of the polygon of shifts and passes unless rounding decides otherwise.
const LARGE_GROUP_TESTS: usize = 32;

/// One wholly active group with the multipliers of its rows.
struct Star<'a> {
    rows: &'a [usize],
    coef: &'a [[f64; 2]],
    z: &'a [f64],
}

impl Star<'_> {
    /// The shift a with a·c_i = −z_i and a·c_j = −z_j, and the pair's conditioning
    /// |det| / (|c_i| |c_j|); None for (nearly) parallel rows.
    fn shift(&self, i: usize, j: usize) -> Option<([f64; 2], f64)> {
        let (a, b) = (self.coef[i], self.coef[j]);
        let det = a[0] * b[1] - a[1] * b[0];
        let norms = a[0].hypot(a[1]) * b[0].hypot(b[1]);
        if det.abs() <= 1e-6 * norms {
            return None;
        }
        let (zi, zj) = (self.z[self.rows[i]], self.z[self.rows[j]]);
        let shift = [
            (-zi * b[1] + zj * a[1]) / det,
            (-zj * a[0] + zi * b[0]) / det,
        ];
        Some((shift, det.abs() / norms))
    }

    /// Whether shifting z by a keeps every multiplier of the group non-negative.
    fn keeps_non_negative(&self, shift: [f64; 2]) -> bool {
        self.rows.iter().zip(self.coef).all(|(&r, c)| {
            let z = self.z[r];
            z + shift[0] * c[0] + shift[1] * c[1] >= -1e-9 * z.abs().max(1e-300)
        })
    }

    /// The best conditioned of `pairs` whose shift keeps the multipliers non-negative,
    /// testing at most `tests` of them, best conditioned first.
    fn best_feasible(
        &self,
        pairs: impl Iterator<Item = (usize, usize)>,
        tests: usize,
    ) -> Option<(usize, usize)> {
        let mut candidates: Vec<(f64, usize, usize, [f64; 2])> = pairs
            .filter_map(|(i, j)| self.shift(i, j).map(|(s, q)| (q, i, j, s)))
            .collect();
        // Stable, so that among equally conditioned pairs the first listed wins.
        candidates.sort_by(|a, b| b.0.total_cmp(&a.0));
        (candidates.into_iter().take(tests))
            .find(|c| self.keeps_non_negative(c.3))
            .map(|(_, i, j, _)| (i, j))
    }

    /// The pairs of rows whose lines meet at a vertex of the polygon of shifts
    /// {a : z_k + a·c_k ≥ 0} (indices into the group), which holds a = 0. Rows with z_k > 0
    /// bound it by a·p_k ≤ 1 with p_k = −c_k / z_k: its vertices are the edges of the convex
    /// hull of the points p_k and the origin that do not end at the origin. Rows with z_k ≤ 0
    /// pass through a = 0, which every pair of them shares: their best conditioned pair (the
    /// nearest to perpendicular) is a candidate too.
    fn vertex_pairs(&self) -> Vec<(usize, usize)> {
        let k = self.rows.len();
        let (zero, positive): (Vec<usize>, Vec<usize>) =
            (0..k).partition(|&i| self.z[self.rows[i]] <= 0.0);
        let mut pairs: Vec<(usize, usize)> =
            most_perpendicular(&zero, self.coef).into_iter().collect();
        // The points (index, p), the origin as index k.
        let mut points: Vec<(usize, [f64; 2])> = positive
            .iter()
            .map(|&i| {
                let (c, z) = (self.coef[i], self.z[self.rows[i]]);
                (i, [-c[0] / z, -c[1] / z])
            })
            .collect();
        points.push((k, [0.0, 0.0]));
        for chain in hull_chains(points) {
            pairs.extend(
                chain
                    .windows(2)
                    .filter(|w| w[0] != k && w[1] != k)
                    .map(|w| (w[0].min(w[1]), w[0].max(w[1]))),
            );
        }
        pairs
    }
}

/// The lower and upper chains of the convex hull of `points` (Andrew's monotone chain), as
/// the points' indices, collinear points on the hull kept.
fn hull_chains(mut points: Vec<(usize, [f64; 2])>) -> [Vec<usize>; 2] {
    points.sort_by(|a, b| a.1[0].total_cmp(&b.1[0]).then(a.1[1].total_cmp(&b.1[1])));
    let turn = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let chain = |order: &mut dyn Iterator<Item = &(usize, [f64; 2])>| {
        let mut hull: Vec<(usize, [f64; 2])> = Vec::new();
        for &p in order {
            while hull.len() >= 2 && turn(hull[hull.len() - 2].1, hull[hull.len() - 1].1, p.1) < 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.into_iter().map(|p| p.0).collect::<Vec<usize>>()
    };
    [chain(&mut points.iter()), chain(&mut points.iter().rev())]
}

/// Of the rows `among`, the pair whose coefficients are nearest to perpendicular (None with
/// fewer than two), from their directions sorted modulo π.
fn most_perpendicular(among: &[usize], coef: &[[f64; 2]]) -> Option<(usize, usize)> {
    use std::f64::consts::{FRAC_PI_2, PI};
    let mut angles: Vec<(f64, usize)> = among
        .iter()
        .map(|&i| (coef[i][1].atan2(coef[i][0]).rem_euclid(PI), i))
        .collect();
    angles.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut best: Option<(f64, usize, usize)> = None;
    for &(angle, i) in &angles {
        let target = (angle + FRAC_PI_2).rem_euclid(PI);
        let at = angles.partition_point(|a| a.0 < target);
        // The neighbours of the target, cyclically.
        for k in [at, at + angles.len() - 1] {
            let (other, j) = angles[k % angles.len()];
            let sine = (angle - other).sin().abs();
            if j != i && best.is_none_or(|(s, ..)| sine > s) {
                best = Some((sine, i.min(j), i.max(j)));
            }
        }
    }
    best.map(|(_, i, j)| (i, j))
}
