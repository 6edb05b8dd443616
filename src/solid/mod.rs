//! A printable solid: the shell thickened along its vertex normals and closed by side walls
//! (docs/method.md §15).
//!
//! Each referenced vertex `p` with unit normal `n` (the area-weighted mean of its faces'
//! normals, pointing up; turned towards the narrowest cone around them at a crease sharper
//! than 60°) and thickness `t` (the area-weighted mean of its faces') gives an upper vertex
//! `p + d/2 n` and a lower one `p - d/2 n`, where `d` is `t` divided by the area-weighted mean
//! cosine between `n` and the faces' normals (at most `2t`): each face then keeps its
//! thickness across a crease, and the volume is close to Σ area × thickness. The upper faces
//! keep the mesh's counter-clockwise (upward) orientation, the lower ones are reversed, and
//! every boundary edge, outer or around a hole, gets a wall of two triangles: the result is
//! closed, every edge is shared by exactly two faces in opposite directions, and the faces
//! point outwards. A thickness at which it would cross itself is refused.

mod crossing;

use crate::mesh::Mesh;
use crate::{Error, Result};

/// How thick the solid is: the same everywhere or per face (one entry per face of the mesh).
///
/// Per-face thicknesses become per-vertex ones as the area-weighted mean over each vertex's
/// faces. [`Thickness::from_density`] derives them from the per-face density (weight per
/// unit area) that the form finding used.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Thickness {
    /// One thickness, in the units of the positions.
    Uniform(f64),
    /// One thickness per face, in the mesh's face order.
    PerFace(Vec<f64>),
}

impl Thickness {
    /// `density[f] / unit_weight` per face: density is thickness × unit weight (weight per
    /// unit volume). `unit_weight` must be finite and > 0.
    pub fn from_density(density: &[f64], unit_weight: f64) -> Result<Thickness> {
        crate::validate::above("unit_weight", unit_weight, 0.0)?;
        Ok(Thickness::PerFace(
            density.iter().map(|d| d / unit_weight).collect(),
        ))
    }

    /// The thickness of each of `n_faces` faces: one per face, each finite and > 0 (errors
    /// name the first face that is not, or the wrong count).
    pub(crate) fn per_face(&self, n_faces: usize) -> Result<Vec<f64>> {
        let values = match self {
            Thickness::Uniform(t) => vec![*t; n_faces],
            Thickness::PerFace(t) if t.len() != n_faces => {
                return Err(Error::InvalidArgument {
                    name: "thickness",
                    reason: format!("has {} entries, expected one per face ({n_faces})", t.len()),
                })
            }
            Thickness::PerFace(t) => t.clone(),
        };
        crate::validate::all_finite("thickness", &values, "face")?;
        match values.iter().position(|t| *t <= 0.0) {
            Some(f) => Err(Error::InvalidArgument {
                name: "thickness",
                reason: format!("face {f}: {} must be > 0", values[f]),
            }),
            None => Ok(values),
        }
    }
}

/// A closed triangle mesh: vertex positions and outward-oriented triangles (0-based).
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct Solid {
    /// The upper vertices (one per referenced mesh vertex, in id order), then the lower ones
    /// in the same order.
    pub positions: Vec<[f64; 3]>,
    /// The upper faces (the mesh's faces in order), the lower faces (reversed), then two wall
    /// triangles per boundary edge.
    pub faces: Vec<[u32; 3]>,
    /// The distance between the upper and lower copy of each referenced mesh vertex, in id
    /// order: its thickness divided by the mean cosine between its normal and its faces'.
    pub vertex_thickness: Vec<f64>,
}

impl Solid {
    /// The enclosed volume (positive: the faces point outwards).
    pub fn volume(&self) -> f64 {
        signed_volume(&self.positions, &self.faces)
    }
}

/// The signed volume enclosed by `faces` (positive when a closed mesh's faces point
/// outwards).
pub fn signed_volume(positions: &[[f64; 3]], faces: &[[u32; 3]]) -> f64 {
    faces
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|i| positions[i as usize]);
            dot(a, cross(b, c)) / 6.0
        })
        .sum()
}

/// The smallest mean cosine by which a vertex's offset is divided: at most a doubling, at
/// creases sharper than 120°.
const MIN_MEAN_COSINE: f64 = 0.5;

