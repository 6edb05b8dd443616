//! Masonry assessment: the envelope (a thickness, or intrados and extrados surfaces), keyword
//! settings → `AssessSettings` (converted here, checked by the library's
//! `AssessSettings::validate` as the C API's `vsr_assess_settings_set_*` are, with the same
//! reasons), and `voussoir::assess` with the GIL released.

use crate::errors::{from_error, invalid};
use crate::mesh::{shape_text, Mesh};
use crate::results::matrix;
use crate::settings;
use numpy::{PyArray1, PyArray2, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use voussoir::report::AssessmentReport;
use voussoir::{AssessResult, AssessSettings, Envelope, LoadRule, Objective, QBound, Thickness};

/// A flat float64 array of any shape (the core checks the values).
fn floats(a: &PyReadonlyArrayDyn<'_, f64>) -> Vec<f64> {
    a.as_array().iter().copied().collect()
}

/// Settings from keyword arguments, on top of the Rust defaults.
pub fn settings_from(kwargs: &Bound<'_, PyDict>) -> PyResult<AssessSettings> {
    let mut s = AssessSettings::default();
    let relative = match kwargs.get_item("q_min_kind")? {
        None => false,
        Some(v) => settings::kind("q_min_kind", &v)?,
    };
    for (key, v) in kwargs.iter() {
        let key: String = key.extract()?;
        match key.as_str() {
            "objective" => s.objective = settings::named::<Objective>(&key, &v)?,
            "fixed_supports" => s.fixed_supports = settings::flag(&key, &v)?,
            "unit_weight" => s.unit_weight = settings::number(&key, &v)?,
            "load_rule" => s.load_rule = settings::named::<LoadRule>(&key, &v)?,
            "load_pattern" => {
                s.load_pattern = if v.is_none() {
                    None
                } else {
                    let a: PyReadonlyArrayDyn<'_, f64> = v
                        .extract()
                        .map_err(|_| invalid(&key, "is not an array of float64"))?;
                    if a.shape().len() != 1 {
                        let shape = shape_text(a.shape());
                        return Err(invalid(
                            &key,
                            format_args!("has shape {shape}, expected (n,)"),
                        ));
                    }
                    Some(a.as_array().iter().copied().collect())
                };
            }
            "q_min" => {
                let q = settings::number(&key, &v)?;
                s.q_min = if relative {
                    QBound::Relative(q)
                } else {
                    QBound::Absolute(q)
                };
            }
            "q_min_kind" => {}
            "tolerance" => s.tolerance = settings::number(&key, &v)?,
            "max_iterations" => s.max_iterations = settings::count(&key, &v)?,
            _ => return Err(invalid(&key, "is not an assessment setting")),
        }
    }
    if kwargs.get_item("q_min")?.is_none() && relative {
        s.q_min = QBound::Relative(0.0);
    }
    s.validate().map_err(|e| match e {
        voussoir::Error::InvalidArgument { name, reason } => invalid(name, reason),
        e => invalid("settings", e),
    })?;
    Ok(s)
}

/// A surface given as (vertices (n, 3) float64, faces (m, 3) int64).
type Surface<'py> = (PyReadonlyArrayDyn<'py, f64>, PyReadonlyArrayDyn<'py, i64>);

/// Its vertices and faces, checked.
type Rows = (Vec<[f64; 3]>, Vec<[u32; 3]>);

fn surface(name: &str, (v, f): &Surface<'_>) -> PyResult<Rows> {
    for (what, shape) in [("vertices", v.shape()), ("faces", f.shape())] {
        if shape.len() != 2 || shape[1] != 3 {
            return Err(invalid(
                name,
                format_args!("{what} have shape {}, expected (n, 3)", shape_text(shape)),
            ));
        }
    }
    let flat = floats(v);
    let n = flat.len() / 3;
    let ids: Vec<i64> = f.as_array().iter().copied().collect();
    if let Some(k) = ids.iter().position(|&i| i < 0 || i as u64 >= n as u64) {
        return Err(invalid(
            name,
            format_args!(
                "face {} refers to vertex {}, beyond its {n} vertices",
                k / 3,
                ids[k]
            ),
        ));
    }
    let rows = flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    let faces = (ids.chunks_exact(3))
        .map(|c| [c[0] as u32, c[1] as u32, c[2] as u32])
        .collect();
    Ok((rows, faces))
}

/// The envelope of `thickness` (1 or #F values) or of intrados and extrados surfaces, and
/// the thickness when it is one value.
fn envelope(
    mesh: &voussoir::Mesh,
    thickness: Option<PyReadonlyArrayDyn<'_, f64>>,
    intrados: Option<Surface<'_>>,
    extrados: Option<Surface<'_>>,
) -> PyResult<(Envelope, Option<f64>)> {
    match (thickness, intrados, extrados) {
        (Some(t), None, None) => {
            let values = floats(&t);
            let uniform = (values.len() == 1).then(|| values[0]);
            let t = match values.len() {
                1 => Thickness::Uniform(values[0]),
                n if n == mesh.n_faces() => Thickness::PerFace(values),
                n => {
                    return Err(invalid(
                        "thickness",
                        format_args!(
                            "has {n} values: give one (uniform) or one per face ({})",
                            mesh.n_faces()
                        ),
                    ))
                }
            };
            let env = Envelope::from_thickness(mesh, &t).map_err(|e| from_error("thickness", e))?;
            Ok((env, uniform))
        }
        (None, Some(lo), Some(hi)) => {
            let (lo, hi) = (surface("intrados", &lo)?, surface("extrados", &hi)?);
            let env = Envelope::from_surfaces(mesh, (&lo.0, &lo.1), (&hi.0, &hi.1))
                .map_err(|e| from_error("intrados", e))?;
            Ok((env, None))
        }
        _ => Err(invalid(
            "thickness",
            "give the masonry's envelope: thickness, or intrados and extrados (not both)",
        )),
    }
}

/// Per-vertex values from an (n,) array; `None` or a number (applied at the supports by
/// `with_joints`) keeps `default`. Not checked here: `Envelope::with_springing` checks them.
fn per_vertex(
    name: &str,
    value: Option<&PyReadonlyArrayDyn<'_, f64>>,
    default: &[f64],
) -> PyResult<Vec<f64>> {
    match value.map(|a| (a.shape().len(), a)) {
        None | Some((0, _)) => Ok(default.to_vec()),
        Some((1, a)) => Ok(a.as_array().iter().copied().collect()),
        Some((_, a)) => Err(invalid(
            name,
            format_args!(
                "has shape {}, expected (n,) or a number",
                shape_text(a.shape())
            ),
        )),
    }
}

/// The value of a 0-d array.
fn number(value: Option<&PyReadonlyArrayDyn<'_, f64>>) -> Option<f64> {
    value
        .filter(|a| a.shape().is_empty())
        .and_then(|a| a.as_array().iter().copied().next())
}

/// The envelope with the springing joints given: a number holds at every support of `mesh`
/// (`Envelope::with_joint_at_supports`), an array gives one value per vertex; `None` keeps
/// the envelope's own.
fn with_joints(
    env: Envelope,
    mesh: &voussoir::Mesh,
    springing: Option<&PyReadonlyArrayDyn<'_, f64>>,
    reach: Option<&PyReadonlyArrayDyn<'_, f64>>,
) -> PyResult<Envelope> {
    if springing.is_none() && reach.is_none() {
        return Ok(env);
    }
    let env = env
        .with_joint_at_supports(mesh, number(springing), number(reach))
        .map_err(|e| from_error("springing", e))?;
    let s = per_vertex("springing", springing, &env.springing)?;
    let r = per_vertex("reach", reach, &env.reach)?;
    env.with_springing(s, r)
        .map_err(|e| from_error("springing", e))
}

/// The input files a report's settings name: intrados, extrados and load pattern.
type ReportFiles = (Option<String>, Option<String>, Option<String>);

/// `assess(mesh, thickness, intrados, extrados, settings, progress, report, springing,
/// reach)`: the result's fields; with `report` (the input files to name), also the
/// library's report as JSON text (`voussoir::report::AssessmentReport`, formfind's schema)
/// under `"report"`; `springing` and `reach` (a number or one per vertex) replace the
/// envelope's springing joints.
#[pyfunction]
#[pyo3(signature = (mesh, thickness, intrados, extrados, settings, progress=None, report=None,
                    springing=None, reach=None))]
