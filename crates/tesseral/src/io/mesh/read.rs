//! Mesh parsers: STL (ASCII and binary), Wavefront OBJ, PLY (ASCII and binary, either
//! byte order). Polygons are fanned into triangles. Every parser treats its input as
//! hostile: counts in headers are checked against the bytes that are actually there
//! before anything is allocated, and errors name the line and column (text) or the
//! byte offset (binary).

use std::path::Path;

use crate::io::{extension, FormatError};
use crate::mesh::TriMesh;

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

fn syntax(line: usize, column: usize, message: impl Into<String>) -> FormatError {
    FormatError::Syntax {
        line,
        column,
        message: message.into(),
    }
}

/// Whitespace-separated words of a line with their 1-based columns.
fn words(line: &str) -> impl Iterator<Item = (usize, &str)> {
    let base = line.as_ptr() as usize;
    line.split_ascii_whitespace()
        .map(move |w| (w.as_ptr() as usize - base + 1, w))
}

fn parse_coord(line: usize, col: usize, w: &str) -> Result<f64, FormatError> {
    match w.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        _ => Err(syntax(line, col, format!("`{w}` is not a finite number"))),
    }
}

/// The three coordinates after `key` on line number `line_no` (text `line`).
fn parse_point<'a>(
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

/// Parses STL, binary when the size matches its triangle count, ASCII otherwise.
///
/// # Errors
/// As [`read`].
pub fn parse_stl(bytes: &[u8]) -> Result<TriMesh, FormatError> {
    if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        let binary_len = 84 + 50 * n as u64;
        let looks_ascii = bytes.trim_ascii_start().starts_with(b"solid")
            && bytes.iter().take(1024).all(|b| b.is_ascii());
        if bytes.len() as u64 == binary_len || (!looks_ascii && bytes.len() as u64 > binary_len) {
            return parse_stl_binary(bytes, n);
        }
        if !looks_ascii {
            return Err(FormatError::corrupt(format!(
                "binary STL header says {n} triangles ({binary_len} bytes), the file has {} bytes",
                bytes.len()
            )));
        }
    }
    parse_stl_ascii(bytes)
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
/// As [`read`].
pub fn parse_obj(bytes: &[u8]) -> Result<TriMesh, FormatError> {
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

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "char" | "int8" => Self::I8,
            "uchar" | "uint8" => Self::U8,
            "short" | "int16" => Self::I16,
            "ushort" | "uint16" => Self::U16,
            "int" | "int32" => Self::I32,
            "uint" | "uint32" => Self::U32,
            "float" | "float32" => Self::F32,
            "double" | "float64" => Self::F64,
            _ => return None,
        })
    }
    fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::F64 => 8,
        }
    }
}

#[derive(Debug)]
struct Property {
    name: String,
    /// `Some(count type)` for a list.
    list: Option<Scalar>,
    ty: Scalar,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: u64,
    props: Vec<Property>,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum PlyFormat {
    Ascii,
    Little,
    Big,
}

/// A cursor over the PLY body, ASCII or binary.
struct PlyBody<'a> {
    bytes: &'a [u8],
    pos: usize,
    format: PlyFormat,
    line: usize,
}

impl PlyBody<'_> {
    fn value(&mut self, ty: Scalar) -> Result<f64, FormatError> {
        if self.format == PlyFormat::Ascii {
            while self.pos < self.bytes.len() && self.bytes[self.pos].is_ascii_whitespace() {
                if self.bytes[self.pos] == b'\n' {
                    self.line += 1;
                }
                self.pos += 1;
            }
            let start = self.pos;
            while self.pos < self.bytes.len() && !self.bytes[self.pos].is_ascii_whitespace() {
                self.pos += 1;
            }
            if start == self.pos {
                return Err(syntax(self.line, 1, "file ends inside an element"));
            }
            let w = String::from_utf8_lossy(&self.bytes[start..self.pos]);
            return match w.parse::<f64>() {
                Ok(x) if x.is_finite() => Ok(x),
                _ => Err(syntax(self.line, 1, format!("`{w}` is not a number"))),
            };
        }
        let n = ty.size();
        if self.pos + n > self.bytes.len() {
            return Err(FormatError::corrupt(format!(
                "file ends at byte {} inside an element",
                self.pos
            )));
        }
        let mut b = [0u8; 8];
        b[..n].copy_from_slice(&self.bytes[self.pos..self.pos + n]);
        if self.format == PlyFormat::Big {
            b[..n].reverse();
        }
        self.pos += n;
        let v = match ty {
            Scalar::I8 => f64::from(b[0] as i8),
            Scalar::U8 => f64::from(b[0]),
            Scalar::I16 => f64::from(i16::from_le_bytes([b[0], b[1]])),
            Scalar::U16 => f64::from(u16::from_le_bytes([b[0], b[1]])),
            Scalar::I32 => f64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::U32 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::F64 => f64::from_le_bytes(b),
        };
        if !v.is_finite() {
            return Err(FormatError::corrupt(format!(
                "value at byte {} is not finite",
                self.pos - n
            )));
        }
        Ok(v)
    }
}

