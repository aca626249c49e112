//! numpy arrays in and out: N×3 coordinate arrays without per-element Python work.
//!
//! Points (world coordinates) and cells (integer keys) are taken from anything
//! `numpy.asarray` makes an N×3 array of numbers of: a float64 or int64 array is read
//! where it lies, a float32 one is widened as it is read, and any other dtype, byte
//! order or a list of tuples goes through `numpy.asarray` first. Errors name the
//! argument and say what was expected and what came.
//!
//! Codes (1-D, u64) are taken likewise: a uint64 array is read where it lies, any
//! other integer dtype, byte order, a list of ints or a float array of whole numbers
//! is converted, and a value that is no code (negative, past 2**63 - 1) is named.

use numpy::ndarray::ArrayView1;
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2,
    PyReadonlyArray3,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

/// An N×3 array as rows (one copy; any memory layout), each element converted.
fn rows<T: numpy::Element + Copy, U>(
    arr: &PyReadonlyArray2<'_, T>,
    name: &str,
    f: impl Fn(T) -> U,
) -> PyResult<Vec<[U; 3]>> {
    let a = arr.as_array();
    if a.ncols() != 3 {
        return Err(PyValueError::new_err(format!(
            "{name}: expected an N×3 array, got an array of shape {}",
            shape_text(a.shape())
        )));
    }
    if let Some(flat) = a.as_slice() {
        return Ok(flat
            .chunks_exact(3)
            .map(|c| [f(c[0]), f(c[1]), f(c[2])])
            .collect());
    }
    Ok(a.rows()
        .into_iter()
        .map(|r| [f(r[0]), f(r[1]), f(r[2])])
        .collect())
}

/// The rows of `obj` if it is a two-dimensional array of exactly `T` (native byte
/// order), else None.
fn rows_of<T: numpy::Element + Copy, U>(
    obj: &Bound<'_, PyAny>,
    name: &str,
    f: impl Fn(T) -> U,
) -> Option<PyResult<Vec<[U; 3]>>> {
    let a = obj.downcast::<PyArray2<T>>().ok()?;
    Some(match a.try_readonly() {
        Ok(r) => rows(&r, name, f),
        Err(e) => Err(PyValueError::new_err(format!("{name}: {e}"))),
    })
}

/// A value as an error names it: "an array", "a list", "a str", ...
fn describe(obj: &Bound<'_, PyAny>) -> String {
    let n = obj
        .get_type()
        .name()
        .map_or_else(|_| "object".to_owned(), |n| n.to_string());
    match n.as_str() {
        "ndarray" => "an array".to_owned(),
        _ if n.starts_with(['a', 'e', 'i', 'o', 'u']) => format!("an {n}"),
        _ => format!("a {n}"),
    }
}

/// A shape as Python writes it: `(5,)`, `(5, 2)`.
fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// `numpy.asarray(obj)`, its dtype and the dtype's kind ('b', 'i', 'u', 'f', 'O',
/// ...). numpy's own refusals (TypeError, ValueError) are told as `name: expected
/// …, got …`; anything else (an interrupt, a MemoryError) passes through.
fn asarray<'py>(
    obj: &Bound<'py, PyAny>,
    name: &str,
    expected: &str,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, char)> {
    let py = obj.py();
    let arr = py
        .import("numpy")?
        .call_method1("asarray", (obj,))
        .map_err(|e| {
            if !(e.is_instance_of::<PyTypeError>(py) || e.is_instance_of::<PyValueError>(py)) {
                return e;
            }
            PyValueError::new_err(format!(
                "{name}: {expected}, got {} that numpy cannot make one array of: {}",
                describe(obj),
                e.value(py)
            ))
        })?;
    let dtype = arr.getattr("dtype")?;
    let kind: char = dtype.getattr("kind")?.extract()?;
    Ok((arr, dtype, kind))
}

/// 2**63: the first float past int64.
const PAST_I64: f64 = 9_223_372_036_854_775_808.0;

/// A float that is a whole number within int64, as one.
fn whole_i64(x: f64) -> Option<i64> {
    (x.fract() == 0.0 && (-PAST_I64..PAST_I64).contains(&x)).then_some(x as i64)
}

