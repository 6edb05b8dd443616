//! `Mesh`: a validated mesh and its loading (a `voussoir::Problem`), from arrays or a file.

use crate::errors::{from_error, invalid, VoussoirError};
use numpy::{PyArray1, PyArray2, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use std::path::PathBuf;
use voussoir::io::{read_model, Model, ReadOptions, Supports, UpAxis};
use voussoir::{Mesh as RustMesh, Problem};

/// A validated triangle mesh with its supports and loads (native half of `voussoir.Mesh`).
#[pyclass(frozen, module = "voussoir._voussoir")]
pub struct Mesh {
    /// The problem and how it was read (`Model::from_problem` for arrays).
    pub model: Model,
}

/// Rows of `width` numbers from an array of shape (n, width) (or (n,) when `width` is 1).
fn rows<T: numpy::Element + Copy>(
    name: &str,
    array: &PyReadonlyArrayDyn<'_, T>,
    width: usize,
) -> PyResult<Vec<T>> {
    let shape = array.shape();
    let ok = match shape {
        [_] => width == 1,
        [_, w] => *w == width,
        _ => false,
    };
    if !ok {
        let want = if width == 1 {
            "(n,)".to_string()
        } else {
            format!("(n, {width})")
        };
        return Err(invalid(
            name,
            format_args!("has shape {}, expected {want}", shape_text(shape)),
        ));
    }
    Ok(array.as_array().iter().copied().collect())
}

/// Vertex or face ids: non-negative and within u32.
fn ids(name: &str, values: Vec<i64>, width: usize) -> PyResult<Vec<u32>> {
    values
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            u32::try_from(v).map_err(|_| {
                // Rows name the face (or pair) and its place, not the flattened entry.
                let at = match width {
                    1 => format!("entry {i}"),
                    3 => format!("face {}, corner {}", i / 3, i % 3),
                    _ => format!("row {}, entry {}", i / width, i % width),
                };
                VoussoirError::new_err(format!(
                    "argument `{name}`: {at} is {v}, not a vertex id (0 to {})",
                    u32::MAX
                ))
            })
        })
        .collect()
}

/// A shape as Python prints it: `(5,)`, `(5, 2)`.
pub fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => {
            let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
            format!("({})", dims.join(", "))
        }
    }
}

fn triples<T: Copy>(flat: &[T]) -> Vec<[T; 3]> {
    flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
}

impl Mesh {
    /// The problem, with its loads.
    pub fn problem(&self) -> &Problem {
        &self.model.problem
    }

    fn mesh(&self) -> &RustMesh {
        &self.model.problem.mesh
    }

    /// Faces in the orientation they were given (the library stores them counter-clockwise).
    pub fn input_faces(&self) -> Vec<[u32; 3]> {
        self.mesh().input_faces()
    }
}

/// Per-row values checked as the C API's `set_rows` checks them, then handed to `set`.
fn loads(
    problem: Problem,
    name: &str,
    array: Option<PyReadonlyArrayDyn<'_, f64>>,
    width: usize,
    per_face: bool,
    set: impl FnOnce(Problem, Vec<f64>) -> voussoir::Result<Problem>,
) -> PyResult<Problem> {
    let Some(array) = array else {
        return Ok(problem);
    };
    let m = &problem.mesh;
    let (expected, what) = if per_face {
        (m.n_faces(), "face")
    } else {
        (m.n_vertices(), "vertex")
    };
    // A single number stands for every row (`face_density=2.0`).
    let values = match array.shape() {
        [] if width == 1 => vec![array.as_array().iter().copied().next().unwrap_or(0.0); expected],
        _ => rows(name, &array, width)?,
    };
    let n = values.len() / width;
    if n != expected {
        return Err(invalid(
            name,
            format_args!("has {n} rows, expected {expected} (one row per {what})"),
        ));
    }
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(invalid(
            name,
            format_args!("entry {i} (row {}) is {}", i / width, values[i]),
        ));
    }
    set(problem, values).map_err(|e| match e {
        voussoir::Error::InvalidArgument { reason, .. } => invalid(name, reason),
        e => from_error(name, e),
    })
}

type Array<'py> = Option<PyReadonlyArrayDyn<'py, f64>>;

