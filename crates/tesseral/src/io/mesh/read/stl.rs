//! STL, ASCII and binary.

use super::{parse_point, syntax, words, MAX_MESH_ELEMENTS};
use crate::io::FormatError;
use crate::mesh::TriMesh;

/// Parses STL, binary when the size matches its triangle count, ASCII otherwise.
///
/// # Errors
/// As [`read`](super::read).
pub fn parse_stl(bytes: &[u8]) -> Result<TriMesh, FormatError> {
    if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        let binary_len = 84 + 50 * n as u64;
        let text = crate::io::strip_bom(bytes);
        let looks_ascii = text.trim_ascii_start().starts_with(b"solid")
            && text.iter().take(1024).all(|b| b.is_ascii());
        if bytes.len() as u64 == binary_len || (!looks_ascii && bytes.len() as u64 > binary_len) {
            return parse_stl_binary(bytes, n);
        }
        if !looks_ascii {
            crate::io::text_start(bytes)?;
            return Err(FormatError::corrupt(format!(
                "binary STL header says {n} triangles ({binary_len} bytes), the file has {} bytes",
                bytes.len()
            )));
        }
    }
    // A byte order mark before `solid` is skipped.
    parse_stl_ascii(crate::io::text_start(bytes)?)
}

fn parse_stl_binary(bytes: &[u8], n: usize) -> Result<TriMesh, FormatError> {
    if n > MAX_MESH_ELEMENTS {
        return Err(FormatError::too_large(format!("{n} triangles")));
    }
    let mut m = TriMesh {
        positions: Vec::with_capacity(3 * n),
        triangles: Vec::with_capacity(n),
        colors: Vec::new(),
    };
    for t in 0..n {
        let rec = &bytes[84 + 50 * t..84 + 50 * t + 50];
        for v in 0..3 {
            let mut p = [0.0; 3];
            for (a, x) in p.iter_mut().enumerate() {
                let o = 12 + 12 * v + 4 * a;
                let f = f32::from_le_bytes([rec[o], rec[o + 1], rec[o + 2], rec[o + 3]]);
                if !f.is_finite() {
                    return Err(FormatError::corrupt(format!(
                        "triangle {t}: coordinate at byte {} is not finite",
                        84 + 50 * t + o
                    )));
                }
                *x = f64::from(f);
            }
            m.positions.push(p);
        }
        let b = 3 * t as u32;
        m.triangles.push([b, b + 1, b + 2]);
    }
    Ok(m)
}

fn parse_stl_ascii(bytes: &[u8]) -> Result<TriMesh, FormatError> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        FormatError::corrupt(format!(
            "ASCII STL is not UTF-8 at byte {}",
            e.valid_up_to()
        ))
    })?;
    let mut m = TriMesh::default();
    let mut saw_solid = false;
    // Whether the last solid was closed: a file cut short loses its tail silently
    // otherwise.
    let mut ended = false;
    let mut last_line = 0;
    for (i, line) in text.lines().enumerate() {
        let mut ws = words(line);
        let Some((col, key)) = ws.next() else {
            continue;
        };
        last_line = i + 1;
        match key {
            "solid" => {
                saw_solid = true;
                ended = false;
            }
            "endsolid" => ended = true,
            "vertex" => {
                let p = parse_point(&mut ws, i + 1, line, "vertex")?;
                if m.positions.len() >= 3 * MAX_MESH_ELEMENTS {
                    return Err(FormatError::too_large("too many vertices"));
                }
                m.positions.push(p);
            }
            "facet" | "outer" | "endloop" | "endfacet" => {}
            other => {
                return Err(syntax(
                    i + 1,
                    col,
                    format!("unexpected `{other}` in ASCII STL"),
                ));
            }
        }
    }
    if !saw_solid {
        return Err(syntax(1, 1, "not an STL file (no `solid`)"));
    }
    if !ended {
        return Err(syntax(
            last_line,
            1,
            "ASCII STL ends without `endsolid` (the file is cut short)",
        ));
    }
    if m.positions.len() % 3 != 0 {
        return Err(syntax(
            last_line,
            1,
            format!(
                "{} vertices is not a whole number of triangles",
                m.positions.len()
            ),
        ));
    }
    m.triangles = (0..m.positions.len() as u32 / 3)
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    Ok(m)
}
