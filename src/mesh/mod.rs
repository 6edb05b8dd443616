//! Connectivity and validation of the input triangle mesh.
//!
//! `Mesh::new` takes raw positions, triangles and anchored ids, validates them in a fixed
//! order (sizes, indices, finiteness, face-local checks, manifoldness, orientation, plan
//! validity, supports) and derives everything the solvers need: oriented faces, edges with
//! their adjacent faces, boundary loops, holes and connected components.

mod access;
mod build;
mod connectivity;
mod overlap;
mod query;
pub mod repair;
pub use build::{MAX_COORDINATE, MIN_PLAN_EXTENT};

#[cfg(test)]
mod repair_tests;
#[cfg(test)]
mod tests;

/// A face adjacent to an edge, and the vertex of that face opposite the edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Side {
    /// The face.
    pub face: u32,
    /// Its vertex opposite the edge.
    pub opposite: u32,
}

/// An undirected edge `v[0]` < `v[1]`. `left` is the face that contains the directed edge
/// `v[0]`→`v[1]` (its opposite vertex lies to the left of `v[0]`→`v[1]` in the counter-clockwise
/// plan), `right` the face that contains `v[1]`→`v[0]`. A boundary edge has exactly one side.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Edge {
    /// The two vertices, smaller id first.
    pub v: [u32; 2],
    /// The face with the directed edge `v[0]`→`v[1]`.
    pub left: Option<Side>,
    /// The face with the directed edge `v[1]`→`v[0]`.
    pub right: Option<Side>,
}

impl Edge {
    /// Whether the edge has one side only.
    pub fn is_boundary(&self) -> bool {
        self.left.is_none() || self.right.is_none()
    }
}

/// A closed boundary loop, its vertices in order with the surface on the left.
#[derive(Debug, Clone, PartialEq)]
pub struct BoundaryLoop {
    /// The loop's vertices, in order, the surface on their left.
    pub vertices: Vec<u32>,
    /// Connected component the loop belongs to.
    pub component: u32,
    /// Signed plan area enclosed (positive for the outer loop of a component).
    pub signed_area: f64,
    /// True for the loop of largest |area| of its component; the others are holes.
    pub is_outer: bool,
}

/// A validated triangle mesh: plan (x, y), heights z, supports and derived connectivity.
///
/// Built by [`Mesh::new`] (or read by [`crate::io::read_model`]) and read through its
/// accessors; [`Mesh::with_heights`] changes the heights, which the plan's connectivity does
/// not depend on. Nothing else changes a mesh once validated.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct Mesh {
    /// Vertex positions as given (x, y plan; z height). Length n_vertices.
    pub(crate) positions: Vec<[f64; 3]>,
    /// Faces, counter-clockwise in plan (all reversed if the input was clockwise).
    pub(crate) faces: Vec<[u32; 3]>,
    /// True when the input faces were clockwise in plan and have been reversed.
    pub(crate) reversed: bool,
    /// All edges, sorted by (`v[0]`, `v[1]`).
    pub(crate) edges: Vec<Edge>,
    /// For face t, the edge ids of (`f[0]`,`f[1]`), (`f[1]`,`f[2]`), (`f[2]`,`f[0]`).
    pub(crate) face_edges: Vec<[u32; 3]>,
    /// CSR vertex → incident edge ids: `vertex_edges[vertex_edge_start[v]..vertex_edge_start[v+1]]`.
    pub(crate) vertex_edge_start: Vec<u32>,
    /// The incident edge ids of every vertex, concatenated (see `vertex_edge_start`).
    pub(crate) vertex_edges: Vec<u32>,
    /// Anchored (support) flag per vertex.
    pub(crate) anchored: Vec<bool>,
    /// Vertex lies on a boundary loop.
    pub(crate) on_boundary: Vec<bool>,
    /// Vertex referenced by at least one face. Unreferenced vertices are ignored.
    pub(crate) referenced: Vec<bool>,
    /// Connected component per vertex (u32::MAX for unreferenced vertices) and per face.
    pub(crate) vertex_component: Vec<u32>,
    /// Connected component per face.
    pub(crate) face_component: Vec<u32>,
    /// The number of connected components.
    pub(crate) n_components: usize,
    /// Boundary loops of all components; holes are the loops with `is_outer == false`.
    pub(crate) loops: Vec<BoundaryLoop>,
    /// Ids of vertices referenced by no face (ignored by every solver, reported to the user).
    pub(crate) unreferenced: Vec<u32>,
}
