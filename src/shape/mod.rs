//! Height steps (docs/method.md §11): with the force densities fixed, new heights for the non-anchored
//! vertices from one sparse least-squares system, K = L_q[V_N, V_N], b = p − L_q[V_N, V_A] z_A:
//!
//! - the paper's step, a proximal pull towards the current heights weighted by inverse
//!   residuals: (KᵀK + μ Λ + ν I) z = Kᵀb + μ Λ zᵏ + ν z⁰;
//! - the nearest-shape step, a pull towards the input heights weighted by plan area and an
//!   optional fairness term on the change: (KᵀK + ρ (A + γ L_c)) z = Kᵀb + ρ (A + γ L_c) z⁰.
//!
//! Both share KᵀK's pattern (the two-ring of the mesh), analysed once per mesh.

mod dense;

use crate::error::{Error, Result};
use crate::geometry::loads::LoadJacobian;
use crate::mesh::Mesh;
use dense::{DenseRow, Lower, Woodbury};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Mat, Side};

/// Parameters of the paper's proximal schedule ([`crate::FormMethod::Paper`]): μ_k = max(μ₀ βᵏ, μ_min) · mean diag(KᵀK).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[non_exhaustive]
pub struct Schedule {
    /// μ₀: the first step's weight (relative to mean diag(KᵀK)).
    pub mu0: f64,
    /// β: the factor on μ per step, in [0, 1].
    pub beta: f64,
    /// μ_min: the smallest μ.
    pub mu_min: f64,
    /// η in λ_i = ‖r‖∞ / (|r_i| + η ‖r‖∞).
    pub eta: f64,
    /// ν: pull towards the input heights (relative to mean diag(KᵀK)); 0 = none.
    pub pull: f64,
}

impl Default for Schedule {
    /// The paper's schedule (de Goes et al. 2013, §5.2).
    fn default() -> Self {
        Schedule {
            mu0: 1.0,
            beta: 0.25,
            mu_min: 1e-9,
            eta: 1e-3,
            pull: 0.0,
        }
    }
}

impl Schedule {
    /// Checks every parameter, naming the first bad one (`schedule.mu0`, ...): μ₀, μ_min and
    /// ν finite and >= 0, β in [0, 1], η finite and > 0.
    pub fn validate(&self) -> Result<()> {
        use crate::validate::{above, at_least, within};
        at_least("schedule.mu0", self.mu0, 0.0)?;
        within("schedule.beta", self.beta, 0.0, 1.0, false)?;
        at_least("schedule.mu_min", self.mu_min, 0.0)?;
        above("schedule.eta", self.eta, 0.0)?;
        at_least("schedule.pull", self.pull, 0.0)
    }
}

crate::setters::with_setters!(Schedule {
    with_mu0: mu0: f64,
    with_beta: beta: f64,
    with_mu_min: mu_min: f64,
    with_eta: eta: f64,
    with_pull: pull: f64,
});

/// The height step with its sparsity pattern analysed once: KᵀK has the two-ring pattern of
/// the mesh restricted to non-anchored vertices, whatever the force densities, but for K's
/// dense rows (`dense`).
pub struct ShapeStep {
    /// The non-anchored vertices, in the order of the system's rows.
    vertices: Vec<u32>,
    k: KStructure,
    /// Per row of K: more columns than `dense_row_limit` (a fan's hub), so kept out of KᵀK's
    /// pattern and solved apart (`dense.rs`).
    dense: Vec<bool>,
    /// KᵀK's lower triangle (row ≥ col), column by column: `col_ptr`, `row_idx`.
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Slot in `row_idx` of every product K_ia K_ic (a ≥ c) in the order `step` forms them,
    /// and of every diagonal entry: the values are summed in place, in the same order each step
    /// (u32: tens of products per vertex, 31 MB at 100k vertices).
    product_slot: Vec<u32>,
    diag_slot: Vec<usize>,
    /// Both ends of every edge at a non-anchored vertex, for the fairness term.
    fair_edges: Vec<FairEnd>,
    /// The two vertices of every mesh edge.
    edge_ends: Vec<[u32; 2]>,
    symbolic: SymbolicLlt<usize>,
}