/// Checks that point `p`, row `row` of argument `name`, lies in a cell: `lattice` is
/// its position in cells (fractional), whose floors must be within int64 (a cast
/// would saturate, or make NaN cell 0). The error names the row, the point and the
/// coordinate; `unit` is what a cell is called ("voxel", "cell").
pub fn check_cell(
    name: &str,
    unit: &str,
    row: usize,
    p: [f64; 3],
    lattice: [f64; 3],
) -> Result<(), String> {
    for (a, (&x, &c)) in ["x", "y", "z"].iter().zip(p.iter().zip(&lattice)) {
        if !x.is_finite() {
            return Err(format!(
                "{name}: row {row} is {p:?}, whose {a} is {x:?} (every coordinate must \
                 be a finite number)"
            ));
        }
        if !(-PAST_I64..PAST_I64).contains(&c) {
            return Err(format!(
                "{name}: row {row} is {p:?}, whose {a} = {x:?} lies in {unit} {:?}, \
                 past the range of int64 (-2**63 to 2**63 - 1)",
                c.floor()
            ));
        }
    }
    Ok(())
}

/// `obj` as a numpy array of numbers, N×3 (a zero-length sequence is 0×3), and its
/// dtype's kind ('i', 'u' or 'f').
fn numeric<'py>(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<(Bound<'py, PyAny>, char)> {
    let (arr, dtype, kind) = asarray(obj, name, "expected an N×3 array of numbers")?;
    if !matches!(kind, 'i' | 'u' | 'f') {
        return Err(PyTypeError::new_err(format!(
            "{name}: expected an N×3 array of numbers, got {} of dtype {}",
            describe(obj),
            dtype.str()?
        )));
    }
    let shape: Vec<usize> = arr.getattr("shape")?.extract()?;
    if shape == [0] {
        return Ok((arr.call_method1("reshape", (0, 3))?, kind));
    }
    if shape.len() != 2 || shape[1] != 3 {
        return Err(PyValueError::new_err(format!(
            "{name}: expected an N×3 array, got {} of shape {}",
            describe(obj),
            shape_text(&shape)
        )));
    }
    Ok((arr, kind))
}

