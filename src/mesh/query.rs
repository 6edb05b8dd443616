//! Small queries on a validated mesh.

use super::Mesh;
use crate::geometry::Frame;

impl Mesh {
    /// The vertex pairs among `pairs` that are interior edges of this mesh: the polygon
    /// diagonals of a file that welding or a plan repair's flip left in place (for
    /// [`crate::Problem::with_polygon_diagonals`]).
    pub fn interior_edges_among(&self, pairs: impl IntoIterator<Item = [u32; 2]>) -> Vec<[u32; 2]> {
        pairs
            .into_iter()
            .filter(|&[a, b]| {
                (self.edge_between(a, b)).is_some_and(|e| !self.edges[e].is_boundary())
            })
            .collect()
    }

    /// The faces in the orientation they were given ([`Mesh::faces`] are counter-clockwise in
    /// plan, all reversed when the input was clockwise): the faces to write back.
    pub fn input_faces(&self) -> Vec<[u32; 3]> {
        if self.reversed {
            self.faces.iter().map(|&[a, b, c]| [a, c, b]).collect()
        } else {
            self.faces.clone()
        }
    }

    /// L₀, the length unit of relative force-density bounds ([`crate::QBound::Relative`]):
    /// half the plan bounding-box diagonal of the referenced vertices at `positions`.
    pub fn plan_scale(&self, positions: &[[f64; 3]]) -> f64 {
        Frame::of(self, positions).scale
    }

    /// Number of vertices, including unreferenced ones.
    pub fn n_vertices(&self) -> usize {
        self.positions.len()
    }

    /// Number of faces.
    pub fn n_faces(&self) -> usize {
        self.faces.len()
    }

    /// Number of (undirected) edges.
    pub fn n_edges(&self) -> usize {
        self.edges.len()
    }

    /// A referenced boundary vertex that is not anchored (false for out-of-range ids).
    pub fn is_free_boundary(&self, v: usize) -> bool {
        self.is_non_anchored(v) && self.on_boundary.get(v).copied().unwrap_or(false)
    }

    /// A referenced vertex that is not anchored, interior or boundary (false for out-of-range
    /// ids).
    pub fn is_non_anchored(&self, v: usize) -> bool {
        self.referenced.get(v).copied().unwrap_or(false)
            && !self.anchored.get(v).copied().unwrap_or(false)
    }

    /// Indices into `loops` of the holes (loops that are not the outer loop of their component).
    pub fn holes(&self) -> impl Iterator<Item = usize> + '_ {
        self.loops
            .iter()
            .enumerate()
            .filter(|(_, l)| !l.is_outer)
            .map(|(i, _)| i)
    }

    /// The id of the edge joining `a` and `b` (in either order), by binary search.
    pub fn edge_between(&self, a: u32, b: u32) -> Option<usize> {
        let key = [a.min(b), a.max(b)];
        self.edges.binary_search_by(|e| e.v.cmp(&key)).ok()
    }

    /// The end of edge `e` that is not `v` (`v` must be one of its ends).
    pub fn other_end(&self, e: usize, v: u32) -> u32 {
        let [a, b] = self.edges[e].v;
        if a == v {
            b
        } else {
            a
        }
    }

    /// The vertices joined to `v` by an edge, in the order of `edges_at`.
    pub fn neighbours(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        self.edges_at(v as usize)
            .iter()
            .map(move |&e| self.other_end(e as usize, v))
    }

    /// Ids of the edges incident to vertex `v`, in increasing order (empty for out-of-range
    /// or unreferenced vertices).
    pub fn edges_at(&self, v: usize) -> &[u32] {
        let (Some(&s), Some(&e)) = (
            self.vertex_edge_start.get(v),
            self.vertex_edge_start.get(v + 1),
        ) else {
            return &[];
        };
        self.vertex_edges.get(s as usize..e as usize).unwrap_or(&[])
    }
}
