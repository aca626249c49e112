//! The points after a PCD header: `DATA ascii`, `binary` and `binary_compressed`.

use super::lzf_decode;
use super::pcd::{Field, Header};
use super::{check_budget, syntax, words};
use crate::io::FormatError;

/// The most bytes LZF gives back per compressed byte: a back reference of three
/// bytes copies at most 264.
const LZF_RATIO: usize = 88;

/// `DATA ascii`: one point a line, every field's values in turn.
pub(super) fn ascii(bytes: &[u8], h: &Header) -> Result<Vec<[f64; 3]>, FormatError> {
    let (declared, fields) = (h.declared, &h.fields);
    let left = bytes.len() - h.body;
    // A point takes at least two bytes per value (a digit and a separator).
    let values: usize = fields.iter().map(|f| f.count).sum();
    if declared > (left / (2 * values).max(1)) as u64 + 1 {
        let (line, col) = h.count_at;
        return Err(syntax(
            line,
            col,
            format!(
                "the header declares {declared} points; the {left} bytes after it (from line {}) hold fewer",
                h.body_line
            ),
        ));
    }
    check_budget(declared as usize)?;
    let mut out = Vec::with_capacity(declared as usize);
    let mut starts = Vec::with_capacity(fields.len());
    let mut at = 0;
    for f in fields {
        starts.push(at);
        at += f.count;
    }
    let mut lines = bytes[h.body..].split(|&b| b == b'\n').enumerate();
    // The last line read, and its length: where the data ends.
    let mut last = (h.body_line, 0);
    while (out.len() as u64) < declared {
        let Some((k, raw)) = lines.next() else {
            return Err(syntax(
                last.0,
                last.1 + 1,
                format!(
                    "the data ends after {} of {declared} points (the count is on line {})",
                    out.len(),
                    h.count_at.0
                ),
            ));
        };
        let line_no = h.body_line + k;
        last = (line_no, raw.len());
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
        for (i, f) in fields.iter().enumerate() {
            for e in 0..f.count {
                let (c, w) = ws[starts[i] + e];
                let v = f.text(w).map_err(|m| syntax(line_no, c, m))?;
                if e == 0 {
                    for (x, &axis) in p.iter_mut().zip(&h.xyz) {
                        if axis == i {
                            *x = v;
                        }
                    }
                }
            }
        }
        out.push(p);
    }
    // Past the declared points, only blank lines: more points mean a wrong count.
    if let Some((k, _)) = lines.find(|(_, raw)| raw.iter().any(|b| !b.is_ascii_whitespace())) {
        return Err(syntax(
            h.body_line + k,
            1,
            format!(
                "more points than the {declared} the header declares (the count is on line {})",
                h.count_at.0
            ),
        ));
    }
    Ok(out)
}

/// The byte offset of each field in a record, and the record's size.
fn offsets(fields: &[Field]) -> (Vec<usize>, usize) {
    let mut offsets = Vec::with_capacity(fields.len());
    let mut at = 0;
    for f in fields {
        offsets.push(at);
        at += f.width();
    }
    (offsets, at)
}

/// `DATA binary`: packed little-endian records.
pub(super) fn binary(bytes: &[u8], h: &Header) -> Result<Vec<[f64; 3]>, FormatError> {
    let (offsets, record) = offsets(&h.fields);
    let (pos, declared) = (h.body, h.declared);
    let left = bytes.len() - pos;
    if declared > (left / record) as u64 {
        return Err(FormatError::corrupt(format!(
            "byte {pos}: the header declares {declared} points of {record} bytes (the count is on line {}); {left} bytes follow",
            h.count_at.0
        )));
    }
    check_budget(declared as usize)?;
    let axes = h.xyz.map(|i| (&h.fields[i], offsets[i]));
    Ok(bytes[pos..]
        .chunks_exact(record)
        .take(declared as usize)
        .map(|r| axes.map(|(f, o)| f.value(&r[o..])))
        .collect())
}

/// `DATA binary_compressed`, decompressed in pieces: only the points are held, each
/// `x`, `y`, `z` read from its field's column as the pieces pass. Every size is
/// checked before anything is allocated: the uncompressed size must be exactly the
/// declared points' and at most what the compressed bytes can give.
pub(super) fn compressed(bytes: &[u8], h: &Header) -> Result<Vec<[f64; 3]>, FormatError> {
    let (at, declared) = (h.body, h.declared);
    let body = &bytes[at..];
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
    let (_, record) = offsets(&h.fields);
    let want = usize::try_from(declared)
        .ok()
        .and_then(|n| n.checked_mul(record));
    if want != Some(size) {
        return Err(corrupt(format!(
            "{declared} points of {record} bytes make {} bytes (the count is on line {}), but the data says {size} uncompressed",
            want.map_or_else(|| "too many".to_string(), |w| w.to_string()),
            h.count_at.0
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
    let n = declared as usize;
    // Field f's values for every point lie together, from its column's start.
    let mut column = Vec::with_capacity(h.fields.len());
    let mut start = 0;
    for f in &h.fields {
        column.push(start);
        start += n * f.width();
    }
    let axes = h.xyz.map(|i| (&h.fields[i], column[i]));
    let mut points = vec![[0.0; 3]; n];
    lzf_decode::decompress(&body[8..8 + packed], at + 8, size, |start, buf, new| {
        let end = start + buf.len();
        for (a, &(f, c)) in axes.iter().enumerate() {
            // The values whose last byte is new: c + p·w + s in (new, end].
            let (w, s) = (f.width(), f.size);
            let lo = if new < c + s {
                0
            } else {
                (new - c - s) / w + 1
            };
            let hi = if end < c + s {
                0
            } else {
                ((end - c - s) / w + 1).min(n)
            };
            for (p, point) in points.iter_mut().enumerate().take(hi).skip(lo) {
                // The piece keeps 8 KiB before `new`, so the value's first byte is
                // in it.
                point[a] = f.value(&buf[c + p * w - start..]);
            }
        }
    })?;
    Ok(points)
}