#[allow(clippy::too_many_arguments)]
pub fn assess<'py>(
    py: Python<'py>,
    mesh: &Bound<'py, Mesh>,
    thickness: Option<PyReadonlyArrayDyn<'py, f64>>,
    intrados: Option<Surface<'py>>,
    extrados: Option<Surface<'py>>,
    settings: &Bound<'py, PyDict>,
    progress: Option<Bound<'py, PyAny>>,
    report: Option<ReportFiles>,
    springing: Option<PyReadonlyArrayDyn<'py, f64>>,
    reach: Option<PyReadonlyArrayDyn<'py, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let s = settings_from(settings)?;
    let m: &Mesh = mesh.get();
    let (env, uniform) = envelope(&m.problem().mesh, thickness, intrados, extrados)?;
    let env = with_joints(env, &m.problem().mesh, springing.as_ref(), reach.as_ref())?;
    if let Some(p) = &progress {
        if !p.is_none() && !p.is_callable() {
            return Err(invalid("progress", "is not callable"));
        }
    }
    let callback: Option<Py<PyAny>> = progress.filter(|p| !p.is_none()).map(Bound::unbind);
    let mut raised: Option<PyErr> = None;
    let result = crate::solve::interruptible(py, || {
        let mut hook = |k: usize, infeasibility: f64| {
            Python::attach(|py| {
                let step = || -> PyResult<bool> {
                    py.check_signals()?;
                    let Some(cb) = &callback else {
                        return Ok(true);
                    };
                    let answer = cb.call1(py, (k, infeasibility))?;
                    let answer = answer.bind(py);
                    Ok(answer.is_none() || answer.is_truthy()?)
                };
                step().unwrap_or_else(|e| {
                    raised = Some(e);
                    false
                })
            })
        };
        voussoir::assess(m.problem(), &env, &s, Some(&mut hook))
    })?;
    if let Some(e) = raised {
        return Err(e);
    }
    let result = result.map_err(|e| from_error("mesh", e))?;
    let d = fields(py, &m.problem().mesh, &env, &result)?;
    if let Some((intrados, extrados, load_pattern)) = report {
        let mut r = AssessmentReport::new(&m.model, &env, &s, &result, uniform);
        (r.settings.intrados, r.settings.extrados) = (intrados, extrados);
        r.settings.load_pattern = load_pattern;
        d.set_item("report", r.to_json())?;
    }
    Ok(d)
}

