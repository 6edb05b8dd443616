//! The solves, with the GIL released; the progress hook re-attaches once per iteration to
//! check for Ctrl-C and to call the user's callback, either of which may cancel. Within an
//! iteration, the library's interrupt check (see [`interruptible`]) re-attaches every 50 ms or so
//! to check for Ctrl-C, so that a long step is interrupted too.

use crate::errors::{from_error, invalid};
use crate::mesh::Mesh;
use crate::results;
use crate::settings;
use numpy::{PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use voussoir::report::Report;

/// Runs `work` with the GIL released, interrupted by Ctrl-C: the library's interrupt check
/// (called between its inner iterations, at most every `voussoir::interrupt::CHECK_INTERVAL`)
/// re-attaches to run Python's signal handlers; the exception one raises (KeyboardInterrupt for
/// Ctrl-C) abandons `work` and is returned.
pub fn interruptible<T: Send>(py: Python<'_>, work: impl FnOnce() -> T + Send) -> PyResult<T> {
    let raised: Arc<Mutex<Option<PyErr>>> = Arc::default();
    let seen = Arc::clone(&raised);
    let done = py.detach(move || {
        let check = move || match Python::attach(|py| py.check_signals()) {
            Ok(()) => false,
            Err(e) => {
                *seen.lock().unwrap_or_else(|p| p.into_inner()) = Some(e);
                true
            }
        };
        voussoir::interrupt::interruptible(check, work)
    });
    let error = raised.lock().unwrap_or_else(|p| p.into_inner()).take();
    match (done, error) {
        (Some(r), _) => Ok(r),
        (None, Some(e)) => Err(e),
        (None, None) => Err(pyo3::exceptions::PyKeyboardInterrupt::new_err(())),
    }
}

fn settings_of(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<voussoir::FormFindSettings> {
    match kwargs {
        Some(k) => settings::from_kwargs(k),
        None => Ok(voussoir::FormFindSettings::default()),
    }
}

/// Stress analysis of the mesh as it stands; returns the result's fields, plus the library's
/// JSON report under "report" when `report` is true.
#[pyfunction]
#[pyo3(signature = (mesh, settings=None, report=false))]
pub fn analyse<'py>(
    py: Python<'py>,
    mesh: &Bound<'py, Mesh>,
    settings: Option<&Bound<'py, PyDict>>,
    report: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let form = settings_of(settings)?;
    let m: &Mesh = mesh.get();
    let stress = interruptible(py, || voussoir::analyse(m.problem(), &form.stress))?
        .map_err(|e| from_error("mesh", e))?;
    // A Ctrl-C during the solve is a KeyboardInterrupt now, not somewhere after.
    py.check_signals()?;
    let d = results::stress(py, &m.problem().mesh, m.problem().mesh.positions(), &stress)?;
    if report {
        let run = voussoir::report::Run::Analysis(&stress);
        d.set_item("report", Report::new(&m.model, &form, run).to_json())?;
    }
    Ok(d)
}

/// What the progress hook saw: a Python exception (KeyboardInterrupt from Ctrl-C, or one the
/// callback raised) is raised again once the solve has returned.
fn progress_step(
    py: Python<'_>,
    callback: Option<&Py<PyAny>>,
    k: usize,
    eps: f64,
) -> PyResult<bool> {
    py.check_signals()?;
    let Some(cb) = callback else {
        return Ok(true);
    };
    let answer = cb.call1(py, (k, eps))?;
    let answer = answer.bind(py);
    Ok(answer.is_none() || answer.is_truthy()?)
}

/// A form-finding result kept whole for a warm re-solve (`form_find(..., start=...)`): the
/// penalty state and solver cache that the Python fields do not carry.
#[pyclass(frozen, module = "voussoir._voussoir")]
pub struct Warm {
    pub result: voussoir::FormFindResult,
}

/// Immutable, so copies share it (`copy`, `dataclasses.asdict`); a pickled result drops it
/// (the solver state lives in this process), becoming a result without a warm start.
#[pymethods]
impl Warm {
    fn __copy__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __deepcopy__<'py>(slf: PyRef<'py, Self>, _memo: &Bound<'py, PyAny>) -> PyRef<'py, Self> {
        slf
    }

    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, ())> {
        Ok((py.None().into_bound(py).get_type().into_any(), ()))
    }
}

