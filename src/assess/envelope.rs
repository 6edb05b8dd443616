//! The masonry's envelope over the plan: per vertex the intrados (lower) and extrados (upper)
//! heights on the vertical through the vertex, the middle surface, and the thickness whose
//! weight loads the vault (docs/method.md §16.1).

use crate::mesh::Mesh;
use crate::solid::Thickness;
use crate::{Error, Result};

/// Vertical bounds of the masonry at each vertex of a mesh's plan.
///
/// Build it from a thickness about the mesh as middle surface ([`Envelope::from_thickness`])
/// or from intrados and extrados surfaces ([`Envelope::from_surfaces`]). Unreferenced
/// vertices get zeros.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Envelope {
    /// Height of the middle surface, (lower + upper) / 2.
    pub middle: Vec<f64>,
    /// Intrados height per vertex.
    pub lower: Vec<f64>,
    /// Extrados height per vertex.
    pub upper: Vec<f64>,
    /// Thickness per face measured along the middle surface's normal: its weight is the load.
    pub face_thickness: Vec<f64>,
    /// Height of the springing plane per vertex, read at free supports (docs/method.md
    /// §16.1): the reaction's line of action, followed down from the support to this plane,
    /// must meet it within `reach` of the support's plan point, and the support lies on or
    /// above it. Default: `lower`, the bottom of the masonry on the support's vertical
    /// (from a thickness: the middle surface's height).
    pub springing: Vec<f64>,
    /// Horizontal reach of the springing joint per vertex (half its width), read at free
    /// supports; `f64::INFINITY` leaves the support's height bounded by the envelope alone
    /// (the vertical reading). Default: half the vertex's thickness (the area-weighted mean
    /// of its faces' `face_thickness`; from a thickness: the slab's horizontal section,
    /// t / (2 |n_h|)).
    pub reach: Vec<f64>,
}

impl Envelope {
    /// The mesh is the middle surface; the masonry extends `t/2` to either side along the
    /// unit vertex normal n (the area-weighted mean of the faces' normals). Read vertically
    /// through the vertex by the offset's tangent plane, that is `t / (2 n_z)` above and below
    /// the vertex. A per-face thickness gives each vertex the area-weighted mean of its faces'.
    /// The springing joint of a support (read at free supports, docs/method.md §16.1) is the
    /// horizontal section of that slab through the mesh's vertex: the plane at the vertex's
    /// height, reach `t / (2 |n_h|)` (n_h the normal's plan part; infinite where it is 0).
    ///
    /// Errors name the face with a thickness that is not finite and > 0, and the vertex
    /// where the surface is vertical or overhangs (n_z ≤ 1e-6), where a normal thickness has
    /// no vertical reading (give intrados and extrados there instead).
    pub fn from_thickness(mesh: &Mesh, thickness: &Thickness) -> Result<Envelope> {
        let face_thickness = thickness.per_face(mesh.n_faces())?;
        let vertex_thickness = area_mean(mesh, &mesh.positions, &face_thickness);
        let normals = vertex_normals(mesh, &mesh.positions);
        let n = mesh.positions.len();
        let (mut lower, mut upper, mut middle) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let mut reach = vec![0.0; n];
        for v in (0..n).filter(|&v| mesh.referenced[v]) {
            let nz = normals[v][2];
            if nz.is_nan() || nz <= MIN_NORMAL_Z {
                return Err(Error::InvalidArgument {
                    name: "thickness",
                    reason: format!(
                        "vertex {v}: the middle surface is vertical or overhangs there (normal \
                         z-component {nz:.3e}), so a thickness along the normal has no vertical \
                         reading; give intrados and extrados surfaces instead"
                    ),
                });
            }
            let half = vertex_thickness[v] / (2.0 * nz);
            let z = mesh.positions[v][2];
            (lower[v], upper[v], middle[v]) = (z - half, z + half, z);
            // The slab's horizontal section through the vertex: t / (2 |n_h|) to either side.
            let nh = (1.0 - nz * nz).max(0.0).sqrt();
            reach[v] = if nh > 0.0 {
                vertex_thickness[v] / (2.0 * nh)
            } else {
                f64::INFINITY
            };
        }
        Ok(Envelope {
            springing: middle.clone(),
            reach,
            middle,
            lower,
            upper,
            face_thickness,
        })
    }

