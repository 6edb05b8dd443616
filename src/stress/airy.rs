//! The reduced operator of de Goes et al.: force densities as a linear map of the Airy values
//! φ (vertex weights), the hole jumps and the boundary creases, q = S y (docs/method.md §4–7).

use super::gauge;
use super::holes::{cut_holes, HoleCut};
use super::sparse::{bucketed, Csr};
use crate::error::Result;
use crate::geometry::Plan;
use crate::mesh::{Mesh, Side};

/// How the Airy function may jump around a hole.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum HoleMode {
    /// A constant jump c_h per hole (the paper's hole-induced stress): a net torque only, so
    /// on holes whose rings are anchored or loaded by τ the optimum can lie above the
    /// edge-based one.
    Constant,
    /// An affine jump c_h + a_h·u: also a net horizontal force through the hole. With it the
    /// reduced feasible set equals the edge-based one on every domain, so the reduced optimum
    /// is the true optimum.
    #[default]
    Affine,
}

impl HoleMode {
    /// The unknowns per hole: 1 (constant) or 3 (affine).
    pub fn width(self) -> usize {
        match self {
            HoleMode::Constant => 1,
            HoleMode::Affine => 3,
        }
    }
}

/// q = S y for y = (φ without the gauge vertices (`gauge::pinned_vertices`), hole
/// coefficients, boundary creases).
#[derive(Debug, Clone)]
pub struct AiryOperator {
    /// One row per mesh edge (inactive edges have empty rows).
    pub s: Csr,
    /// Column of φ_v, None for gauge and unreferenced vertices (φ = 0 there).
    pub phi_col: Vec<Option<usize>>,
    /// First column of the hole coefficients; hole h uses `width` columns from
    /// `hole_start + h * width`: (c, a_x, a_y) in frame coordinates.
    pub hole_start: usize,
    /// Columns per hole: 1 (constant jumps) or 3 (affine).
    pub hole_width: usize,
    /// The cuts that join the holes to the outer boundary, in the order made.
    pub cuts: Vec<HoleCut>,
    /// The cuts whose right faces contain face t, in increasing order:
    /// `face_cuts[face_cut_start[t]..face_cut_start[t + 1]]` (see `cuts_at_face`).
    face_cut_start: Vec<usize>,
    face_cuts: Vec<usize>,
    /// Column of the crease unknown of each boundary edge that has a non-anchored end.
    pub crease_col: Vec<Option<usize>>,
}

/// Coefficients κ_{e,t,v} of face `side` in the closed form (A) for edge (i, j) of length l:
/// φ_opposite / (2A) − (cot θ_j φ_i + cot θ_i φ_j) / l².
pub fn face_coefficients(
    mesh: &Mesh,
    plan: &Plan,
    i: u32,
    j: u32,
    l: f64,
    side: Side,
) -> [(u32, f64); 3] {
    let t = side.face;
    let l2 = l * l;
    [
        (side.opposite, 1.0 / (2.0 * plan.area[t as usize])),
        (i, -plan.cot_at(mesh, t, j) / l2),
        (j, -plan.cot_at(mesh, t, i) / l2),
    ]
}

fn hole_basis(u: [f64; 2]) -> [f64; 3] {
    [1.0, u[0], u[1]]
}

impl AiryOperator {
    /// The operator of `mesh` over `plan`, with hole jumps of `mode`.
    pub fn new(mesh: &Mesh, plan: &Plan, mode: HoleMode) -> Result<AiryOperator> {
        let n = mesh.positions.len();
        let gauge = gauge::pinned_vertices(mesh, plan);
        let mut phi_col = vec![None; n];
        let mut cols = 0;
        for v in 0..n {
            if mesh.referenced[v] && !gauge[v] {
                phi_col[v] = Some(cols);
                cols += 1;
            }
        }
        let cuts = cut_holes(mesh)?;
        let hole_start = cols;
        let hole_width = mode.width();
        cols += cuts.len() * hole_width;
        let mut crease_col = vec![None; mesh.edges.len()];
        for (e, edge) in mesh.edges.iter().enumerate() {
            let active = edge.v.iter().any(|&v| !mesh.anchored[v as usize]);
            if edge.is_boundary() && active {
                crease_col[e] = Some(cols);
                cols += 1;
            }
        }
        // Each face asks only the cuts it lies beside, so that a mesh with many holes does
        // not scan every cut per face.
        let beside = cuts.iter().map(|c| c.right_faces.len()).sum();
        let (face_cut_start, face_cuts) = bucketed(mesh.faces.len(), beside, || {
            (cuts.iter().enumerate())
                .flat_map(|(h, c)| c.right_faces.iter().map(move |&t| (t as usize, h)))
        });
        let mut op = AiryOperator {
            s: Csr::new(cols),
            phi_col,
            hole_start,
            hole_width,
            cuts,
            face_cut_start,
            face_cuts,
            crease_col,
        };
        for e in 0..mesh.edges.len() {
            let row = op.edge_row(mesh, plan, e);
            op.s.push_row(row);
        }
        Ok(op)
    }

