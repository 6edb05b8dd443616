//! Plan geometry (cotangents, areas, lengths) in a nondimensional frame, and vertical loads.
//!
//! Everything the solvers see is expressed in the frame u' = (u − centre)/L₀, z' = z/L₀ with
//! L₀ half the plan bounding-box diagonal (docs/method.md §1), so conditioning does not depend
//! on units.

pub mod distance;
pub mod dual;
pub mod loads;

use crate::mesh::Mesh;

/// The nondimensional frame: centre of the plan bounding box and L₀.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Centre of the plan bounding box.
    pub centre: [f64; 2],
    /// L₀: half the plan bounding-box diagonal (1 for a plan of no extent).
    pub scale: f64,
}

impl Frame {
    /// The frame of the referenced vertices' plan bounding box.
    pub fn of(mesh: &Mesh, positions: &[[f64; 3]]) -> Frame {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for (p, _) in positions.iter().zip(&mesh.referenced).filter(|(_, r)| **r) {
            for d in 0..2 {
                lo[d] = lo[d].min(p[d]);
                hi[d] = hi[d].max(p[d]);
            }
        }
        let diag = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2)).sqrt();
        Frame {
            centre: [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0],
            scale: if diag > 0.0 { diag / 2.0 } else { 1.0 },
        }
    }

    /// The plan position of `p` in the frame: (u − centre) / L₀.
    pub fn to_local(self, p: &[f64; 3]) -> [f64; 2] {
        [
            (p[0] - self.centre[0]) / self.scale,
            (p[1] - self.centre[1]) / self.scale,
        ]
    }
}

/// The mean of `reference` heights where it lies far from the heights `all` span (beyond a
/// thousand times their range: a model lifted by 10⁷, say), else 0: the base that solvers
/// subtract from heights so that their differences keep their digits, while ordinary models
/// keep the arithmetic they always had.
pub(crate) fn far_base(reference: &[f64], all: &[f64]) -> f64 {
    let finite = |h: &&f64| h.is_finite();
    let (lo, hi) = (all.iter().filter(finite))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &z| {
            (l.min(z), h.max(z))
        });
    let count = reference.iter().filter(finite).count();
    if count == 0 || lo > hi {
        return 0.0;
    }
    let mean = reference.iter().filter(finite).sum::<f64>() / count as f64;
    if mean.abs() > 1e3 * (hi - lo) {
        mean
    } else {
        0.0
    }
}

/// Per-face plan areas and corner cotangents, per-edge plan lengths, in frame coordinates.
#[derive(Debug, Clone)]
pub struct Plan {
    /// Plan positions u' of every vertex (unreferenced ones included, unused).
    pub u: Vec<[f64; 2]>,
    /// Plan area A_t (> 0 for a validated mesh).
    pub area: Vec<f64>,
    /// cot θ at the three corners of each face, in the face's vertex order.
    pub cot: Vec<[f64; 3]>,
    /// Plan length of each edge.
    pub length: Vec<f64>,
}

pub fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

pub fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

pub fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

impl Plan {
    /// The plan of `positions` in `frame`.
    pub fn new(mesh: &Mesh, positions: &[[f64; 3]], frame: &Frame) -> Plan {
        let u: Vec<[f64; 2]> = positions.iter().map(|p| frame.to_local(p)).collect();
        let mut area = Vec::with_capacity(mesh.faces.len());
        let mut cot = Vec::with_capacity(mesh.faces.len());
        for f in &mesh.faces {
            let [a, b, c] = f.map(|i| u[i as usize]);
            let twice_area = cross(sub(b, a), sub(c, a));
            area.push(twice_area / 2.0);
            cot.push([
                dot(sub(b, a), sub(c, a)) / twice_area,
                dot(sub(c, b), sub(a, b)) / twice_area,
                dot(sub(a, c), sub(b, c)) / twice_area,
            ]);
        }
        let length = mesh
            .edges
            .iter()
            .map(|e| {
                let d = sub(u[e.v[1] as usize], u[e.v[0] as usize]);
                dot(d, d).sqrt()
            })
            .collect();
        Plan {
            u,
            area,
            cot,
            length,
        }
    }

    /// cot θ at vertex `v` of face `t` (v must be a corner of t).
    pub fn cot_at(&self, mesh: &Mesh, t: u32, v: u32) -> f64 {
        let f = mesh.faces[t as usize];
        let k = f.iter().position(|&x| x == v).expect("vertex of face");
        self.cot[t as usize][k]
    }
}
