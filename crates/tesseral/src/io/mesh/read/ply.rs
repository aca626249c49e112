//! PLY: ASCII and binary of either byte order.

use super::{syntax, words, MAX_MESH_ELEMENTS};
use crate::io::{text_number, FormatError};
use crate::mesh::TriMesh;

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
    fn name(self) -> &'static str {
        match self {
            Self::I8 => "char",
            Self::U8 => "uchar",
            Self::I16 => "short",
            Self::U16 => "ushort",
            Self::I32 => "int",
            Self::U32 => "uint",
            Self::F32 => "float",
            Self::F64 => "double",
        }
    }
    /// Reads an ASCII value of this type: a whole number within an integer type's
    /// range, a real within `f32` for `float`; the error completes a sentence.
    fn text(self, w: &str) -> Result<f64, String> {
        let (signed, bytes) = match self {
            Self::F32 => {
                let v = text_number::real(w)?;
                return match text_number::real32(w) {
                    Err(m) if m.contains("out of range") => Err(format!("{m} for `float`")),
                    _ => Ok(v),
                };
            }
            Self::F64 => return text_number::real(w),
            Self::I8 | Self::I16 | Self::I32 => (true, self.size()),
            Self::U8 | Self::U16 | Self::U32 => (false, self.size()),
        };
        let (lo, hi) = text_number::int_range(bytes, signed);
        text_number::whole(w, lo, hi, &format!("`{}`", self.name()))
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
    /// The header line that declares it.
    line: usize,
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
    /// Where the current line starts (ASCII), for error columns.
    line_start: usize,
    /// Where the last value read starts, for errors.
    token: usize,
    /// Whether a NaN or infinite value is an error (a mesh), or passed on (a point
    /// cloud, whose reader skips and counts such points).
    finite: bool,
    /// Whether the next value is an element's first (ASCII): only that one may
    /// start on a later line, as each element takes one line.
    fresh: bool,
}

impl PlyBody<'_> {
    /// The next value; `finite` asks for a finite one whatever the body allows (list
    /// lengths and vertex indices).
    fn value(&mut self, ty: Scalar, finite: bool) -> Result<f64, FormatError> {
        let finite = finite || self.finite;
        if self.format == PlyFormat::Ascii {
            while self.pos < self.bytes.len() && self.bytes[self.pos].is_ascii_whitespace() {
                if self.bytes[self.pos] == b'\n' {
                    if !self.fresh {
                        let column = self.pos - self.line_start + 1;
                        return Err(syntax(
                            self.line,
                            column,
                            "the line ends inside an element (each takes one line)",
                        ));
                    }
                    self.line += 1;
                    self.line_start = self.pos + 1;
                }
                self.pos += 1;
            }
            self.fresh = false;
            let start = self.pos;
            while self.pos < self.bytes.len() && !self.bytes[self.pos].is_ascii_whitespace() {
                self.pos += 1;
            }
            self.token = start;
            let column = start - self.line_start + 1;
            if start == self.pos {
                return Err(syntax(self.line, column, "file ends inside an element"));
            }
            let w = String::from_utf8_lossy(&self.bytes[start..self.pos]);
            return match ty.text(&w) {
                Ok(x) if x.is_finite() || !finite => Ok(x),
                Ok(_) => Err(syntax(self.line, column, format!("`{w}` is not finite"))),
                Err(m) => Err(syntax(self.line, column, m)),
            };
        }
        let n = ty.size();
        self.token = self.pos;
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
        if finite && !v.is_finite() {
            return Err(FormatError::corrupt(format!(
                "value at byte {} is not finite",
                self.pos - n
            )));
        }
        Ok(v)
    }
}

impl PlyBody<'_> {
    /// An error at the last value read: its line and column (ASCII) or byte offset.
    fn fault(&self, message: String) -> FormatError {
        if self.format == PlyFormat::Ascii {
            syntax(self.line, self.token - self.line_start + 1, message)
        } else {
            FormatError::corrupt(format!("byte {}: {message}", self.token))
        }
    }

    /// An error where the data ends: the line and column of the file's end (ASCII),
    /// else the byte offset of the current element.
    fn short(&self, message: String) -> FormatError {
        if self.format == PlyFormat::Ascii {
            let rest = &self.bytes[self.pos..];
            let lines = rest.iter().filter(|&&b| b == b'\n').count();
            let last = rest
                .iter()
                .rposition(|&b| b == b'\n')
                .map_or(self.pos - self.line_start, |k| rest.len() - k - 1);
            syntax(self.line + lines, last + 1, message)
        } else {
            FormatError::corrupt(format!(
                "byte {}: {message}; the file ends at byte {}",
                self.pos,
                self.bytes.len()
            ))
        }
    }

    /// Ends an element (ASCII): nothing but spaces may follow its last value on its
    /// line, and the next value starts a new element.
    fn end_element(&mut self) -> Result<(), FormatError> {
        if self.format != PlyFormat::Ascii {
            return Ok(());
        }
        while self.pos < self.bytes.len()
            && self.bytes[self.pos] != b'\n'
            && self.bytes[self.pos].is_ascii_whitespace()
        {
            self.pos += 1;
        }
        if self.pos < self.bytes.len() && self.bytes[self.pos] != b'\n' {
            let column = self.pos - self.line_start + 1;
            return Err(syntax(
                self.line,
                column,
                "more values on the line than the element's properties",
            ));
        }
        self.fresh = true;
        Ok(())
    }
}