/// Form finding; `progress(iteration, eps_inf)` is called after every stress step. The
/// library's JSON report is added under "report" when `report` is true. With `start` (the
/// "_warm" field of an earlier result), a warm re-solve from it (`voussoir::form_find_from`).
#[pyfunction]
#[pyo3(signature = (mesh, settings=None, progress=None, report=false, start=None))]
pub fn form_find<'py>(
    py: Python<'py>,
    mesh: &Bound<'py, Mesh>,
    settings: Option<&Bound<'py, PyDict>>,
    progress: Option<Bound<'py, PyAny>>,
    report: bool,
    start: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let start: Option<Bound<'py, Warm>> = match start.filter(|s| !s.is_none()) {
        None => None,
        Some(s) => Some(
            s.cast_into::<Warm>()
                .map_err(|_| invalid("start", "is not a result of form_find (a FormFindResult)"))?,
        ),
    };
    let previous = start.as_ref().map(|w| &w.get().result);
    let form = settings_of(settings)?;
    if let Some(p) = &progress {
        if !p.is_none() && !p.is_callable() {
            return Err(invalid("progress", "is not callable"));
        }
    }
    let callback: Option<Py<PyAny>> = progress.filter(|p| !p.is_none()).map(Bound::unbind);
    let m: &Mesh = mesh.get();
    let mut raised: Option<PyErr> = None;
    let found = interruptible(py, || {
        let mut hook = |k: usize, eps: f64| {
            Python::attach(|py| match progress_step(py, callback.as_ref(), k, eps) {
                Ok(go_on) => go_on,
                Err(e) => {
                    raised = Some(e);
                    false
                }
            })
        };
        match previous {
            Some(p) => voussoir::form_find_from(m.problem(), &form, p, Some(&mut hook)),
            None => voussoir::form_find(m.problem(), &form, Some(&mut hook)),
        }
    })?;
    if let Some(e) = raised {
        return Err(e);
    }
    let found = found.map_err(|e| match e {
        voussoir::Error::InvalidArgument {
            name: "previous",
            reason,
        } => invalid("start", reason),
        e => from_error("mesh", e),
    })?;
    let d = results::form_found(py, &m.problem().mesh, &found)?;
    if report {
        let run = voussoir::report::Run::FormFinding(&found);
        d.set_item("report", Report::new(&m.model, &form, run).to_json())?;
    }
    d.set_item("_warm", Warm { result: found })?;
    Ok(d)
}

/// Writes `positions` with the mesh's faces (as given) to `path`, in the format of its
/// extension and the axes of the file the mesh was read from, all or nothing.
#[pyfunction]
pub fn write_mesh(
    mesh: &Bound<'_, Mesh>,
    positions: PyReadonlyArrayDyn<'_, f64>,
    path: PathBuf,
) -> PyResult<()> {
    let m: &Mesh = mesh.get();
    let n = m.problem().mesh.n_vertices();
    if positions.shape() != [n, 3] {
        return Err(invalid(
            "positions",
            format_args!(
                "has shape {}, expected ({n}, 3)",
                crate::mesh::shape_text(positions.shape())
            ),
        ));
    }
    let flat: Vec<f64> = positions.as_array().iter().copied().collect();
    // Written in the axes of the file the mesh was read from.
    let rows: Vec<[f64; 3]> = (flat.chunks_exact(3))
        .map(|c| m.model.options.up.to_file([c[0], c[1], c[2]]))
        .collect();
    voussoir::io::write_mesh(&path, &rows, &m.input_faces()).map_err(|e| from_error("path", e))
}