/// Below this cosine between a vertex's area-weighted normal and one of its faces' normals
/// (60°), the offset direction is turned to widen the smallest angle.
const SHARP_COSINE: f64 = 0.5;

/// Steps of the search for that direction; its smallest cosine is within a few percent of
/// the best after these.
const CONE_ITERATIONS: usize = 200;

/// Fraction of its base face's area below which an offset face counts as turned over: a
/// face that thin is a sliver about to flip.
const MIN_OFFSET_AREA: f64 = 1e-2;

/// Thickens the shell `mesh` with vertex `positions` (the form-found ones, or
/// `mesh.positions`) into a [`Solid`]: half the thickness above the surface, half below,
/// along area-weighted vertex normals, with walls along every boundary loop.
///
/// Errors ([`Error::InvalidArgument`]): `positions` of another length than the mesh's
/// vertices or not finite; a thickness that is not finite and > 0 (naming the face), or below
/// 1e-12 times the shell's size (the larger of its bounding-box diagonal and its largest
/// coordinate: the two surfaces would not differ in double precision), naming the least
/// thickness; a
/// vertex whose faces' normals cancel, or whose offset direction points away from one of its
/// faces (a fold no direction clears, where no thickness fits), naming it; a thickness so
/// large that the layer between a face and its offset folds over (the offset face turns
/// over or keeps less than 1 % of its area), which would make the solid intersect itself:
/// the message names the face that allows the least thickness, its vertices and that
/// thickness; a thickness above 1e12 times the shell's size, naming the largest; then any
/// other crossing of the solid with itself (parts of the shell far apart
/// along the surface but near in space), naming the two parts that cross.
pub fn thicken(mesh: &Mesh, positions: &[[f64; 3]], thickness: &Thickness) -> Result<Solid> {
    check_positions(mesh, positions)?;
    let face_thickness = thickness.per_face(mesh.n_faces())?;
    let size = shell_size(mesh, positions);
    check_range(&face_thickness, size, Range::Below)?;
    let thickest = face_thickness.iter().copied().fold(0.0, f64::max);
    // Offsets per unit of the thickest face's thickness, so that no product overflows.
    let (normals, relative) =
        vertex_normals_and_thickness(mesh, positions, &face_thickness, thickest)?;
    let unit_offset = |v: usize, side: f64| normals[v].map(|c| side * relative[v] / 2.0 * c);
    check_no_flips(mesh, positions, &face_thickness, thickest, &unit_offset)?;
    check_range(&face_thickness, size, Range::Above)?;
    let vertex_thickness: Vec<f64> = relative.iter().map(|r| r * thickest).collect();
    let referenced: Vec<usize> = (0..mesh.n_vertices())
        .filter(|&v| mesh.referenced[v])
        .collect();
    let mut new_id = vec![u32::MAX; mesh.n_vertices()];
    for (k, &v) in referenced.iter().enumerate() {
        new_id[v] = k as u32;
    }
    let offset = |v: usize, side: f64| -> [f64; 3] {
        let h = side * vertex_thickness[v] / 2.0;
        let (p, n) = (positions[v], normals[v]);
        [p[0] + h * n[0], p[1] + h * n[1], p[2] + h * n[2]]
    };
    let n = referenced.len() as u32;
    let mut out_positions: Vec<[f64; 3]> = referenced.iter().map(|&v| offset(v, 1.0)).collect();
    out_positions.extend(referenced.iter().map(|&v| offset(v, -1.0)));
    let mut faces: Vec<[u32; 3]> = mesh
        .faces
        .iter()
        .map(|f| f.map(|v| new_id[v as usize]))
        .collect();
    faces.extend(
        mesh.faces
            .iter()
            .map(|f| [f[0], f[2], f[1]].map(|v| new_id[v as usize] + n)),
    );
    let walls: Vec<[u32; 2]> = boundary_edges(mesh).collect();
    for &[a, b] in &walls {
        let (a, b) = (new_id[a as usize], new_id[b as usize]);
        faces.push([b, a, a + n]);
        faces.push([b, a + n, b + n]);
    }
    if let Some(pair) = crossing::first_crossing(&out_positions, &faces) {
        return Err(crossing_error(mesh, &walls, pair, thickest));
    }
    Ok(Solid {
        positions: out_positions,
        faces,
        vertex_thickness: referenced.iter().map(|&v| vertex_thickness[v]).collect(),
    })
}