/// One end of an edge in the fairness term Σ_e c_e (Δ_i − Δ_j)², seen from row `row`.
struct FairEnd {
    edge: u32,
    row: usize,
    own: u32,
    other: u32,
    /// None: the other end is anchored; Some(slot): it is free, and the entry's off-diagonal
    /// slot is listed at one of the two ends only (None at the other).
    other_row: Option<Option<usize>>,
}

impl ShapeStep {
    pub fn new(mesh: &Mesh) -> Result<ShapeStep> {
        let n = mesh.positions.len();
        let mut row = vec![None; n];
        let mut vertices = Vec::new();
        for (v, slot) in row.iter_mut().enumerate() {
            if mesh.is_non_anchored(v) {
                *slot = Some(vertices.len());
                vertices.push(v as u32);
            }
        }
        let m = vertices.len();
        let k = KStructure::new(mesh, &row, m);
        let limit = crate::stress::sparse::dense_row_limit(m);
        let dense: Vec<bool> = (0..m)
            .map(|i| dense::distinct(k.columns(i)) > limit)
            .collect();
        // A dense row's products are left out of the pattern, and so of `product_slot`.
        let k_rows: Vec<&[usize]> = (0..m)
            .map(|i| if dense[i] { &[][..] } else { k.columns(i) })
            .collect();
        // The lower triangle's (col, row) pairs, sorted: column-major order. The diagonal is
        // always in it (the proximal term), whatever the products.
        let mut pairs: Vec<(usize, usize)> = (0..m).map(|i| (i, i)).collect();
        for cols in &k_rows {
            for &a in *cols {
                for &c in *cols {
                    if a >= c {
                        pairs.push((c, a));
                    }
                }
            }
        }
        pairs.sort_unstable();
        pairs.dedup();
        let mut col_ptr = vec![0usize; m + 1];
        for &(c, _) in &pairs {
            col_ptr[c + 1] += 1;
        }
        for c in 0..m {
            col_ptr[c + 1] += col_ptr[c];
        }
        let row_idx: Vec<usize> = pairs.iter().map(|&(_, r)| r).collect();
        let slot_of = |a: usize, c: usize| {
            let range = col_ptr[c]..col_ptr[c + 1];
            range.start + row_idx[range].binary_search(&a).expect("in the pattern")
        };
        let too_large = || Error::Numerical {
            what: format!("shape system: {} non-zeros exceed u32", row_idx.len()),
        };
        u32::try_from(row_idx.len()).map_err(|_| too_large())?;
        let mut product_slot = Vec::new();
        for cols in &k_rows {
            for &a in *cols {
                for &c in *cols {
                    if a >= c {
                        product_slot.push(slot_of(a, c) as u32);
                    }
                }
            }
        }
        let diag_slot = (0..m).map(|i| slot_of(i, i)).collect();
        let mut fair_edges = Vec::new();
        for (e, edge) in mesh.edges.iter().enumerate() {
            let [a, b] = edge.v;
            let (ra, rb) = (row[a as usize], row[b as usize]);
            for (own, other, r_own, r_other) in [(a, b, ra, rb), (b, a, rb, ra)] {
                let Some(r) = r_own else { continue };
                fair_edges.push(FairEnd {
                    edge: e as u32,
                    row: r,
                    own,
                    other,
                    other_row: r_other.map(|o| (r > o).then(|| slot_of(r, o))),
                });
            }
        }
        let structure = SymbolicSparseColMatRef::new_checked(m, m, &col_ptr, None, &row_idx);
        let symbolic =
            SymbolicLlt::try_new(structure, Side::Lower).map_err(|e| Error::Numerical {
                what: format!(
                    "the height system's analysis failed: {}",
                    crate::error::faer_failure(&e)
                ),
            })?;
        Ok(ShapeStep {
            vertices,
            k,
            dense,
            col_ptr,
            row_idx,
            product_slot,
            diag_slot,
            fair_edges,
            edge_ends: mesh.edges.iter().map(|e| e.v).collect(),
            symbolic,
        })
    }

    /// The non-anchored vertices, in the order of the system's rows.
    pub fn vertices(&self) -> &[u32] {
        &self.vertices
    }