    /// Intrados and extrados given as triangle surfaces (any connectivity), sampled on the
    /// vertical through each referenced vertex of `mesh` (by linear interpolation on the
    /// triangle whose plan contains it; where several do, the highest intrados and the
    /// lowest extrados count). The middle surface is halfway between; the load's thickness
    /// is the vertical extent times the middle surface's normal z-component there.
    ///
    /// Errors name the vertex that a surface does not cover and the vertex where the
    /// intrados lies above the extrados.
    pub fn from_surfaces(
        mesh: &Mesh,
        intrados: (&[[f64; 3]], &[[u32; 3]]),
        extrados: (&[[f64; 3]], &[[u32; 3]]),
    ) -> Result<Envelope> {
        let mut lower = sample(mesh, intrados, "intrados", Pick::Highest)?;
        let mut upper = sample(mesh, extrados, "extrados", Pick::Lowest)?;
        let n = mesh.positions.len();
        let mut middle = vec![0.0; n];
        let scale = crate::geometry::Frame::of(mesh, &mesh.positions).scale;
        for v in (0..n).filter(|&v| mesh.referenced[v]) {
            // Surfaces that meet at a vertex read apart by their interpolation's rounding.
            let rounding = 1e-12 * lower[v].abs().max(upper[v].abs()).max(scale);
            if lower[v] > upper[v] && lower[v] - upper[v] <= rounding {
                let meet = 0.5 * (lower[v] + upper[v]);
                (lower[v], upper[v]) = (meet, meet);
            }
            if lower[v] > upper[v] {
                return Err(Error::InvalidArgument {
                    name: "intrados",
                    reason: format!(
                        "at vertex {v} the intrados ({}) lies above the extrados ({})",
                        lower[v], upper[v]
                    ),
                });
            }
            middle[v] = 0.5 * (lower[v] + upper[v]);
        }
        let mid_positions: Vec<[f64; 3]> = (0..n)
            .map(|v| [mesh.positions[v][0], mesh.positions[v][1], middle[v]])
            .collect();
        let normals = vertex_normals(mesh, &mid_positions);
        let vertex_thickness: Vec<f64> = (0..n)
            .map(|v| (upper[v] - lower[v]) * normals[v][2].max(0.0))
            .collect();
        let face_thickness = mesh
            .faces
            .iter()
            .map(|f| f.iter().map(|&v| vertex_thickness[v as usize]).sum::<f64>() / 3.0)
            .collect();
        Ok(Envelope::with_default_joints(
            mesh,
            middle,
            lower,
            upper,
            face_thickness,
        ))
    }

    /// Bounds given per vertex (as compas_tno's `zlb`, `zub`), with the thickness whose
    /// weight loads the vault (uniform or per face, as in [`Envelope::from_thickness`]).
    ///
    /// Errors name the argument with the wrong length, the vertex with a bound that is not
    /// finite or with lower above upper, and the face with a bad thickness.
    pub fn from_bounds(
        mesh: &Mesh,
        lower: Vec<f64>,
        upper: Vec<f64>,
        thickness: &Thickness,
    ) -> Result<Envelope> {
        let n = mesh.positions.len();
        for (name, values) in [("lower", &lower), ("upper", &upper)] {
            crate::validate::one_per_vertex(name, values.len(), n)?;
        }
        for v in (0..n).filter(|&v| mesh.referenced[v]) {
            if !(lower[v].is_finite() && upper[v].is_finite() && lower[v] <= upper[v]) {
                return Err(Error::InvalidArgument {
                    name: "lower",
                    reason: format!(
                        "vertex {v} has bounds [{}, {}]: they must be finite with lower <= upper",
                        lower[v], upper[v]
                    ),
                });
            }
        }
        let middle = (lower.iter().zip(&upper))
            .map(|(l, u)| 0.5 * (l + u))
            .collect();
        let face_thickness = thickness.per_face(mesh.n_faces())?;
        Ok(Envelope::with_default_joints(
            mesh,
            middle,
            lower,
            upper,
            face_thickness,
        ))
    }

