//! Optimal Delaunay Triangulation smoothing of the plan on the 3-D surface (docs/method.md §12).
//!
//! Each movable vertex goes towards x* = Σ_t |t| c_t / Σ_t |t| (c_t the circumcentre and |t|
//! the area of the 3-D triangle), one vertex at a time; its height is resampled from the
//! surface as it was before the sweep. A move that would flip a plan triangle or leave the
//! vertex's old fan is halved, up to six times, then abandoned: a plan triangle never flips.
//! A sweep is kept only if it raises the plan's [`quality`]; the first that does not ends
//! the smoothing ([`Odt`]), so any number of sweeps leaves the plan at least as good as
//! fewer would.

use crate::geometry::{cross, sub};
use crate::mesh::Mesh;

fn sub3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot3(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Circumcentre and area of the 3-D triangle (a, b, c).
pub fn circumcentre(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> ([f64; 3], f64) {
    let (ab, ac) = (sub3(b, a), sub3(c, a));
    let n = cross3(ab, ac);
    let n2 = dot3(n, n);
    let t1 = cross3(n, ab);
    let t2 = cross3(ac, n);
    let (s1, s2) = (dot3(ac, ac), dot3(ab, ab));
    let o = [0, 1, 2].map(|d| a[d] + (s1 * t1[d] + s2 * t2[d]) / (2.0 * n2));
    (o, n2.sqrt() / 2.0)
}

fn plan(p: [f64; 3]) -> [f64; 2] {
    [p[0], p[1]]
}

/// Barycentric height of plan point `u` in triangle `t` of `positions`, if `u` lies inside.
fn height_in(positions: &[[f64; 3]], f: [u32; 3], u: [f64; 2]) -> Option<f64> {
    let [a, b, c] = f.map(|v| positions[v as usize]);
    let area = cross(sub(plan(b), plan(a)), sub(plan(c), plan(a)));
    let la = cross(sub(plan(b), u), sub(plan(c), u)) / area;
    let lb = cross(sub(plan(c), u), sub(plan(a), u)) / area;
    let lc = 1.0 - la - lb;
    let tol = -1e-12;
    (la >= tol && lb >= tol && lc >= tol).then(|| la * a[2] + lb * b[2] + lc * c[2])
}

/// The harmonic mean over the plan triangles of their quality 4√3·area / (sum of the squared
/// edge lengths): 1 when every triangle is equilateral, towards 0 as any one becomes a sliver
/// (the harmonic mean is dominated by the worst triangles).
pub fn quality(mesh: &Mesh, positions: &[[f64; 3]]) -> f64 {
    let inverse: f64 = (mesh.faces.iter())
        .map(|f| {
            let [a, b, c] = f.map(|v| plan(positions[v as usize]));
            let twice_area = cross(sub(b, a), sub(c, a));
            let squares: f64 = [sub(b, a), sub(c, b), sub(a, c)]
                .iter()
                .map(|d| d[0] * d[0] + d[1] * d[1])
                .sum();
            squares / (2.0 * 3f64.sqrt() * twice_area.max(0.0))
        })
        .sum();
    mesh.faces.len() as f64 / inverse
}

/// ODT smoothing in sweeps that each must raise the plan's [`quality`]: the first sweep that
/// does not is undone and ends the smoothing.
pub struct Odt {
    fans: Vec<Vec<u32>>,
    quality: f64,
    move_free_boundary: bool,
    done: bool,
}

impl Odt {
    pub fn new(mesh: &Mesh, positions: &[[f64; 3]], move_free_boundary: bool) -> Odt {
        Odt {
            fans: vertex_faces(mesh),
            quality: quality(mesh, positions),
            move_free_boundary,
            done: false,
        }
    }

    /// One sweep of `positions`, kept if it raises the plan's quality (true); otherwise
    /// `positions` are left as they were and every later call does nothing (false).
    pub fn sweep(&mut self, mesh: &Mesh, positions: &mut [[f64; 3]]) -> bool {
        if self.done {
            return false;
        }
        let mut trial = positions.to_vec();
        odt_sweep(mesh, &self.fans, &mut trial, self.move_free_boundary);
        let q = quality(mesh, &trial);
        if q > self.quality {
            self.quality = q;
            positions.copy_from_slice(&trial);
        } else {
            self.done = true;
        }
        !self.done
    }
}

/// Faces around each vertex.
pub fn vertex_faces(mesh: &Mesh) -> Vec<Vec<u32>> {
    let mut fans = vec![Vec::new(); mesh.positions.len()];
    for (t, f) in mesh.faces.iter().enumerate() {
        f.iter().for_each(|&v| fans[v as usize].push(t as u32));
    }
    fans
}

/// One ODT sweep over the non-anchored vertices (interior ones, and free boundary ones when
/// `move_free_boundary`). Returns the number of vertices moved.
pub fn odt_sweep(
    mesh: &Mesh,
    fans: &[Vec<u32>],
    positions: &mut [[f64; 3]],
    move_free_boundary: bool,
) -> usize {
    let before = positions.to_vec();
    let mut moved = 0;
    for v in 0..positions.len() {
        if !mesh.is_non_anchored(v) || (mesh.on_boundary[v] && !move_free_boundary) {
            continue;
        }
        let (mut acc, mut weight) = ([0.0; 2], 0.0);
        for &t in &fans[v] {
            let [a, b, c] = mesh.faces[t as usize].map(|x| positions[x as usize]);
            let (o, area) = circumcentre(a, b, c);
            acc = [acc[0] + area * o[0], acc[1] + area * o[1]];
            weight += area;
        }
        if weight <= 0.0 {
            continue;
        }
        let old = plan(positions[v]);
        let target = [acc[0] / weight, acc[1] / weight];
        let mut step = 1.0;
        for _ in 0..7 {
            let u = [
                old[0] + step * (target[0] - old[0]),
                old[1] + step * (target[1] - old[1]),
            ];
            let z = fans[v]
                .iter()
                .find_map(|&t| height_in(&before, mesh.faces[t as usize], u));
            let keeps_orientation = fans[v].iter().all(|&t| {
                let [a, b, c] = mesh.faces[t as usize].map(|x| {
                    if x as usize == v {
                        u
                    } else {
                        plan(positions[x as usize])
                    }
                });
                cross(sub(b, a), sub(c, a)) > 0.0
            });
            if let (Some(z), true) = (z, keeps_orientation) {
                positions[v] = [u[0], u[1], z];
                moved += 1;
                break;
            }
            step *= 0.5;
        }
    }
    moved
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn circumcentre_is_equidistant_and_in_plane() {
        let (a, b, c) = ([0.1, 0.2, 0.3], [1.3, -0.2, 0.7], [0.4, 0.9, -0.5]);
        let (o, area) = circumcentre(a, b, c);
        let d = |p: [f64; 3]| dot3(sub3(o, p), sub3(o, p)).sqrt();
        assert!((d(a) - d(b)).abs() < 1e-12 && (d(a) - d(c)).abs() < 1e-12);
        let n = cross3(sub3(b, a), sub3(c, a));
        assert!(dot3(n, sub3(o, a)).abs() < 1e-12);
        assert!((area - dot3(n, n).sqrt() / 2.0).abs() < 1e-15);
    }
}