    /// New heights for the non-anchored vertices of the mesh given to `new` (anchored ones
    /// are copied), given force densities `q` per edge, loads `p`, current heights `z`, input
    /// heights `z0`, iteration k: the inverse-residual proximal step of the paper's loop.
    pub fn step(
        &self,
        q: &[f64],
        p: &[f64],
        z: &[f64],
        z0: &[f64],
        k: usize,
        schedule: &Schedule,
    ) -> Result<Vec<f64>> {
        self.relative(z, z0, |z, z0| {
            let normal = self.normal_equations(q, p, z, None);
            let r_inf = normal.r.iter().fold(0.0f64, |a, x| a.max(x.abs()));
            let mu =
                (schedule.mu0 * schedule.beta.powi(k as i32)).max(schedule.mu_min) * normal.scale;
            let nu = schedule.pull * normal.scale;
            let pull: Vec<(f64, f64)> = (normal.r.iter().zip(&self.vertices))
                .map(|(ri, &v)| {
                    let lambda = if r_inf > 0.0 {
                        r_inf / (ri.abs() + schedule.eta * r_inf)
                    } else {
                        1.0
                    };
                    let v = v as usize;
                    (mu * lambda + nu, mu * lambda * z[v] + nu * z0[v])
                })
                .collect();
            self.solve(normal, &pull, None, z)
        })
    }

    /// The heights minimising ‖K z − b‖² + ρ Σ_i a_i (z_i − z⁰_i)² + ρ γ Σ_e c_e (Δ_i − Δ_j)²
    /// (Δ = z − z⁰; `fair` = (γ, c_e per mesh edge)): the height step of the nearest-shape
    /// method, whose normal equations are those of the paper's step with another diagonal.
    /// With `jacobian`, the loads are linearised at `z` (p + J (z' − z)) instead of held.
    #[allow(clippy::too_many_arguments)]
    pub fn nearest(
        &self,
        q: &[f64],
        p: &[f64],
        z: &[f64],
        z0: &[f64],
        rho: f64,
        area: &[f64],
        fair: Option<(f64, &[f64])>,
        jacobian: Option<&LoadJacobian>,
    ) -> Result<Vec<f64>> {
        self.relative(z, z0, |z, z0| {
            let normal = self.normal_equations(q, p, z, jacobian);
            let pull: Vec<(f64, f64)> = (area.iter().zip(&self.vertices))
                .map(|(&a, &v)| (rho * a, rho * a * z0[v as usize]))
                .collect();
            let fair = fair.map(|(gamma, c)| (rho * gamma, c, z0));
            self.solve(normal, &pull, fair, z)
        })
    }

    /// `step` run on heights relative to the supports' mean height (that of the anchored
    /// vertices next to free ones, or the free vertices' mean without any) where that lies far
    /// from the heights (`crate::geometry::far_base`): the height systems only see differences
    /// (K's rows sum to 0 with their anchored terms, and the pulls are towards heights shifted
    /// alike), so their answer is the same up to the shift, but solved for heights near 0 it
    /// keeps its digits where a whole model lifted by 10⁷ lost seven of them and stalled.
    /// Anchored heights are copied unchanged.
    fn relative(
        &self,
        z: &[f64],
        z0: &[f64],
        step: impl FnOnce(&[f64], &[f64]) -> Result<Vec<f64>>,
    ) -> Result<Vec<f64>> {
        let height = |v: &u32| z[*v as usize];
        let free: Vec<f64> = self.vertices.iter().map(height).collect();
        let mut supports: Vec<f64> = self.k.anchored.iter().map(|(_, _, c)| height(c)).collect();
        let reference = if supports.is_empty() {
            &free
        } else {
            &supports
        };
        let base = crate::geometry::far_base(reference, &[&free[..], &supports[..]].concat());
        if base == 0.0 {
            return step(z, z0);
        }
        supports.clear();
        let shift = |h: &[f64]| h.iter().map(|h| h - base).collect::<Vec<f64>>();
        let relative = step(&shift(z), &shift(z0))?;
        let mut out = z.to_vec();
        for &v in &self.vertices {
            out[v as usize] = relative[v as usize] + base;
        }
        Ok(out)
    }