/// The error for solid faces `s` and `t` crossing: which parts of the solid they are.
fn crossing_error(mesh: &Mesh, walls: &[[u32; 2]], (s, t): (usize, usize), thickest: f64) -> Error {
    let nf = mesh.n_faces();
    let part = |i: usize| match i {
        i if i < nf => format!("the upper surface at face {i}"),
        i if i < 2 * nf => format!("the lower surface at face {}", i - nf),
        i => {
            let [a, b] = walls[(i - 2 * nf) / 2];
            format!("the wall along boundary edge {a}-{b}")
        }
    };
    Error::InvalidArgument {
        name: "thickness",
        reason: format!(
            "{thickest:.4e} is too large: the solid would intersect itself where {} crosses {}; \
             parts of the shell there are nearer to each other than the thickness",
            part(s),
            part(t)
        ),
    }
}

/// The thickness range a solid can be made in, relative to the shell's size: below it, the
/// upper and lower surfaces cannot be told apart in double precision; above it, the solid's
/// coordinates lose the precision its crossing test needs.
const THICKNESS_RANGE: (f64, f64) = (1e-12, 1e12);

/// The side of [`THICKNESS_RANGE`] a check looks at.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Range {
    Below,
    Above,
}

/// The size the thickness is measured against: the larger of the bounding-box diagonal of the
/// referenced vertices and their largest coordinate (whose precision the offsets share).
fn shell_size(mesh: &Mesh, positions: &[[f64; 3]]) -> f64 {
    let (mut lo, mut hi, mut largest) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3], 0.0f64);
    for v in (0..mesh.n_vertices()).filter(|&v| mesh.referenced[v]) {
        for k in 0..3 {
            let c = positions[v][k];
            (lo[k], hi[k], largest) = (lo[k].min(c), hi[k].max(c), largest.max(c.abs()));
        }
    }
    let diagonal = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    diagonal.max(largest)
}

/// Refuses the first face whose thickness lies on `side` of [`THICKNESS_RANGE`] × `size`,
/// naming the limit.
fn check_range(face_thickness: &[f64], size: f64, side: Range) -> Result<()> {
    let (least, most) = (THICKNESS_RANGE.0 * size, THICKNESS_RANGE.1 * size);
    let out = |t: f64| match side {
        Range::Below => t < least,
        Range::Above => t > most,
    };
    let Some(f) = face_thickness.iter().position(|&t| out(t)) else {
        return Ok(());
    };
    let t = face_thickness[f];
    let reason = match side {
        Range::Below => format!(
            "{t:.4e} at face {f} is too small for a solid: below {:e} of the shell's size \
             ({size:.4e}), its upper and lower surfaces cannot be told apart in double \
             precision; give at least {least:.4e}",
            THICKNESS_RANGE.0
        ),
        Range::Above => format!(
            "{t:.4e} at face {f} is too large for a solid: beyond {:e} times the shell's size \
             ({size:.4e}), its coordinates lose the precision the check for self-intersection \
             needs; give at most {most:.4e}",
            THICKNESS_RANGE.1
        ),
    };
    Err(Error::InvalidArgument {
        name: "thickness",
        reason,
    })
}

fn check_positions(mesh: &Mesh, positions: &[[f64; 3]]) -> Result<()> {
    crate::validate::one_per_vertex("positions", positions.len(), mesh.n_vertices())?;
    match positions
        .iter()
        .position(|p| p.iter().any(|c| !c.is_finite()))
    {
        Some(v) => Err(Error::InvalidArgument {
            name: "positions",
            reason: format!("vertex {v} has a NaN or infinite coordinate"),
        }),
        None => Ok(()),
    }
}

