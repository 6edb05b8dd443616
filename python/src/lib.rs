//! `voussoir._voussoir`: the native half of the Python package `voussoir`.
//!
//! It converts numpy arrays and keyword settings into the Rust library's types, runs the
//! solvers with the GIL released, and hands results back as numpy arrays in a dict that
//! `voussoir/_results.py` wraps in typed classes. Errors carry the C API's one-line messages,
//! with the argument named as the Python signature names it.

mod assess;
mod errors;
mod mesh;
mod results;
mod settings;
mod solve;

use pyo3::prelude::*;

#[pymodule]
fn _voussoir(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // numpy's C API is looked up on first use, by importing numpy from Rust. Done there (in
    // the first `analyse`, say), a Ctrl-C pending from the solve interrupts that import and
    // rust-numpy panics (a PanicException, not a KeyboardInterrupt): look it up now.
    let _ = numpy::PyArray1::<f64>::zeros(m.py(), 0, false);
    m.add("VoussoirError", m.py().get_type::<errors::VoussoirError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<mesh::Mesh>()?;
    m.add_class::<solve::Warm>()?;
    m.add("WELD_TOLERANCE", voussoir::io::DEFAULT_WELD_TOLERANCE)?;
    m.add("REPAIR_TOLERANCE", voussoir::DEFAULT_REPAIR_TOLERANCE)?;
    m.add_function(wrap_pyfunction!(settings::defaults, m)?)?;
    m.add_function(wrap_pyfunction!(settings::choices, m)?)?;
    m.add_function(wrap_pyfunction!(solve::analyse, m)?)?;
    m.add_function(wrap_pyfunction!(solve::form_find, m)?)?;
    m.add_function(wrap_pyfunction!(assess::assess, m)?)?;
    m.add_function(wrap_pyfunction!(assess::min_thickness_of_family, m)?)?;
    m.add_function(wrap_pyfunction!(assess::read_surface, m)?)?;
    m.add_function(wrap_pyfunction!(assess::read_load_pattern, m)?)?;
    m.add_function(wrap_pyfunction!(solve::write_mesh, m)?)?;
    Ok(())
}