    /// K's values, b, the residual r = K z − b, KᵀK on the fixed pattern and Kᵀb; with the
    /// loads' Jacobian J, K − J and b − J z (free columns), the residual of linearised loads.
    fn normal_equations(
        &self,
        q: &[f64],
        p: &[f64],
        z: &[f64],
        jacobian: Option<&LoadJacobian>,
    ) -> Normal {
        let m = self.vertices.len();
        let mut k_val: Vec<f64> = (self.k.edge.iter().zip(&self.k.negative))
            .map(|(&e, &negative)| {
                if negative {
                    -q[e as usize]
                } else {
                    q[e as usize]
                }
            })
            .collect();
        let mut shift = vec![0.0; m];
        if let Some(jac) = jacobian {
            self.subtract_jacobian(jac, z, &mut k_val, &mut shift);
        }
        let k_rows: Vec<(&[usize], &[f64])> = (0..m)
            .map(|i| {
                let range = self.k.start[i]..self.k.start[i + 1];
                (&self.k.col[range.clone()], &k_val[range])
            })
            .collect();
        let mut b: Vec<f64> = (self.vertices.iter().zip(&shift))
            .map(|(&v, s)| p[v as usize] - s)
            .collect();
        for &(ra, e, c) in &self.k.anchored {
            b[ra] += q[e as usize] * z[c as usize];
        }
        let r: Vec<f64> = (k_rows.iter().zip(&b))
            .map(|((cols, vals), bi)| {
                cols.iter()
                    .zip(*vals)
                    .map(|(&c, v)| v * z[self.vertices[c] as usize])
                    .sum::<f64>()
                    - bi
            })
            .collect();
        let mut ktk = vec![0.0; self.row_idx.len()];
        let mut ktb = vec![0.0; m];
        let mut slots = self.product_slot.iter();
        let mut dense = Vec::new();
        for (i, (cols, vals)) in k_rows.iter().enumerate() {
            if self.dense[i] {
                (cols.iter().zip(*vals)).for_each(|(&a, &va)| ktb[a] += va * b[i]);
                dense.push(dense::merged(cols, vals));
                continue;
            }
            for (&a, &va) in cols.iter().zip(*vals) {
                ktb[a] += va * b[i];
                for (&c, &vc) in cols.iter().zip(*vals) {
                    if a >= c {
                        ktk[*slots.next().expect("one slot per product") as usize] += va * vc;
                    }
                }
            }
        }
        let dense_diag: f64 = dense.iter().flatten().map(|(_, v)| v * v).sum();
        let mean_diag =
            (self.diag_slot.iter().map(|&k| ktk[k]).sum::<f64>() + dense_diag) / m.max(1) as f64;
        Normal {
            ktk,
            ktb,
            dense,
            r,
            scale: if mean_diag > 0.0 { mean_diag } else { 1.0 },
        }
    }

    /// K − J on K's entries (J's diagonal on each row's first entry, a diagonal one; J_ac on
    /// the entry of column c), and J z over the free columns per row into `shift`.
    fn subtract_jacobian(
        &self,
        jac: &LoadJacobian,
        z: &[f64],
        k_val: &mut [f64],
        shift: &mut [f64],
    ) {
        for (row, &v) in self.vertices.iter().enumerate() {
            let d = jac.diagonal[v as usize];
            let range = self.k.start[row]..self.k.start[row + 1];
            if range.is_empty() {
                continue;
            }
            k_val[range.start] -= d;
            shift[row] += d * z[v as usize];
            for k in range {
                if !self.k.negative[k] {
                    continue;
                }
                let e = self.k.edge[k] as usize;
                let ends = self.edge_ends[e];
                let j_vc = jac.edge[e][usize::from(ends[0] != v)];
                let c = self.vertices[self.k.col[k]];
                k_val[k] -= j_vc;
                shift[row] += j_vc * z[c as usize];
            }
        }
    }

