//! `tesseral.encode/decode/add/sub`: tesseral codes, vectorised over numpy arrays.
//! Codes are u64: 21 octal digits, coordinates 0 to 2**21 - 1 (add and sub wrap
//! per axis, as the bounded space of Ahuja & Nash). Codes come as any 1-D array or
//! list of integers (a uint64 array read where it lies), or of whole floats.

use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use tesseral::code::Space;

use crate::arrays::{cells, codes as code_array, to_array};

const SIDE: u64 = 1 << 21;

/// The codes of an N×3 integer array of coordinates in [0, 2**21): a uint64 array.
#[pyfunction]
pub fn encode<'py>(
    py: Python<'py>,
    coords: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<u64>>> {
    let c = cells(coords, "coords")?;
    if let Some(bad) = c
        .iter()
        .find(|p| p.iter().any(|&x| !(0..SIDE as i64).contains(&x)))
    {
        return Err(PyValueError::new_err(format!(
            "coordinate {bad:?} outside [0, 2**21)"
        )));
    }
    let codes: Vec<u64> = py.allow_threads(|| {
        c.iter()
            .map(|p| tesseral::code::encode(p[0] as u32, p[1] as u32, p[2] as u32))
            .collect()
    });
    Ok(codes.into_pyarray(py))
}

/// The coordinates of a 1-D array of codes (any integer dtype, a list of ints, or
/// whole floats; each in [0, 2**63)): N×3 int64.
#[pyfunction]
pub fn decode<'py>(
    py: Python<'py>,
    codes: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<i64>>> {
    let codes = code_array(codes, "codes")?;
    let c = codes.view();
    let v: Vec<[i64; 3]> = py.allow_threads(|| {
        c.iter()
            .map(|&k| tesseral::code::decode(k).map(i64::from))
            .collect()
    });
    to_array(py, v)
}

fn binary<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    f: impl Fn(&Space<u64>, u64, u64) -> u64 + Send + Sync,
) -> PyResult<Bound<'py, PyArray1<u64>>> {
    let (a, b) = (code_array(a, "a")?, code_array(b, "b")?);
    let (a, b) = (a.view(), b.view());
    if a.len() != b.len() {
        return Err(PyValueError::new_err(format!(
            "arrays of {} and {} codes",
            a.len(),
            b.len()
        )));
    }
    let s = Space::<u64>::full();
    let out: Vec<u64> =
        py.allow_threads(|| a.iter().zip(b.iter()).map(|(&x, &y)| f(&s, x, y)).collect());
    Ok(out.into_pyarray(py))
}

/// Tesseral addition of two code arrays (translation), without decoding, wrapping
/// per axis: a uint64 array. The carry out of the 21st digit is dropped, so each
/// coordinate is added modulo 2**21 (2**21 - 1 plus 1 is 0). Codes are taken as
/// `decode` takes them.
#[pyfunction]
pub fn add<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<u64>>> {
    binary(py, a, b, |s, x, y| s.add(x, y))
}

/// Tesseral subtraction a - b of two code arrays, wrapping per axis: a uint64
/// array. Each coordinate is subtracted modulo 2**21 (0 minus 1 is 2**21 - 1).
/// Codes are taken as `decode` takes them.
#[pyfunction]
pub fn sub<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<u64>>> {
    binary(py, a, b, |s, x, y| s.sub(x, y))
}
