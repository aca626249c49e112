//! OctoMap's plain-text scan log, the input of `log2graph`:
//!
//! ```text
//! NODE x y z roll pitch yaw
//! x y z
//! x y z
//! NODE ...
//! ```
//!
//! The `NODE` line gives the sensor pose (roll, pitch, yaw in radians, OctoMap's
//! convention); the lines after it are that scan's points in the sensor frame. As in
//! `log2graph`, lines that are empty or begin with `#` or a space are skipped, a line
//! is a node when it begins with `NODE`, numbers are read as `f32`, and words after
//! the numbers a line needs are ignored. Unlike `log2graph`, a malformed number is an
//! error naming its line and column (OctoMap would insert a garbage point), as is one
//! past `f32` (`1e39`; `inf` written as such is read), and a last line without a
//! newline is read (OctoMap drops it).

use super::{check_budget, syntax, words, PointFrame, ScanRecord};
use crate::io::{text_number, text_start, FormatError};

/// Parses a scan log.
///
/// # Errors
/// [`FormatError::Syntax`] naming the line and column of a malformed or missing
/// number, or of a point before the first `NODE`; [`FormatError::TooLarge`] past
/// [`super::MAX_SCAN_POINTS`].
pub fn parse(bytes: &[u8]) -> Result<Vec<ScanRecord>, FormatError> {
    let mut scans: Vec<ScanRecord> = Vec::new();
    let mut total = 0usize;
    for (i, raw) in text_start(bytes)?.split(|&b| b == b'\n').enumerate() {
        let line_no = i + 1;
        let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
        if raw.is_empty() || raw[0] == b'#' || raw[0] == b' ' {
            continue;
        }
        let line = std::str::from_utf8(raw)
            .map_err(|e| syntax(line_no, e.valid_up_to() + 1, "not UTF-8 text"))?;
        if line.starts_with("NODE") {
            let v: [f64; 6] = numbers(line_no, line, 1)?;
            if v.iter().any(|x| !x.is_finite()) {
                return Err(syntax(line_no, 1, "the node's pose is not finite"));
            }
            scans.push(ScanRecord {
                translation: [v[0], v[1], v[2]],
                rpy: [v[3], v[4], v[5]],
                points: Vec::new(),
                frame: PointFrame::Sensor,
            });
        } else {
            let Some(scan) = scans.last_mut() else {
                return Err(syntax(
                    line_no,
                    1,
                    "a point before the first `NODE x y z roll pitch yaw` line",
                ));
            };
            let p: [f64; 3] = numbers(line_no, line, 0)?;
            total += 1;
            check_budget(total)?;
            scan.points.push(p);
        }
    }
    Ok(scans)
}

/// The `N` numbers of a line after its first `skip` words, each read as `f32`.
fn numbers<const N: usize>(
    line_no: usize,
    line: &str,
    skip: usize,
) -> Result<[f64; N], FormatError> {
    let mut w = words(line).skip(skip);
    let mut out = [0.0; N];
    for (k, x) in out.iter_mut().enumerate() {
        let Some((col, word)) = w.next() else {
            let what = if skip == 1 {
                "a node needs `NODE x y z roll pitch yaw`"
            } else {
                "a point needs three numbers `x y z`"
            };
            return Err(syntax(
                line_no,
                line.len() + 1,
                format!("{what}; found {k}"),
            ));
        };
        *x = text_number::real32(word).map_err(|m| syntax(line_no, col, m))?;
    }
    Ok(out)
}
