//! Cuts for the multivalued Airy function on domains with holes (docs/method.md §7).
//!
//! Each hole gets a shortest edge path through interior vertices from its loop to the outer
//! loop or to a hole cut before it (the cuts form a tree per component), and the set R_h of
//! faces that touch the path on its right. The faces of R_h see φ + J_h on the path's
//! vertices, which lets the stress carry a net torque (constant part) and a net force (affine
//! part) around the hole while keeping every interior vertex in exact horizontal balance. The
//! jump J_h across a cut is the sum of the jumps around its hole and around every hole cut
//! through it (`AiryOperator::hole_periods`).

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// The cut of one hole: path vertices (hole loop first, the outer loop or an earlier hole's
/// loop last), cut edges and the faces on the right of the path.
#[derive(Debug, Clone)]
pub struct HoleCut {
    /// Index into `mesh.loops` of the hole.
    #[cfg_attr(not(feature = "internals"), allow(dead_code))]
    pub loop_index: usize,
    /// The hole whose loop the path ends on (None: the outer loop).
    pub ends_at_hole: Option<usize>,
    pub path: Vec<u32>,
    pub cut_edges: Vec<u32>,
    /// Sorted face ids of R_h.
    pub right_faces: Vec<u32>,
}

impl HoleCut {
    pub fn is_cut_edge(&self, e: u32) -> bool {
        self.cut_edges.contains(&e)
    }

    pub fn is_right_face(&self, t: u32) -> bool {
        self.right_faces.binary_search(&t).is_ok()
    }

    pub fn on_path(&self, v: u32) -> bool {
        self.path.contains(&v)
    }
}

/// The face containing the directed edge a→b, and its third vertex.
pub fn face_of_directed(mesh: &Mesh, a: u32, b: u32) -> Option<(u32, u32)> {
    let e = &mesh.edges[mesh.edge_between(a, b)?];
    let side = if e.v[0] == a { e.left } else { e.right };
    side.map(|s| (s.face, s.opposite))
}

/// Builds the cut of every hole of `mesh`, in the order of its holes. The cuts form a tree
/// per component, grown from the outer loop: each round joins the hole nearest to the loops
/// already joined by a shortest path through interior vertices (Prim's order). Any cut system
/// that leaves the domain simply connected spans the same multivalued Airy functions; short
/// cuts keep each hole's unknowns coupled to few others in the normal equations.
pub fn cut_holes(mesh: &Mesh) -> Result<Vec<HoleCut>> {
    let n = mesh.positions.len();
    let mut loop_of = vec![usize::MAX; n];
    for (l, lp) in mesh.loops.iter().enumerate() {
        for &v in &lp.vertices {
            loop_of[v as usize] = l;
        }
    }
    let holes: Vec<usize> = mesh.holes().collect();
    let mut hole_of_loop = vec![usize::MAX; mesh.loops.len()];
    for (h, &l) in holes.iter().enumerate() {
        hole_of_loop[l] = h;
    }
    let mut search = Search::new(mesh, loop_of);
    for l in (0..mesh.loops.len()).filter(|&l| mesh.loops[l].is_outer) {
        search.join(l);
    }
    let mut cuts: Vec<Option<HoleCut>> = vec![None; holes.len()];
    for _ in 0..holes.len() {
        // Not expected on a validated mesh (the first boundary vertex on any edge path out of
        // the joined loops is on a loop not yet joined); kept as an error, not a panic.
        let Some(path) = search.nearest_path() else {
            let h = (0..holes.len())
                .find(|&h| cuts[h].is_none())
                .expect("a hole left");
            return Err(Error::HoleNotCuttable {
                hole: h,
                vertex: mesh.loops[holes[h]].vertices[0] as usize,
            });
        };
        let from = search.loop_of[path[0] as usize];
        let to = search.loop_of[*path.last().expect("path") as usize];
        search.join(from);
        let cut_edges: Vec<u32> = path
            .windows(2)
            .map(|w| mesh.edge_between(w[0], w[1]).expect("path edge") as u32)
            .collect();
        let mut right_faces = Vec::new();
        for k in 0..path.len() {
            right_sector(mesh, &path, k, &mut right_faces);
        }
        right_faces.sort_unstable();
        right_faces.dedup();
        cuts[hole_of_loop[from]] = Some(HoleCut {
            loop_index: from,
            ends_at_hole: (!mesh.loops[to].is_outer).then(|| hole_of_loop[to]),
            path,
            cut_edges,
            right_faces,
        });
    }
    Ok(cuts
        .into_iter()
        .map(|c| c.expect("every hole cut"))
        .collect())
}

