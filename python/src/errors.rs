//! The Python exceptions, carrying the CLI's messages.

use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

create_exception!(tesseral, FormatError, PyValueError, "A file that cannot be read or written: bad format, bad data, or an input/output error (its message names the file).");
create_exception!(tesseral, SceneError, PyValueError, "A scene that does not parse or build; `line` and `column` locate a parse error (None otherwise).");
create_exception!(tesseral, OctreeError, PyValueError, "An octree operation that cannot be done: frames that do not line up, a result outside the lattice, a bad argument.");

/// A file error: an `OSError` when the system refused (missing file, permissions),
/// else a `FormatError`.
pub fn format(e: tesseral::io::FormatError) -> PyErr {
    match e.kind() {
        tesseral::io::FormatError::Io(io) if io.kind() != std::io::ErrorKind::InvalidData => {
            pyo3::exceptions::PyOSError::new_err(e.to_string())
        }
        _ => FormatError::new_err(e.to_string()),
    }
}

/// A scene error, with `line` and `column` set for a parse error.
pub fn scene(py: Python<'_>, e: tesseral::csg::SceneError) -> PyErr {
    let err = SceneError::new_err(e.to_string());
    let (line, column) = e
        .diagnostic()
        .map_or((None, None), |d| (Some(d.line), Some(d.column)));
    let value = err.value(py);
    let _ = value.setattr("line", line);
    let _ = value.setattr("column", column);
    err
}

/// Any octree or model error.
pub fn octree(e: impl std::fmt::Display) -> PyErr {
    OctreeError::new_err(e.to_string())
}
