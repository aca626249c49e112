//! Integer arguments checked against their range, so that a value outside it is a
//! `ValueError` naming the argument and the range, not pyo3's `OverflowError`
//! ("out of range integral type conversion attempted") from the conversion.

use std::ops::RangeInclusive;

use pyo3::exceptions::{PyOverflowError, PyTypeError, PyValueError};
use pyo3::prelude::*;

/// `obj` as an integer: `Some` when it lies in `range`, `None` when it lies outside
/// (however large); anything but an integer is a TypeError naming `name`.
pub fn int_within(
    obj: &Bound<'_, PyAny>,
    name: &str,
    range: RangeInclusive<i64>,
) -> PyResult<Option<i64>> {
    // Told apart from an integer too large by `Int`'s extraction.
    match obj.extract::<Int>() {
        Ok(Int::Fits(n)) => Ok(i64::try_from(n).ok().filter(|n| range.contains(n))),
        Ok(Int::Huge(_)) => Ok(None),
        Err(_) => Err(PyTypeError::new_err(format!(
            "{name}: expected an integer, got {}",
            obj.repr()
                .map_or_else(|_| "?".to_owned(), |r| r.to_string())
        ))),
    }
}

/// The `N` integers of a tuple argument (such as `size` or `background`), each in
/// `range`; `rule` says what they must be, in the ValueError that names `name` and
/// shows the value.
pub fn ints_within<const N: usize>(
    obj: &Bound<'_, PyAny>,
    name: &str,
    range: RangeInclusive<i64>,
    rule: &str,
) -> PyResult<[i64; N]> {
    let shown = || {
        obj.repr()
            .map_or_else(|_| "?".to_owned(), |r| r.to_string())
    };
    let items: Vec<Bound<'_, PyAny>> = obj
        .extract()
        .ok()
        .filter(|v: &Vec<_>| v.len() == N && !obj.is_instance_of::<pyo3::types::PyString>())
        .ok_or_else(|| {
            PyTypeError::new_err(format!("{name}: expected {N} integers, got {}", shown()))
        })?;
    let mut out = [0; N];
    for (o, item) in out.iter_mut().zip(&items) {
        *o = int_within(item, name, range.clone())?.ok_or_else(|| {
            pyo3::exceptions::PyValueError::new_err(format!("{name} {}: {rule}", shown()))
        })?;
    }
    Ok(out)
}

/// An integer argument as Python gave it: its value when it fits an `i128` (every
/// `i64` and `u64` does), else its decimal text, so that a value of any size can be
/// checked against a range and shown. Anything but an integer is pyo3's TypeError
/// naming the argument, as before.
#[derive(Clone, Debug)]
pub enum Int {
    Fits(i128),
    Huge(String),
}

/// The range of `u64`, of counts and seeds.
pub const U64: RangeInclusive<i128> = 0..=u64::MAX as i128;
/// The range of `i64`, of voxel coordinates and offsets.
pub const I64: RangeInclusive<i128> = i64::MIN as i128..=i64::MAX as i128;
/// What a coordinate triple outside [`I64`] is told.
pub const I64_RULE: &str = "each of x, y, z must lie in int64 (-2**63 to 2**63 - 1)";
/// The triple (0, 0, 0), a default.
pub const ZERO3: (Int, Int, Int) = (Int::Fits(0), Int::Fits(0), Int::Fits(0));

impl<'py> FromPyObject<'py> for Int {
    fn extract_bound(obj: &Bound<'py, PyAny>) -> PyResult<Self> {
        match obj.extract::<i128>() {
            Ok(n) => Ok(Int::Fits(n)),
            Err(e) if e.is_instance_of::<PyOverflowError>(obj.py()) => {
                Ok(Int::Huge(obj.str()?.to_string()))
            }
            Err(e) => Err(e),
        }
    }
}

impl std::fmt::Display for Int {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Int::Fits(n) => write!(f, "{n}"),
            Int::Huge(s) => f.write_str(s),
        }
    }
}

impl Int {
    /// The value as a `T` when it lies in `range` (a range `T` holds), else the
    /// ValueError "`name` `value`: `rule`".
    pub fn within<T: TryFrom<i128>>(
        &self,
        name: &str,
        range: RangeInclusive<i128>,
        rule: &str,
    ) -> PyResult<T> {
        match self {
            Int::Fits(n) if range.contains(n) => T::try_from(*n).ok(),
            _ => None,
        }
        .ok_or_else(|| PyValueError::new_err(format!("{name} {self}: {rule}")))
    }
}

/// The three integers of a triple argument (such as an offset), each in `range`,
/// else the ValueError "`name` (x, y, z): `rule`".
pub fn within3<T: TryFrom<i128>>(
    v: &(Int, Int, Int),
    name: &str,
    range: RangeInclusive<i128>,
    rule: &str,
) -> PyResult<[T; 3]> {
    let one = |i: &Int| {
        i.within(name, range.clone(), rule).map_err(|_| {
            PyValueError::new_err(format!("{name} ({}, {}, {}): {rule}", v.0, v.1, v.2))
        })
    };
    Ok([one(&v.0)?, one(&v.1)?, one(&v.2)?])
}
