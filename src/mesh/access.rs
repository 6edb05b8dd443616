//! Read access to a validated mesh, and the one change that keeps it valid: new heights.

use super::build::check_heights;
use super::{BoundaryLoop, Edge, Mesh};
use crate::Result;

impl Mesh {
    /// Vertex positions as given (x, y plan; z height), one per vertex.
    pub fn positions(&self) -> &[[f64; 3]] {
        &self.positions
    }

    /// Faces, counter-clockwise in plan (all reversed if the input was clockwise; see
    /// [`Mesh::input_faces`]).
    pub fn faces(&self) -> &[[u32; 3]] {
        &self.faces
    }

    /// True when the input faces were clockwise in plan and have been reversed.
    pub fn reversed(&self) -> bool {
        self.reversed
    }

    /// All edges, sorted by (`v[0]`, `v[1]`).
    pub fn edges(&self) -> &[Edge] {
        &self.edges
    }

    /// For face t, the edge ids of (`f[0]`,`f[1]`), (`f[1]`,`f[2]`), (`f[2]`,`f[0]`).
    pub fn face_edges(&self) -> &[[u32; 3]] {
        &self.face_edges
    }

    /// Anchored (support) flag per vertex.
    pub fn anchored(&self) -> &[bool] {
        &self.anchored
    }

    /// The ids of the anchored vertices, in increasing order.
    pub fn anchored_ids(&self) -> Vec<u32> {
        (0..self.anchored.len())
            .filter(|&v| self.anchored[v])
            .map(|v| v as u32)
            .collect()
    }

    /// Whether each vertex lies on a boundary loop.
    pub fn on_boundary(&self) -> &[bool] {
        &self.on_boundary
    }

    /// Whether each vertex is referenced by at least one face (the others are ignored).
    pub fn referenced(&self) -> &[bool] {
        &self.referenced
    }

    /// Connected component per vertex (`u32::MAX` for unreferenced vertices).
    pub fn vertex_component(&self) -> &[u32] {
        &self.vertex_component
    }

    /// Connected component per face.
    pub fn face_component(&self) -> &[u32] {
        &self.face_component
    }

    /// The number of connected components.
    pub fn n_components(&self) -> usize {
        self.n_components
    }

    /// Boundary loops of all components; holes are the loops with `is_outer == false`
    /// ([`Mesh::holes`]).
    pub fn loops(&self) -> &[BoundaryLoop] {
        &self.loops
    }

    /// Ids of vertices referenced by no face (ignored by every solver, reported to the user).
    pub fn unreferenced(&self) -> &[u32] {
        &self.unreferenced
    }

    /// The same mesh at new heights `z` (one per vertex): the plan, and so the connectivity,
    /// is unchanged. Errors as [`Mesh::new`] for heights: [`crate::Error::InvalidArgument`]
    /// for `heights` of the wrong length or beyond ±[`super::MAX_COORDINATE`],
    /// [`crate::Error::NonFiniteCoordinate`] for a NaN or infinite height of a referenced
    /// vertex.
    pub fn with_heights(mut self, heights: &[f64]) -> Result<Mesh> {
        check_heights(heights, &self.referenced)?;
        for (p, &z) in self.positions.iter_mut().zip(heights) {
            p[2] = z;
        }
        Ok(self)
    }
}
