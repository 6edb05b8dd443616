//! `VoussoirError` and the mapping of library errors onto it, as the C API words them.

use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::PyErr;
use voussoir::Error;

create_exception!(
    _voussoir,
    VoussoirError,
    PyValueError,
    "Bad input or a failed solve: the message names the argument, vertex, face or edge at fault."
);

/// `argument `{name}`: {reason}`, the C API's wording of an invalid argument.
pub fn invalid(name: &str, reason: impl std::fmt::Display) -> PyErr {
    VoussoirError::new_err(format!("argument `{name}`: {reason}"))
}

/// A library error, prefixed with the argument at fault as the C API's `from_error` does:
/// `arg` is the argument the call was about; mesh errors name the array they come from.
pub fn from_error(arg: &str, e: Error) -> PyErr {
    use Error::*;
    let arg = match &e {
        InvalidArgument { name, .. } => python_name(name),
        NonFiniteCoordinate { .. } => "vertices",
        DegenerateFaces { .. }
        | FlippedFaces { .. }
        | OverlappingPlan { .. }
        | OverlappingFaces { .. } => "vertices",
        IndexOutOfRange { .. }
        | RepeatedVertexInFace { .. }
        | DuplicateFace { .. }
        | NonManifoldEdge { .. }
        | NonManifoldVertex { .. }
        | InconsistentOrientation { .. }
        | HoleNotCuttable { .. } => "faces",
        InvalidAnchor { .. } | UnsupportedComponent { .. } | NoSupports => "anchored",
        _ => arg,
    };
    match e {
        // Its own wording starts "invalid argument `name`": said once.
        InvalidArgument { reason, .. } => invalid(arg, reason),
        e => invalid(arg, e),
    }
}

/// The Python spelling of an argument the library names: its arrays are `vertices` and
/// `faces` in the Python signature where the C API says `positions` and `triangles`.
fn python_name(name: &str) -> &str {
    match name {
        "positions" => "vertices",
        "triangles" => "faces",
        other => other,
    }
}
