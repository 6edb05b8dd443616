//! Shared helpers of the integration tests: a small deterministic RNG, generated meshes and the
//! path to the shared real models.
#![allow(dead_code)]

pub mod assess;
mod models;
#[allow(unused_imports)] // each test binary uses its own part
pub use models::{central_vertex, find_models, models_dir, models_required, read_shared, MODELS};
use voussoir::generate::{self, Domain};
use voussoir::Mesh;

/// xorshift64*: deterministic, bounded floats only (no NaN or inf by construction).
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

pub fn load_model(name: &str) -> Option<Mesh> {
    let dir = models_dir()?;
    Some(
        models::read_shared(&dir, name)
            .unwrap_or_else(|e| panic!("{name}: {e}"))
            .mesh,
    )
}

/// A latitude-longitude dome in quads, as a modeller builds one, as OBJ text: a centre
/// vertex (a fan of triangles around it) and `rings` rings of `sectors` vertices joined by
/// quads, every ring's quads split along the same diagonal by a fan split. With it the
/// 0-based ids of the outer ring.
pub fn quad_dome_obj(rings: usize, sectors: usize) -> (String, Vec<u32>) {
    let mut obj = String::from("v 0 0 0.6\n");
    for r in 1..=rings {
        for s in 0..sectors {
            let a = std::f64::consts::TAU * s as f64 / sectors as f64;
            let rr = r as f64 / rings as f64;
            obj += &format!("v {} {} {}\n", rr * a.cos(), rr * a.sin(), 0.6 * (1.0 - rr));
        }
    }
    let id = |r: usize, s: usize| 2 + (r - 1) * sectors + s % sectors;
    for s in 0..sectors {
        obj += &format!("f 1 {} {}\n", id(1, s), id(1, s + 1));
    }
    for r in 1..rings {
        for s in 0..sectors {
            let quad = [id(r, s), id(r + 1, s), id(r + 1, s + 1), id(r, s + 1)];
            obj += &format!("f {} {} {} {}\n", quad[0], quad[1], quad[2], quad[3]);
        }
    }
    let rim = (0..sectors).map(|s| id(rings, s) as u32 - 1).collect();
    (obj, rim)
}

/// A spherical cap of rim angle `angle` on the structured polar disk, rim anchored.
pub fn polar_cap(rings: usize, angle: f64) -> Mesh {
    let (p, t) = generate::polar_disk(rings);
    generate::lift(
        &p,
        &t,
        |u| generate::spherical_cap(1.0, angle, u[0].hypot(u[1])),
        |_, outer| outer,
    )
    .unwrap()
}

/// A unit disk meshed by spade with an off-centre hole of radius 0.25, heights of a 40° cap
/// plus a random bump; `anchor` decides the supports from (plan point, on outer boundary).
pub fn holed_disk(seed: u64, max_area: f64, anchor: impl Fn([f64; 2], bool) -> bool) -> Mesh {
    let mut rng = Rng::new(seed);
    let (a, b) = (rng.uniform(0.5, 2.0), rng.uniform(0.0, 6.0));
    let domain = Domain {
        outer: generate::circle([0.0, 0.0], 1.0, 48),
        holes: vec![generate::circle([0.3, 0.1], 0.25, 16)],
    };
    let (p, t) = generate::triangulate(&domain, max_area).unwrap();
    generate::lift(
        &p,
        &t,
        |u| {
            generate::spherical_cap(1.0, 0.7, u[0].hypot(u[1])) + 0.03 * (a * u[0] + b).sin() * u[1]
        },
        anchor,
    )
    .unwrap()
}

/// Moves every interior vertex of `mesh` by up to `amount` × (shortest incident edge) in plan,
/// keeping the plan valid (Mesh::new validates), so the mesh is no longer Delaunay.
pub fn jiggle(mesh: &Mesh, seed: u64, amount: f64) -> Mesh {
    let mut rng = Rng::new(seed);
    let mut pos = mesh.positions().to_vec();
    for (v, p) in pos.iter_mut().enumerate() {
        if mesh.on_boundary()[v] || !mesh.referenced()[v] {
            continue;
        }
        let h = mesh
            .edges_at(v)
            .iter()
            .map(|&e| {
                let [a, b] = mesh.edges()[e as usize]
                    .v
                    .map(|x| mesh.positions()[x as usize]);
                (a[0] - b[0]).hypot(a[1] - b[1])
            })
            .fold(f64::INFINITY, f64::min);
        p[0] += amount * h * rng.uniform(-1.0, 1.0);
        p[1] += amount * h * rng.uniform(-1.0, 1.0);
    }
    let anchored: Vec<u32> = (0..pos.len() as u32)
        .filter(|&v| mesh.anchored()[v as usize])
        .collect();
    Mesh::new(pos, mesh.faces().to_vec(), &anchored).expect("jiggled mesh stays valid")
}

/// ε∞ of a form-finding result recomputed here from its positions and force densities: loads
/// a third of each 3-D triangle's area (the default load rule, unit density), vertical
/// residuals Σ_j q_ij (z_i − z_j) − p_i at the non-anchored vertices, over their mean load.
pub fn recomputed_eps_inf(mesh: &Mesh, r: &voussoir::FormFindResult) -> f64 {
    let n = mesh.positions().len();
    let mut load = vec![0.0; n];
    for f in mesh.faces() {
        let [a, b, c] = f.map(|v| r.positions[v as usize]);
        let (u, w) = (
            [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
            [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
        );
        let cross = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        let area = (cross[0].powi(2) + cross[1].powi(2) + cross[2].powi(2)).sqrt() / 2.0;
        f.iter().for_each(|&v| load[v as usize] += area / 3.0);
    }
    let mut residual = vec![0.0; n];
    for (edge, q) in mesh.edges().iter().zip(&r.stress.force_densities) {
        let [i, j] = edge.v.map(|v| v as usize);
        let dz = r.positions[i][2] - r.positions[j][2];
        (residual[i], residual[j]) = (residual[i] + q * dz, residual[j] - q * dz);
    }
    let free: Vec<usize> = (0..n).filter(|&v| mesh.is_non_anchored(v)).collect();
    let p_bar = free.iter().map(|&v| load[v]).sum::<f64>() / free.len() as f64;
    free.iter()
        .map(|&v| (residual[v] - load[v]).abs())
        .fold(0.0, f64::max)
        / p_bar
}

/// The plan bounding-box diagonal of the referenced vertices of `mesh`.
pub fn plan_diagonal(mesh: &Mesh) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for (p, _) in (mesh.positions().iter().zip(mesh.referenced())).filter(|(_, r)| **r) {
        for d in 0..2 {
            (lo[d], hi[d]) = (lo[d].min(p[d]), hi[d].max(p[d]));
        }
    }
    (hi[0] - lo[0]).hypot(hi[1] - lo[1])
}

/// The largest height change between `mesh` and `positions` over the plan diagonal, measured
/// here.
pub fn largest_change(mesh: &Mesh, positions: &[[f64; 3]]) -> f64 {
    let diagonal = plan_diagonal(mesh);
    (mesh.positions().iter().zip(positions))
        .map(|(a, b)| (a[2] - b[2]).abs() / diagonal)
        .fold(0.0, f64::max)
}