/// The fields of an assessment, with its envelope.
fn fields<'py>(
    py: Python<'py>,
    mesh: &voussoir::Mesh,
    env: &Envelope,
    r: &AssessResult,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let (vertices, detail) = crate::results::termination(&r.termination);
    let name = r.termination.name();
    d.set_item("objective", r.objective.as_str())?;
    d.set_item("feasible", r.feasible)?;
    d.set_item("termination", name)?;
    d.set_item("termination_message", r.termination_message())?;
    d.set_item("termination_vertices", PyArray1::from_vec(py, vertices))?;
    d.set_item("termination_detail", detail)?;
    d.set_item("iterations", r.iterations)?;
    d.set_item("positions", matrix(py, &r.positions))?;
    let edges: Vec<[u32; 2]> = mesh.edges().iter().map(|e| e.v).collect();
    d.set_item("edges", matrix(py, &edges))?;
    d.set_item(
        "force_densities",
        PyArray1::from_slice(py, &r.force_densities),
    )?;
    d.set_item("loads", PyArray1::from_slice(py, &r.loads))?;
    d.set_item("residuals", PyArray1::from_slice(py, &r.residuals))?;
    d.set_item("eps_inf", r.eps_inf)?;
    d.set_item("horizontal_imbalance", r.horizontal_imbalance)?;
    d.set_item("lower", PyArray1::from_slice(py, &r.lower))?;
    d.set_item("upper", PyArray1::from_slice(py, &r.upper))?;
    d.set_item("thickness_scale", r.thickness_scale)?;
    d.set_item("safety_factor", r.safety_factor)?;
    d.set_item("reactions", matrix(py, &r.reactions))?;
    d.set_item("thrust_horizontal", r.thrust_horizontal)?;
    d.set_item("load_factor", r.load_factor)?;
    d.set_item("unbounded", r.unbounded)?;
    d.set_item("worst_bound", r.worst_bound.0)?;
    d.set_item("worst_bound_vertex", r.worst_bound.1)?;
    d.set_item("worst_residual_vertex", r.worst_residual_vertex)?;
    let joint_vertices: Vec<u32> = r.joints.iter().map(|j| j.vertex).collect();
    d.set_item("joint_vertices", PyArray1::from_vec(py, joint_vertices))?;
    d.set_item("stranded", PyArray1::from_vec(py, r.stranded.clone()))?;
    let joints: Vec<[f64; 9]> = r.joints.iter().map(|j| j.row()).collect();
    d.set_item("joints", matrix(py, &joints))?;
    d.set_item("worst_joint", r.worst_joint.0)?;
    d.set_item("worst_joint_vertex", r.worst_joint.1)?;
    d.set_item("seconds", r.seconds)?;
    d.set_item("envelope_lower", PyArray1::from_slice(py, &env.lower))?;
    d.set_item("envelope_upper", PyArray1::from_slice(py, &env.upper))?;
    d.set_item("envelope_middle", PyArray1::from_slice(py, &env.middle))?;
    d.set_item(
        "face_thickness",
        PyArray1::from_slice(py, &env.face_thickness),
    )?;
    Ok(d)
}