    /// The number of unknowns (columns of S).
    #[cfg(any(test, feature = "internals"))]
    pub fn n_unknowns(&self) -> usize {
        self.s.ncols
    }

    /// The cuts whose right faces R_h contain face t, in increasing order.
    pub fn cuts_at_face(&self, t: u32) -> &[usize] {
        &self.face_cuts[self.face_cut_start[t as usize]..self.face_cut_start[t as usize + 1]]
    }

    fn edge_row(&self, mesh: &Mesh, plan: &Plan, e: usize) -> Vec<(usize, f64)> {
        let edge = &mesh.edges[e];
        if let Some(c) = self.crease_col[e] {
            return vec![(c, 1.0)];
        }
        let (Some(left), Some(right)) = (edge.left, edge.right) else {
            return Vec::new();
        };
        let [i, j] = edge.v;
        let l = plan.length[e];
        let mut row = Vec::with_capacity(6);
        for side in [left, right] {
            let kappa = face_coefficients(mesh, plan, i, j, l, side);
            for (v, k) in kappa {
                if let Some(c) = self.phi_col[v as usize] {
                    row.push((c, k));
                }
            }
            for &h in self.cuts_at_face(side.face) {
                let cut = &self.cuts[h];
                // On the cut, compare with the right face shifted back by M_h, which agrees with
                // the left face along the edge: only the off-path vertex moves, by −M_h.
                let terms: Vec<(u32, f64)> = if cut.is_cut_edge(e as u32) {
                    vec![(side.opposite, -kappa[0].1)]
                } else {
                    kappa
                        .iter()
                        .copied()
                        .filter(|(v, _)| cut.on_path(*v))
                        .collect()
                };
                for (v, k) in terms {
                    let m = hole_basis(plan.u[v as usize]);
                    for (d, md) in m.iter().enumerate().take(self.hole_width) {
                        row.push((self.hole_start + h * self.hole_width + d, k * md));
                    }
                }
            }
        }
        row
    }

    /// φ per vertex (0 at gauge and unreferenced vertices), from the unknowns y.
    pub fn airy_values(&self, y: &[f64]) -> Vec<f64> {
        self.phi_col
            .iter()
            .map(|c| c.map_or(0.0, |c| y[c]))
            .collect()
    }

    /// Jump coefficients (c, a_x, a_y) across the cut of hole h in frame coordinates (zeros past
    /// `width`).
    pub fn hole_jump(&self, y: &[f64], h: usize) -> [f64; 3] {
        let mut m = [0.0; 3];
        for (d, md) in m.iter_mut().enumerate().take(self.hole_width) {
            *md = y[self.hole_start + h * self.hole_width + d];
        }
        m
    }

    /// The jump of the Airy function once counter-clockwise around each hole, c_h + a_h·u
    /// (frame coordinates), as a cut from the hole straight to the outer loop would carry it:
    /// the jump across the hole's own cut less those across the cuts that end on its loop
    /// (crossed the other way by a small loop around the hole). Unlike the jumps across the
    /// cuts, it does not depend on where the cuts run.
    pub fn hole_periods(&self, y: &[f64]) -> Vec<[f64; 3]> {
        let mut periods: Vec<[f64; 3]> =
            (0..self.cuts.len()).map(|h| self.hole_jump(y, h)).collect();
        for (c, cut) in self.cuts.iter().enumerate() {
            if let Some(h) = cut.ends_at_hole {
                let j = self.hole_jump(y, c);
                (0..3).for_each(|d| periods[h][d] -= j[d]);
            }
        }
        periods
    }

    /// The Airy value that face t sees at its vertex v: φ_v plus the jump of every hole whose
    /// right faces contain t and whose path contains v.
    pub fn face_local_airy(&self, plan: &Plan, phi: &[f64], y: &[f64], t: u32, v: u32) -> f64 {
        let mut value = phi[v as usize];
        for &h in self.cuts_at_face(t) {
            if self.cuts[h].on_path(v) {
                let m = self.hole_jump(y, h);
                let b = hole_basis(plan.u[v as usize]);
                value += m[0] * b[0] + m[1] * b[1] + m[2] * b[2];
            }
        }
        value
    }
}