/// Shortest paths through interior vertices from the joined loops, kept up to date as loops
/// join (each join only revisits the vertices it brings nearer), and the steps from them onto
/// loops not yet joined.
struct Search<'a> {
    mesh: &'a Mesh,
    loop_of: Vec<usize>,
    joined: Vec<bool>,
    /// Edges from the nearest joined loop, and the previous vertex on that path (a joined
    /// loop's vertices are their own).
    distance: Vec<u32>,
    parent: Vec<u32>,
    queue: BinaryHeap<Reverse<(u32, u32)>>,
    /// (path length, vertex of a loop not yet joined, the vertex it steps from).
    steps: BinaryHeap<Reverse<(u32, u32, u32)>>,
}

impl<'a> Search<'a> {
    fn new(mesh: &'a Mesh, loop_of: Vec<usize>) -> Search<'a> {
        let n = mesh.positions.len();
        Search {
            mesh,
            loop_of,
            joined: vec![false; mesh.loops.len()],
            distance: vec![u32::MAX; n],
            parent: vec![u32::MAX; n],
            queue: BinaryHeap::new(),
            steps: BinaryHeap::new(),
        }
    }

    /// Joins loop l and brings the distances up to date (Dijkstra with unit lengths).
    fn join(&mut self, l: usize) {
        self.joined[l] = true;
        for &v in &self.mesh.loops[l].vertices {
            self.distance[v as usize] = 0;
            self.parent[v as usize] = v;
            self.queue.push(Reverse((0, v)));
        }
        while let Some(Reverse((d, v))) = self.queue.pop() {
            if d > self.distance[v as usize] {
                continue;
            }
            for w in self.mesh.neighbours(v) {
                let lw = self.loop_of[w as usize];
                if lw != usize::MAX && !self.joined[lw] {
                    self.steps.push(Reverse((d + 1, w, v)));
                } else if !self.mesh.on_boundary[w as usize] && d + 1 < self.distance[w as usize] {
                    self.distance[w as usize] = d + 1;
                    self.parent[w as usize] = v;
                    self.queue.push(Reverse((d + 1, w)));
                }
            }
        }
    }

    /// The shortest path from a loop not yet joined to a joined one, loop vertices at both
    /// ends and interior vertices between; None when no loop can be reached.
    fn nearest_path(&mut self) -> Option<Vec<u32>> {
        while let Some(Reverse((d, w, v))) = self.steps.pop() {
            // Skip steps onto loops joined since, and those from vertices brought nearer
            // since (their shorter step was queued then).
            if self.joined[self.loop_of[w as usize]] || d != self.distance[v as usize] + 1 {
                continue;
            }
            let mut path = vec![w, v];
            let mut x = v;
            while self.parent[x as usize] != x {
                x = self.parent[x as usize];
                path.push(x);
            }
            return Some(path);
        }
        None
    }
}

/// Adds the faces of path vertex k's fan that lie on the right of the path: counter-clockwise
/// from the incoming path edge (or the start of a boundary fan) to the outgoing one (or the
/// end of the fan).
fn right_sector(mesh: &Mesh, path: &[u32], k: usize, out: &mut Vec<u32>) {
    let v = path[k];
    let next = path.get(k + 1).copied();
    let start = if k > 0 {
        face_of_directed(mesh, v, path[k - 1])
    } else {
        fan_start(mesh, v)
    };
    let mut current = start;
    let mut guard = 0;
    while let Some((t, _)) = current {
        out.push(t);
        let f = mesh.faces[t as usize];
        let i = f.iter().position(|&x| x == v).expect("fan face");
        let y = f[(i + 2) % 3];
        if Some(y) == next {
            return;
        }
        current = face_of_directed(mesh, v, y);
        guard += 1;
        if guard > mesh.faces.len() {
            return;
        }
    }
}

/// The first face of a boundary vertex's fan in counter-clockwise order: the face (v, x, y)
/// whose edge v–x is a boundary edge.
fn fan_start(mesh: &Mesh, v: u32) -> Option<(u32, u32)> {
    mesh.edges_at(v as usize).iter().find_map(|&e| {
        if !mesh.edges[e as usize].is_boundary() {
            return None;
        }
        face_of_directed(mesh, v, mesh.other_end(e as usize, v))
    })
}