fn with_loads(
    problem: Problem,
    face_density: Array<'_>,
    extra_loads: Array<'_>,
    horizontal_forces: Array<'_>,
    prescribed_tau: Array<'_>,
) -> PyResult<Problem> {
    let p = loads(problem, "face_density", face_density, 1, true, |p, v| {
        p.with_face_density(v)
    })?;
    let p = loads(p, "extra_loads", extra_loads, 1, false, |p, v| {
        p.with_extra_loads(v)
    })?;
    let p = loads(
        p,
        "horizontal_forces",
        horizontal_forces,
        2,
        false,
        |p, v| p.with_horizontal_forces(v.chunks_exact(2).map(|c| [c[0], c[1]]).collect()),
    )?;
    loads(p, "prescribed_tau", prescribed_tau, 1, false, |p, v| {
        p.with_prescribed_tau(v)
    })
}

/// The problem with the polygon diagonals `pairs` ((k, 2) vertex ids) marked.
fn with_diagonals(problem: Problem, pairs: &PyReadonlyArrayDyn<'_, i64>) -> PyResult<Problem> {
    let name = "polygon_diagonals";
    let flat = match pairs.shape() {
        [0] => Vec::new(),
        _ => ids(name, rows(name, pairs, 2)?, 2)?,
    };
    let pairs: Vec<[u32; 2]> = flat.chunks_exact(2).map(|p| [p[0], p[1]]).collect();
    problem.with_polygon_diagonals(&pairs).map_err(|e| match e {
        voussoir::Error::InvalidArgument { reason, .. } => invalid(name, reason),
        e => from_error(name, e),
    })
}

/// The one way of choosing supports among `Mesh.from_file`'s keywords.
fn supports_of(
    file: Option<PathBuf>,
    ids: Option<Vec<u32>>,
    boundary: bool,
    lowest: Option<f64>,
) -> PyResult<Supports> {
    let ids = ids.filter(|ids| !ids.is_empty());
    if file.is_some() && ids.is_some() {
        return Err(invalid(
            "anchored",
            "give either `supports` or `anchored`, not both",
        ));
    }
    let given = [file.is_some(), ids.is_some(), boundary, lowest.is_some()];
    if given.iter().filter(|g| **g).count() > 1 {
        return Err(invalid(
            if boundary {
                "anchor_boundary"
            } else {
                "anchor_lowest"
            },
            "give one of `supports`, `anchored`, `anchor_boundary` and `anchor_lowest`",
        ));
    }
    Ok(match (file, ids, lowest) {
        (Some(file), _, _) => Supports::File(file),
        (_, Some(ids), _) => Supports::Ids(ids),
        (_, _, Some(tolerance)) => Supports::Lowest {
            tolerance,
            absolute: false,
        },
        _ if boundary => Supports::Boundary,
        _ => Supports::Ids(Vec::new()),
    })
}

#[pymethods]
impl Mesh {
    #[new]
    #[pyo3(signature = (vertices, faces, anchored, face_density=None, extra_loads=None, horizontal_forces=None, prescribed_tau=None, polygon_diagonals=None))]
    #[allow(clippy::too_many_arguments)]
    fn py_new(
        vertices: PyReadonlyArrayDyn<'_, f64>,
        faces: PyReadonlyArrayDyn<'_, i64>,
        anchored: PyReadonlyArrayDyn<'_, i64>,
        face_density: Array<'_>,
        extra_loads: Array<'_>,
        horizontal_forces: Array<'_>,
        prescribed_tau: Array<'_>,
        polygon_diagonals: Option<PyReadonlyArrayDyn<'_, i64>>,
    ) -> PyResult<Mesh> {
        let positions = triples(&rows("vertices", &vertices, 3)?);
        let faces = triples(&ids("faces", rows("faces", &faces, 3)?, 3)?);
        let anchored = ids("anchored", rows("anchored", &anchored, 1)?, 1)?;
        // An empty mesh is the fault of whichever array is empty.
        let arg = if positions.is_empty() {
            "vertices"
        } else {
            "faces"
        };
        let mesh = RustMesh::new(positions, faces, &anchored).map_err(|e| from_error(arg, e))?;
        let problem = with_loads(
            Problem::new(mesh),
            face_density,
            extra_loads,
            horizontal_forces,
            prescribed_tau,
        )?;
        let problem = match polygon_diagonals {
            Some(pairs) => with_diagonals(problem, &pairs)?,
            None => problem,
        };
        Ok(Mesh {
            model: Model::from_problem(problem, "arrays"),
        })
    }

