//! The force diagram (Maxwell–Cremona dual): one point per face, the gradient of the Airy
//! function there, which is the power centre of the face's weighted vertices (docs/method.md §5).
//! An interior edge's dual segment joins its two faces' points; its signed length over the
//! plan length is the edge's force density.

use super::{cross, dot, sub, Plan};
use crate::mesh::Mesh;
use crate::stress::airy::AiryOperator;
use std::collections::VecDeque;

/// Force diagram in physical units (force).
#[derive(Debug, Clone, Default)]
#[non_exhaustive]
pub struct ForceDiagram {
    /// One point per face.
    pub centres: Vec<[f64; 2]>,
    /// Per edge: (left face point, right face point) for interior edges, None on the boundary.
    /// Across a hole's cut the right-hand point is shifted by the gradient of the jump there.
    pub segments: Vec<Option<[[f64; 2]; 2]>>,
}

/// Gradient of the linear interpolant of `f` on the triangle `u`.
pub fn gradient(u: [[f64; 2]; 3], f: [f64; 3]) -> [f64; 2] {
    let (d1, d2) = (sub(u[1], u[0]), sub(u[2], u[0]));
    let (f1, f2) = (f[1] - f[0], f[2] - f[0]);
    let det = cross(d1, d2);
    [
        (f1 * d2[1] - d1[1] * f2) / det,
        (d1[0] * f2 - f1 * d2[0]) / det,
    ]
}

/// Power centre of three weighted sites: the point with equal |c − u_a|² − w_a to all three.
#[cfg(any(test, feature = "internals"))]
pub fn power_centre(u: [[f64; 2]; 3], w: [f64; 3]) -> [f64; 2] {
    // 2 c·(u_b − u_a) = |u_b|² − w_b − |u_a|² + w_a for b = 1, 2.
    let rhs = |b: usize| (dot(u[b], u[b]) - w[b] - dot(u[0], u[0]) + w[0]) / 2.0;
    let (d1, d2) = (sub(u[1], u[0]), sub(u[2], u[0]));
    let (r1, r2) = (rhs(1), rhs(2));
    let det = cross(d1, d2);
    [
        (r1 * d2[1] - d1[1] * r2) / det,
        (d1[0] * r2 - r1 * d2[0]) / det,
    ]
}

/// Unit normal of edge e pointing from its left face into its right face.
pub fn edge_normal(mesh: &Mesh, plan: &Plan, e: usize) -> [f64; 2] {
    let [i, j] = mesh.edges[e].v;
    let d = sub(plan.u[j as usize], plan.u[i as usize]);
    let l = plan.length[e];
    [d[1] / l, -d[0] / l]
}

/// Face points (frame units) from Airy values and hole jumps.
pub fn centres_from_airy(
    mesh: &Mesh,
    plan: &Plan,
    op: &AiryOperator,
    phi: &[f64],
    y: &[f64],
) -> Vec<[f64; 2]> {
    mesh.faces
        .iter()
        .enumerate()
        .map(|(t, f)| {
            let vals = f.map(|v| op.face_local_airy(plan, phi, y, t as u32, v));
            gradient(f.map(|v| plan.u[v as usize]), vals)
        })
        .collect()
}

/// Breadth-first order of faces across interior edges, one root per component, with the edge
/// each face was reached through.
fn face_tree(mesh: &Mesh) -> Vec<(u32, Option<usize>)> {
    let mut seen = vec![false; mesh.faces.len()];
    let mut order = Vec::with_capacity(mesh.faces.len());
    for root in 0..mesh.faces.len() {
        if seen[root] {
            continue;
        }
        seen[root] = true;
        let mut queue = VecDeque::from([(root as u32, None)]);
        while let Some((t, via)) = queue.pop_front() {
            order.push((t, via));
            for &e in &mesh.face_edges[t as usize] {
                let edge = &mesh.edges[e as usize];
                for side in [edge.left, edge.right].into_iter().flatten() {
                    if !seen[side.face as usize] {
                        seen[side.face as usize] = true;
                        queue.push_back((side.face, Some(e as usize)));
                    }
                }
            }
        }
    }
    order
}

