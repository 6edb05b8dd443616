//! The gauge of the Airy function. Affine φ gives q = 0, so φ is pinned to 0 at three
//! vertices of every component (docs/method.md §4). They are spread far apart because pinning
//! one small face leaves a nearly affine φ whose curvature lies about 1/n below the rest, a
//! direction the factorisation of a large normal matrix cannot resolve.

use crate::geometry::Plan;
use crate::mesh::Mesh;
use std::cmp::Reverse;

/// Per vertex, whether φ is pinned to 0 there: three free vertices of every component that
/// are far apart in hops along edges (a choice that depends on the connectivity only, so it
/// stays the same through a form finding), or the vertices of the component's first face
/// with a free vertex where that triangle is no larger in the plan (fewer than three free
/// vertices, or a mesh so thin that they line up; then the plan decides, and smoothing may
/// flip the choice between steps, which only costs the next step its cached structure).
pub fn pinned_vertices(mesh: &Mesh, plan: &Plan) -> Vec<bool> {
    let n = mesh.positions.len();
    let mut free: Vec<Vec<usize>> = vec![Vec::new(); mesh.n_components];
    for v in (0..n).filter(|&v| mesh.is_non_anchored(v)) {
        let component = mesh.vertex_component.get(v).map(|&c| c as usize);
        if let Some(list) = component.and_then(|c| free.get_mut(c)) {
            list.push(v);
        }
    }
    // The fallback: the component's first face with a free vertex (all three of its
    // vertices then enter active rows), or its first face.
    let mut first_face = vec![None; mesh.n_components];
    let has_free = |t: usize| {
        mesh.faces[t]
            .iter()
            .any(|&v| mesh.is_non_anchored(v as usize))
    };
    for (t, &c) in mesh.face_component.iter().enumerate() {
        let slot = &mut first_face[c as usize];
        if slot.is_none_or(|f: usize| !has_free(f) && has_free(t)) {
            *slot = Some(t);
        }
    }
    let mut pinned = vec![false; n];
    let mut hops = Hops::new(mesh, n);
    for (candidates, face) in free.iter().zip(first_face) {
        let Some(face) = face else { continue };
        let face = mesh.faces[face].map(|v| v as usize);
        let chosen = spread(&mut hops, candidates)
            .filter(|far| plan_area(plan, far) > plan_area(plan, &face))
            .unwrap_or(face);
        chosen.iter().for_each(|&v| pinned[v] = true);
    }
    pinned
}

/// Three distinct candidates far apart: the farthest from the first, the farthest from that
/// one, and the one farthest from both.
fn spread(hops: &mut Hops, candidates: &[usize]) -> Option<[usize; 3]> {
    let &start = candidates.first()?;
    // The index of the candidate with the largest key; ties go to the lowest index (the
    // lowest vertex id), so the choice is deterministic.
    let farthest =
        |key: &dyn Fn(usize) -> u32| (0..candidates.len()).max_by_key(|&i| (key(i), Reverse(i)));
    let from_start = hops.from(start, candidates);
    let a = farthest(&|i| from_start[i])?;
    let from_a = hops.from(candidates[a], candidates);
    let b = farthest(&|i| from_a[i])?;
    let from_b = hops.from(candidates[b], candidates);
    let c = farthest(&|i| from_a[i].min(from_b[i]))?;
    (a != b && b != c && c != a).then(|| [a, b, c].map(|i| candidates[i]))
}

fn plan_area(plan: &Plan, v: &[usize; 3]) -> f64 {
    let [a, b, c] = v.map(|v| plan.u[v]);
    ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).abs()
}

/// Breadth-first hop counts along the mesh's edges.
struct Hops<'a> {
    mesh: &'a Mesh,
    /// Per vertex, u32::MAX between searches.
    hops: Vec<u32>,
    queue: Vec<usize>,
}