    /// The default springing joints of bounds and surfaces: the plane at `lower` and a
    /// reach of half the vertex's thickness (the area-weighted mean of its faces' on the
    /// middle surface).
    fn with_default_joints(
        mesh: &Mesh,
        middle: Vec<f64>,
        lower: Vec<f64>,
        upper: Vec<f64>,
        face_thickness: Vec<f64>,
    ) -> Envelope {
        let n = mesh.positions.len();
        let positions: Vec<[f64; 3]> = (0..n)
            .map(|v| [mesh.positions[v][0], mesh.positions[v][1], middle[v]])
            .collect();
        let reach = (area_mean(mesh, &positions, &face_thickness).iter())
            .map(|t| 0.5 * t)
            .collect();
        Envelope {
            springing: lower.clone(),
            middle,
            lower,
            upper,
            face_thickness,
            reach,
        }
    }

    /// This envelope with the springing plane's height and the joint's reach given per
    /// vertex (read at free supports only; `f64::INFINITY` as reach: no joint, the support's
    /// height is bounded by the envelope alone).
    ///
    /// Errors name the argument with the wrong length and the vertex whose springing is not
    /// finite or lies above its upper bound, or whose reach is not a number >= 0.
    pub fn with_springing(mut self, springing: Vec<f64>, reach: Vec<f64>) -> Result<Envelope> {
        let n = self.lower.len();
        for (name, values) in [("springing", &springing), ("reach", &reach)] {
            crate::validate::one_per_vertex(name, values.len(), n)?;
        }
        if let Some(v) =
            (0..n).find(|&v| !(springing[v].is_finite() && springing[v] <= self.upper[v]))
        {
            return Err(Error::InvalidArgument {
                name: "springing",
                reason: format!(
                    "vertex {v} has {}: it must be finite and at most the upper bound {}",
                    springing[v], self.upper[v]
                ),
            });
        }
        if let Some(v) = reach.iter().position(|b| b.is_nan() || *b < 0.0) {
            return Err(Error::InvalidArgument {
                name: "reach",
                reason: format!("vertex {v} has {}, not a number >= 0", reach[v]),
            });
        }
        (self.springing, self.reach) = (springing, reach);
        Ok(self)
    }

    /// This envelope with one springing height and one reach at every support of `mesh`
    /// (`None` keeps the envelope's own), the values the joints of free supports read; as
    /// [`Envelope::with_springing`] otherwise (its errors name the support).
    pub fn with_joint_at_supports(
        self,
        mesh: &Mesh,
        springing: Option<f64>,
        reach: Option<f64>,
    ) -> Result<Envelope> {
        crate::validate::one_per_vertex("mesh", mesh.positions.len(), self.lower.len())?;
        let (mut s, mut r) = (self.springing.clone(), self.reach.clone());
        for v in mesh.anchored_ids() {
            s[v as usize] = springing.unwrap_or(s[v as usize]);
            r[v as usize] = reach.unwrap_or(r[v as usize]);
        }
        self.with_springing(s, r)
    }

    /// Positions of the middle surface over the mesh's plan.
    pub fn middle_positions(&self, mesh: &Mesh) -> Vec<[f64; 3]> {
        (mesh.positions.iter().zip(&self.middle))
            .map(|(p, &m)| [p[0], p[1], m])
            .collect()
    }

    /// Half the vertical extent per vertex.
    pub(crate) fn half_extent(&self) -> Vec<f64> {
        (self.lower.iter().zip(&self.upper))
            .map(|(l, u)| 0.5 * (u - l))
            .collect()
    }
}

/// Below this normal z-component a thickness along the normal is not read vertically.
const MIN_NORMAL_Z: f64 = 1e-6;