/// Face points (frame units) propagated from force densities across a spanning tree of faces:
/// the right face's point is the left one's plus q_e l_e n_e. Path-independent where the
/// interior vertices are in horizontal balance (around holes it depends on the tree).
pub fn centres_from_forces(mesh: &Mesh, plan: &Plan, q: &[f64]) -> Vec<[f64; 2]> {
    let mut c = vec![[0.0; 2]; mesh.faces.len()];
    for (t, via) in face_tree(mesh) {
        let Some(e) = via else { continue };
        let edge = &mesh.edges[e];
        let (left, right) = (edge.left.unwrap().face, edge.right.unwrap().face);
        let n = edge_normal(mesh, plan, e);
        let jump = [q[e] * plan.length[e] * n[0], q[e] * plan.length[e] * n[1]];
        if t == right {
            let cl = c[left as usize];
            c[t as usize] = [cl[0] + jump[0], cl[1] + jump[1]];
        } else {
            let cr = c[right as usize];
            c[t as usize] = [cr[0] - jump[0], cr[1] - jump[1]];
        }
    }
    c
}

/// Airy values consistent with face gradients `c`: each face's plane φ = c_t·u + k_t is joined
/// to its tree parent at a shared vertex.
pub fn airy_from_centres(mesh: &Mesh, plan: &Plan, c: &[[f64; 2]]) -> Vec<f64> {
    let mut k = vec![0.0; mesh.faces.len()];
    let mut phi = vec![f64::NAN; mesh.positions.len()];
    for (t, via) in face_tree(mesh) {
        if let Some(e) = via {
            let edge = &mesh.edges[e];
            let parent = [edge.left, edge.right]
                .into_iter()
                .flatten()
                .map(|s| s.face)
                .find(|&f| f != t)
                .unwrap();
            let v = plan.u[edge.v[0] as usize];
            let value = dot(c[parent as usize], v) + k[parent as usize];
            k[t as usize] = value - dot(c[t as usize], v);
        }
        for v in mesh.faces[t as usize] {
            if phi[v as usize].is_nan() {
                phi[v as usize] = dot(c[t as usize], plan.u[v as usize]) + k[t as usize];
            }
        }
    }
    phi.iter()
        .map(|x| if x.is_nan() { 0.0 } else { *x })
        .collect()
}

/// The force diagram in physical units (frame points × p̄).
pub fn diagram(
    mesh: &Mesh,
    centres: &[[f64; 2]],
    op: Option<&AiryOperator>,
    y: &[f64],
    p_bar: f64,
) -> ForceDiagram {
    let scaled = |c: [f64; 2]| [c[0] * p_bar, c[1] * p_bar];
    let segments = mesh
        .edges
        .iter()
        .enumerate()
        .map(|(e, edge)| {
            let (l, r) = (edge.left?, edge.right?);
            let mut ends = [centres[l.face as usize], centres[r.face as usize]];
            let Some(op) = op else {
                return Some(ends.map(scaled));
            };
            // A cut edge has its right face in the cut's R_h: only the cuts beside its two
            // faces can cut it (in increasing order, each once).
            let (at_l, at_r) = (op.cuts_at_face(l.face), op.cuts_at_face(r.face));
            if at_l.is_empty() && at_r.is_empty() {
                return Some(ends.map(scaled));
            }
            let mut beside = [at_l, at_r].concat();
            beside.sort_unstable();
            beside.dedup();
            for h in beside {
                let cut = &op.cuts[h];
                if cut.is_cut_edge(e as u32) {
                    let m = op.hole_jump(y, h);
                    for (k, side) in [l, r].iter().enumerate() {
                        if cut.is_right_face(side.face) {
                            ends[k] = [ends[k][0] - m[1], ends[k][1] - m[2]];
                        }
                    }
                }
            }
            Some(ends.map(scaled))
        })
        .collect();
    ForceDiagram {
        centres: centres.iter().map(|&c| scaled(c)).collect(),
        segments,
    }
}