    /// Solves (KᵀK + D + G) z = Kᵀb + d + g, where `pull` holds (D_ii, d_i) per row and
    /// `fair` = (weight, c_e, centre) adds G, the weighted graph Laplacian of the edges, and
    /// g = G centre (anchored neighbours count at their centre height).
    fn solve(
        &self,
        normal: Normal,
        pull: &[(f64, f64)],
        fair: Option<(f64, &[f64], &[f64])>,
        z: &[f64],
    ) -> Result<Vec<f64>> {
        let m = self.vertices.len();
        let Normal {
            mut ktk,
            ktb,
            dense,
            ..
        } = normal;
        let mut rhs = Mat::from_fn(m, 1, |i, _| ktb[i] + pull[i].1);
        for (i, &k) in self.diag_slot.iter().enumerate() {
            ktk[k] += pull[i].0;
        }
        if let Some((weight, c, centre)) = fair {
            for f in &self.fair_edges {
                let w = weight * c[f.edge as usize];
                let (ci, cj) = (centre[f.own as usize], centre[f.other as usize]);
                ktk[self.diag_slot[f.row]] += w;
                rhs[(f.row, 0)] += w * (ci - cj);
                match f.other_row {
                    None => rhs[(f.row, 0)] += w * cj,
                    Some(Some(slot)) => ktk[slot] -= w,
                    Some(None) => {}
                }
            }
        }
        let mat = SparseColMatRef::new(
            SymbolicSparseColMatRef::new_checked(m, m, &self.col_ptr, None, &self.row_idx),
            &ktk[..],
        );
        let llt = Llt::try_new_with_symbolic(self.symbolic.clone(), mat, Side::Lower)
            .map_err(|e| crate::error::factorisation_failure("the height system", &e))?;
        let solution: Vec<f64> = if dense.is_empty() {
            llt.solve_in_place(rhs.as_mut());
            (0..m).map(|i| rhs[(i, 0)]).collect()
        } else {
            let lower = Lower {
                col_ptr: &self.col_ptr,
                row_idx: &self.row_idx,
                values: &ktk,
            };
            let woodbury = Woodbury::new(&llt, lower, &dense).ok_or_else(|| Error::Numerical {
                what: "the height system's dense rows: not positive definite".into(),
            })?;
            woodbury.solve(&(0..m).map(|i| rhs[(i, 0)]).collect::<Vec<f64>>())
        };
        let mut out = z.to_vec();
        for (i, &v) in self.vertices.iter().enumerate() {
            out[v as usize] = solution[i];
        }
        if out.iter().any(|x| !x.is_finite()) {
            return Err(Error::Numerical {
                what: "shape step produced non-finite heights".into(),
            });
        }
        Ok(out)
    }
}

/// The normal equations of one height step before any pull is added.
struct Normal {
    /// KᵀK without the dense rows' products.
    ktk: Vec<f64>,
    ktb: Vec<f64>,
    /// K's dense rows, their columns merged.
    dense: Vec<DenseRow>,
    /// r = K z − b at the current heights, per row.
    r: Vec<f64>,
    /// Mean diagonal of KᵀK (1 when zero): the unit of the proximal weights.
    scale: f64,
}

/// K = L_q[V_N, V_N] as a structure fixed by the mesh: per row, one diagonal entry +q_e per
/// incident edge and, for a non-anchored neighbour, an entry −q_e in its column, in edge order;
/// an anchored neighbour's q_e z_c goes to b instead. `ShapeStep::new` derives KᵀK's pattern
/// and product slots from it, and `step` fills it with values, so both see one order.
/// (The stress solver's `product_pattern` / `product_slots` need one entry per column, i.e.
/// the diagonal summed first: tried, that changed KᵀK's rounding, and three_pillar's and
/// cheese's fragile last QPs then took 1.06 s and 3.0 s instead of 0.56 s and 2.6 s.)
struct KStructure {
    /// Row i is `start[i]..start[i + 1]` of `col`, `edge`, `negative`.
    start: Vec<usize>,
    col: Vec<usize>,
    edge: Vec<u32>,
    negative: Vec<bool>,
    /// (row, edge, anchored vertex), in edge order.
    anchored: Vec<(usize, u32, u32)>,
}