/// Per-face values to per-vertex ones, weighted by the faces' 3-D areas.
fn area_mean(mesh: &Mesh, positions: &[[f64; 3]], face: &[f64]) -> Vec<f64> {
    let n = positions.len();
    let (mut sum, mut area) = (vec![0.0; n], vec![0.0; n]);
    for (f, tri) in mesh.faces.iter().enumerate() {
        let a = norm(face_normal(positions, tri)) / 2.0;
        for &v in tri {
            sum[v as usize] += a * face[f];
            area[v as usize] += a;
        }
    }
    (0..n)
        .map(|v| if area[v] > 0.0 { sum[v] / area[v] } else { 0.0 })
        .collect()
}

/// Unit area-weighted vertex normals, pointing up (the faces are counter-clockwise in plan).
fn vertex_normals(mesh: &Mesh, positions: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let mut normals = vec![[0.0; 3]; positions.len()];
    for tri in &mesh.faces {
        let n = face_normal(positions, tri);
        for &v in tri {
            for d in 0..3 {
                normals[v as usize][d] += n[d];
            }
        }
    }
    for n in &mut normals {
        let len = norm(*n);
        if len > 0.0 {
            *n = n.map(|c| c / len);
        }
    }
    normals
}

fn face_normal(p: &[[f64; 3]], f: &[u32; 3]) -> [f64; 3] {
    let [a, b, c] = f.map(|v| p[v as usize]);
    let (u, w) = (sub3(b, a), sub3(c, a));
    [
        u[1] * w[2] - u[2] * w[1],
        u[2] * w[0] - u[0] * w[2],
        u[0] * w[1] - u[1] * w[0],
    ]
}

fn sub3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// The Euclidean length, scaled so that its squares neither overflow nor underflow at any
/// coordinate scale the mesh accepts.
fn norm(a: [f64; 3]) -> f64 {
    let m = a.iter().fold(0.0f64, |m, c| m.max(c.abs()));
    if m == 0.0 || !m.is_finite() {
        return m;
    }
    let [x, y, z] = a.map(|c| c / m);
    m * (x * x + y * y + z * z).sqrt()
}

#[derive(Clone, Copy)]
enum Pick {
    Highest,
    Lowest,
}

/// Heights of a triangle surface on the vertical through each referenced vertex of `mesh`.
fn sample(
    mesh: &Mesh,
    (positions, faces): (&[[f64; 3]], &[[u32; 3]]),
    name: &'static str,
    pick: Pick,
) -> Result<Vec<f64>> {
    if let Some((f, v)) = (faces.iter().enumerate()).find_map(|(f, t)| {
        t.iter()
            .find(|&&v| v as usize >= positions.len())
            .map(|v| (f, v))
    }) {
        return Err(Error::InvalidArgument {
            name,
            reason: format!(
                "face {f} refers to vertex {v}, beyond its {} vertices",
                positions.len()
            ),
        });
    }
    if let Some(v) = positions
        .iter()
        .position(|p| p.iter().any(|c| !c.is_finite()))
    {
        return Err(Error::InvalidArgument {
            name,
            reason: format!("vertex {v} has a coordinate that is not finite"),
        });
    }
    let grid = Grid::new(positions, faces);
    let diag = plan_diagonal(mesh);
    let n = mesh.positions.len();
    let mut out = vec![0.0; n];
    for v in (0..n).filter(|&v| mesh.referenced[v]) {
        let p = mesh.positions[v];
        out[v] = grid
            .heights_at(positions, faces, [p[0], p[1]], 1e-9 * diag)
            .reduce(|a, b| match pick {
                Pick::Highest => a.max(b),
                Pick::Lowest => a.min(b),
            })
            .ok_or_else(|| Error::InvalidArgument {
                name,
                reason: format!(
                    "does not cover vertex {v} at plan point ({}, {})",
                    p[0], p[1]
                ),
            })?;
    }
    Ok(out)
}

pub(super) fn plan_diagonal(mesh: &Mesh) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for (p, _) in mesh.positions.iter().zip(&mesh.referenced).filter(|x| *x.1) {
        for d in 0..2 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2)).sqrt()
}

