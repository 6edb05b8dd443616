//! Shape optimisation (MATH §9): with the force densities fixed, move the heights of the
//! non-anchored vertices by a weighted least-squares step. Vertices far from balance get small
//! proximal weights and move freely; balanced ones barely move.
//!
//!   (KᵀK + μ Λ + ν I) z = Kᵀ b + μ Λ zᵏ + ν z⁰,   K = L_q[V_N, V_N],  b = p − L_q[V_N, V_A] z_A

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Mat, Side};

/// Parameters of the proximal schedule μ_k = max(μ₀ βᵏ, μ_min) · mean diag(KᵀK).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Schedule {
    pub mu0: f64,
    pub beta: f64,
    pub mu_min: f64,
    /// η in λ_i = ‖r‖∞ / (|r_i| + η ‖r‖∞).
    pub eta: f64,
    /// ν: pull towards the input heights (relative to mean diag(KᵀK)); 0 = none.
    pub pull: f64,
}

impl Default for Schedule {
    fn default() -> Self {
        // μ₀ = 0.3 rather than MATH's 1 and β = 0.2: measured over the nine shared models this
        // converges on all of them within 20 iterations (β = 0.25: 21 on three_pillar and
        // vault_pq; μ₀ = 1: 27; counted before height steps were certified, which saves one
        // stress step on most); smaller μ₀ slows some down (hex: 31 with μ₀ = 0.1).
        Schedule {
            mu0: 0.3,
            beta: 0.2,
            mu_min: 1e-9,
            eta: 1e-3,
            pull: 0.0,
        }
    }
}