/// Parses PLY (ASCII, binary little- or big-endian): the `vertex` element's `x`, `y`,
/// `z` and the `face` element's `vertex_indices` (or `vertex_index`) list; other
/// elements and properties are skipped.
///
/// # Errors
/// As [`read`].
pub fn parse_ply(bytes: &[u8]) -> Result<TriMesh, FormatError> {
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n" || w == b"end_header\r")
        .ok_or_else(|| syntax(1, 1, "no `end_header` line"))?;
    let header = String::from_utf8_lossy(&bytes[..end]);
    let mut body_start = end + 11;
    if bytes.get(end + 10) == Some(&b'\r') && bytes.get(body_start) == Some(&b'\n') {
        body_start += 1;
    }
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut header_lines = 0;
    for (i, line) in header.lines().enumerate() {
        header_lines = i + 1;
        let ws: Vec<(usize, &str)> = words(line).collect();
        let Some(&(col, key)) = ws.first() else {
            continue;
        };
        let err = |m: &str| syntax(i + 1, col, m.to_string());
        match key {
            "ply" if i == 0 => {}
            _ if i == 0 => return Err(err("not a PLY file (first line must be `ply`)")),
            "comment" | "obj_info" => {}
            "format" => {
                format = Some(match ws.get(1).map(|w| w.1) {
                    Some("ascii") => PlyFormat::Ascii,
                    Some("binary_little_endian") => PlyFormat::Little,
                    Some("binary_big_endian") => PlyFormat::Big,
                    _ => return Err(err("unknown PLY format")),
                });
            }
            "element" => {
                let (Some(name), Some(count)) = (ws.get(1), ws.get(2)) else {
                    return Err(err("`element` needs a name and a count"));
                };
                let count: u64 = count
                    .1
                    .parse()
                    .map_err(|_| syntax(i + 1, count.0, "element count is not a number"))?;
                elements.push(Element {
                    name: name.1.to_string(),
                    count,
                    props: Vec::new(),
                });
            }
            "property" => {
                let el = elements
                    .last_mut()
                    .ok_or_else(|| err("`property` before any `element`"))?;
                let prop = if ws.get(1).map(|w| w.1) == Some("list") {
                    let (Some(ct), Some(ty), Some(name)) = (ws.get(2), ws.get(3), ws.get(4)) else {
                        return Err(err("`property list` needs two types and a name"));
                    };
                    Property {
                        name: name.1.to_string(),
                        list: Some(
                            Scalar::parse(ct.1)
                                .ok_or_else(|| syntax(i + 1, ct.0, "unknown type"))?,
                        ),
                        ty: Scalar::parse(ty.1)
                            .ok_or_else(|| syntax(i + 1, ty.0, "unknown type"))?,
                    }
                } else {
                    let (Some(ty), Some(name)) = (ws.get(1), ws.get(2)) else {
                        return Err(err("`property` needs a type and a name"));
                    };
                    Property {
                        name: name.1.to_string(),
                        list: None,
                        ty: Scalar::parse(ty.1)
                            .ok_or_else(|| syntax(i + 1, ty.0, "unknown type"))?,
                    }
                };
                el.props.push(prop);
            }
            _ => return Err(err(&format!("unexpected `{key}` in the PLY header"))),
        }
    }
    let format = format.ok_or_else(|| syntax(2, 1, "no `format` line"))?;
    let remaining = (bytes.len() - body_start.min(bytes.len())) as u64;
    let mut body = PlyBody {
        bytes,
        pos: body_start.min(bytes.len()),
        format,
        line: header_lines + 2,
    };
    let mut m = TriMesh::default();
    for el in &elements {
        // Every element takes at least one byte (binary) or two (ASCII: a digit and a
        // separator), so a count beyond the bytes left is a lie.
        let min = if format == PlyFormat::Ascii {
            2 * el.props.len() as u64
        } else {
            el.props
                .iter()
                .map(|p| p.list.unwrap_or(p.ty).size() as u64)
                .sum()
        };
        if el.count > 0 && min > 0 && el.count > remaining / min {
            return Err(FormatError::corrupt(format!(
                "header declares {} `{}` elements; the file is too short for them",
                el.count, el.name
            )));
        }
        if el.count > MAX_MESH_ELEMENTS as u64 {
            return Err(FormatError::too_large(format!(
                "{} `{}` elements",
                el.count, el.name
            )));
        }
        let xyz: Vec<Option<usize>> = ["x", "y", "z"]
            .iter()
            .map(|n| {
                el.props
                    .iter()
                    .position(|p| p.name == *n && p.list.is_none())
            })
            .collect();
        let faces = el.props.iter().position(|p| {
            p.list.is_some() && (p.name == "vertex_indices" || p.name == "vertex_index")
        });
        let is_vertex = el.name == "vertex";
        if is_vertex && xyz.iter().any(Option::is_none) {
            return Err(syntax(1, 1, "`vertex` element lacks x, y or z"));
        }
        let is_face = el.name == "face";
        if is_face && faces.is_none() {
            return Err(syntax(1, 1, "`face` element lacks a vertex_indices list"));
        }
        let mut poly: Vec<u32> = Vec::new();
        for index in 0..el.count {
            let mut p = [0.0; 3];
            for (pi, prop) in el.props.iter().enumerate() {
                match prop.list {
                    None => {
                        let v = body.value(prop.ty)?;
                        if is_vertex {
                            for a in 0..3 {
                                if xyz[a] == Some(pi) {
                                    p[a] = v;
                                }
                            }
                        }
                    }
                    Some(ct) => {
                        let n = body.value(ct)?;
                        if !(0.0..=1e9).contains(&n) || n.fract() != 0.0 {
                            return Err(FormatError::corrupt(format!(
                                "element {index}: bad list length {n}"
                            )));
                        }
                        let take = is_face && faces == Some(pi);
                        poly.clear();
                        for _ in 0..n as u64 {
                            let v = body.value(prop.ty)?;
                            if take {
                                // A vertex index is a whole number from 0: `1.5` or `-2`
                                // is an error that says so, not a face to guess at.
                                let why = if v.fract() != 0.0 {
                                    Some("is not a whole number")
                                } else if v < 0.0 {
                                    Some("is negative")
                                } else {
                                    None
                                };
                                if let Some(why) = why {
                                    let msg = format!("face {index}: vertex index {v} {why}");
                                    return Err(if body.format == PlyFormat::Ascii {
                                        syntax(body.line, 1, msg)
                                    } else {
                                        FormatError::corrupt(format!("{msg} (byte {})", body.pos))
                                    });
                                }
                                poly.push(if v < u32::MAX as f64 {
                                    v as u32
                                } else {
                                    u32::MAX
                                });
                            }
                        }
                        if take {
                            if poly.len() < 3 {
                                return Err(FormatError::corrupt(format!(
                                    "face {index} has fewer than three vertices"
                                )));
                            }
                            for j in 1..poly.len() - 1 {
                                m.triangles.push([poly[0], poly[j], poly[j + 1]]);
                            }
                            if m.triangles.len() > MAX_MESH_ELEMENTS {
                                return Err(FormatError::too_large("too many triangles"));
                            }
                        }
                    }
                }
            }
            if is_vertex {
                m.positions.push(p);
            }
        }
    }
    let n = m.positions.len() as u32;
    if let Some(t) = m.triangles.iter().position(|t| t.iter().any(|&i| i >= n)) {
        return Err(FormatError::corrupt(format!(
            "face {t} names a vertex beyond the {n} there are"
        )));
    }
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube_obj() -> String {
        let mut s = String::from("# unit cube\n");
        for z in 0..2 {
            for y in 0..2 {
                for x in 0..2 {
                    s += &format!("v {x} {y} {z}\n");
                }
            }
        }
        // Quads, counter-clockwise from outside (1-based, x + 2y + 4z + 1).
        s += "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
        s
    }

    #[test]
    fn garbage_and_binary_stl_are_not_obj() {
        // Seeded random bytes: never an empty mesh, always an error with a place.
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        for seed in 0..200 {
            let bytes: Vec<u8> = (0..64 + seed)
                .map(|_| {
                    x ^= x << 13;
                    x ^= x >> 7;
                    x ^= x << 17;
                    x as u8
                })
                .collect();
            if let Ok(m) = parse_obj(&bytes) {
                // Only text made of OBJ statements may parse.
                assert!(std::str::from_utf8(&bytes).is_ok(), "seed {seed}: {m:?}");
            }
        }
        let mut stl = vec![0u8; 84];
        stl[..10].copy_from_slice(b"binary stl");
        stl[80] = 1;
        stl.extend(std::iter::repeat_n(0x41u8, 50));
        let e = parse_obj(&stl).unwrap_err().with_path("m.obj").to_string();
        assert!(e.starts_with("m.obj:1:1:"), "{e}");
        let e = parse_obj(b"v 0 0 0\nhello world\n")
            .unwrap_err()
            .to_string();
        assert_eq!(e, "2:1: `hello` is not an OBJ statement");
        // The statements of the format that we do not use are read past.
        let ok = "mtllib a.mtl\no cube\ng side\nusemtl red\ns off\nvt 0 0\nvn 0 0 1\n";
        assert_eq!(
            parse_obj(format!("{ok}{}", cube_obj()).as_bytes())
                .unwrap()
                .triangles
                .len(),
            12
        );
    }

    #[test]
    fn obj_quads_become_a_closed_cube() {
        let m = parse_obj(cube_obj().as_bytes()).unwrap();
        assert_eq!((m.positions.len(), m.triangles.len()), (8, 12));
        assert_eq!(m.edge_defects(), 0);
        assert!((m.volume() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn written_meshes_parse_back() {
        let m = parse_obj(cube_obj().as_bytes()).unwrap();
        for (ext, f) in [
            (
                "stl",
                super::super::write::write_stl
                    as fn(&mut dyn std::io::Write, &TriMesh) -> std::io::Result<()>,
            ),
            ("obj", super::super::write::write_obj),
            ("ply", super::super::write::write_ply),
        ] {
            let mut bytes = Vec::new();
            f(&mut bytes, &m).unwrap();
            let back = parse(&bytes, ext).unwrap();
            assert_eq!(back.triangles.len(), 12, "{ext}");
            assert!((back.volume() - 1.0).abs() < 1e-6, "{ext}");
        }
    }

    #[test]
    fn ascii_stl_and_ply_parse() {
        let stl = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
        let m = parse_stl(stl.as_bytes()).unwrap();
        assert_eq!(m.triangles.len(), 1);
        let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
        let m = parse_ply(ply.as_bytes()).unwrap();
        assert_eq!((m.positions.len(), m.triangles.len()), (3, 1));
    }

    #[test]
    fn a_cut_ascii_stl_is_an_error() {
        // Only the header, or facets without the closing `endsolid`: the tail is lost.
        for text in [
            "solid x\n",
            "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n",
        ] {
            let e = parse_stl(text.as_bytes()).unwrap_err();
            assert!(e.to_string().contains("without `endsolid`"), "{e}");
        }
        // An empty but closed solid is a valid, empty mesh.
        let m = parse_stl(b"solid x\nendsolid x\n").unwrap();
        assert!(m.triangles.is_empty());
    }

    #[test]
    fn a_short_point_names_its_keyword() {
        let e = parse_obj(b"v 1 2\n").unwrap_err().with_path("a.obj");
        assert_eq!(e.to_string(), "a.obj:1:6: `v` needs three numbers");
        let e = parse_stl(b"solid x\nvertex 1 2\n")
            .unwrap_err()
            .with_path("a.stl");
        assert_eq!(e.to_string(), "a.stl:2:11: `vertex` needs three numbers");
    }

    #[test]
    fn errors_name_line_and_column() {
        let e = parse_obj(b"v 0 0 0\nv 1 x 0\n")
            .unwrap_err()
            .with_path("a.obj");
        assert_eq!(e.to_string(), "a.obj:2:5: `x` is not a finite number");
        let e = parse_obj(b"v 0 0 0\nf 1 2 3\n")
            .unwrap_err()
            .with_path("a.obj");
        assert!(e.to_string().starts_with("a.obj:2:5:"), "{e}");
        let e = parse_stl(b"solid x\nvertex 1 2\n")
            .unwrap_err()
            .with_path("a.stl");
        assert!(e.to_string().starts_with("a.stl:2:"), "{e}");
        // A hostile PLY header.
        let ply = b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
        assert!(parse_ply(ply).is_err());
        // A binary STL claiming more triangles than it holds.
        let mut stl = vec![0u8; 84 + 50];
        stl[80..84].copy_from_slice(&1000u32.to_le_bytes());
        assert!(parse_stl(&stl).is_err());
    }
}
