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
//! organised clouds hold) are kept; mapping skips and counts them.

use super::{check_budget, syntax, words, PointFrame, ScanRecord};
use crate::io::FormatError;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Int,
    Uint,
    Float,
}

#[derive(Debug, Clone)]
struct Field {
    name: String,
    size: usize,
    kind: Kind,
    count: usize,
}

impl Field {
    /// Decodes one little-endian value of this field.
    fn value(&self, b: &[u8]) -> f64 {
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
}

/// How the points follow the header.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Data {
    Ascii,
    Binary,
    Compressed,
}

/// The most bytes LZF gives back per compressed byte: a back reference of three
/// bytes copies at most 264.
const LZF_RATIO: usize = 88;

/// The points of `DATA binary_compressed` (`body`, starting at byte `at` of the
/// file), decompressed and put back into records of all fields, as `DATA binary`
/// holds them. Every size is checked before anything is allocated: the
/// uncompressed size must be the declared points' and at most what the compressed
/// bytes can give.
fn decompress(
    body: &[u8],
    at: usize,
    declared: u64,
    fields: &[Field],
) -> Result<Vec<u8>, FormatError> {
    let corrupt = |m: String| FormatError::corrupt(format!("byte {at}: {m}"));
    let word = |k: usize| {
        body.get(k..k + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
    };
    let (Some(packed), Some(size)) = (word(0), word(4)) else {
        return Err(corrupt(
            "`binary_compressed` data needs its two sizes (8 bytes)".into(),
        ));
    };
    let record: usize = fields.iter().map(|f| f.size * f.count).sum();
    let want = usize::try_from(declared)
        .ok()
        .and_then(|n| n.checked_mul(record));
    if want != Some(size) {
        return Err(corrupt(format!(
            "{declared} points of {record} bytes make {} bytes, but the data says {size} uncompressed",
            want.map_or_else(|| "too many".to_string(), |w| w.to_string())
        )));
    }
    if packed > body.len() - 8 {
        return Err(corrupt(format!(
            "{packed} compressed bytes declared; {} follow",
            body.len() - 8
        )));
    }
    if size == 0 {
        return Ok(Vec::new());
    }
    check_budget(declared as usize)?;
    if size > packed.saturating_mul(LZF_RATIO) + 64 {
        return Err(corrupt(format!(
            "{packed} compressed bytes cannot hold {size}"
        )));
    }
    let columns = lzf::decompress(&body[8..8 + packed], size)
        .map_err(|e| corrupt(format!("the compressed data is damaged ({e:?})")))?;
    if columns.len() != size {
        return Err(corrupt(format!(
            "the data decompresses to {} bytes, not {size}",
            columns.len()
        )));
    }
    // Field f's values for every point lie together; a record takes each in turn.
    let n = declared as usize;
    let mut records = vec![0u8; size];
    let (mut column, mut offset) = (0, 0);
    for f in fields {
        let w = f.size * f.count;
        let values = &columns[column..column + n * w];
        for (p, v) in values.chunks_exact(w).enumerate() {
            records[p * record + offset..][..w].copy_from_slice(v);
        }
        column += n * w;
        offset += w;
    }
    Ok(records)
}

/// Parses a PCD file.
///
/// # Errors
/// [`FormatError::Syntax`] naming the header or data line at fault;
/// [`FormatError::Corrupt`] naming the byte offset where binary data ends early or a
/// point count the bytes cannot hold, or compressed data that does not decompress
/// to the declared points; [`FormatError::TooLarge`] past
/// [`super::MAX_SCAN_POINTS`].
pub fn parse(bytes: &[u8]) -> Result<ScanRecord, FormatError> {
    let mut pos = 0usize;
    let mut line_no = 0usize;
    let mut names: Option<Vec<String>> = None;
    let mut sizes: Option<Vec<usize>> = None;
    let mut kinds: Option<Vec<Kind>> = None;
    let mut counts: Option<Vec<usize>> = None;
    let (mut width, mut height, mut points): (Option<u64>, Option<u64>, Option<u64>) =
        (None, None, None);
    let mut viewpoint = [0.0f64; 7];
    viewpoint[3] = 1.0;
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
            "FIELDS" | "COLUMNS" => names = Some(rest.iter().map(|w| w.1.to_string()).collect()),
            "SIZE" => {
                let mut v = Vec::new();
                for &(c, w) in rest {
                    v.push(match w {
                        "1" => 1,
                        "2" => 2,
                        "4" => 4,
                        "8" => 8,
                        _ => return Err(err(c, format!("field size `{w}` must be 1, 2, 4 or 8"))),
                    });
                }
                sizes = Some(v);
            }
            "TYPE" => {
                let mut v = Vec::new();
                for &(c, w) in rest {
                    v.push(match w {
                        "I" => Kind::Int,
                        "U" => Kind::Uint,
                        "F" => Kind::Float,
                        _ => return Err(err(c, format!("field type `{w}` must be I, U or F"))),
                    });
                }
                kinds = Some(v);
            }
            "COUNT" => {
                let mut v = Vec::new();
                for &w in rest {
                    let n = uint(w)?;
                    if n == 0 || n > 1 << 16 {
                        return Err(err(w.0, format!("field count {n} must be 1..65536")));
                    }
                    v.push(n as usize);
                }
                counts = Some(v);
            }
            "WIDTH" | "HEIGHT" | "POINTS" => {
                let w = *rest
                    .first()
                    .ok_or_else(|| err(col, format!("`{key}` needs a number")))?;
                let n = Some(uint(w)?);
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
                    viewpoint[k] = w
                        .parse::<f64>()
                        .ok()
                        .filter(|x| x.is_finite())
                        .ok_or_else(|| err(c, format!("`{w}` is not a finite number")))?;
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
    let header_end_line = line_no;
    let names = names.ok_or_else(|| syntax(line_no, 1, "the header has no `FIELDS` line"))?;
    let n_fields = names.len();
    let sizes = sizes.unwrap_or_else(|| vec![4; n_fields]);
    let kinds = kinds.unwrap_or_else(|| vec![Kind::Float; n_fields]);
    let counts = counts.unwrap_or_else(|| vec![1; n_fields]);
    if sizes.len() != n_fields || kinds.len() != n_fields || counts.len() != n_fields {
        return Err(syntax(
            line_no,
            1,
            format!(
                "{n_fields} FIELDS but {} SIZE, {} TYPE and {} COUNT entries",
                sizes.len(),
                kinds.len(),
                counts.len()
            ),
        ));
    }
    let fields: Vec<Field> = (0..n_fields)
        .map(|i| Field {
            name: names[i].clone(),
            size: sizes[i],
            kind: kinds[i],
            count: counts[i],
        })
        .collect();
    if let Some(f) = fields
        .iter()
        .find(|f| f.kind == Kind::Float && f.size != 4 && f.size != 8)
    {
        return Err(syntax(
            line_no,
            1,
            format!("float field `{}` has size {}", f.name, f.size),
        ));
    }
    let xyz: Vec<usize> = ["x", "y", "z"]
        .iter()
        .map(|n| fields.iter().position(|f| f.name == *n))
        .collect::<Option<_>>()
        .ok_or_else(|| syntax(line_no, 1, "FIELDS lacks x, y or z"))?;
    let declared = match (points, width, height) {
        (Some(p), _, _) => p,
        (None, Some(w), Some(h)) => w.saturating_mul(h),
        (None, Some(w), None) => w,
        _ => {
            return Err(syntax(
                line_no,
                1,
                "the header has no `POINTS` (or `WIDTH`)",
            ))
        }
    };
    let left = bytes.len() - pos;
    let mut out = Vec::new();
    if data == Data::Ascii {
        // A point takes at least two bytes per value (a digit and a separator).
        let values: usize = fields.iter().map(|f| f.count).sum();
        if declared > (left / (2 * values).max(1)) as u64 + 1 {
            return Err(FormatError::corrupt(format!(
                "the header declares {declared} points; the {left} bytes after it hold fewer"
            )));
        }
        check_budget(declared as usize)?;
        out.reserve(declared as usize);
        let mut starts = Vec::with_capacity(n_fields);
        let mut at = 0;
        for f in &fields {
            starts.push(at);
            at += f.count;
        }
        let want = [starts[xyz[0]], starts[xyz[1]], starts[xyz[2]]];
        let mut lines = bytes[pos..].split(|&b| b == b'\n').enumerate();
        while (out.len() as u64) < declared {
            let Some((k, raw)) = lines.next() else {
                return Err(syntax(
                    header_end_line + 1,
                    1,
                    format!("the data ends after {} of {declared} points", out.len()),
                ));
            };
            let line_no = header_end_line + 1 + k;
            let line = String::from_utf8_lossy(raw);
            let ws: Vec<(usize, &str)> = words(&line).take(values + 1).collect();
            if ws.is_empty() {
                continue;
            }
            if ws.len() < values {
                return Err(syntax(
                    line_no,
                    line.trim_end().len() + 1,
                    format!("a point needs {values} values; found {}", ws.len()),
                ));
            }
            let mut p = [0.0; 3];
            for (a, &i) in want.iter().enumerate() {
                let (c, w) = ws[i];
                let v = w
                    .parse::<f64>()
                    .map_err(|_| syntax(line_no, c, format!("`{w}` is not a number")))?;
                // A 4-byte float field holds an `f32`, as PCL reads it and as the
                // same cloud saved as `binary` holds it.
                let f = &fields[xyz[a]];
                p[a] = if f.kind == Kind::Float && f.size == 4 {
                    f64::from(v as f32)
                } else {
                    v
                };
            }
            out.push(p);
        }
    } else {
        let record: usize = fields.iter().map(|f| f.size * f.count).sum();
        let unpacked;
        let (bytes, pos) = if data == Data::Compressed {
            unpacked = decompress(&bytes[pos..], pos, declared, &fields)?;
            (unpacked.as_slice(), 0)
        } else {
            (bytes, pos)
        };
        let left = bytes.len() - pos;
        if declared > (left / record) as u64 {
            return Err(FormatError::corrupt(format!(
                "byte {pos}: the header declares {declared} points of {record} bytes; {left} bytes follow"
            )));
        }
        check_budget(declared as usize)?;
        let mut offsets = Vec::with_capacity(n_fields);
        let mut at = 0;
        for f in &fields {
            offsets.push(at);
            at += f.size * f.count;
        }
        out.reserve(declared as usize);
        for r in bytes[pos..].chunks_exact(record).take(declared as usize) {
            out.push(std::array::from_fn(|a| {
                let f = &fields[xyz[a]];
                f.value(&r[offsets[xyz[a]]..])
            }));
        }
    }
    let [tx, ty, tz, ..] = viewpoint;
    Ok(ScanRecord {
        translation: [tx, ty, tz],
        rpy: [0.0; 3],
        points: out,
        frame: PointFrame::World,
    })
}
