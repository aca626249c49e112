//! Point clouds without a pose: `.xyz` float points and `.ply` vertices. Each file is
//! one scan in the sensor frame at the identity pose (the sensor at the world origin);
//! `tesseral map --origin` or `--pose` places it.

use super::{check_budget, syntax, PointFrame, ScanRecord};
use crate::io::{text_number, text_start, FormatError};

/// Parses `.xyz` points: one point per line, its first three numbers (separated by
/// white space or commas) its `x y z`; further columns (intensity, colour) are
/// ignored; `#` starts a comment; blank lines are skipped; a UTF-8 byte order mark
/// is skipped. `nan` and `inf` are read (mapping skips and counts them).
///
/// # Errors
/// [`FormatError::Syntax`] naming the line and column of a malformed or missing
/// number, or of one out of range (`1e400`); [`FormatError::TooLarge`] past
/// [`super::MAX_SCAN_POINTS`].
///
/// ```
/// let s = tesseral::io::scan::cloud::parse_xyz(b"# a cloud\n1 2 3\n4.5,5,6 255\n").unwrap();
/// assert_eq!(s.points, vec![[1.0, 2.0, 3.0], [4.5, 5.0, 6.0]]);
/// ```
pub fn parse_xyz(bytes: &[u8]) -> Result<ScanRecord, FormatError> {
    let mut points = Vec::new();
    for (i, raw) in text_start(bytes)?.split(|&b| b == b'\n').enumerate() {
        let line_no = i + 1;
        let content = raw.split(|&b| b == b'#').next().unwrap_or_default();
        let line = std::str::from_utf8(content)
            .map_err(|e| syntax(line_no, e.valid_up_to() + 1, "not UTF-8 text"))?;
        let mut words = line
            .split(|c: char| c.is_ascii_whitespace() || c == ',')
            .scan(0usize, |at, w| {
                let col = *at + 1;
                *at += w.len() + 1;
                Some((col, w))
            })
            .filter(|(_, w)| !w.is_empty())
            .peekable();
        if words.peek().is_none() {
            continue;
        }
        let mut p = [0.0; 3];
        for (k, x) in p.iter_mut().enumerate() {
            let Some((col, w)) = words.next() else {
                return Err(syntax(
                    line_no,
                    line.trim_end().len() + 1,
                    format!("a point needs three numbers `x y z`; found {k}"),
                ));
            };
            *x = text_number::real(w).map_err(|m| syntax(line_no, col, m))?;
        }
        points.push(p);
        check_budget(points.len())?;
    }
    Ok(ScanRecord {
        points,
        ..ScanRecord::default()
    })
}

/// Parses the `vertex` element of a PLY file (ASCII, binary little- or big-endian)
/// with the mesh reader, [`crate::io::mesh::parse_ply`]; faces, if any, are ignored.
/// NaN or infinite coordinates (a sensor's missing returns) are kept, for the map
/// to skip and count, as in `.xyz` and `.pcd`.
///
/// # Errors
/// As [`crate::io::mesh::parse_ply`] (line and column for ASCII, byte offset for
/// binary) but for non-finite coordinates; [`FormatError::Corrupt`] for a file
/// without vertices.
pub fn parse_ply(bytes: &[u8]) -> Result<ScanRecord, FormatError> {
    let mesh = crate::io::mesh::parse_ply_points(bytes)?;
    check_budget(mesh.positions.len())?;
    Ok(ScanRecord {
        points: mesh.positions,
        frame: PointFrame::Sensor,
        ..ScanRecord::default()
    })
}
