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
    /// The non-anchored vertices, in the order of the system's rows.
    vertices: Vec<u32>,
    k: KStructure,
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
        let k = KStructure::new(mesh, &row, m);
        let k_rows: Vec<&[usize]> = (0..m).map(|i| k.columns(i)).collect();
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
        let structure = SymbolicSparseColMatRef::new_checked(m, m, &col_ptr, None, &row_idx);
        let symbolic =
            SymbolicLlt::try_new(structure, Side::Lower).map_err(|e| Error::Numerical {
                what: format!("shape system analysis: {e:?}"),
            })?;
        Ok(ShapeStep {
            vertices,
            k,
            col_ptr,
            row_idx,
            product_slot,
            diag_slot,
            symbolic,
        })
    }

    /// New heights for the non-anchored vertices of the mesh given to `new` (anchored ones
    /// are copied), given force densities `q` per edge, loads `p`, current heights `z`, input
    /// heights `z0`, iteration k.
    pub fn step(
        &self,
        q: &[f64],
        p: &[f64],
        z: &[f64],
        z0: &[f64],
        k: usize,
        schedule: &Schedule,
    ) -> Result<Vec<f64>> {
        let m = self.vertices.len();
        // K's values (one per entry of its structure), b, and r = K z − b.
        let k_val: Vec<f64> = (self.k.edge.iter().zip(&self.k.negative))
            .map(|(&e, &negative)| {
                if negative {
                    -q[e as usize]
                } else {
                    q[e as usize]
                }
            })
            .collect();
        let k_rows: Vec<(&[usize], &[f64])> = (0..m)
            .map(|i| {
                let range = self.k.start[i]..self.k.start[i + 1];
                (&self.k.col[range.clone()], &k_val[range])
            })
            .collect();
        let mut b: Vec<f64> = self.vertices.iter().map(|&v| p[v as usize]).collect();
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
        let r_inf = r.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        // KᵀK values on the fixed pattern, Kᵀb.
        let mut ktk = vec![0.0; self.row_idx.len()];
        let mut ktb = vec![0.0; m];
        let mut slots = self.product_slot.iter();
        for (i, (cols, vals)) in k_rows.iter().enumerate() {
            for (&a, &va) in cols.iter().zip(*vals) {
                ktb[a] += va * b[i];
                for (&c, &vc) in cols.iter().zip(*vals) {
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