/// A uniform grid over the plan bounding box with the faces whose plan boxes meet each cell.
struct Grid {
    lo: [f64; 2],
    cell: f64,
    dims: [usize; 2],
    cells: Vec<Vec<u32>>,
}

impl Grid {
    fn new(positions: &[[f64; 3]], faces: &[[u32; 3]]) -> Grid {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for f in faces {
            for &v in f {
                for d in 0..2 {
                    lo[d] = lo[d].min(positions[v as usize][d]);
                    hi[d] = hi[d].max(positions[v as usize][d]);
                }
            }
        }
        let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(f64::MIN_POSITIVE);
        let per_side = ((faces.len() as f64).sqrt().ceil() as usize).clamp(1, 1024);
        let cell = extent / per_side as f64 * (1.0 + 1e-9);
        let dims = [per_side, per_side];
        let mut cells = vec![Vec::new(); per_side * per_side];
        let grid_lo = lo;
        for (t, f) in faces.iter().enumerate() {
            let (mut a, mut b) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for &v in f {
                for d in 0..2 {
                    a[d] = a[d].min(positions[v as usize][d]);
                    b[d] = b[d].max(positions[v as usize][d]);
                }
            }
            let index = |x: f64, d: usize| (((x - grid_lo[d]) / cell) as usize).min(dims[d] - 1);
            for i in index(a[0], 0)..=index(b[0], 0) {
                for j in index(a[1], 1)..=index(b[1], 1) {
                    cells[j * dims[0] + i].push(t as u32);
                }
            }
        }
        Grid {
            lo,
            cell,
            dims,
            cells,
        }
    }

    /// Heights at plan point `u` of the faces whose plan contains it (within `slack`).
    fn heights_at<'a>(
        &'a self,
        positions: &'a [[f64; 3]],
        faces: &'a [[u32; 3]],
        u: [f64; 2],
        slack: f64,
    ) -> impl Iterator<Item = f64> + 'a {
        let mut ids: Vec<u32> = Vec::new();
        let (ci, cj) = (
            (u[0] - self.lo[0] - slack) / self.cell,
            (u[1] - self.lo[1] - slack) / self.cell,
        );
        let (di, dj) = (
            (u[0] - self.lo[0] + slack) / self.cell,
            (u[1] - self.lo[1] + slack) / self.cell,
        );
        let clamp = |x: f64, d: usize| (x.max(0.0) as usize).min(self.dims[d] - 1);
        let inside = di >= 0.0 && dj >= 0.0;
        if inside {
            for i in clamp(ci, 0)..=clamp(di, 0) {
                for j in clamp(cj, 1)..=clamp(dj, 1) {
                    ids.extend_from_slice(&self.cells[j * self.dims[0] + i]);
                }
            }
        }
        ids.sort_unstable();
        ids.dedup();
        ids.into_iter()
            .filter_map(move |t| interpolate(positions, &faces[t as usize], u, slack))
    }
}

/// The height at `u` of the plane through triangle `f`, if `u` lies in its plan (within
/// `slack`, measured along the edges' normals).
fn interpolate(p: &[[f64; 3]], f: &[u32; 3], u: [f64; 2], slack: f64) -> Option<f64> {
    let [a, b, c] = f.map(|v| p[v as usize]);
    let area2 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if area2.abs() <= f64::MIN_POSITIVE {
        return None;
    }
    let edge = |p: [f64; 3], q: [f64; 3]| {
        let cross = (q[0] - p[0]) * (u[1] - p[1]) - (q[1] - p[1]) * (u[0] - p[0]);
        let len = ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2)).sqrt();
        (cross, len)
    };
    let sign = area2.signum();
    let mut w = [0.0; 3];
    for (k, (p, q)) in [(b, c), (c, a), (a, b)].into_iter().enumerate() {
        let (cross, len) = edge(p, q);
        if cross * sign < -slack * len {
            return None;
        }
        w[k] = cross / area2;
    }
    Some(w[0] * a[2] + w[1] * b[2] + w[2] * c[2])
}
