//! Numbers in text formats, read by the type a file declares for them: a real whose
//! literal overflows (`1e400`) is out of range rather than infinite (`inf` and `nan`
//! written as such are read), and a whole-number type takes whole numbers within
//! its range. Each error is the rest of a sentence that starts with the word.

/// A real number, as `f64`.
pub(crate) fn real(w: &str) -> Result<f64, String> {
    let v: f64 = w.parse().map_err(|_| format!("`{w}` is not a number"))?;
    finite_or_literal(w, v.is_infinite()).map(|()| v)
}

/// A real number read as `f32` (a 4-byte float, rounded once from the decimal),
/// returned as `f64`.
pub(crate) fn real32(w: &str) -> Result<f64, String> {
    let v: f32 = w.parse().map_err(|_| format!("`{w}` is not a number"))?;
    finite_or_literal(w, v.is_infinite()).map(|()| f64::from(v))
}

/// A whole number from `min` to `max` (a `kind` such as "`uchar`" or "a 1-byte
/// unsigned field" names the type in errors). `2.0` is whole; `1.5` is not.
pub(crate) fn whole(w: &str, min: i128, max: i128, kind: &str) -> Result<f64, String> {
    let v = match w.parse::<i128>() {
        Ok(v) => v,
        Err(_) => {
            let f: f64 = w.parse().map_err(|_| format!("`{w}` is not a number"))?;
            if f.fract() != 0.0 || !f.is_finite() {
                return Err(format!("`{w}` is not a whole number"));
            }
            if f.abs() > 1e30 {
                return Err(format!("`{w}` is out of range for {kind}"));
            }
            f as i128
        }
    };
    if v < min || v > max {
        return Err(format!("`{w}` is out of range for {kind}"));
    }
    Ok(v as f64)
}

/// The range of an integer of `bytes` bytes, signed or not.
pub(crate) fn int_range(bytes: usize, signed: bool) -> (i128, i128) {
    let bits = 8 * bytes as u32;
    if signed {
        (-(1i128 << (bits - 1)), (1i128 << (bits - 1)) - 1)
    } else {
        (0, (1i128 << bits) - 1)
    }
}

/// An infinite value is read only from a literal `inf` or `infinity`.
fn finite_or_literal(w: &str, infinite: bool) -> Result<(), String> {
    let t = w.trim_start_matches(['+', '-']);
    if infinite && !t.eq_ignore_ascii_case("inf") && !t.eq_ignore_ascii_case("infinity") {
        return Err(format!("`{w}` is out of range"));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_and_literals() {
        assert_eq!(real("1e300"), Ok(1e300));
        assert!(real("1e400").unwrap_err().contains("out of range"));
        assert!(real("-1E400").unwrap_err().contains("out of range"));
        assert!(real("-inf").unwrap().is_infinite());
        assert!(real("Infinity").unwrap().is_infinite());
        assert!(real("nan").unwrap().is_nan());
        assert!(real("x").unwrap_err().contains("not a number"));
        assert_eq!(real32("0.1"), Ok(f64::from(0.1f32)));
        assert!(real32("1e39").unwrap_err().contains("out of range"));
        assert!(real32("inf").unwrap().is_infinite());
        let (lo, hi) = int_range(1, false);
        assert_eq!((lo, hi), (0, 255));
        assert_eq!(whole("255", lo, hi, "u8"), Ok(255.0));
        assert_eq!(whole("2.0", lo, hi, "u8"), Ok(2.0));
        assert!(whole("256", lo, hi, "u8")
            .unwrap_err()
            .contains("out of range"));
        assert!(whole("-1", lo, hi, "u8")
            .unwrap_err()
            .contains("out of range"));
        assert!(whole("1.5", lo, hi, "u8")
            .unwrap_err()
            .contains("not a whole"));
        assert!(whole("nan", lo, hi, "u8")
            .unwrap_err()
            .contains("not a whole"));
        assert!(whole("1e40", lo, hi, "u8")
            .unwrap_err()
            .contains("out of range"));
        assert_eq!(int_range(8, true), (i64::MIN.into(), i64::MAX.into()));
        assert_eq!(int_range(8, false).1, u64::MAX.into());
        assert!(whole("18446744073709551616", 0, int_range(8, false).1, "u64").is_err());
    }
}
