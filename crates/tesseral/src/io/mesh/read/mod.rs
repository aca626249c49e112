//! Mesh parsers: STL (ASCII and binary), Wavefront OBJ, PLY (ASCII and binary, either
//! byte order). Polygons are fanned into triangles. Every parser treats its input as
//! hostile: counts in headers are checked against the bytes that are actually there
//! before anything is allocated, and errors name the line and column (text) or the
//! byte offset (binary).

use std::path::Path;

use crate::io::{extension, FormatError};
use crate::mesh::TriMesh;

mod obj;
mod ply;
mod stl;
#[cfg(test)]
mod tests;

pub use obj::parse_obj;
pub use ply::parse_ply;
pub(crate) use ply::parse_ply_points;
pub use stl::parse_stl;

/// The most vertices or triangles a mesh file may hold.
pub const MAX_MESH_ELEMENTS: usize = 1 << 26;

/// Reads a mesh by extension (`.stl`, `.obj`, `.ply`).
///
/// # Errors
/// [`FormatError::Syntax`] or [`FormatError::Corrupt`] naming where the file is bad;
/// [`FormatError::TooLarge`] past [`MAX_MESH_ELEMENTS`].
pub fn read(path: &Path) -> Result<TriMesh, FormatError> {
    let bytes = crate::io::read_limited(path, crate::io::MAX_FILE_BYTES)?;
    parse(&bytes, &extension(path)).map_err(|e| e.with_path(path))
}

/// Parses mesh bytes in the format named by `ext`.
///
/// # Errors
/// As [`read`].
pub fn parse(bytes: &[u8], ext: &str) -> Result<TriMesh, FormatError> {
    match ext {
        "stl" => parse_stl(bytes),
        "obj" => parse_obj(bytes),
        "ply" => parse_ply(bytes),
        _ => Err(FormatError::UnknownFormat {
            known: "stl, obj, ply",
        }),
    }
}

pub(super) fn syntax(line: usize, column: usize, message: impl Into<String>) -> FormatError {
    FormatError::Syntax {
        line,
        column,
        message: message.into(),
    }
}

/// Whitespace-separated words of a line with their 1-based columns.
pub(super) fn words(line: &str) -> impl Iterator<Item = (usize, &str)> {
    let base = line.as_ptr() as usize;
    line.split_ascii_whitespace()
        .map(move |w| (w.as_ptr() as usize - base + 1, w))
}

pub(super) fn parse_coord(line: usize, col: usize, w: &str) -> Result<f64, FormatError> {
    match w.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        _ => Err(syntax(line, col, format!("`{w}` is not a finite number"))),
    }
}

/// The three coordinates after `key` on line number `line_no` (text `line`).
pub(super) fn parse_point<'a>(
    ws: &mut impl Iterator<Item = (usize, &'a str)>,
    line_no: usize,
    line: &str,
    key: &str,
) -> Result<[f64; 3], FormatError> {
    let mut p = [0.0; 3];
    for x in &mut p {
        let (c, w) = ws.next().ok_or_else(|| {
            syntax(
                line_no,
                line.len() + 1,
                format!("`{key}` needs three numbers"),
            )
        })?;
        *x = parse_coord(line_no, c, w)?;
    }
    Ok(p)
}
