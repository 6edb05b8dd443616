//! [`read_model`]: a mesh file made a [`Problem`], the one read path of every layer (the C
//! API's `vsr_mesh_read`, Python's `Mesh.from_file`, the command lines).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use super::{read_mesh_with_diagonals, read_supports, weld, MeshFormat, Welded};
use crate::mesh::repair::{repair_plan, PlanRepair, DEFAULT_REPAIR_TOLERANCE};
use crate::{Error, Mesh, Problem, Result};

impl std::fmt::Display for Supports {
    /// How the supports are chosen, in words (for reports).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Supports::Ids(ids) => write!(f, "{} vertex ids given", ids.len()),
            Supports::File(path) => write!(f, "{}", path.display()),
            Supports::Boundary => write!(f, "every boundary vertex"),
            Supports::Lowest {
                tolerance,
                absolute,
            } => {
                let unit = if *absolute {
                    ""
                } else {
                    " x the bounding box diagonal"
                };
                write!(
                    f,
                    "every vertex within {tolerance}{unit} of the lowest height"
                )
            }
        }
    }
}

/// Which vertices of a mesh file are anchored (its supports).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Supports {
    /// The file's own 0-based vertex ids (before welding; an STL file has three per triangle:
    /// vertex `3t + k` is corner `k` of triangle `t`).
    Ids(Vec<u32>),
    /// A JSON file of such ids (see [`super::parse_supports`]).
    File(PathBuf),
    /// Every boundary vertex (of the welded mesh).
    Boundary,
    /// Every vertex of some face within `tolerance` of the lowest such vertex's height:
    /// `tolerance` is relative to the bounding box diagonal of those vertices unless
    /// `absolute`.
    Lowest {
        /// The reach above the lowest height.
        tolerance: f64,
        /// Whether `tolerance` is a length (else a multiple of the bounding box diagonal).
        absolute: bool,
    },
}

/// The axis that points up in a mesh file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum UpAxis {
    /// z up: x, y is the plan (default).
    #[default]
    Z,
    /// y up, as most modellers export: the file's (x, y, z) is (x, −z, y) in the Z-up frame.
    Y,
}

impl UpAxis {
    /// A file position in the Z-up frame of the solvers.
    pub fn to_z_up(self, p: [f64; 3]) -> [f64; 3] {
        match self {
            UpAxis::Z => p,
            UpAxis::Y => [p[0], -p[2], p[1]],
        }
    }

    /// A Z-up position in the file's axes (the inverse of [`UpAxis::to_z_up`]).
    pub fn to_file(self, p: [f64; 3]) -> [f64; 3] {
        match self {
            UpAxis::Z => p,
            UpAxis::Y => [p[0], p[2], -p[1]],
        }
    }
}

/// How [`read_model`] turns a file into a problem. Build with [`ReadOptions::new`] and the
/// `with_*` setters.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ReadOptions {
    /// The anchored vertices.
    pub supports: Supports,
    /// Vertices closer than this × the bounding box diagonal are merged into the first of them
    /// (0: exactly equal positions only); `None` keeps the file's vertices as they are, except
    /// in STL files (whose triangles never share vertices), welded at
    /// [`super::DEFAULT_WELD_TOLERANCE`]. Finite and >= 0. Default
    /// `Some(DEFAULT_WELD_TOLERANCE)`.
    pub weld_tolerance: Option<f64>,
    /// Faces whose plan area is below this × the median plan area are mended by
    /// [`repair_plan`] before validation (0: none, and the faces the default tolerance would
    /// mend are rejected, [`Error::DegenerateFaces`] naming them). Finite and >= 0. Default
    /// [`DEFAULT_REPAIR_TOLERANCE`].
    pub repair_tolerance: f64,
    /// The file's up axis. Default z.
    pub up: UpAxis,
}

impl ReadOptions {
    /// Default options with `supports`.
    pub fn new(supports: Supports) -> ReadOptions {
        ReadOptions {
            supports,
            weld_tolerance: Some(super::DEFAULT_WELD_TOLERANCE),
            repair_tolerance: DEFAULT_REPAIR_TOLERANCE,
            up: UpAxis::Z,
        }
    }