/// Unit offset direction and offset distance per vertex (zero for vertices no face refers
/// to), the distance in units of `unit` (the thickest face's thickness, so that the weighted
/// sums cannot overflow).
fn vertex_normals_and_thickness(
    mesh: &Mesh,
    positions: &[[f64; 3]],
    face_thickness: &[f64],
    unit: f64,
) -> Result<(Vec<[f64; 3]>, Vec<f64>)> {
    let nv = mesh.n_vertices();
    let face_normals: Vec<[f64; 3]> = mesh
        .faces
        .iter()
        .map(|f| face_normal(positions, f))
        .collect();
    let (mut normals, mut weighted, mut area) = (vec![[0.0; 3]; nv], vec![0.0; nv], vec![0.0; nv]);
    for (f, face) in mesh.faces.iter().enumerate() {
        let a = norm(face_normals[f]) / 2.0;
        for &v in face {
            let v = v as usize;
            normals[v] = add(normals[v], face_normals[f]);
            weighted[v] += a * (face_thickness[f] / unit);
            area[v] += a;
        }
    }
    for v in (0..nv).filter(|&v| mesh.referenced[v]) {
        let len = norm(normals[v]);
        if !(len > 0.0 && area[v] > 0.0) {
            return Err(Error::InvalidArgument {
                name: "positions",
                reason: format!("vertex {v} has no normal: its faces' normals cancel"),
            });
        }
        normals[v] = normals[v].map(|c| c / len);
    }
    widen_sharp_normals(mesh, &face_normals, &mut normals);
    // Σ A (n · n_f) / Σ A is the area-weighted mean cosine between the offset direction and
    // the faces' normals: dividing by it keeps the faces' own thickness at a crease.
    let mut cosine_area = vec![0.0; nv];
    for (f, face) in mesh.faces.iter().enumerate() {
        for &v in face {
            cosine_area[v as usize] += dot(normals[v as usize], face_normals[f]) / 2.0;
        }
    }
    for v in (0..nv).filter(|&v| mesh.referenced[v]) {
        let mean_cosine = cosine_area[v] / area[v];
        weighted[v] /= area[v] * mean_cosine.max(MIN_MEAN_COSINE);
    }
    Ok((normals, weighted))
}

/// Where the area-weighted normal makes more than 60° with one of the vertex's faces (at a
/// sharp crease, or where a large face outweighs a steep small one), turns it towards the
/// axis of the narrowest cone around the faces' normals, which maximises the smallest cosine:
/// iterations of the Bădoiu–Clarkson kind, each a step towards the worst face's normal.
fn widen_sharp_normals(mesh: &Mesh, face_normals: &[[f64; 3]], normals: &mut [[f64; 3]]) {
    let unit: Vec<[f64; 3]> = face_normals
        .iter()
        .map(|n| n.map(|c| c / norm(*n)))
        .collect();
    let mut faces_of: std::collections::HashMap<usize, Vec<usize>> = Default::default();
    for (f, face) in mesh.faces.iter().enumerate() {
        for &v in face {
            if dot(normals[v as usize], unit[f]) < SHARP_COSINE {
                faces_of.entry(v as usize).or_default();
            }
        }
    }
    for (f, face) in mesh.faces.iter().enumerate() {
        for &v in face {
            if let Some(list) = faces_of.get_mut(&(v as usize)) {
                list.push(f);
            }
        }
    }
    for (v, faces) in faces_of {
        let worst = |n: [f64; 3]| {
            faces
                .iter()
                .map(|&f| (dot(n, unit[f]), f))
                .fold((f64::INFINITY, 0), |a, b| if b.0 < a.0 { b } else { a })
        };
        let (mut n, mut best) = (normals[v], worst(normals[v]).0);
        let mut current = n;
        for k in 0..CONE_ITERATIONS {
            let (_, f) = worst(current);
            let step = add(current, unit[f].map(|c| c / (k as f64 + 2.0)));
            current = step.map(|c| c / norm(step));
            let (cosine, _) = worst(current);
            if cosine > best {
                (n, best) = (current, cosine);
            }
        }
        normals[v] = n;
    }
}

