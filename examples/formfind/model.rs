//! The input of a run: the embedded default vault, or a mesh file with its supports.

use std::path::Path;

use voussoir::generate::{self, Domain};
use voussoir::io::{self, UpAxis};
use voussoir::{Mesh, Problem};

use crate::args::Options;

/// The problem of a run, how it was read, and the faces to write back (as read, before any
/// reorientation).
pub struct Model {
    /// Short name used for default output file names.
    pub name: String,
    /// How the supports were chosen, for the report.
    pub supports: String,
    /// The problem (its loads those of `--density` once `run::run` set them) and how it was
    /// read: the library's `io::read_model`, or `io::Model::from_problem` for the embedded
    /// default.
    pub read: io::Model,
    pub faces: Vec<[u32; 3]>,
}

impl Model {
    pub fn mesh(&self) -> &Mesh {
        &self.read.problem.mesh
    }
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
    let faces = mesh.faces().to_vec();
    let source = "embedded default: sail vault on four pillars, free arches, two oculi";
    Model {
        name: "vault".into(),
        supports: "corner pillars".into(),
        read: io::Model::from_problem(Problem::new(mesh), source),
        faces,
    }
}

/// Reads `mesh_path` with the library's read path (`io::read_model`) and the options of the
/// command line. A mesh whose plan is invalid but would be valid seen Y-up gets a hint to
/// `--up y` in its error.
pub fn from_files(mesh_path: &Path, o: &Options) -> Result<Model, String> {
    let options = o.read_options();
    let read = io::read_model(mesh_path, &options);
    let model = match read {
        Err(e) if options.up == UpAxis::Z && is_plan_error(&e) => {
            let y_up = options.clone().with_up(UpAxis::Y);
            return Err(match io::read_model(mesh_path, &y_up) {
                Ok(_) => format!(
                    "{e} (seen with y up, as most modellers export, the plan is valid: try --up y)"
                ),
                Err(_) => e.to_string(),
            });
        }
        Err(voussoir::Error::InvalidArgument {
            name: "weld_tolerance",
            reason,
        }) => return Err(format!("--weld: {reason} (or --no-weld)")),
        Err(e @ voussoir::Error::InvalidAnchor { .. }) => {
            return Err(anchor_error(&e, mesh_path, &options.supports))
        }
        other => other.map_err(|e| e.to_string())?,
    };
    let name = mesh_path
        .file_stem()
        .map_or("mesh".into(), |s| s.to_string_lossy().into_owned());
    Ok(Model {
        name,
        supports: options.supports.to_string(),
        faces: model.problem.mesh.input_faces(),
        read: model,
    })
}

/// An anchored id out of range or repeated, with the supports' source and MESH's id range
/// (its own vertices, before welding).
fn anchor_error(e: &voussoir::Error, mesh_path: &Path, supports: &io::Supports) -> String {
    let range = io::read_mesh(mesh_path).map_or(String::new(), |(positions, _)| {
        let last = positions.len().saturating_sub(1);
        format!(" (MESH's vertex ids are 0 to {last}, before welding)")
    });
    format!("--supports {supports}: {e}{range}")
}

/// Whether `e` says the plan (the projection along z) is not a valid one.
fn is_plan_error(e: &voussoir::Error) -> bool {
    matches!(
        e,
        voussoir::Error::DegenerateFaces { .. }
            | voussoir::Error::FlippedFaces { .. }
            | voussoir::Error::OverlappingPlan { .. }
            | voussoir::Error::OverlappingFaces { .. }
    )
}