    /// Rejects NaN, negative or infinite tolerances, naming the field
    /// ([`Error::InvalidArgument`]).
    pub fn validate(&self) -> Result<()> {
        let check = |name, value: f64| {
            if value.is_finite() && value >= 0.0 {
                Ok(())
            } else {
                Err(Error::InvalidArgument {
                    name,
                    reason: format!("{value} is not a finite number >= 0"),
                })
            }
        };
        if let Some(t) = self.weld_tolerance {
            check("weld_tolerance", t)?;
        }
        check("repair_tolerance", self.repair_tolerance)?;
        if let Supports::Lowest { tolerance, .. } = self.supports {
            check("anchor_lowest", tolerance)?;
        }
        Ok(())
    }

    /// Whether `e`, an error of [`read_model`] with these options, is about the supports file
    /// rather than the mesh file (it names the supports file's path).
    pub fn blames_supports_file(&self, e: &Error) -> bool {
        let Supports::File(file) = &self.supports else {
            return false;
        };
        let path = match e {
            Error::Io { path, .. } | Error::Parse { path, .. } | Error::Malformed { path, .. } => {
                path
            }
            _ => return false,
        };
        *path == file.display().to_string()
    }
}

crate::setters::with_setters!(ReadOptions {
    with_weld_tolerance: weld_tolerance: Option<f64>,
    with_repair_tolerance: repair_tolerance: f64,
    with_up: up: UpAxis,
});

/// How the file's vertices were welded.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[non_exhaustive]
pub struct WeldSummary {
    /// The file's vertex count.
    pub input_vertices: usize,
    /// How many of them were merged into an earlier one.
    pub merged: usize,
    /// The tolerance asked for, relative to the bounding box diagonal.
    pub relative_tolerance: f64,
    /// The absolute tolerance used.
    pub tolerance: f64,
    /// File faces dropped because welding merged two of their corners.
    pub collapsed_faces: Vec<usize>,
}

/// A mesh file read by [`read_model`]: the problem (default loads) and what was done to get
/// it.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct Model {
    /// The validated mesh (welded vertices, numbered in the order of their first file
    /// vertex; the Z-up frame), its supports and default loads, its polygon diagonals marked.
    pub problem: Problem,
    /// The mesh vertex of each file vertex (identity when not welded).
    pub welded_ids: Vec<u32>,
    /// The welding, `None` when the file's vertices were kept as they are.
    pub weld: Option<WeldSummary>,
    /// The plan repairs made before validation, in order.
    pub repairs: Vec<PlanRepair>,
    /// The mesh edges that split the file's polygons into triangles (those welding and the
    /// repairs left), marked on `problem`.
    pub diagonals: Vec<[u32; 2]>,
    /// The file's path (or what the problem was made from).
    pub source: String,
    /// The options it was read with (its up axis: positions in `problem` are Z-up).
    pub options: ReadOptions,
}

impl Model {
    /// A problem built from arrays, as a model read from `source` would describe it: every
    /// vertex its own, no repair, supports given as ids, z up.
    pub fn from_problem(problem: Problem, source: impl Into<String>) -> Model {
        let mesh = &problem.mesh;
        let n = mesh.n_vertices() as u32;
        let anchored = (0..n).filter(|&v| mesh.anchored[v as usize]).collect();
        let diagonals = problem.polygon_diagonals();
        Model {
            welded_ids: (0..n).collect(),
            weld: None,
            repairs: Vec::new(),
            diagonals,
            source: source.into(),
            options: ReadOptions::new(Supports::Ids(anchored))
                .with_weld_tolerance(None)
                .with_repair_tolerance(0.0),
            problem,
        }
    }
}

/// With no repair asked for (tolerance 0), the faces the default tolerance would mend are
/// degenerate: a plan sliver left as drawn carries force densities many orders of magnitude
/// apart, which no step balances to the tolerance. (A flip names its sliver first.)
fn reject_slivers(positions: &[[f64; 3]], faces: &[[u32; 3]], anchored: &[u32]) -> Result<()> {
    let (mut p, mut f) = (positions.to_vec(), faces.to_vec());
    let repairs = repair_plan(&mut p, &mut f, anchored, DEFAULT_REPAIR_TOLERANCE)?;
    let mut slivers: Vec<usize> = (repairs.iter())
        .map(|r| match r {
            PlanRepair::Flip { faces, .. } => faces[0],
            PlanRepair::Nudge { face, .. } => *face,
        })
        .collect();
    slivers.sort_unstable();
    slivers.dedup();
    match slivers.is_empty() {
        true => Ok(()),
        false => Err(Error::DegenerateFaces { faces: slivers }),
    }
}

