//! PCL's point cloud files (`.pcd`, versions 0.6 and 0.7): a text header, then the
//! points as text (`DATA ascii`), packed little-endian records (`DATA binary`), or
//! LZF-compressed fields (`DATA binary_compressed`: the compressed and uncompressed
//! sizes as two `u32`, then the compressed bytes of each field's values for every
//! point, one field after another, as PCL's `PCDWriter::writeBinaryCompressed`
//! writes them).
//!
//! The header's `FIELDS` must include `x`, `y` and `z`; `SIZE`, `TYPE` (`I`, `U`,
//! `F`) and `COUNT` describe each field (a field with `COUNT` > 1 contributes its
//! first element). `POINTS` (or `WIDTH` × `HEIGHT`) is the number of points.
//! `VIEWPOINT tx ty tz qw qx qy qz` is where the sensor was: the points are world
//! coordinates and the sensor origin is the viewpoint's translation. NaN points (as
//! organised clouds hold) are kept; mapping skips and counts them. In `DATA ascii`
//! every value must fit its field's type (a whole number within an `I` or `U`
//! field's size, a 4-byte float within `f32`).

use super::pcd_data;
use super::{syntax, words, PointFrame, ScanRecord};
use crate::io::{text_number, text_start, FormatError};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Kind {
    Int,
    Uint,
    Float,
}

#[derive(Debug, Clone)]
pub(super) struct Field {
    pub(super) name: String,
    pub(super) size: usize,
    pub(super) kind: Kind,
    pub(super) count: usize,
}

impl Field {
    /// Decodes one little-endian value of this field from the start of `b`.
    pub(super) fn value(&self, b: &[u8]) -> f64 {
        let mut w = [0u8; 8];
        w[..self.size].copy_from_slice(&b[..self.size]);
        match (self.kind, self.size) {
            (Kind::Float, 4) => f64::from(f32::from_le_bytes([w[0], w[1], w[2], w[3]])),
            (Kind::Float, _) => f64::from_le_bytes(w),
            (Kind::Uint, _) => u64::from_le_bytes(w) as f64,
            (Kind::Int, n) => {
                // Sign-extend from n bytes.
                let shift = 64 - 8 * n as u32;
                ((u64::from_le_bytes(w) << shift) as i64 >> shift) as f64
            }
        }
    }

    /// Reads one value of this field from text; the error completes a sentence.
    /// A 4-byte float holds an `f32`, as PCL reads it and as the same cloud saved
    /// as `binary` holds it.
    pub(super) fn text(&self, w: &str) -> Result<f64, String> {
        match (self.kind, self.size) {
            (Kind::Float, 4) => text_number::real32(w),
            (Kind::Float, _) => text_number::real(w),
            (kind, n) => {
                let (lo, hi) = text_number::int_range(n, kind == Kind::Int);
                let sign = if kind == Kind::Int { "" } else { "un" };
                let what = format!("a {n}-byte {sign}signed field (`{}`)", self.name);
                text_number::whole(w, lo, hi, &what)
            }
        }
    }

    /// Bytes of one point's values of this field.
    pub(super) fn width(&self) -> usize {
        self.size * self.count
    }
}

/// How the points follow the header.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Data {
    Ascii,
    Binary,
    Compressed,
}

/// What the header says, with where it says it.
pub(super) struct Header {
    pub(super) fields: Vec<Field>,
    /// The fields of `x`, `y` and `z`.
    pub(super) xyz: [usize; 3],
    /// The number of points.
    pub(super) declared: u64,
    /// The line and column of that number (`POINTS`, else `WIDTH`).
    pub(super) count_at: (usize, usize),
    pub(super) data: Data,
    /// The byte offset and line number where the data starts.
    pub(super) body: usize,
    pub(super) body_line: usize,
    pub(super) origin: [f64; 3],
}

/// One header line's entries: the line, the column after its last word, and each
/// entry with its column.
struct Entries<T> {
    line: usize,
    end: usize,
    values: Vec<(usize, T)>,
}

/// The entries after a header line's key (`ws`, its words), each parsed.
fn entries<T>(
    line: usize,
    ws: &[(usize, &str)],
    parse: impl Fn((usize, &str)) -> Result<T, FormatError>,
) -> Result<Entries<T>, FormatError> {
    let values = ws[1..]
        .iter()
        .map(|&(c, w)| parse((c, w)).map(|v| (c, v)))
        .collect::<Result<Vec<_>, _>>()?;
    let end = ws.last().map_or(1, |&(c, w)| c + w.len());
    Ok(Entries { line, end, values })
}