/// The height step with its sparsity pattern analysed once: KᵀK has the two-ring pattern of
/// the mesh restricted to non-anchored vertices, whatever the force densities.
pub struct ShapeStep {
    /// Row of each non-anchored vertex in the system (None for anchored / unreferenced).
    row: Vec<Option<usize>>,
    vertices: Vec<u32>,
    /// KᵀK's lower triangle (row ≥ col), column by column: `col_ptr`, `row_idx`.
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Slot in `row_idx` of every product K_ia K_ic (a ≥ c) in the order `step` forms them,
    /// and of every diagonal entry: the values are summed in place, in the same order each step
    /// (u32: tens of products per vertex, 31 MB at 100k vertices).
    product_slot: Vec<u32>,
    diag_slot: Vec<usize>,
    symbolic: SymbolicLlt<usize>,
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
        let k_rows = k_columns(mesh, &row, m);
        // The lower triangle's (col, row) pairs, sorted: column-major order. The diagonal is
        // always in it (the proximal term), whatever the products.
        let mut pairs: Vec<(usize, usize)> = (0..m).map(|i| (i, i)).collect();
        for cols in &k_rows {
            for &a in cols {
                for &c in cols {
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
            for &a in cols {
                for &c in cols {
                    if a >= c {
                        product_slot.push(slot_of(a, c) as u32);
                    }
                }
            }
        }
        let diag_slot = (0..m).map(|i| slot_of(i, i)).collect();
        let structure = SymbolicSparseColMatRef::new_checked(m, m, &col_ptr, None, &row_idx);
        let symbolic =
            SymbolicLlt::try_new(structure, Side::Lower).map_err(|e| Error::Numerical {
                what: format!("shape system analysis: {e:?}"),
            })?;
        Ok(ShapeStep {
            row,
            vertices,
            col_ptr,
            row_idx,
            product_slot,
            diag_slot,
            symbolic,
        })
    }

    /// New heights for the non-anchored vertices (anchored ones are copied), given force
    /// densities `q` per edge, loads `p`, current heights `z`, input heights `z0`, iteration k.
    #[allow(clippy::too_many_arguments)]
    pub fn step(
        &self,
        mesh: &Mesh,
        q: &[f64],
        p: &[f64],
        z: &[f64],
        z0: &[f64],
        k: usize,
        schedule: &Schedule,
    ) -> Result<Vec<f64>> {
        let m = self.vertices.len();
        // K rows as (col, value) lists, b, and r = K z − b.
        let mut k_rows: Vec<Vec<(usize, f64)>> = self.vertices.iter().map(|_| Vec::new()).collect();
        let mut b: Vec<f64> = self.vertices.iter().map(|&v| p[v as usize]).collect();
        for (e, edge) in mesh.edges.iter().enumerate() {
            let [i, j] = edge.v.map(|v| v as usize);
            for (a, c) in [(i, j), (j, i)] {
                if let Some(ra) = self.row[a] {
                    k_rows[ra].push((ra, q[e]));
                    match self.row[c] {
                        Some(rc) => k_rows[ra].push((rc, -q[e])),
                        None => b[ra] += q[e] * z[c],
                    }
                }
            }
        }
        let r: Vec<f64> = (0..m)
            .map(|i| {
                k_rows[i]
                    .iter()
                    .map(|&(c, v)| v * z[self.vertices[c] as usize])
                    .sum::<f64>()
                    - b[i]
            })
            .collect();
        let r_inf = r.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        // KᵀK values on the fixed pattern, Kᵀb.
        let mut ktk = vec![0.0; self.row_idx.len()];
        let mut ktb = vec![0.0; m];
        let mut slots = self.product_slot.iter();
        for (i, cols) in k_rows.iter().enumerate() {
            for &(a, va) in cols {
                ktb[a] += va * b[i];
                for &(c, vc) in cols {
                    if a >= c {
                        ktk[*slots.next().expect("one slot per product") as usize] += va * vc;
                    }
                }
            }
        }
        let mean_diag = self.diag_slot.iter().map(|&k| ktk[k]).sum::<f64>() / m.max(1) as f64;
        let scale = if mean_diag > 0.0 { mean_diag } else { 1.0 };
        let mu = (schedule.mu0 * schedule.beta.powi(k as i32)).max(schedule.mu_min) * scale;
        let nu = schedule.pull * scale;
        let lambda: Vec<f64> = r
            .iter()
            .map(|ri| {
                if r_inf > 0.0 {
                    r_inf / (ri.abs() + schedule.eta * r_inf)
                } else {
                    1.0
                }
            })
            .collect();
        for (i, &k) in self.diag_slot.iter().enumerate() {
            ktk[k] += mu * lambda[i] + nu;
        }
        let mat = SparseColMatRef::new(
            SymbolicSparseColMatRef::new_checked(m, m, &self.col_ptr, None, &self.row_idx),
            &ktk[..],
        );
        let llt =
            Llt::try_new_with_symbolic(self.symbolic.clone(), mat, Side::Lower).map_err(|e| {
                Error::Numerical {
                    what: format!("shape system is not positive definite: {e:?}"),
                }
            })?;
        let mut rhs = Mat::from_fn(m, 1, |i, _| {
            let v = self.vertices[i] as usize;
            ktb[i] + mu * lambda[i] * z[v] + nu * z0[v]
        });
        llt.solve_in_place(rhs.as_mut());
        let mut out = z.to_vec();
        for (i, &v) in self.vertices.iter().enumerate() {
            out[v as usize] = rhs[(i, 0)];
        }
        if out.iter().any(|x| !x.is_finite()) {
            return Err(Error::Numerical {
                what: "shape step produced non-finite heights".into(),
            });
        }
        Ok(out)
    }
}

/// The columns of each row of K in the order `ShapeStep::step` pushes them (one diagonal
/// entry per incident edge, then the neighbour's column if it is not anchored).
fn k_columns(mesh: &Mesh, row: &[Option<usize>], m: usize) -> Vec<Vec<usize>> {
    let mut rows: Vec<Vec<usize>> = vec![Vec::new(); m];
    for edge in &mesh.edges {
        let [i, j] = edge.v.map(|v| v as usize);
        for (a, c) in [(i, j), (j, i)] {
            if let Some(ra) = row[a] {
                rows[ra].push(ra);
                if let Some(rc) = row[c] {
                    rows[ra].push(rc);
                }
            }
        }
    }
    rows
}
