//! The input of a run: the embedded default vault, or a mesh file with its supports.

use std::path::Path;

use voussoir::generate::{self, Domain};
use voussoir::{io, Mesh};
use voussoir::{repair_plan, PlanRepair, DEFAULT_REPAIR_TOLERANCE};

use crate::args::Options;

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
    /// The welding of a mesh file (`None` for the embedded default and `--no-weld`).
    pub weld: Option<WeldSummary>,
    /// Plan repairs made before validation (none with `--strict`).
    pub repairs: Vec<PlanRepair>,
    /// The mesh edges that split the file's polygons into triangles (welded ids).
    pub diagonals: Vec<[u32; 2]>,
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
        weld: None,
        repairs: Vec::new(),
        diagonals: Vec::new(),
    }
}

/// How the input's vertices were welded, for the report.
pub struct WeldSummary {
    pub input_vertices: usize,
    pub merged: usize,
    pub relative_tolerance: f64,
    pub tolerance: f64,
    pub collapsed_faces: Vec<usize>,
    /// The welded vertex of each input vertex.
    pub welded_id: Vec<u32>,
}

/// Reads `mesh_path` (any format), turns it Z-up for `--up y`, welds it unless `--no-weld` (STL
/// always, at the default tolerance if need be), and anchors the vertices of `--supports`
/// (input ids, mapped onto welded ones), of `--anchor-lowest` or every boundary vertex. A mesh
/// whose plan is invalid but would be valid seen Y-up gets a hint to `--up y` in its error.
pub fn from_files(mesh_path: &Path, o: &Options) -> Result<Model, String> {
    let ((positions, faces), diagonals) =
        io::read_mesh_with_diagonals(mesh_path).map_err(|e| e.to_string())?;
    let read = |y_up: bool| {
        let positions = if y_up {
            positions.iter().map(|&p| from_y_up(p)).collect()
        } else {
            positions.clone()
        };
        build(mesh_path, o, positions, faces.clone(), &diagonals)
    };
    match read(o.y_up) {
        Err(e) if !o.y_up && is_plan_error(&e) && read(true).is_ok() => Err(format!(
            "{e} (seen with y up, as most modellers export, the plan is valid: try --up y)"
        )),
        other => other.map_err(|e| e.to_string()),
    }
}

/// A position of a Y-up file in the Z-up frame: a quarter turn about the x axis.
pub fn from_y_up(p: [f64; 3]) -> [f64; 3] {
    [p[0], -p[2], p[1]]
}

/// A Z-up position back in a Y-up file's axes (the inverse of [`from_y_up`]).
pub fn to_y_up(p: [f64; 3]) -> [f64; 3] {
    [p[0], p[2], -p[1]]
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

/// The model of `positions` and `faces` (already Z-up): welding, supports, plan repair and
/// validation.
fn build(
    mesh_path: &Path,
    o: &Options,
    positions: Vec<[f64; 3]>,
    faces: Vec<[u32; 3]>,
    diagonals: &[[u32; 2]],
) -> voussoir::Result<Model> {
    let is_stl = io::MeshFormat::from_path(mesh_path)?.is_single_precision();
    let tolerance = o.weld.or(is_stl.then_some(io::DEFAULT_WELD_TOLERANCE));
    let (positions, faces, welded) = match tolerance {
        Some(t) => {
            let w = io::weld(&positions, &faces, t)?;
            let summary = WeldSummary {
                input_vertices: positions.len(),
                merged: w.merged,
                relative_tolerance: t,
                tolerance: w.tolerance,
                collapsed_faces: w.collapsed_faces.clone(),
                welded_id: w.welded_id.clone(),
            };
            (w.positions.clone(), w.faces.clone(), Some((w, summary)))
        }
        None => (positions, faces, None),
    };
    let (anchored, supports_label) = if let Some(path) = &o.supports {
        let ids = io::read_supports(path)?;
        let ids = match &welded {
            Some((w, _)) => w.map_ids(&ids)?,
            None => ids,
        };
        (ids, path.display().to_string())
    } else if let Some((tol, absolute)) = o.anchor_lowest {
        let ids = lowest(&positions, &faces, tol, absolute);
        let unit = if absolute {
            ""
        } else {
            " x the bounding box diagonal"
        };
        let label =
            format!("every vertex within {tol}{unit} of the lowest height (--anchor-lowest)");
        (ids, label)
    } else {
        (
            boundary_vertices(&faces),
            "every boundary vertex (--anchor-boundary)".into(),
        )
    };
    let (mut positions, mut faces) = (positions, faces);
    let repairs = if o.strict {
        Vec::new()
    } else {
        repair_plan(
            &mut positions,
            &mut faces,
            &anchored,
            DEFAULT_REPAIR_TOLERANCE,
        )?
    };
    let mesh = Mesh::new(positions, faces.clone(), &anchored)?;
    let welded_id = |v: u32| match &welded {
        Some((w, _)) => w.welded_id[v as usize],
        None => v,
    };
    // Welding or a plan repair's flip may have removed a diagonal: only the edges left count.
    let diagonals = mesh.interior_edges_among(diagonals.iter().map(|d| d.map(welded_id)));
    let name = mesh_path
        .file_stem()
        .map_or("mesh".into(), |s| s.to_string_lossy().into_owned());
    Ok(Model {
        name,
        source: mesh_path.display().to_string(),
        supports: supports_label,
        mesh,
        faces,
        weld: welded.map(|(_, s)| s),
        repairs,
        diagonals,
    })
}

/// The vertices on an edge of a single face, in id order.
fn boundary_vertices(faces: &[[u32; 3]]) -> Vec<u32> {
    let mut uses: std::collections::HashMap<(u32, u32), usize> = Default::default();
    for f in faces {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            *uses.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let mut boundary: Vec<u32> = uses
        .iter()
        .filter(|(_, &n)| n == 1)
        .flat_map(|(&(a, b), _)| [a, b])
        .collect();
    boundary.sort_unstable();
    boundary.dedup();
    boundary
}

/// The vertices of some face within `tol` of the lowest such vertex's height; `tol` is
/// relative to the bounding box diagonal of those vertices unless `absolute`.
fn lowest(positions: &[[f64; 3]], faces: &[[u32; 3]], tol: f64, absolute: bool) -> Vec<u32> {
    let mut referenced = vec![false; positions.len()];
    for &v in faces.iter().flatten() {
        referenced[v as usize] = true;
    }
    let used = || {
        (0..positions.len())
            .filter(|&v| referenced[v])
            .map(|v| positions[v])
    };
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in used() {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let diagonal = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    let reach = if absolute { tol } else { tol * diagonal };
    (0..positions.len() as u32)
        .filter(|&v| referenced[v as usize] && positions[v as usize][2] <= lo[2] + reach)
        .collect()
}