/// Parses a PCD file.
///
/// # Errors
/// [`FormatError::Syntax`] naming the header or data line at fault (the entry of
/// `SIZE`, `TYPE` or `COUNT` that disagrees, the `POINTS` count the data cannot
/// hold, or where text data ends early); [`FormatError::Corrupt`] naming the byte
/// offset where binary data ends early or a point count the bytes cannot hold, or
/// where compressed data is malformed or does not decompress to the declared
/// points; [`FormatError::TooLarge`] past [`super::MAX_SCAN_POINTS`].
pub fn parse(bytes: &[u8]) -> Result<ScanRecord, FormatError> {
    let h = header(bytes)?;
    let points = match h.data {
        Data::Ascii => pcd_data::ascii(bytes, &h)?,
        Data::Binary => pcd_data::binary(bytes, &h)?,
        Data::Compressed => pcd_data::compressed(bytes, &h)?,
    };
    Ok(ScanRecord {
        translation: h.origin,
        rpy: [0.0; 3],
        points,
        frame: PointFrame::World,
    })
}

/// Reads the header, up to and including its `DATA` line.
fn header(bytes: &[u8]) -> Result<Header, FormatError> {
    let mut pos = bytes.len() - text_start(bytes)?.len();
    let mut line_no = 0usize;
    let mut names: Option<Entries<String>> = None;
    let mut sizes: Option<Entries<usize>> = None;
    let mut kinds: Option<Entries<Kind>> = None;
    let mut counts: Option<Entries<usize>> = None;
    // Each count with its line and column.
    let (mut width, mut height, mut points) = (None, None, None);
    let mut origin = [0.0f64; 3];
    let data = loop {
        if pos >= bytes.len() {
            return Err(syntax(
                line_no + 1,
                1,
                "the header ends without a `DATA` line",
            ));
        }
        line_no += 1;
        let end = bytes[pos..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |n| pos + n);
        let raw = &bytes[pos..end];
        pos = (end + 1).min(bytes.len());
        let line = std::str::from_utf8(raw)
            .map_err(|e| syntax(line_no, e.valid_up_to() + 1, "the header is not UTF-8 text"))?;
        let ws: Vec<(usize, &str)> = words(line).take(4096).collect();
        let Some(&(col, key)) = ws.first() else {
            continue;
        };
        if key.starts_with('#') {
            continue;
        }
        let rest = &ws[1..];
        let err = |c: usize, m: String| syntax(line_no, c, m);
        let uint = |(c, w): (usize, &str)| -> Result<u64, FormatError> {
            w.parse::<u64>()
                .map_err(|_| err(c, format!("`{w}` is not a whole number")))
        };
        match key {
            "VERSION" => {}
            "FIELDS" | "COLUMNS" => {
                names = Some(entries(line_no, &ws, |(_, w)| Ok(w.to_string()))?);
            }
            "SIZE" => {
                sizes = Some(entries(line_no, &ws, |(c, w)| match w {
                    "1" => Ok(1),
                    "2" => Ok(2),
                    "4" => Ok(4),
                    "8" => Ok(8),
                    _ => Err(err(c, format!("field size `{w}` must be 1, 2, 4 or 8"))),
                })?);
            }
            "TYPE" => {
                kinds = Some(entries(line_no, &ws, |(c, w)| match w {
                    "I" => Ok(Kind::Int),
                    "U" => Ok(Kind::Uint),
                    "F" => Ok(Kind::Float),
                    _ => Err(err(c, format!("field type `{w}` must be I, U or F"))),
                })?);
            }
            "COUNT" => {
                counts = Some(entries(line_no, &ws, |w| {
                    let n = uint(w)?;
                    if n == 0 || n > 1 << 16 {
                        return Err(err(w.0, format!("field count {n} must be 1..65536")));
                    }
                    Ok(n as usize)
                })?);
            }
            "WIDTH" | "HEIGHT" | "POINTS" => {
                let w = *rest
                    .first()
                    .ok_or_else(|| err(col, format!("`{key}` needs a number")))?;
                let n = Some((uint(w)?, (line_no, w.0)));
                match key {
                    "WIDTH" => width = n,
                    "HEIGHT" => height = n,
                    _ => points = n,
                }
            }
            "VIEWPOINT" => {
                if rest.len() != 7 {
                    return Err(err(col, "`VIEWPOINT` needs tx ty tz qw qx qy qz".into()));
                }
                for (k, &(c, w)) in rest.iter().enumerate() {
                    let v = w
                        .parse::<f64>()
                        .ok()
                        .filter(|x| x.is_finite())
                        .ok_or_else(|| err(c, format!("`{w}` is not a finite number")))?;
                    if k < 3 {
                        origin[k] = v;
                    }
                }
            }
            "DATA" => {
                let Some(&(c, w)) = rest.first() else {
                    return Err(err(col, "`DATA` needs ascii or binary".into()));
                };
                break match w {
                    "ascii" => Data::Ascii,
                    "binary" => Data::Binary,
                    "binary_compressed" => Data::Compressed,
                    _ => return Err(err(c, format!("unknown data format `{w}`"))),
                };
            }
            _ => return Err(err(col, format!("unexpected `{key}` in the PCD header"))),
        }
    };
    let names = names.ok_or_else(|| syntax(line_no, 1, "the header has no `FIELDS` line"))?;
    let n = names.values.len();
    // Each of SIZE, TYPE, COUNT: as many entries as FIELDS, or absent (the default).
    fn check<T>(
        e: &Option<Entries<T>>,
        key: &str,
        n: usize,
        fields: usize,
    ) -> Result<(), FormatError> {
        match e {
            Some(e) if e.values.len() != n => {
                let col = e.values.get(n).map_or(e.end, |v| v.0);
                Err(syntax(
                    e.line,
                    col,
                    format!(
                        "`{key}` has {} entries; `FIELDS` (line {fields}) names {n}",
                        e.values.len()
                    ),
                ))
            }
            _ => Ok(()),
        }
    }
    check(&sizes, "SIZE", n, names.line)?;
    check(&kinds, "TYPE", n, names.line)?;
    check(&counts, "COUNT", n, names.line)?;
    fn entry<T: Copy>(e: &Option<Entries<T>>, i: usize, default: T) -> T {
        e.as_ref().map_or(default, |e| e.values[i].1)
    }
    let fields: Vec<Field> = (0..n)
        .map(|i| Field {
            name: names.values[i].1.clone(),
            size: entry(&sizes, i, 4),
            kind: entry(&kinds, i, Kind::Float),
            count: entry(&counts, i, 1),
        })
        .collect();
    if let Some(i) = fields
        .iter()
        .position(|f| f.kind == Kind::Float && f.size != 4 && f.size != 8)
    {
        // Only a given SIZE can make a float of 1 or 2 bytes.
        let (line, col) = sizes
            .as_ref()
            .map_or((line_no, 1), |e| (e.line, e.values[i].0));
        return Err(syntax(
            line,
            col,
            format!(
                "float field `{}` has size {}; a float takes 4 or 8 bytes",
                fields[i].name, fields[i].size
            ),
        ));
    }
    let mut xyz = [0; 3];
    for (a, axis) in ["x", "y", "z"].iter().enumerate() {
        xyz[a] = fields
            .iter()
            .position(|f| f.name == *axis)
            .ok_or_else(|| syntax(names.line, names.end, format!("`FIELDS` lacks `{axis}`")))?;
    }
    if let (Some((p, (line, col))), Some((w, _)), Some((h, _))) = (points, width, height) {
        // PCL refuses this too: which count would be the points?
        if w.checked_mul(h) != Some(p) {
            return Err(syntax(
                line,
                col,
                format!("`POINTS` {p} disagrees with `WIDTH` × `HEIGHT` = {w} × {h}"),
            ));
        }
    }
    let (declared, count_at) = match (points, width, height) {
        (Some(p), _, _) => p,
        (None, Some((w, at)), Some((h, _))) => (w.saturating_mul(h), at),
        (None, Some(w), None) => w,
        _ => {
            return Err(syntax(
                line_no,
                1,
                "the header has no `POINTS` (or `WIDTH`)",
            ))
        }
    };
    Ok(Header {
        fields,
        xyz,
        declared,
        count_at,
        data,
        body: pos,
        body_line: line_no + 1,
        origin,
    })
}