/// Points in world units: any N×3 array of numbers (integers converted to float64).
pub fn points(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<[f64; 3]>> {
    if let Some(r) = rows_of::<f64, f64>(obj, name, |x| x) {
        return r;
    }
    if let Some(r) = rows_of::<f32, f64>(obj, name, f64::from) {
        return r;
    }
    let py = obj.py();
    let (arr, _) = numeric(obj, name)?;
    let f64s = arr.call_method1("astype", (numpy::dtype::<f64>(py),))?;
    rows_of::<f64, f64>(&f64s, name, |x| x).expect("astype gives float64")
}

/// Integer coordinates (cells, voxels): any N×3 array of integers, or of floats that
/// are all whole numbers in the range of int64 (anything else is refused, not
/// rounded).
pub fn cells(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<[i64; 3]>> {
    if let Some(r) = rows_of::<i64, i64>(obj, name, |x| x) {
        return r;
    }
    let py = obj.py();
    let (arr, kind) = numeric(obj, name)?;
    let as_type = |t| arr.call_method1("astype", (t,));
    // Each row back as i64, or the first value that is not one.
    let checked = |rows: Vec<[f64; 3]>| -> PyResult<Vec<[i64; 3]>> {
        rows.iter()
            .enumerate()
            .map(|(i, r)| match r.iter().find(|x| whole_i64(**x).is_none()) {
                Some(x) => Err(PyValueError::new_err(format!(
                    "{name}: expected integers, got {x} in row {i} (a float array is \
                     taken only when every value is a whole number within int64)"
                ))),
                None => Ok(r.map(|x| x as i64)),
            })
            .collect()
    };
    match kind {
        'f' => {
            let f64s = as_type(numpy::dtype::<f64>(py))?;
            let rows = rows_of::<f64, f64>(&f64s, name, |x| x).expect("astype gives float64")?;
            // Rows mixing floats with ints past 2**53 were made floats by numpy,
            // rounding the ints: read them value by value instead.
            if !obj.is_instance_of::<numpy::PyUntypedArray>()
                && rows.iter().flatten().any(|x| x.abs() >= EXACT)
            {
                return object_cells(obj, name);
            }
            checked(rows)
        }
        'u' => {
            let u64s = as_type(numpy::dtype::<u64>(py))?;
            let r = rows_of::<u64, u64>(&u64s, name, |x| x).expect("astype gives uint64")?;
            r.iter()
                .enumerate()
                .map(|(i, r)| {
                    let mut out = [0i64; 3];
                    for (o, &x) in out.iter_mut().zip(r) {
                        *o = i64::try_from(x).map_err(|_| {
                            PyValueError::new_err(format!(
                                "{name}: {x} in row {i} is past the range of int64"
                            ))
                        })?;
                    }
                    Ok(out)
                })
                .collect()
        }
        _ => {
            let i64s = as_type(numpy::dtype::<i64>(py))?;
            rows_of::<i64, i64>(&i64s, name, |x| x).expect("astype gives int64")
        }
    }
}

/// The cells of a list of rows whose floats numpy would round: each value an int
/// within int64 or a float that is a whole number there, read one by one.
fn object_cells(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<[i64; 3]>> {
    let index = obj.py().import("operator")?.getattr("index")?;
    let value = |i: usize, x: Bound<'_, PyAny>| -> PyResult<i64> {
        let refuse = || {
            PyValueError::new_err(format!(
                "{name}: expected integers, got {x} in row {i} (a value must be a whole \
                 number within int64)"
            ))
        };
        if let Ok(f) = x.downcast::<pyo3::types::PyFloat>() {
            return whole_i64(f.value()).ok_or_else(refuse);
        }
        index.call1((&x,))?.extract::<i64>().map_err(|_| refuse())
    };
    obj.try_iter()?
        .enumerate()
        .map(|(i, row)| {
            let values: Vec<Bound<'_, PyAny>> = row?.try_iter()?.collect::<PyResult<_>>()?;
            // numpy made an N×3 array of the rows: three values each, unless a row
            // changed since.
            let [x, y, z] = <[_; 3]>::try_from(values).map_err(|v| {
                PyValueError::new_err(format!("{name}: row {i} has {} values, not 3", v.len()))
            })?;
            Ok([value(i, x)?, value(i, y)?, value(i, z)?])
        })
        .collect()
}

/// A mask indexed [x, y, z]: a 3-D bool array read where it lies, or one that
/// `numpy.asarray` makes (nested lists of bools). Another dtype is a TypeError
/// (integers are not taken for bools), another number of dimensions a ValueError;
/// both name `name` and say the dtype and dimensions that came.
pub fn mask3<'py>(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<PyReadonlyArray3<'py, bool>> {
    let expected = "expected a 3-D bool array";
    let (arr, dtype, kind) = asarray(obj, name, expected)?;
    let shape: Vec<usize> = arr.getattr("shape")?.extract()?;
    let got = format!(
        "got {} of dtype {}, {}-D (shape {})",
        describe(obj),
        dtype.str()?,
        shape.len(),
        shape_text(&shape)
    );
    if kind != 'b' {
        return Err(PyTypeError::new_err(format!("{name}: {expected}, {got}")));
    }
    if shape.len() != 3 {
        return Err(PyValueError::new_err(format!("{name}: {expected}, {got}")));
    }
    let a = arr
        .downcast_into::<PyArray3<bool>>()
        .map_err(|e| PyTypeError::new_err(format!("{name}: {expected}: {e}")))?;
    a.try_readonly()
        .map_err(|e| PyValueError::new_err(format!("{name}: {e}")))
}

/// Codes of a one-dimensional argument: a uint64 array borrowed where it lies, or
/// the values of any other converted.
pub enum Codes<'py> {
    InPlace(PyReadonlyArray1<'py, u64>),
    Converted(Vec<u64>),
}

impl Codes<'_> {
    /// The codes, in order.
    pub fn view(&self) -> ArrayView1<'_, u64> {
        match self {
            Codes::InPlace(a) => a.as_array(),
            Codes::Converted(v) => ArrayView1::from(v.as_slice()),
        }
    }
}

/// Past the largest code: 21 octal digits take 63 bits.
const CODE_END: u64 = 1 << 63;

/// The error of `name[i]`, which is `value` and no code.
fn not_a_code(name: &str, i: usize, value: impl std::fmt::Display, why: &str) -> PyErr {
    PyValueError::new_err(format!("{name}[{i}] is {value}: {why}"))
}
const UNSIGNED: &str = "codes are unsigned";
const PAST: &str = "past the largest code, 2**63 - 1 (21 octal digits)";