impl KStructure {
    fn new(mesh: &Mesh, row: &[Option<usize>], m: usize) -> KStructure {
        let mut rows: Vec<Vec<(usize, u32, bool)>> = vec![Vec::new(); m];
        let mut anchored = Vec::new();
        for (e, edge) in mesh.edges.iter().enumerate() {
            let [i, j] = edge.v;
            for (a, c) in [(i, j), (j, i)] {
                if let Some(ra) = row[a as usize] {
                    rows[ra].push((ra, e as u32, false));
                    match row[c as usize] {
                        Some(rc) => rows[ra].push((rc, e as u32, true)),
                        None => anchored.push((ra, e as u32, c)),
                    }
                }
            }
        }
        let mut start = vec![0];
        let (mut col, mut edge, mut negative) = (Vec::new(), Vec::new(), Vec::new());
        for entries in rows {
            for (c, e, n) in entries {
                col.push(c);
                edge.push(e);
                negative.push(n);
            }
            start.push(col.len());
        }
        KStructure {
            start,
            col,
            edge,
            negative,
            anchored,
        }
    }

    fn columns(&self, i: usize) -> &[usize] {
        &self.col[self.start[i]..self.start[i + 1]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// J(z) = ‖K z − b‖² + ρ Σ a_i Δ_i² + ρ γ Σ_e c_e (Δ_i − Δ_j)² and its gradient, computed
    /// from the mesh's edges directly (Δ = z − z⁰, zero at anchored vertices).
    fn objective(
        mesh: &Mesh,
        q: &[f64],
        p: &[f64],
        z: &[f64],
        z0: &[f64],
        (rho, area, gamma, c): (f64, &[f64], f64, &[f64]),
    ) -> (f64, Vec<f64>) {
        let n = z.len();
        let mut r = vec![0.0; n];
        for (v, rv) in r
            .iter_mut()
            .enumerate()
            .filter(|(v, _)| mesh.is_non_anchored(*v))
        {
            *rv = -p[v];
        }
        for (e, edge) in mesh.edges.iter().enumerate() {
            let [i, j] = edge.v.map(|v| v as usize);
            r[i] += q[e] * (z[i] - z[j]);
            r[j] += q[e] * (z[j] - z[i]);
        }
        let free = |v: usize| mesh.is_non_anchored(v);
        let mut grad = vec![0.0; n];
        let mut j_val = 0.0;
        for v in (0..n).filter(|&v| free(v)) {
            j_val += r[v] * r[v] + rho * area[v] * (z[v] - z0[v]).powi(2);
            grad[v] += 2.0 * rho * area[v] * (z[v] - z0[v]);
        }
        for (e, edge) in mesh.edges.iter().enumerate() {
            let [i, j] = edge.v.map(|v| v as usize);
            // d r_i / d z_i = q, d r_i / d z_j = −q, for the free rows.
            for (a, b) in [(i, j), (j, i)] {
                if free(a) {
                    grad[a] += 2.0 * r[a] * q[e];
                    grad[b] -= 2.0 * r[a] * q[e];
                }
            }
            let d = (z[i] - z0[i]) - (z[j] - z0[j]);
            j_val += rho * gamma * c[e] * d * d;
            grad[i] += 2.0 * rho * gamma * c[e] * d;
            grad[j] -= 2.0 * rho * gamma * c[e] * d;
        }
        for (v, g) in grad.iter_mut().enumerate() {
            if !free(v) {
                *g = 0.0;
            }
        }
        (j_val, grad)
    }

    /// A wheel: a hub joined to every vertex of the first of three rings (`spokes` each),
    /// quads split alternately, the outer ring anchored; the hub's row of K has a column per
    /// spoke.
    fn wheel(spokes: usize) -> Mesh {
        let rings = [0.35, 0.7, 1.0];
        let mut positions = vec![[0.0, 0.0, 1.0]];
        for r in rings {
            for k in 0..spokes {
                let a = std::f64::consts::TAU * k as f64 / spokes as f64;
                positions.push([r * a.cos(), r * a.sin(), 1.0 - r * r]);
            }
        }
        let at = |ring: usize, k: usize| (1 + ring * spokes + k % spokes) as u32;
        let mut faces: Vec<[u32; 3]> = (0..spokes).map(|k| [0, at(0, k), at(0, k + 1)]).collect();
        for ring in 0..rings.len() - 1 {
            for k in 0..spokes {
                let (a, b) = (at(ring, k), at(ring, k + 1));
                let (c, d) = (at(ring + 1, k), at(ring + 1, k + 1));
                faces.extend(if k % 2 == 0 {
                    [[a, c, b], [b, c, d]]
                } else {
                    [[a, c, d], [a, d, b]]
                });
            }
        }
        let anchored: Vec<u32> = (0..spokes).map(|k| at(rings.len() - 1, k)).collect();
        Mesh::new(positions, faces, &anchored).unwrap()
    }

    /// On a dome, and on a wheel whose hub's row of K is solved apart (`dense.rs`).
    #[test]
    fn the_nearest_step_minimises_its_objective() {
        let dome = crate::generate::cap_dome(0.9, 300).unwrap();
        let hub = wheel(300);
        let split = ShapeStep::new(&hub).unwrap();
        assert!(split.dense.iter().any(|&d| d));
        // The hub's 300 × 300 couplings are not in KᵀK's pattern: a few per vertex remain.
        let per_vertex = split.row_idx.len() as f64 / split.vertices.len() as f64;
        assert!(per_vertex < 12.0, "{per_vertex} entries per row of KᵀK");
        assert!(!ShapeStep::new(&dome).unwrap().dense.iter().any(|&d| d));
        for mesh in [dome, hub] {
            minimises_its_objective(&mesh);
        }
    }

    fn minimises_its_objective(mesh: &Mesh) {
        let n = mesh.positions.len();
        let wave = |k: usize, f: f64| ((k as f64 * f).sin() + 1.5) / 2.5;
        let q: Vec<f64> = (0..mesh.edges.len()).map(|e| 50.0 * wave(e, 0.7)).collect();
        let c: Vec<f64> = (0..mesh.edges.len()).map(|e| wave(e, 1.3)).collect();
        let p: Vec<f64> = (0..n).map(|v| 0.01 * wave(v, 0.3)).collect();
        let z0: Vec<f64> = mesh.positions.iter().map(|x| x[2]).collect();
        // Anchored vertices stay at their input heights, as in form finding.
        let z: Vec<f64> = (0..n)
            .map(|v| {
                z0[v]
                    + if mesh.is_non_anchored(v) {
                        0.01 * wave(v, 2.1)
                    } else {
                        0.0
                    }
            })
            .collect();
        let area: Vec<f64> = (0..n).map(|v| wave(v, 0.9) / n as f64).collect();
        let step = ShapeStep::new(mesh).unwrap();
        let rows: Vec<f64> = step.vertices().iter().map(|&v| area[v as usize]).collect();
        for (rho, gamma) in [(1e3, 0.0), (1e3, 0.5), (1e-2, 2.0)] {
            let terms = (rho, &area[..], gamma, &c[..]);
            let fair = (gamma > 0.0).then_some((gamma, &c[..]));
            let zs = step
                .nearest(&q, &p, &z, &z0, rho, &rows, fair, None)
                .unwrap();
            let (_, g0) = objective(mesh, &q, &p, &z, &z0, terms);
            let (j, g) = objective(mesh, &q, &p, &zs, &z0, terms);
            let norm = |g: &[f64]| g.iter().map(|x| x * x).sum::<f64>().sqrt();
            assert!(
                norm(&g) < 1e-8 * norm(&g0),
                "ρ {rho} γ {gamma}: |∇J| {:e}",
                norm(&g)
            );
            // A minimum, not only a stationary point: every nearby point is worse.
            for k in 0..5 {
                let dz: Vec<f64> = (0..n)
                    .map(|v| 1e-4 * (wave(v + 7 * k, 1.7) - 0.5))
                    .collect();
                for sign in [1.0, -1.0] {
                    let moved: Vec<f64> = (0..n)
                        .map(|v| {
                            zs[v]
                                + if mesh.is_non_anchored(v) {
                                    sign * dz[v]
                                } else {
                                    0.0
                                }
                        })
                        .collect();
                    assert!(objective(mesh, &q, &p, &moved, &z0, terms).0 >= j);
                }
            }
            // Anchored heights are kept.
            for v in (0..n).filter(|&v| !mesh.is_non_anchored(v)) {
                assert_eq!(zs[v], z[v]);
            }
        }
    }
}
