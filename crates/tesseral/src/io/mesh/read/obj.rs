//! Wavefront OBJ.

use super::{parse_point, syntax, words, MAX_MESH_ELEMENTS};
use crate::io::FormatError;
use crate::mesh::TriMesh;

/// The statements of the OBJ format (Wavefront's specification) that we read past:
/// texture and normal vertices, groups, materials, smoothing, and free-form geometry.
const OBJ_IGNORED: &[&str] = &[
    "vt",
    "vn",
    "vp",
    "l",
    "p",
    "o",
    "g",
    "s",
    "mg",
    "usemtl",
    "mtllib",
    "maplib",
    "usemap",
    "lod",
    "shadow_obj",
    "trace_obj",
    "ctech",
    "stech",
    "bevel",
    "c_interp",
    "d_interp",
    "cstype",
    "deg",
    "bmat",
    "step",
    "curv",
    "curv2",
    "surf",
    "parm",
    "trim",
    "hole",
    "scrv",
    "sp",
    "end",
    "con",
    "call",
    "csh",
];

/// The 1-based line and column of byte `offset` in `bytes`.
fn line_col(bytes: &[u8], offset: usize) -> (usize, usize) {
    let before = &bytes[..offset.min(bytes.len())];
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let col = offset
        - before
            .iter()
            .rposition(|&b| b == b'\n')
            .map_or(0, |p| p + 1)
        + 1;
    (line, col)
}

/// Parses Wavefront OBJ: `v` and `f` lines (`f` references may be `i`, `i/t`,
/// `i/t/n`, `i//n`, negative for relative). The other statements of the format are
/// read past; anything else (binary data, an unknown keyword) is an error naming
/// its line and column, so that a file that is not OBJ is never read as an empty
/// mesh.
///
/// # Errors
/// As [`read`](super::read).
pub fn parse_obj(bytes: &[u8]) -> Result<TriMesh, FormatError> {
    let bytes = crate::io::text_start(bytes)?;
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let (line, column) = line_col(bytes, e.valid_up_to());
        syntax(line, column, "not text (an OBJ file is UTF-8 text)")
    })?;
    let mut m = TriMesh::default();
    let mut poly: Vec<u32> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("");
        let mut ws = words(line);
        let Some((_, key)) = ws.next() else { continue };
        match key {
            "v" => {
                let p = parse_point(&mut ws, i + 1, line, "v")?;
                if m.positions.len() >= MAX_MESH_ELEMENTS {
                    return Err(FormatError::too_large("too many vertices"));
                }
                m.positions.push(p);
            }
            "f" => {
                poly.clear();
                for (c, w) in ws {
                    let idx = w.split('/').next().unwrap_or("");
                    let n: i64 = idx.parse().map_err(|_| {
                        syntax(i + 1, c, format!("`{w}` is not a vertex reference"))
                    })?;
                    let count = m.positions.len() as i64;
                    let k = if n > 0 { n - 1 } else { count + n };
                    if n == 0 || k < 0 || k >= count {
                        return Err(syntax(
                            i + 1,
                            c,
                            format!("vertex {n} does not exist ({count} so far)"),
                        ));
                    }
                    poly.push(k as u32);
                }
                if poly.len() < 3 {
                    return Err(syntax(i + 1, 1, "a face needs at least three vertices"));
                }
                if m.triangles.len() + poly.len() > MAX_MESH_ELEMENTS {
                    return Err(FormatError::too_large("too many triangles"));
                }
                for j in 1..poly.len() - 1 {
                    m.triangles.push([poly[0], poly[j], poly[j + 1]]);
                }
            }
            _ if OBJ_IGNORED.contains(&key) => {}
            other => {
                let col = line.find(other).map_or(1, |c| c + 1);
                let shown: String = other.chars().take(20).collect();
                return Err(syntax(
                    i + 1,
                    col,
                    format!("`{}` is not an OBJ statement", shown.escape_default()),
                ));
            }
        }
    }
    Ok(m)
}
