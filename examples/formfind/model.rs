//! The input of a run: the embedded default vault, or a mesh file with its supports.

use std::path::{Path, PathBuf};

use voussoir::generate::{self, Domain};
use voussoir::{io, Mesh};

/// A validated mesh, the faces to write back (as read, before any reorientation) and where it
/// came from.
pub struct Model {
    /// Short name used for default output file names.
    pub name: String,
    /// Where the mesh came from, for the report.
    pub source: String,
    pub supports: String,
    pub mesh: Mesh,
    pub faces: Vec<[u32; 3]>,
}

/// Plan of the embedded default: a rectangle of half-widths `HALF_X` × `HALF_Y` whose sides bow
/// inwards by `SAG` at their middle.
const HALF_X: f64 = 4.0;
const HALF_Y: f64 = 3.0;
const SAG: f64 = 0.5;
/// Height of the sphere over the centre of the plan.
const CROWN: f64 = 3.5;
/// Depth of the flattening of the crown, relative to `CROWN` (a Gaussian dip of radius 2).
const FLATTENING: f64 = 0.1;
/// Boundary vertices closer than this to a corner stand on the corner pillars.
const PILLAR: f64 = 0.9;

/// The embedded default: a sail vault (a sphere through the four corners of its plan) standing
/// on four corner pillars, its crown flattened as a designer might draw it (form finding lifts
/// it back). Its sides are free arches, bowed inwards in plan between the pillars, and two round
/// oculi open its crown. Meshed by spade's constrained Delaunay refinement, coarse
/// enough to form-find in well under a second.
pub fn embedded_default() -> Model {
    let outer = generate::rectangle(-HALF_X, -HALF_Y, HALF_X, HALF_Y, 16, 12)
        .into_iter()
        .map(|[x, y]| {
            if (y.abs() - HALF_Y).abs() < 1e-12 {
                [x, y - y.signum() * SAG * (1.0 - (x / HALF_X).powi(2))]
            } else {
                [x - x.signum() * SAG * (1.0 - (y / HALF_Y).powi(2)), y]
            }
        })
        .collect();
    let holes = vec![
        generate::circle([-1.7, 0.0], 0.6, 12),
        generate::circle([1.7, 0.0], 0.6, 12),
    ];
    let domain = Domain { outer, holes };
    let (points, triangles) =
        generate::triangulate(&domain, 0.2).expect("the embedded domain is valid");
    // The sphere through the four corners with its top at height CROWN.
    let corner2 = HALF_X * HALF_X + HALF_Y * HALF_Y;
    let sink = (corner2 - CROWN * CROWN) / (2.0 * CROWN);
    let radius = sink + CROWN;
    let height = |[x, y]: [f64; 2]| {
        let r2 = x * x + y * y;
        (radius * radius - r2).sqrt() - sink - FLATTENING * CROWN * (-r2 / 4.0).exp()
    };
    let pillar = |[x, y]: [f64; 2], outer: bool| {
        outer && (HALF_X - x.abs()).hypot(HALF_Y - y.abs()) < PILLAR
    };
    let mesh = generate::lift(&points, &triangles, height, pillar)
        .expect("the embedded vault is a valid mesh");
    let faces = mesh.faces.clone();
    Model {
        name: "vault".into(),
        source: "embedded default: sail vault on four pillars, free arches, two oculi".into(),
        supports: "corner pillars".into(),
        mesh,
        faces,
    }
}

/// Reads `mesh_path` and anchors the vertices listed in `supports`, or every boundary vertex.
pub fn from_files(mesh_path: &Path, supports: Option<&PathBuf>) -> voussoir::Result<Model> {
    let (positions, faces) = io::read_obj(mesh_path)?;
    let (mesh, supports_label) = match supports {
        Some(path) => {
            let anchored = io::read_supports(path)?;
            (
                Mesh::new(positions, faces.clone(), &anchored)?,
                path.display().to_string(),
            )
        }
        None => {
            // Validate once with every vertex anchored to learn the boundary, then anchor it.
            let all: Vec<u32> = (0..positions.len() as u32).collect();
            let probe = Mesh::new(positions.clone(), faces.clone(), &all)?;
            let boundary: Vec<u32> = (0..positions.len() as u32)
                .filter(|&v| probe.on_boundary[v as usize] && probe.referenced[v as usize])
                .collect();
            (
                Mesh::new(positions, faces.clone(), &boundary)?,
                "every boundary vertex (--anchor-boundary)".into(),
            )
        }
    };
    let name = mesh_path
        .file_stem()
        .map_or("mesh".into(), |s| s.to_string_lossy().into_owned());
    Ok(Model {
        name,
        source: mesh_path.display().to_string(),
        supports: supports_label,
        mesh,
        faces,
    })
}
