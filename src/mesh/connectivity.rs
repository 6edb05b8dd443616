//! Connectivity building blocks: sorted half-edges, union-find, edges with their sides,
//! connected components and boundary loops. Plan coordinates are only used for loop areas.

use super::{BoundaryLoop, Edge, Side};

/// The directed edge `faces[face][corner] → faces[face][(corner + 1) % 3]`, keyed by its
/// undirected vertex pair `lo < hi`; `forward` is true when it runs lo → hi.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(super) struct HalfEdge {
    pub lo: u32,
    pub hi: u32,
    pub face: u32,
    pub corner: u8,
    pub forward: bool,
}

impl HalfEdge {
    pub fn same_edge(a: &HalfEdge, b: &HalfEdge) -> bool {
        a.lo == b.lo && a.hi == b.hi
    }
}

/// All half-edges, sorted by (lo, hi, face): those of one undirected edge are contiguous.
pub(super) fn half_edges(faces: &[[u32; 3]]) -> Vec<HalfEdge> {
    let mut halves = Vec::with_capacity(3 * faces.len());
    for (t, f) in faces.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            halves.push(HalfEdge {
                lo: a.min(b),
                hi: a.max(b),
                face: t as u32,
                corner: k as u8,
                forward: a < b,
            });
        }
    }
    halves.sort_unstable();
    halves
}

/// Edges sorted by (v0, v1) with their left / right sides, and the edge ids of each face.
/// Expects a manifold, consistently oriented mesh (at most one half-edge per direction).
pub(super) fn build_edges(faces: &[[u32; 3]], halves: &[HalfEdge]) -> (Vec<Edge>, Vec<[u32; 3]>) {
    let mut edges = Vec::with_capacity(halves.len() / 2 + 1);
    let mut face_edges = vec![[0u32; 3]; faces.len()];
    for group in halves.chunk_by(HalfEdge::same_edge) {
        let id = edges.len() as u32;
        let mut edge = Edge {
            v: [group[0].lo, group[0].hi],
            left: None,
            right: None,
        };
        for h in group {
            let t = h.face as usize;
            let k = h.corner as usize;
            let (Some(f), Some(fe)) = (faces.get(t), face_edges.get_mut(t)) else {
                continue;
            };
            let side = Side {
                face: h.face,
                opposite: f[(k + 2) % 3],
            };
            if h.forward {
                edge.left = Some(side);
            } else {
                edge.right = Some(side);
            }
            fe[k % 3] = id;
        }
        edges.push(edge);
    }
    (edges, face_edges)
}

/// Disjoint sets with path halving and union by size.
pub(super) struct UnionFind {
    parent: Vec<usize>,
    size: Vec<usize>,
}

impl UnionFind {
    pub fn new(n: usize) -> Self {
        UnionFind {
            parent: (0..n).collect(),
            size: vec![1; n],
        }
    }

    pub fn find(&mut self, mut x: usize) -> usize {
        while self.parent[x] != x {
            self.parent[x] = self.parent[self.parent[x]];
            x = self.parent[x];
        }
        x
    }

    pub fn union(&mut self, a: usize, b: usize) {
        let (mut a, mut b) = (self.find(a), self.find(b));
        if a == b {
            return;
        }
        if self.size[a] < self.size[b] {
            std::mem::swap(&mut a, &mut b);
        }
        self.parent[b] = a;
        self.size[a] += self.size[b];
    }
}

/// Connected components through faces: per vertex (`u32::MAX` if unreferenced) and their
/// number. Components are numbered in order of their smallest vertex id.
pub(super) fn components(faces: &[[u32; 3]], referenced: &[bool]) -> (Vec<u32>, usize) {
    let n = referenced.len();
    let mut sets = UnionFind::new(n);
    for f in faces {
        sets.union(f[0] as usize, f[1] as usize);
        sets.union(f[0] as usize, f[2] as usize);
    }
    let mut number_of_root = vec![u32::MAX; n];
    let mut vertex_component = vec![u32::MAX; n];
    let mut count = 0usize;
    for v in (0..n).filter(|&v| referenced[v]) {
        let root = sets.find(v);
        if number_of_root[root] == u32::MAX {
            number_of_root[root] = count as u32;
            count += 1;
        }
        vertex_component[v] = number_of_root[root];
    }
    (vertex_component, count)
}

/// Boundary loops, each followed with the surface on its left (a boundary edge runs in the
/// direction it has in its face), starting at its smallest vertex id; loops are listed in
/// order of that vertex. Per component, the loop of largest |signed area| is the outer one.
pub(super) fn boundary_loops(
    positions: &[[f64; 3]],
    edges: &[Edge],
    on_boundary: &[bool],
    vertex_component: &[u32],
    n_components: usize,
) -> Vec<BoundaryLoop> {
    let n = positions.len();
    let mut next = vec![u32::MAX; n];
    for e in edges.iter().filter(|e| e.is_boundary()) {
        let (from, to) = if e.left.is_some() {
            (e.v[0], e.v[1])
        } else {
            (e.v[1], e.v[0])
        };
        next[from as usize] = to;
    }
    let mut visited = vec![false; n];
    let mut loops = Vec::new();
    for start in 0..n {
        if !on_boundary[start] || visited[start] {
            continue;
        }
        let mut vertices = Vec::new();
        let mut cur = start;
        loop {
            visited[cur] = true;
            vertices.push(cur as u32);
            match next.get(cur) {
                Some(&nx) if (nx as usize) < n && !visited[nx as usize] => cur = nx as usize,
                _ => break,
            }
        }
        loops.push(BoundaryLoop {
            signed_area: shoelace(positions, &vertices),
            component: vertex_component[start],
            vertices,
            is_outer: false,
        });
    }
    let mut outer: Vec<Option<usize>> = vec![None; n_components];
    for (i, l) in loops.iter().enumerate() {
        if let Some(slot) = outer.get_mut(l.component as usize) {
            if slot.is_none_or(|j| l.signed_area.abs() > loops[j].signed_area.abs()) {
                *slot = Some(i);
            }
        }
    }
    for i in outer.into_iter().flatten() {
        loops[i].is_outer = true;
    }
    loops
}

/// Signed plan area of a closed polygon (positive counter-clockwise), relative to its first
/// vertex for accuracy far from the origin.
fn shoelace(positions: &[[f64; 3]], vertices: &[u32]) -> f64 {
    let Some(&first) = vertices.first() else {
        return 0.0;
    };
    let o = positions[first as usize];
    let mut twice = 0.0;
    for (i, &a) in vertices.iter().enumerate() {
        let b = vertices[(i + 1) % vertices.len()];
        let (p, q) = (positions[a as usize], positions[b as usize]);
        twice += (p[0] - o[0]) * (q[1] - o[1]) - (q[0] - o[0]) * (p[1] - o[1]);
    }
    0.5 * twice
}
