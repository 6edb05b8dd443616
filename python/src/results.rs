//! Results as dicts of numpy arrays and numbers (wrapped in typed classes by `_results.py`).

use numpy::{PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use voussoir::{FormFindResult, Mesh, StressResult, Termination};

/// An (n, W) array from rows of W numbers.
pub fn matrix<'py, T: numpy::Element + Copy, const W: usize>(
    py: Python<'py>,
    rows: &[[T; W]],
) -> Bound<'py, PyArray2<T>> {
    let flat: Vec<T> = rows.iter().flatten().copied().collect();
    let array = PyArray1::from_vec(py, flat);
    array
        .reshape([rows.len(), W])
        .expect("a flat array of n * W entries reshapes to (n, W)")
}

use numpy::PyArrayMethods;

/// The fields of a stress result at `positions`.
pub fn stress<'py>(
    py: Python<'py>,
    mesh: &Mesh,
    positions: &[[f64; 3]],
    s: &StressResult,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("status", s.status.as_str())?;
    d.set_item("positions", matrix(py, positions))?;
    let edges: Vec<[u32; 2]> = mesh.edges().iter().map(|e| e.v).collect();
    d.set_item("edges", matrix(py, &edges))?;
    d.set_item(
        "force_densities",
        PyArray1::from_slice(py, &s.force_densities),
    )?;
    d.set_item("airy", PyArray1::from_slice(py, &s.airy))?;
    d.set_item("weights", PyArray1::from_slice(py, &s.weights))?;
    d.set_item("hole_coefficients", matrix(py, &s.hole_coefficients))?;
    d.set_item("tau", PyArray1::from_slice(py, &s.tau))?;
    d.set_item("external_horizontal", matrix(py, &s.external_horizontal))?;
    d.set_item("loads", PyArray1::from_slice(py, &s.loads))?;
    d.set_item("residuals", PyArray1::from_slice(py, &s.residuals))?;
    d.set_item("horizontal_imbalance", matrix(py, &s.horizontal_imbalance))?;
    d.set_item("eps_inf", s.eps_inf)?;
    d.set_item("objective", s.objective)?;
    d.set_item(
        "force_diagram_centres",
        matrix(py, &s.force_diagram.centres),
    )?;
    let (segments, segment_edges): (Vec<[f64; 4]>, Vec<u32>) = s
        .force_diagram
        .segments
        .iter()
        .enumerate()
        .filter_map(|(e, seg)| seg.map(|[a, b]| ([a[0], a[1], b[0], b[1]], e as u32)))
        .unzip();
    let segments = matrix(py, &segments)
        .reshape([segment_edges.len(), 2, 2])
        .expect("(S, 4) reshapes to (S, 2, 2)");
    let segments: Bound<'py, PyArray3<f64>> = segments;
    d.set_item("force_diagram_segments", segments)?;
    d.set_item(
        "force_diagram_segment_edges",
        PyArray1::from_vec(py, segment_edges),
    )?;
    d.set_item("qp_iterations", s.iterations)?;
    d.set_item("formulation", s.formulation.as_str())?;
    d.set_item("qp_solver", s.solver.as_str())?;
    d.set_item("lifted", s.lifted)?;
    d.set_item("regularisation", s.regularisation)?;
    d.set_item("seconds", s.seconds)?;
    Ok(d)
}

/// (the vertices it lists, the constraint, hint or failure it names).
pub fn termination(t: &Termination) -> (Vec<u32>, Option<String>) {
    match t {
        Termination::Stalled { vertices } => (vertices.clone(), None),
        Termination::Infeasible { constraint } => (vec![], Some(constraint.clone())),
        Termination::NumericalError { what } => (vec![], Some(what.clone())),
        Termination::Blocked { vertices, hint } => (vertices.clone(), Some(hint.clone())),
        _ => (vec![], None),
    }
}

/// The fields of a form-finding result: its final stress result's plus the loop's.
pub fn form_found<'py>(
    py: Python<'py>,
    mesh: &Mesh,
    r: &FormFindResult,
) -> PyResult<Bound<'py, PyDict>> {
    let d = stress(py, mesh, &r.positions, &r.stress)?;
    let (vertices, detail) = termination(&r.termination);
    d.set_item("termination", r.termination.name())?;
    d.set_item("termination_message", r.termination.to_string())?;
    d.set_item("termination_vertices", PyArray1::from_vec(py, vertices))?;
    d.set_item("termination_detail", detail)?;
    d.set_item("history", PyArray1::from_slice(py, &r.history))?;
    d.set_item("iterations", r.iterations)?;
    let solvers: Vec<&str> = r.solvers.iter().map(|s| s.as_str()).collect();
    d.set_item("step_solvers", solvers)?;
    d.set_item("hausdorff", r.hausdorff)?;
    d.set_item("l2", r.l2)?;
    d.set_item("rms_change", r.rms_change)?;
    d.set_item("max_change", r.max_change)?;
    d.set_item("mirrored", r.mirrored)?;
    d.set_item("stress_seconds", r.stress_seconds)?;
    d.set_item("shape_seconds", r.shape_seconds)?;
    d.set_item("total_seconds", r.total_seconds)?;
    Ok(d)
}