/// Per-vertex bounds from `envelope_at(t)`: a pair (lower, upper) of n floats each, or
/// (lower, upper, springing, reach) with the springing joints too (each a number or n
/// floats; `None` keeps the default).
fn family_member(
    py: Python<'_>,
    mesh: &voussoir::Mesh,
    envelope_at: &Py<PyAny>,
    t: f64,
) -> PyResult<Envelope> {
    let answer = envelope_at.call1(py, (t,))?;
    let parts: Vec<Option<PyReadonlyArrayDyn<'_, f64>>> = (answer.bind(py).extract().ok())
        .filter(|p: &Vec<Option<PyReadonlyArrayDyn<'_, f64>>>| {
            matches!(p.len(), 2 | 4) && p[0].is_some() && p[1].is_some()
        })
        .ok_or_else(|| {
            invalid(
                "envelope_at",
                format_args!(
                    "envelope_at({t}) did not return a pair (lower, upper) or (lower, upper, \
                     springing, reach) of float arrays"
                ),
            )
        })?;
    let bound = |k: usize| parts[k].as_ref().map_or_else(Vec::new, floats);
    let (lower, upper) = (bound(0), bound(1));
    let env = Envelope::from_bounds(mesh, lower, upper, &Thickness::Uniform(t))
        .map_err(|e| from_error("envelope_at", e))?;
    match parts.get(2..4) {
        Some([springing, reach]) => with_joints(env, mesh, springing.as_ref(), reach.as_ref()),
        _ => Ok(env),
    }
}

/// `min_thickness_of_family(mesh, envelope_at, thickness, scale_tolerance, settings)`: the
/// least certified thickness of the family and its analysis' fields, with `thickness`,
/// `rounds` and `family_converged` added.
#[pyfunction]
pub fn min_thickness_of_family<'py>(
    py: Python<'py>,
    mesh: &Bound<'py, Mesh>,
    envelope_at: Bound<'py, PyAny>,
    thickness: f64,
    scale_tolerance: f64,
    settings: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyDict>> {
    if !envelope_at.is_callable() {
        return Err(invalid("envelope_at", "is not callable"));
    }
    let s = settings_from(settings)?;
    let m: &Mesh = mesh.get();
    let mesh_ref = &m.problem().mesh;
    let callback = envelope_at.unbind();
    let callback = &callback;
    let mut raised: Option<PyErr> = None;
    let found = crate::solve::interruptible(py, || {
        let member = |t: f64| {
            Python::attach(|py| {
                py.check_signals()
                    .and_then(|_| family_member(py, mesh_ref, callback, t))
            })
            .map_err(|e| {
                raised = Some(e);
                voussoir::Error::InvalidArgument {
                    name: "envelope_at",
                    reason: "raised an exception".into(),
                }
            })
        };
        voussoir::min_thickness_of_family(m.problem(), member, thickness, scale_tolerance, &s)
    })?;
    if let Some(e) = raised {
        return Err(e);
    }
    let found = found.map_err(|e| from_error("envelope_at", e))?;
    let env = family_member(py, mesh_ref, callback, found.thickness)?;
    let d = fields(py, mesh_ref, &env, &found.result)?;
    d.set_item("thickness", found.thickness)?;
    d.set_item("rounds", found.rounds)?;
    d.set_item("family_converged", found.converged)?;
    Ok(d)
}

/// Vertices (n, 3) and faces (m, 3) as numpy arrays.
type SurfaceArrays<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<u32>>);

/// `read_surface(path, up)`: an intrados or extrados file in the Z-up frame
/// (`voussoir::io::read_surface`): (vertices (n, 3) float64, faces (m, 3) uint32).
#[pyfunction]
pub fn read_surface<'py>(
    py: Python<'py>,
    path: std::path::PathBuf,
    up: &str,
) -> PyResult<SurfaceArrays<'py>> {
    let up = up.parse().map_err(|e| from_error("up", e))?;
    let (positions, faces) =
        voussoir::io::read_surface(&path, up).map_err(|e| from_error("path", e))?;
    Ok((matrix(py, &positions), matrix(py, &faces)))
}

/// `read_load_pattern(mesh, path)`: a live load pattern file as a load per mesh vertex
/// (`voussoir::io::read_load_pattern`, file vertex ids mapped by the mesh's welding).
#[pyfunction]
pub fn read_load_pattern<'py>(
    py: Python<'py>,
    mesh: &Bound<'py, Mesh>,
    path: std::path::PathBuf,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let m: &Mesh = mesh.get();
    let n = m.problem().mesh.n_vertices();
    let loads = voussoir::io::read_load_pattern(&path, &m.model.welded_ids, n)
        .map_err(|e| from_error("load_pattern", e))?;
    Ok(PyArray1::from_vec(py, loads))
}
