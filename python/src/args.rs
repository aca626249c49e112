//! Integer arguments checked against their range, so that a value outside it is a
//! `ValueError` naming the argument and the range, not pyo3's `OverflowError`
//! ("out of range integral type conversion attempted") from the conversion.

use std::ops::RangeInclusive;

use pyo3::exceptions::{PyOverflowError, PyTypeError};
use pyo3::prelude::*;

/// `obj` as an integer: `Some` when it lies in `range`, `None` when it lies outside
/// (however large); anything but an integer is a TypeError naming `name`.
pub fn int_within(
    obj: &Bound<'_, PyAny>,
    name: &str,
    range: RangeInclusive<i64>,
) -> PyResult<Option<i64>> {
    match obj.extract::<i64>() {
        Ok(n) => Ok(range.contains(&n).then_some(n)),
        Err(e) if e.is_instance_of::<PyOverflowError>(obj.py()) => Ok(None),
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
