//! Shape optimisation (MATH §9): with the force densities fixed, move the heights of the
//! non-anchored vertices by a weighted least-squares step. Vertices far from balance get small
//! proximal weights and move freely; balanced ones barely move.
//!
//!   (KᵀK + μ Λ + ν I) z = Kᵀ b + μ Λ zᵏ + ν z⁰,   K = L_q[V_N, V_N],  b = p − L_q[V_N, V_A] z_A

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMat, Triplet};
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
    /// Lower-triangle (row ≥ col) pattern of KᵀK, sorted and unique.
    pattern: Vec<(usize, usize)>,
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
        // K's pattern: diagonal + edges between non-anchored vertices; KᵀK = Σ_i (row i)ᵀ(row i).
        let k_rows = k_pattern(mesh, &row, &vertices);
        let mut pattern = Vec::new();
        for cols in &k_rows {
            for &a in cols {
                for &b in cols {
                    if a >= b {
                        pattern.push((a, b));
                    }
                }
            }
        }
        pattern.sort_unstable();
        pattern.dedup();
        let m = vertices.len();
        let entries: Vec<Triplet<usize, usize, f64>> = pattern
            .iter()
            .map(|&(r, c)| Triplet {
                row: r,
                col: c,
                val: 1.0,
            })
            .collect();
        let a = SparseColMat::<usize, f64>::try_new_from_triplets(m, m, &entries).map_err(|e| {
            Error::Numerical {
                what: format!("shape system pattern: {e:?}"),
            }
        })?;
        let symbolic =
            SymbolicLlt::try_new(a.symbolic(), Side::Lower).map_err(|e| Error::Numerical {
                what: format!("shape system analysis: {e:?}"),
            })?;
        Ok(ShapeStep {
            row,
            vertices,
            pattern,
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
        let mut ktk = std::collections::HashMap::with_capacity(self.pattern.len());
        let mut ktb = vec![0.0; m];
        for (i, cols) in k_rows.iter().enumerate() {
            for &(a, va) in cols {
                ktb[a] += va * b[i];
                for &(c, vc) in cols {
                    if a >= c {
                        *ktk.entry((a, c)).or_insert(0.0) += va * vc;
                    }
                }
            }
        }
        let mean_diag = (0..m)
            .map(|i| ktk.get(&(i, i)).copied().unwrap_or(0.0))
            .sum::<f64>()
            / m.max(1) as f64;
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
        let entries: Vec<Triplet<usize, usize, f64>> = self
            .pattern
            .iter()
            .map(|&(a, c)| {
                let mut val = ktk.get(&(a, c)).copied().unwrap_or(0.0);
                if a == c {
                    val += mu * lambda[a] + nu;
                }
                Triplet {
                    row: a,
                    col: c,
                    val,
                }
            })
            .collect();
        let mat =
            SparseColMat::<usize, f64>::try_new_from_triplets(m, m, &entries).map_err(|e| {
                Error::Numerical {
                    what: format!("shape system: {e:?}"),
                }
            })?;
        let llt = Llt::try_new_with_symbolic(self.symbolic.clone(), mat.as_ref(), Side::Lower)
            .map_err(|e| Error::Numerical {
                what: format!("shape system is not positive definite: {e:?}"),
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

fn k_pattern(mesh: &Mesh, row: &[Option<usize>], vertices: &[u32]) -> Vec<Vec<usize>> {
    let mut rows: Vec<Vec<usize>> = (0..vertices.len()).map(|i| vec![i]).collect();
    for edge in &mesh.edges {
        let [i, j] = edge.v.map(|v| v as usize);
        if let (Some(a), Some(b)) = (row[i], row[j]) {
            rows[a].push(b);
            rows[b].push(a);
        }
    }
    rows
}