/// Refuses a thickness at which the layer swept by a face, from the surface to its upper or
/// lower offset, folds over: at each corner, the swept face must keep an orientation that
/// agrees with the corner's offset direction and at least [`MIN_OFFSET_AREA`] of its
/// initial extent (the Jacobian of the sweep is linear across the face, so its corners
/// decide). Of the faces that fold, names the one that allows the least thickness, with its
/// vertices and that thickness.
///
/// `unit_offset(v, side)` is vertex `v`'s offset towards `side` (±1) per unit of `unit` (the
/// thickest face's thickness): the sweep is followed in those units, so that neither a tiny
/// thickness (lost in `p + offset - p`) nor a huge one (overflowing the products) spoils it.
fn check_no_flips(
    mesh: &Mesh,
    positions: &[[f64; 3]],
    face_thickness: &[f64],
    unit: f64,
    unit_offset: &dyn Fn(usize, f64) -> [f64; 3],
) -> Result<()> {
    // (thickness that fits, face, side) of the tightest face that folds.
    let mut tightest: Option<(f64, usize, &str)> = None;
    for (f, face) in mesh.faces.iter().enumerate() {
        let p = face.map(|v| positions[v as usize]);
        let (e1, e2) = (sub(p[1], p[0]), sub(p[2], p[0]));
        for (side, name) in [(1.0, "upper"), (-1.0, "lower")] {
            let d = [0, 1, 2].map(|k| unit_offset(face[k] as usize, side));
            let (de1, de2) = (sub(d[1], d[0]), sub(d[2], d[0]));
            let limits = d.map(|dk| {
                sweep_limit([e1, e2], [de1, de2], dk.map(|c| side * c), unit).map(|u| u / unit)
            });
            if let Some(k) = (0..3).find(|&k| limits[k] == Some(0.0)) {
                return Err(Error::InvalidArgument {
                    name: "positions",
                    reason: format!(
                        "the shell folds too sharply at vertex {} for a solid: its normal \
                         points away from face {f}, so no thickness fits there",
                        face[k]
                    ),
                });
            }
            let fraction = limits.into_iter().flatten().reduce(f64::min);
            if let Some(fits) = fraction.map(|s| s * face_thickness[f]) {
                if tightest.is_none_or(|(t, _, _)| fits < t) {
                    tightest = Some((fits, f, name));
                }
            }
        }
    }
    let Some((fits, f, name)) = tightest else {
        return Ok(());
    };
    let [a, b, c] = mesh.faces[f];
    Err(Error::InvalidArgument {
        name: "thickness",
        reason: format!(
            "{:.4e} is too large at face {f} (vertices {a}, {b}, {c}): its {name} offset face \
             turns over, so the solid would intersect itself; the shell's curvature allows at \
             most {fits:.4e} there",
            face_thickness[f]
        ),
    })
}

/// The smallest `s` in [0, `most`] at which the face with edges `e + s de` keeps less than
/// [`MIN_OFFSET_AREA`] of its initial extent along `n`: `q(s) = ((e1 + s de1) × (e2 + s de2))
/// · n` is quadratic in `s`. `None` when it never does.
fn sweep_limit(e: [[f64; 3]; 2], de: [[f64; 3]; 2], n: [f64; 3], most: f64) -> Option<f64> {
    let c0 = dot(cross(e[0], e[1]), n);
    if c0 <= 0.0 {
        return Some(0.0);
    }
    let c1 = dot(add(cross(e[0], de[1]), cross(de[0], e[1])), n);
    let c2 = dot(cross(de[0], de[1]), n);
    let a0 = c0 * (1.0 - MIN_OFFSET_AREA);
    // The quadratic term is negligible over [0, most] (compared without squaring `most`).
    let roots: Vec<f64> = if c2.abs() * most <= 1e-12 * (c0.abs() / most + c1.abs()) {
        vec![-a0 / c1]
    } else {
        let disc = c1 * c1 - 4.0 * c2 * a0;
        if disc < 0.0 {
            return None;
        }
        let r = disc.sqrt();
        vec![(-c1 - r) / (2.0 * c2), (-c1 + r) / (2.0 * c2)]
    };
    // q(0) > 0, so the first root in [0, most] is where the face first gets too thin.
    roots
        .into_iter()
        .filter(|s| s.is_finite() && (0.0..=most).contains(s))
        .reduce(f64::min)
}

/// Boundary edges as directed in their face (the surface on the left in plan).
fn boundary_edges(mesh: &Mesh) -> impl Iterator<Item = [u32; 2]> + '_ {
    mesh.edges.iter().filter_map(|e| match (e.left, e.right) {
        (Some(_), None) => Some([e.v[0], e.v[1]]),
        (None, Some(_)) => Some([e.v[1], e.v[0]]),
        _ => None,
    })
}

fn face_normal(positions: &[[f64; 3]], face: &[u32; 3]) -> [f64; 3] {
    let [a, b, c] = face.map(|v| positions[v as usize]);
    cross(sub(b, a), sub(c, a))
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}