/// The codes of `obj`: a one-dimensional array (or list) of integers, or of floats
/// that are all whole numbers, every value in [0, 2**63). A uint64 array (native
/// byte order) is read where it lies; any other is converted. A negative value, one
/// past 2**63 - 1 or a fraction is refused (ValueError naming `name[i]`), not
/// wrapped or rounded.
pub fn codes<'py>(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<Codes<'py>> {
    if let Ok(a) = obj.downcast::<PyArray1<u64>>() {
        let r = a
            .try_readonly()
            .map_err(|e| PyValueError::new_err(format!("{name}: {e}")))?;
        if let Some((i, x)) = r
            .as_array()
            .iter()
            .enumerate()
            .find(|&(_, &x)| x >= CODE_END)
        {
            return Err(not_a_code(name, i, x, PAST));
        }
        return Ok(Codes::InPlace(r));
    }
    let py = obj.py();
    let expected = "expected a 1-D array of codes";
    let (arr, dtype, kind) = asarray(obj, name, expected)?;
    if !matches!(kind, 'i' | 'u' | 'f' | 'O') {
        return Err(PyTypeError::new_err(format!(
            "{name}: {expected} (integers, or floats that are whole numbers), got {} of \
             dtype {}",
            describe(obj),
            dtype.str()?
        )));
    }
    let shape: Vec<usize> = arr.getattr("shape")?.extract()?;
    if shape.len() != 1 {
        return Err(PyValueError::new_err(format!(
            "{name}: {expected}, got {} of shape {}",
            describe(obj),
            shape_text(&shape)
        )));
    }
    let as_type = |t| arr.call_method1("astype", (t,));
    // An array of `T` in native byte order, as astype gives it.
    fn read<'py, T: numpy::Element>(a: &Bound<'py, PyAny>) -> PyReadonlyArray1<'py, T> {
        a.downcast::<PyArray1<T>>()
            .expect("astype gives the dtype asked for")
            .readonly()
    }
    match kind {
        // Widened to uint64, then read where it lies.
        'u' => codes(&as_type(numpy::dtype::<u64>(py))?, name),
        'i' => {
            let a = as_type(numpy::dtype::<i64>(py))?;
            let r = read::<i64>(&a);
            let v = r.as_array();
            v.iter()
                .enumerate()
                .map(|(i, &x)| u64::try_from(x).map_err(|_| not_a_code(name, i, x, UNSIGNED)))
                .collect::<PyResult<_>>()
                .map(Codes::Converted)
        }
        'f' => {
            let a = as_type(numpy::dtype::<f64>(py))?;
            let r = read::<f64>(&a);
            let v = r.as_array();
            // A list mixing floats with ints past 2**53 was made floats by numpy,
            // rounding the ints: read it element by element instead.
            if !obj.is_instance_of::<numpy::PyUntypedArray>() && v.iter().any(|x| x.abs() >= EXACT)
            {
                let objects = py.import("numpy")?.call_method1("array", (obj, "object"))?;
                return object_codes(&objects, name).map(Codes::Converted);
            }
            v.iter()
                .enumerate()
                .map(|(i, &x)| float_code(name, i, x))
                .collect::<PyResult<_>>()
                .map(Codes::Converted)
        }
        // Python ints past int64 and uint64 (or of both signs) make an object array.
        _ => object_codes(&arr, name).map(Codes::Converted),
    }
}

/// Past the floats that hold every whole number below them exactly (2**53).
const EXACT: f64 = 9_007_199_254_740_992.0;

/// The code of `name[i]`, a float: a whole number in [0, 2**63).
fn float_code(name: &str, i: usize, x: f64) -> PyResult<u64> {
    if x.fract() != 0.0 || x.is_nan() {
        Err(not_a_code(name, i, x, "not a whole number"))
    } else if x < 0.0 {
        Err(not_a_code(name, i, x, UNSIGNED))
    } else if x >= CODE_END as f64 {
        Err(not_a_code(name, i, x, PAST))
    } else {
        Ok(x as u64)
    }
}

/// The codes of a 1-D object array: Python ints of any size, and floats that are
/// whole numbers; anything else is named.
fn object_codes(arr: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<u64>> {
    let py = arr.py();
    let index = py.import("operator")?.getattr("index")?;
    arr.try_iter()?
        .enumerate()
        .map(|(i, x)| {
            let x = x?;
            if let Ok(f) = x.downcast::<pyo3::types::PyFloat>() {
                return float_code(name, i, f.value());
            }
            let x = match index.call1((&x,)) {
                Ok(x) => x,
                Err(e) if e.is_instance_of::<PyTypeError>(py) => {
                    return Err(PyTypeError::new_err(format!(
                        "{name}[{i}] is {}, not an integer",
                        x.repr()?
                    )))
                }
                Err(e) => return Err(e),
            };
            match x.extract::<u64>() {
                Ok(c) if c < CODE_END => Ok(c),
                _ if x.lt(0)? => Err(not_a_code(name, i, x, UNSIGNED)),
                _ => Err(not_a_code(name, i, x, PAST)),
            }
        })
        .collect()
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
