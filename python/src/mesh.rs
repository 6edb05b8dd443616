//! `Mesh`: a validated mesh and its loading (a `voussoir::Problem`), from arrays or a file.

use crate::errors::{from_error, invalid, VoussoirError};
use numpy::{PyArray1, PyArray2, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use std::path::PathBuf;
use voussoir::io::{read_mesh_with_diagonals, read_supports, weld};
use voussoir::{repair_plan, PlanRepair};
use voussoir::{Mesh as RustMesh, Problem};

/// A validated triangle mesh with its supports and loads (native half of `voussoir.Mesh`).
#[pyclass(frozen, module = "voussoir._voussoir")]
pub struct Mesh {
    pub problem: Problem,
    /// The mesh vertex of each vertex of the file it was read from.
    welded_ids: Option<Vec<u32>>,
    repairs: Vec<PlanRepair>,
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
fn ids(name: &str, values: Vec<i64>) -> PyResult<Vec<u32>> {
    values
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            u32::try_from(v).map_err(|_| {
                VoussoirError::new_err(format!(
                    "argument `{name}`: entry {i} is {v}, not a vertex id (0 to {})",
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
    fn new(problem: Problem) -> Mesh {
        Mesh {
            problem,
            welded_ids: None,
            repairs: Vec::new(),
        }
    }

    fn mesh(&self) -> &RustMesh {
        &self.problem.mesh
    }

    /// Faces in the orientation they were given (the library stores them counter-clockwise).
    pub fn input_faces(&self) -> Vec<[u32; 3]> {
        let m = self.mesh();
        if m.reversed {
            m.faces.iter().map(|&[a, b, c]| [a, c, b]).collect()
        } else {
            m.faces.clone()
        }
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
    let values = rows(name, &array, width)?;
    let m = &problem.mesh;
    let (expected, what) = if per_face {
        (m.n_faces(), "face")
    } else {
        (m.n_vertices(), "vertex")
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

fn tolerance(name: &str, value: f64) -> PyResult<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(invalid(
            name,
            format_args!("{value} is not a finite number >= 0"),
        ))
    }
}

#[pymethods]
impl Mesh {
    #[new]
    #[pyo3(signature = (vertices, faces, anchored, face_density=None, extra_loads=None, horizontal_forces=None, prescribed_tau=None))]
    fn py_new(
        vertices: PyReadonlyArrayDyn<'_, f64>,
        faces: PyReadonlyArrayDyn<'_, i64>,
        anchored: PyReadonlyArrayDyn<'_, i64>,
        face_density: Array<'_>,
        extra_loads: Array<'_>,
        horizontal_forces: Array<'_>,
        prescribed_tau: Array<'_>,
    ) -> PyResult<Mesh> {
        let positions = triples(&rows("vertices", &vertices, 3)?);
        let faces = triples(&ids("faces", rows("faces", &faces, 3)?)?);
        let anchored = ids("anchored", rows("anchored", &anchored, 1)?)?;
        let mesh =
            RustMesh::new(positions, faces, &anchored).map_err(|e| from_error("faces", e))?;
        let problem = with_loads(
            Problem::new(mesh),
            face_density,
            extra_loads,
            horizontal_forces,
            prescribed_tau,
        )?;
        Ok(Mesh::new(problem))
    }

    /// Reads a mesh file (as `vsr_mesh_read`): weld, map support ids, mend the plan, validate.
    #[staticmethod]
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (path, supports, anchored, weld_tolerance, repair_tolerance, face_density=None, extra_loads=None, horizontal_forces=None, prescribed_tau=None))]
    fn read(
        path: PathBuf,
        supports: Option<PathBuf>,
        anchored: Option<PyReadonlyArrayDyn<'_, i64>>,
        weld_tolerance: f64,
        repair_tolerance: f64,
        face_density: Array<'_>,
        extra_loads: Array<'_>,
        horizontal_forces: Array<'_>,
        prescribed_tau: Array<'_>,
    ) -> PyResult<Mesh> {
        let given = match &anchored {
            Some(a) => ids("anchored", rows("anchored", a, 1)?)?,
            None => Vec::new(),
        };
        if supports.is_some() && !given.is_empty() {
            return Err(invalid(
                "anchored",
                "give either `supports` or `anchored`, not both",
            ));
        }
        let weld_tolerance = tolerance("weld_tolerance", weld_tolerance)?;
        let repair_tolerance = tolerance("repair_tolerance", repair_tolerance)?;
        let ((positions, faces), diagonals) =
            read_mesh_with_diagonals(&path).map_err(|e| from_error("path", e))?;
        let ids = match &supports {
            Some(p) => read_supports(p).map_err(|e| from_error("supports", e))?,
            None => given,
        };
        let welded = weld(&positions, &faces, weld_tolerance).map_err(|e| from_error("path", e))?;
        let anchored = welded
            .map_ids(&ids)
            .map_err(|e| from_error("anchored", e))?;
        let (mut positions, mut faces) = (welded.positions, welded.faces);
        let repairs = repair_plan(&mut positions, &mut faces, &anchored, repair_tolerance)
            .map_err(|e| from_error("path", e))?;
        let mesh = RustMesh::new(positions, faces, &anchored).map_err(|e| from_error("path", e))?;
        // q_min does not bind the file's polygon diagonals, as in `vsr_mesh_read`.
        let diagonals = mesh.interior_edges_among(
            (diagonals.iter()).map(|d| d.map(|v| welded.welded_id[v as usize])),
        );
        let problem = Problem::new(mesh)
            .with_polygon_diagonals(&diagonals)
            .map_err(|e| from_error("path", e))?;
        let problem = with_loads(
            problem,
            face_density,
            extra_loads,
            horizontal_forces,
            prescribed_tau,
        )?;
        Ok(Mesh {
            problem,
            welded_ids: Some(welded.welded_id),
            repairs,
        })
    }

    /// Vertex positions, (n, 3) float64: x, y plan, z height.
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        crate::results::matrix(py, &self.mesh().positions)
    }

    /// Faces, (m, 3) uint32, in the orientation given.
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<u32>> {
        crate::results::matrix(py, &self.input_faces())
    }

    /// Anchored vertex ids, sorted, (k,) uint32.
    #[getter]
    fn anchored<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        let ids: Vec<u32> = (0..self.mesh().n_vertices() as u32)
            .filter(|&v| self.mesh().anchored[v as usize])
            .collect();
        PyArray1::from_vec(py, ids)
    }

    /// Edges, (E, 2) uint32, smaller id first, sorted: row e is edge e of per-edge arrays.
    #[getter]
    fn edges<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<u32>> {
        let edges: Vec<[u32; 2]> = self.mesh().edges.iter().map(|e| e.v).collect();
        crate::results::matrix(py, &edges)
    }

    /// Per file vertex, the mesh vertex it became (welding merges some); identity for a mesh
    /// built from arrays. (n_file,) uint32.
    #[getter]
    fn welded_ids<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        let ids = self
            .welded_ids
            .clone()
            .unwrap_or_else(|| (0..self.mesh().n_vertices() as u32).collect());
        PyArray1::from_vec(py, ids)
    }

    /// The plan repairs made while reading the file, one sentence each.
    #[getter]
    fn plan_repairs(&self) -> Vec<String> {
        self.repairs.iter().map(|r| r.to_string()).collect()
    }

    /// Number of holes (inner boundary loops).
    #[getter]
    fn n_holes(&self) -> usize {
        self.mesh().holes().count()
    }

    #[getter]
    fn face_density<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.problem.face_density)
    }

    #[getter]
    fn extra_loads<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.problem.extra_loads)
    }

    #[getter]
    fn horizontal_forces<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        crate::results::matrix(py, &self.problem.horizontal_forces)
    }

    #[getter]
    fn prescribed_tau<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.problem.prescribed_tau)
    }
}