    /// Reads a mesh file with `voussoir::io::read_model` (as `vsr_mesh_read` does): weld,
    /// choose the supports, mend the plan, validate, mark the polygon diagonals.
    #[staticmethod]
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (path, supports, anchored, weld_tolerance, repair_tolerance, anchor_boundary=false, anchor_lowest=None, anchor_lowest_absolute=false, up="z", face_density=None, extra_loads=None, horizontal_forces=None, prescribed_tau=None))]
    fn read(
        path: PathBuf,
        supports: Option<PathBuf>,
        anchored: Option<PyReadonlyArrayDyn<'_, i64>>,
        weld_tolerance: Option<f64>,
        repair_tolerance: f64,
        anchor_boundary: bool,
        anchor_lowest: Option<f64>,
        anchor_lowest_absolute: bool,
        up: &str,
        face_density: Array<'_>,
        extra_loads: Array<'_>,
        horizontal_forces: Array<'_>,
        prescribed_tau: Array<'_>,
    ) -> PyResult<Mesh> {
        let given = match &anchored {
            Some(a) => Some(ids("anchored", rows("anchored", a, 1)?, 1)?),
            None => None,
        };
        let supports = supports_of(supports, given, anchor_boundary, anchor_lowest)?;
        let supports = match supports {
            Supports::Lowest { tolerance, .. } => Supports::Lowest {
                tolerance,
                absolute: anchor_lowest_absolute,
            },
            other => other,
        };
        let up = up.parse::<UpAxis>().map_err(|e| match e {
            voussoir::Error::InvalidArgument { reason, .. } => invalid("up", reason),
            e => from_error("up", e),
        })?;
        let options = ReadOptions::new(supports)
            .with_weld_tolerance(weld_tolerance)
            .with_repair_tolerance(repair_tolerance)
            .with_up(up);
        let model = read_model(&path, &options).map_err(|e| match e {
            voussoir::Error::InvalidArgument { name, reason }
                if matches!(
                    name,
                    "weld_tolerance" | "repair_tolerance" | "anchor_lowest"
                ) =>
            {
                invalid(name, reason)
            }
            e if options.blames_supports_file(&e) => from_error("supports", e),
            e => from_error("path", e),
        })?;
        let mut model = model;
        model.problem = with_loads(
            model.problem,
            face_density,
            extra_loads,
            horizontal_forces,
            prescribed_tau,
        )?;
        Ok(Mesh { model })
    }

    /// Vertex positions, (n, 3) float64: x, y plan, z height.
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        crate::results::matrix(py, self.mesh().positions())
    }

    /// Faces, (m, 3) uint32, in the orientation given.
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<u32>> {
        crate::results::matrix(py, &self.input_faces())
    }

    /// Anchored vertex ids, sorted, (k,) uint32.
    #[getter]
    fn anchored<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        PyArray1::from_vec(py, self.mesh().anchored_ids())
    }

    /// Edges, (E, 2) uint32, smaller id first, sorted: row e is edge e of per-edge arrays.
    #[getter]
    fn edges<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<u32>> {
        let edges: Vec<[u32; 2]> = self.mesh().edges().iter().map(|e| e.v).collect();
        crate::results::matrix(py, &edges)
    }

    /// Per file vertex, the mesh vertex it became (welding merges some); identity for a mesh
    /// built from arrays. (n_file,) uint32.
    #[getter]
    fn welded_ids<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        PyArray1::from_slice(py, &self.model.welded_ids)
    }

    /// The marked polygon diagonals, (k, 2) uint32, smaller id first, in edge order.
    #[getter]
    fn polygon_diagonals<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<u32>> {
        crate::results::matrix(py, &self.model.problem.polygon_diagonals())
    }

    /// The plan repairs made while reading the file, one sentence each.
    #[getter]
    fn plan_repairs(&self) -> Vec<String> {
        self.model.repairs.iter().map(|r| r.to_string()).collect()
    }

    /// Number of holes (inner boundary loops).
    #[getter]
    fn n_holes(&self) -> usize {
        self.mesh().holes().count()
    }

    #[getter]
    fn face_density<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.model.problem.face_density)
    }

    #[getter]
    fn extra_loads<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.model.problem.extra_loads)
    }

    #[getter]
    fn horizontal_forces<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        crate::results::matrix(py, &self.model.problem.horizontal_forces)
    }

    #[getter]
    fn prescribed_tau<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.model.problem.prescribed_tau)
    }
}