/// Reads a mesh file (OBJ, OFF, STL or PLY, by its extension; polygons split into fans) into a
/// problem: the options are checked; the file is read and turned Z-up; the supports file, if
/// any, is read; the vertices are welded; the supports are chosen (file ids mapped onto
/// welded ones, or the boundary, or the lowest vertices); plan slivers are repaired; the mesh
/// is validated ([`Mesh::new`]); and the polygon diagonals are marked
/// ([`Problem::with_polygon_diagonals`]), so that q_min does not bind them.
///
/// Errors: invalid options ([`ReadOptions::validate`]); errors of the mesh file naming its
/// path and line or element; errors of the supports file naming its path (see
/// [`ReadOptions::blames_supports_file`]); a support id out of range or listed twice
/// ([`Error::InvalidAnchor`]); then those of [`Mesh::new`].
pub fn read_model(path: &Path, options: &ReadOptions) -> Result<Model> {
    options.validate()?;
    let ((positions, faces), diagonals) = read_mesh_with_diagonals(path)?;
    // Before the supports are mapped onto it: an id is out of range of an empty file too.
    if positions.is_empty() || faces.is_empty() {
        return Err(Error::EmptyMesh);
    }
    let positions: Vec<[f64; 3]> = match options.up {
        UpAxis::Z => positions,
        up => positions.into_iter().map(|p| up.to_z_up(p)).collect(),
    };
    let file_ids = match &options.supports {
        Supports::File(file) => Some(read_supports(file)?),
        Supports::Ids(ids) => Some(ids.clone()),
        _ => None,
    };
    let is_stl = MeshFormat::from_path(path)?.is_single_precision();
    let tolerance = (options.weld_tolerance).or(is_stl.then_some(super::DEFAULT_WELD_TOLERANCE));
    let n_file = positions.len();
    let (welded, summary) = match tolerance {
        Some(t) => {
            let w = weld(&positions, &faces, t)?;
            let summary = WeldSummary {
                input_vertices: n_file,
                merged: w.merged,
                relative_tolerance: t,
                tolerance: w.tolerance,
                collapsed_faces: w.collapsed_faces.clone(),
            };
            (w, Some(summary))
        }
        None => (unwelded(positions, faces), None),
    };
    let anchored = match (&options.supports, file_ids) {
        (_, Some(ids)) => welded.map_ids(&ids)?,
        (
            Supports::Lowest {
                tolerance,
                absolute,
            },
            None,
        ) => lowest_vertices(&welded.positions, &welded.faces, *tolerance, *absolute),
        _ => boundary_vertices(&welded.faces),
    };
    let Welded {
        mut positions,
        mut faces,
        welded_id,
        ..
    } = welded;
    if options.repair_tolerance == 0.0 {
        reject_slivers(&positions, &faces, &anchored)?;
    }
    let repairs = repair_plan(
        &mut positions,
        &mut faces,
        &anchored,
        options.repair_tolerance,
    )?;
    let mesh = Mesh::new(positions, faces, &anchored)?;
    // Welding or a repair's flip may have removed a diagonal: only the edges left count.
    let diagonals =
        mesh.interior_edges_among((diagonals.iter()).map(|d| d.map(|v| welded_id[v as usize])));
    let problem = Problem::new(mesh).with_polygon_diagonals(&diagonals)?;
    Ok(Model {
        problem,
        welded_ids: welded_id,
        weld: summary,
        repairs,
        diagonals,
        source: path.display().to_string(),
        options: options.clone(),
    })
}

/// The file's vertices as they are, as a [`Welded`] that merged nothing.
fn unwelded(positions: Vec<[f64; 3]>, faces: Vec<[u32; 3]>) -> Welded {
    Welded {
        welded_id: (0..positions.len() as u32).collect(),
        positions,
        faces,
        merged: 0,
        collapsed_faces: Vec::new(),
        tolerance: 0.0,
    }
}

/// The vertices on an edge of a single face, in id order.
fn boundary_vertices(faces: &[[u32; 3]]) -> Vec<u32> {
    let mut uses: HashMap<(u32, u32), usize> = HashMap::new();
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
/// relative to the bounding box diagonal of those vertices unless `absolute`. Face ids out of
/// range are left for [`Mesh::new`] to report.
fn lowest_vertices(
    positions: &[[f64; 3]],
    faces: &[[u32; 3]],
    tol: f64,
    absolute: bool,
) -> Vec<u32> {
    let mut referenced = vec![false; positions.len()];
    for &v in faces.iter().flatten() {
        if let Some(r) = referenced.get_mut(v as usize) {
            *r = true;
        }
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