impl<'a> Hops<'a> {
    fn new(mesh: &'a Mesh, n: usize) -> Hops<'a> {
        Hops {
            mesh,
            hops: vec![u32::MAX; n],
            queue: Vec::new(),
        }
    }

    /// Hops from `source` to each of `targets` (u32::MAX where unreachable). The search
    /// stays in `source`'s component, so a mesh of many components costs O(n) in all.
    fn from(&mut self, source: usize, targets: &[usize]) -> Vec<u32> {
        let mesh = self.mesh;
        self.hops[source] = 0;
        self.queue.clear();
        self.queue.push(source);
        let mut next = 0;
        while let Some(&v) = self.queue.get(next) {
            next += 1;
            for w in mesh.neighbours(v as u32).map(|w| w as usize) {
                if self.hops[w] == u32::MAX {
                    self.hops[w] = self.hops[v] + 1;
                    self.queue.push(w);
                }
            }
        }
        let out = targets.iter().map(|&t| self.hops[t]).collect();
        self.queue.iter().for_each(|&v| self.hops[v] = u32::MAX);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate;
    use crate::geometry::Frame;

    fn pinned(mesh: &Mesh) -> (Vec<usize>, Plan) {
        let plan = Plan::new(mesh, &mesh.positions, &Frame::of(mesh, &mesh.positions));
        let pinned = pinned_vertices(mesh, &plan);
        ((0..pinned.len()).filter(|&v| pinned[v]).collect(), plan)
    }

    #[test]
    fn a_dome_is_pinned_at_three_free_vertices_spanning_its_plan() {
        let mesh = generate::cap_dome(0.8, 2_000).unwrap();
        let (vertices, plan) = pinned(&mesh);
        assert_eq!(vertices.len(), 3);
        assert!(vertices.iter().all(|&v| mesh.is_non_anchored(v)));
        let triangle = plan_area(&plan, &[vertices[0], vertices[1], vertices[2]]) / 2.0;
        let plan_total: f64 = plan.area.iter().sum();
        // Three vertices spread over a disk span about a third of it (the inscribed right
        // isosceles triangle: 1/π); one face spans 1/|F|.
        assert!(triangle > 0.2 * plan_total, "{triangle} of {plan_total}");
    }

    #[test]
    fn the_choice_follows_the_connectivity_not_the_plan() {
        let mesh = generate::cap_dome(0.8, 500).unwrap();
        let (before, _) = pinned(&mesh);
        let first_face: Vec<usize> = mesh.faces[0].iter().map(|&v| v as usize).collect();
        assert_ne!(before, first_face);
        // Warped so that other vertices are farthest apart in the plan and span the largest
        // triangles (the right half squeezed to a fifth, the plan sheared by x): the same
        // vertices.
        let moved: Vec<[f64; 3]> = mesh
            .positions
            .iter()
            .map(|p| {
                let x = if p[0] > 0.0 { 0.2 * p[0] } else { p[0] };
                [x, p[1] * (1.0 + 0.8 * p[0]), p[2]]
            })
            .collect();
        let plan = Plan::new(&mesh, &moved, &Frame::of(&mesh, &moved));
        let after = pinned_vertices(&mesh, &plan);
        assert!(before.iter().all(|&v| after[v]));
    }

    #[test]
    fn every_component_is_pinned_apart() {
        // Two domes side by side, the second's ids after the first's.
        let one = generate::cap_dome(0.8, 300).unwrap();
        let n = one.positions.len() as u32;
        let mut positions = one.positions.clone();
        positions.extend(one.positions.iter().map(|p| [p[0] + 3.0, p[1], p[2]]));
        let mut faces = one.faces.clone();
        faces.extend(one.faces.iter().map(|f| f.map(|v| v + n)));
        let anchored: Vec<u32> = (0..n)
            .filter(|&v| one.anchored[v as usize])
            .flat_map(|v| [v, v + n])
            .collect();
        let two = Mesh::new(positions, faces, &anchored).unwrap();
        assert_eq!(two.n_components, 2);
        let (vertices, _) = pinned(&two);
        let (single, _) = pinned(&one);
        let shifted: Vec<usize> = single.iter().map(|&v| v + n as usize).collect();
        assert_eq!(vertices, [single, shifted].concat());
    }

    #[test]
    fn too_few_free_vertices_fall_back_to_the_first_face_with_one() {
        // A fan of six triangles around one free centre vertex, after a face of three
        // anchored vertices outside its first edge.
        let mut positions = vec![[0.0, 0.0, 1.0]];
        for k in 0..6 {
            let a = k as f64 * std::f64::consts::PI / 3.0;
            positions.push([a.cos(), a.sin(), 0.0]);
        }
        positions.push([1.2, 0.9, 0.0]);
        let mut faces = vec![[2, 1, 7]];
        faces.extend((0..6).map(|k| [0, 1 + k, 1 + (k + 1) % 6]));
        let mesh = Mesh::new(positions, faces, &[1, 2, 3, 4, 5, 6, 7]).unwrap();
        let (vertices, _) = pinned(&mesh);
        assert_eq!(vertices, vec![0, 1, 2]);
    }
}
