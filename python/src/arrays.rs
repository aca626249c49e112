//! numpy arrays in and out: N×3 coordinate arrays without per-element Python work.

use numpy::{IntoPyArray, PyArray2, PyArrayMethods, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// An N×3 array as rows (one copy; any memory layout).
pub fn rows<T: numpy::Element + Copy>(arr: &PyReadonlyArray2<'_, T>) -> PyResult<Vec<[T; 3]>> {
    let a = arr.as_array();
    if a.ncols() != 3 {
        return Err(PyValueError::new_err(format!(
            "expected an N×3 array, got shape {:?}",
            a.shape()
        )));
    }
    if let Some(flat) = a.as_slice() {
        return Ok(flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect());
    }
    Ok(a.rows().into_iter().map(|r| [r[0], r[1], r[2]]).collect())
}

/// Rows as an N×3 array: the vector is handed to numpy without a copy.
pub fn to_array<'py, T: numpy::Element + Copy>(
    py: Python<'py>,
    rows: Vec<[T; 3]>,
) -> PyResult<Bound<'py, PyArray2<T>>> {
    let n = rows.len();
    let mut rows = std::mem::ManuallyDrop::new(rows);
    let (ptr, len, cap) = (rows.as_mut_ptr(), rows.len(), rows.capacity());
    // SAFETY: `[T; 3]` has the alignment of `T` and three times its size, so the
    // allocation of `cap` rows is one of `3 * cap` elements of `T`, holding `3 * len`
    // initialised ones; ownership moves to the new vector (the old one is not dropped).
    let flat = unsafe { Vec::from_raw_parts(ptr.cast::<T>(), 3 * len, 3 * cap) };
    flat.into_pyarray(py).reshape([n, 3])
}
