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
    /// conditioned such pair; with z = 0 every pair qualifies.
    pub(super) fn released(&self, active: &[bool], z: &[f64]) -> Vec<bool> {
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
