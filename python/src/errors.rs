//! The Python exceptions, carrying the CLI's messages.

use std::path::Path;

use pyo3::create_exception;
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::pycell::{PyRef, PyRefMut};
use pyo3::PyClass;

create_exception!(tesseral, FormatError, PyValueError, "A file that cannot be read or written: bad format, bad data, or an input/output error (its message names the file).");
create_exception!(tesseral, SceneError, PyValueError, "A scene that does not parse or build; `line` and `column` locate a parse error (None otherwise).");
create_exception!(tesseral, OctreeError, PyValueError, "An octree operation that cannot be done: frames that do not line up, a result outside the lattice, a bad argument.");

/// An input/output error on `path` as Python raises one: the `OSError` subclass of
/// its errno (`FileNotFoundError`, `IsADirectoryError`, `PermissionError`, ...) with
/// `errno`, `strerror` and `filename` set.
pub fn io(e: &std::io::Error, path: Option<&Path>) -> PyErr {
    use std::io::ErrorKind as K;
    let filename = path.map(|p| p.to_string_lossy().into_owned());
    let text = e.to_string();
    // An error made from an OS error with more words (`cannot create a file in DIR:
    // ...`) keeps its kind but not its errno: the errno of the kind stands for it.
    let errno = e.raw_os_error().or_else(|| {
        let name = match e.kind() {
            K::NotFound => "ENOENT",
            K::PermissionDenied => "EACCES",
            K::IsADirectory => "EISDIR",
            K::NotADirectory => "ENOTDIR",
            K::AlreadyExists => "EEXIST",
            _ => return None,
        };
        Python::with_gil(|py| py.import("errno")?.getattr(name)?.extract::<i32>()).ok()
    });
    let Some(errno) = errno else {
        let words = match &filename {
            Some(f) => format!("{f}: {text}"),
            None => text,
        };
        return PyErr::from(std::io::Error::new(e.kind(), words));
    };
    // `OSError(errno, strerror, filename)` makes the subclass of the errno.
    let strerror = match text.rfind(" (os error ") {
        Some(k) if text.ends_with(')') => text[..k].to_owned(),
        _ => text,
    };
    match filename {
        Some(f) => PyOSError::new_err((errno, strerror, f)),
        None => PyOSError::new_err((errno, strerror)),
    }
}

/// A file error: an `OSError` subclass when the system refused (missing file,
/// a directory, permissions), else a `FormatError`.
pub fn format(e: tesseral::io::FormatError) -> PyErr {
    match e.kind() {
        tesseral::io::FormatError::Io(err) if err.kind() != std::io::ErrorKind::InvalidData => {
            io(err, e.path())
        }
        _ => FormatError::new_err(e.to_string()),
    }
}

/// A scene error, with `line` and `column` set for a parse error; a file the system
/// would not read is an `OSError` subclass, as for `format`.
pub fn scene(py: Python<'_>, e: tesseral::csg::SceneError) -> PyErr {
    if let tesseral::csg::SceneError::Io { path, source } = &e {
        return io(source, Some(path));
    }
    let err = SceneError::new_err(e.to_string());
    let (line, column) = e
        .diagnostic()
        .map_or((None, None), |d| (Some(d.line), Some(d.column)));
    let value = err.value(py);
    let _ = value.setattr("line", line);
    let _ = value.setattr("column", column);
    err
}

/// A world file's error (`simulate`): a file the system would not read (the world
/// file, or an octree or scene it names) as an `OSError` subclass, as for `format`
/// and `scene`; a bad octree file it names as `FormatError`, a bad scene as
/// `SceneError`; the rest (bad JSON, bad values, the leaf budget) as `FormatError`.
pub fn world(py: Python<'_>, e: tesseral::motion::WorldError) -> PyErr {
    use tesseral::motion::WorldError as W;
    match e {
        W::Io { path, source } => io(&source, Some(&path)),
        W::Octree(f) => format(f),
        W::Scene(s) => scene(py, s),
        other => FormatError::new_err(other.to_string()),
    }
}

/// Any octree or model error.
pub fn octree(e: impl std::fmt::Display) -> PyErr {
    OctreeError::new_err(e.to_string())
}

/// The error of an object already in use by a call on another thread (which
/// released the GIL): pyo3's "Already mutably borrowed", said plainly.
fn busy(what: &str) -> PyErr {
    PyRuntimeError::new_err(format!(
        "this {what} is in use by a call on another thread: one {what} is not shared \
         between threads while a call on it runs (give each thread its own, or hold a \
         lock around the calls)"
    ))
}

/// `slf` borrowed to read, or the `busy` error.
pub fn borrow<'py, T: PyClass>(slf: &Bound<'py, T>, what: &str) -> PyResult<PyRef<'py, T>> {
    slf.try_borrow().map_err(|_| busy(what))
}

/// `slf` borrowed to change, or the `busy` error.
pub fn borrow_mut<'py, T: PyClass<Frozen = pyo3::pyclass::boolean_struct::False>>(
    slf: &Bound<'py, T>,
    what: &str,
) -> PyResult<PyRefMut<'py, T>> {
    slf.try_borrow_mut().map_err(|_| busy(what))
}