/// Parses PLY (ASCII, binary little- or big-endian): the `vertex` element's `x`, `y`,
/// `z` and the `face` element's `vertex_indices` (or `vertex_index`) list; other
/// elements and properties are skipped.
///
/// # Errors
/// As [`read`](super::read).
pub fn parse_ply(bytes: &[u8]) -> Result<TriMesh, FormatError> {
    parse(bytes, true)
}

/// [`parse_ply`] for a point cloud: vertex coordinates may be NaN or infinite (a
/// sensor's missing returns), passed on for the scan reader to skip and count.
///
/// # Errors
/// As [`parse_ply`], but for non-finite coordinates.
pub(crate) fn parse_ply_points(bytes: &[u8]) -> Result<TriMesh, FormatError> {
    parse(bytes, false)
}

fn parse(bytes: &[u8], finite: bool) -> Result<TriMesh, FormatError> {
    // A UTF-8 byte order mark before `ply` is skipped; a UTF-16 one refused.
    let bom = bytes.len() - crate::io::text_start(bytes)?.len();
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n" || w == b"end_header\r")
        .ok_or_else(|| syntax(1, 1, "no `end_header` line"))?;
    let header = String::from_utf8_lossy(&bytes[bom.min(end)..end]);
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
                    line: i + 1,
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
    let mut body = PlyBody {
        bytes,
        pos: body_start.min(bytes.len()),
        format,
        line: header_lines + 2,
        line_start: body_start.min(bytes.len()),
        token: 0,
        finite,
        fresh: true,
    };
    let mut m = TriMesh::default();
    // Faces are checked against the vertices the header declares, as they are read.
    let vertices: u64 = elements
        .iter()
        .filter(|e| e.name == "vertex")
        .fold(0, |n, e| n.saturating_add(e.count));
    for el in &elements {
        let remaining = (bytes.len() - body.pos) as u64;
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
            return Err(body.short(format!(
                "header declares {} `{}` elements (line {}), of at least {min} bytes each; the file is too short for them",
                el.count, el.name, el.line
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
        if let Some(a) = xyz.iter().position(Option::is_none).filter(|_| is_vertex) {
            let axis = ["x", "y", "z"][a];
            return Err(syntax(
                el.line,
                1,
                format!("`vertex` element lacks `{axis}` (a property that is not a list)"),
            ));
        }
        let is_face = el.name == "face";
        if is_face && faces.is_none() {
            return Err(syntax(
                el.line,
                1,
                "`face` element lacks a `vertex_indices` list",
            ));
        }
        let mut poly: Vec<u32> = Vec::new();
        for index in 0..el.count {
            let mut p = [0.0; 3];
            for (pi, prop) in el.props.iter().enumerate() {
                match prop.list {
                    None => {
                        let v = body.value(prop.ty, !is_vertex)?;
                        if is_vertex {
                            for a in 0..3 {
                                if xyz[a] == Some(pi) {
                                    p[a] = v;
                                }
                            }
                        }
                    }
                    Some(ct) => {
                        let n = body.value(ct, true)?;
                        if !(0.0..=1e9).contains(&n) || n.fract() != 0.0 {
                            return Err(
                                body.fault(format!("`{}` {index}: bad list length {n}", el.name))
                            );
                        }
                        let take = is_face && faces == Some(pi);
                        poly.clear();
                        for _ in 0..n as u64 {
                            let v = body.value(prop.ty, true)?;
                            if take {
                                // A vertex index is a whole number from 0: `1.5` or `-2`
                                // is an error that says so, not a face to guess at.
                                let why = if v.fract() != 0.0 {
                                    "is not a whole number".to_string()
                                } else if v < 0.0 {
                                    "is negative".to_string()
                                } else if v >= vertices as f64 {
                                    format!("names a vertex beyond the {vertices} there are")
                                } else {
                                    String::new()
                                };
                                if !why.is_empty() {
                                    let msg = format!("face {index}: vertex index {v} {why}");
                                    return Err(body.fault(msg));
                                }
                                // Below the vertex count (a saturating cast past u32).
                                poly.push(v as u32);
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
            if !el.props.is_empty() {
                body.end_element()?;
            }
            if is_vertex {
                m.positions.push(p);
            }
        }
    }
    Ok(m)
}
