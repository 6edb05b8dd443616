//! A vault to analyse: a validated mesh plus what acts on it (densities, point loads,
//! prescribed horizontal forces and normal stresses at free edges).

use crate::error::{Error, Result};
use crate::mesh::Mesh;

/// A mesh and its loading. Construct with [`Problem::new`] and the validating `with_*` setters.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct Problem {
    /// The validated mesh.
    pub mesh: Mesh,
    /// Weight per unit area of each face (density × thickness × g). Default 1.
    pub face_density: Vec<f64>,
    /// Extra vertical load per vertex (downward positive). Default 0.
    pub extra_loads: Vec<f64>,
    /// Prescribed horizontal force per vertex; non-zero only at free boundary vertices.
    pub horizontal_forces: Vec<[f64; 2]>,
    /// Inward normal push per free boundary vertex, used with `TauMode::Prescribed`.
    pub prescribed_tau: Vec<f64>,
    /// Per edge: a diagonal that splits a polygon of the model into triangles, which q_min
    /// does not bind (only q ≥ 0). Default none.
    pub polygon_diagonal: Vec<bool>,
}

fn check_len(name: &'static str, len: usize, expected: usize, what: &str) -> Result<()> {
    if len != expected {
        return Err(Error::InvalidArgument {
            name,
            reason: format!("has {len} entries, expected one per {what} ({expected})"),
        });
    }
    Ok(())
}

impl Problem {
    /// `mesh` with the default loads: density 1 on every face, no extra loads, no horizontal
    /// forces, τ = 0, no polygon diagonals.
    pub fn new(mesh: Mesh) -> Problem {
        let (nv, nf, ne) = (mesh.positions.len(), mesh.faces.len(), mesh.edges.len());
        Problem {
            mesh,
            face_density: vec![1.0; nf],
            extra_loads: vec![0.0; nv],
            horizontal_forces: vec![[0.0; 2]; nv],
            prescribed_tau: vec![0.0; nv],
            polygon_diagonal: vec![false; ne],
        }
    }

    /// Per-face density: finite and >= 0. Zeros are accepted here, but a solve needs a
    /// positive mean load on the non-anchored vertices (see [`crate::analyse`]).
    pub fn with_face_density(mut self, density: Vec<f64>) -> Result<Problem> {
        check_len("face_density", density.len(), self.mesh.faces.len(), "face")?;
        if let Some(t) = density.iter().position(|d| !d.is_finite() || *d < 0.0) {
            return Err(Error::InvalidArgument {
                name: "face_density",
                reason: format!("face {t} has {} (must be finite and >= 0)", density[t]),
            });
        }
        self.face_density = density;
        Ok(self)
    }

    /// Extra vertical loads per vertex: finite (negative values lift).
    pub fn with_extra_loads(mut self, loads: Vec<f64>) -> Result<Problem> {
        check_len(
            "extra_loads",
            loads.len(),
            self.mesh.positions.len(),
            "vertex",
        )?;
        if let Some(v) = loads.iter().position(|d| !d.is_finite()) {
            return Err(Error::InvalidArgument {
                name: "extra_loads",
                reason: format!("vertex {v} has a non-finite load"),
            });
        }
        self.extra_loads = loads;
        Ok(self)
    }

    /// Horizontal forces per vertex; only free boundary vertices may carry one (interior
    /// vertices are balanced exactly by the Airy function, anchored ones by their support).
    pub fn with_horizontal_forces(mut self, forces: Vec<[f64; 2]>) -> Result<Problem> {
        check_len(
            "horizontal_forces",
            forces.len(),
            self.mesh.positions.len(),
            "vertex",
        )?;
        for (v, f) in forces.iter().enumerate() {
            if !f[0].is_finite() || !f[1].is_finite() {
                return Err(Error::InvalidArgument {
                    name: "horizontal_forces",
                    reason: format!("vertex {v} has a non-finite force"),
                });
            }
            if (f[0] != 0.0 || f[1] != 0.0) && !self.mesh.is_free_boundary(v) {
                return Err(Error::InvalidArgument {
                    name: "horizontal_forces",
                    reason: format!("vertex {v} is not a free boundary vertex"),
                });
            }
        }
        self.horizontal_forces = forces;
        Ok(self)
    }

    /// Marks the edges (vertex pairs, either order) that split the model's polygons into
    /// triangles, as [`crate::io::read_mesh_with_diagonals`] lists them (and
    /// [`crate::io::read_model`] marks them), replacing any marked before: a force network on
    /// a polygon mesh needs no force along them, so q_min does not bind them. Such a split can
    /// leave no network with every q ≥ q_min > 0 (rings of quads all split along the same
    /// diagonal, as in a latitude-longitude dome). A pair that is no interior edge of the mesh
    /// (a vertex id out of range included) is an [`Error::InvalidArgument`] naming it.
    pub fn with_polygon_diagonals(mut self, diagonals: &[[u32; 2]]) -> Result<Problem> {
        let mesh = &self.mesh;
        let n = mesh.n_vertices();
        let mut marked = vec![false; mesh.n_edges()];
        for (k, &[a, b]) in diagonals.iter().enumerate() {
            if let Some(&v) = [a, b].iter().find(|&&v| v as usize >= n) {
                return Err(Error::InvalidArgument {
                    name: "diagonals",
                    reason: format!("pair {k} has vertex {v}, but there are only {n} vertices"),
                });
            }
            match mesh.edge_between(a, b) {
                Some(e) if !mesh.edges[e].is_boundary() => marked[e] = true,
                _ => {
                    return Err(Error::InvalidArgument {
                        name: "diagonals",
                        reason: format!("pair {k} ({a}, {b}) is not an interior edge of the mesh"),
                    })
                }
            }
        }
        self.polygon_diagonal = marked;
        Ok(self)
    }

    /// The marked polygon diagonals (see [`Problem::with_polygon_diagonals`]) as vertex
    /// pairs, smaller id first, in edge order.
    pub fn polygon_diagonals(&self) -> Vec<[u32; 2]> {
        (self.mesh.edges.iter().zip(&self.polygon_diagonal))
            .filter(|(_, &d)| d)
            .map(|(e, _)| e.v)
            .collect()
    }

    /// The mean of `loads` (one per vertex, as [`crate::StressResult::loads`]) over the
    /// non-anchored vertices: p̄, the unit of ε∞ and of relative force-density bounds (with
    /// L₀). 1 when there is no such vertex or the mean is not positive, as the solver takes it.
    pub fn mean_load(&self, loads: &[f64]) -> f64 {
        // One pass without a buffer: the form-finding loop asks for it on every merit.
        let (sum, count) = (0..self.mesh.n_vertices())
            .filter(|&v| self.mesh.is_non_anchored(v))
            .filter_map(|v| loads.get(v))
            .fold((0.0, 0usize), |(sum, count), &p| (sum + p, count + 1));
        let mean = sum / count.max(1) as f64;
        if mean > 0.0 {
            mean
        } else {
            1.0
        }
    }

    /// Prescribed normal push per vertex (used at free boundary vertices): finite and >= 0.
    pub fn with_prescribed_tau(mut self, tau: Vec<f64>) -> Result<Problem> {
        check_len(
            "prescribed_tau",
            tau.len(),
            self.mesh.positions.len(),
            "vertex",
        )?;
        if let Some(v) = tau.iter().position(|t| !t.is_finite() || *t < 0.0) {
            return Err(Error::InvalidArgument {
                name: "prescribed_tau",
                reason: format!("vertex {v} has {} (must be finite and >= 0)", tau[v]),
            });
        }
        self.prescribed_tau = tau;
        Ok(self)
    }
}
