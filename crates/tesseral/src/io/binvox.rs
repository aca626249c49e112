//! binvox (Patrick Min's voxelizer): a text header and run-length coded bytes.
//!
//! ```text
//! #binvox 1
//! dim DX DZ DY         (the extents along x, z and y: binvox's "depth height width")
//! translate TX TY TZ
//! scale S
//! data
//! (value, count) byte pairs, count 1..=255, over voxels in x, z, y order, y fastest
//! ```
//!
//! The voxel `(x, y, z)` of the grid has index `x·DZ·DY + z·DY + y`, and its lowest
//! corner lies at `translate + (x, y, z) · S / max(DX, DY, DZ)` in the world. We keep
//! that as a [`Frame`]: voxel size `S / max(D)`, and when `translate` is a whole
//! number of voxels (as OctoMap's `binvox2bt` assumes) the shift goes into the integer
//! voxel coordinates, so binvox voxels and OctoMap keys agree.

use std::io::{self, Write};
use std::path::Path;

use super::{FormatError, Frame, Model, MAX_DENSE_VOXELS};
use crate::code;
use crate::linear::{Leaf, LinearOctree};

/// The largest extent along one axis that we write (the run-length body of an empty
/// `N³` grid takes about `N³/128` bytes).
pub const MAX_WRITE_DIM: u64 = 2048;

/// Reads a `.binvox` file.
///
/// # Errors
/// [`FormatError::Syntax`] for a bad header line, [`FormatError::Corrupt`] for bad
/// run-length data, [`FormatError::TooLarge`] past [`MAX_DENSE_VOXELS`] filled voxels.
pub fn read(path: &Path) -> Result<Model, FormatError> {
    let bytes = super::read_limited(path, super::MAX_FILE_BYTES)?;
    decode(&bytes).map_err(|e| e.with_path(path))
}

/// Decodes `.binvox` bytes; `path` names the source in errors.
///
/// # Runtime
/// O(file size + filled voxels · log).
///
/// # Errors
/// As [`read`].
pub fn decode(bytes: &[u8]) -> Result<Model, FormatError> {
    let syntax = |line: usize, message: String| FormatError::Syntax {
        line,
        column: 1,
        message,
    };
    let mut pos = 0usize;
    let mut line_no = 0usize;
    let next_line = |pos: &mut usize| -> Option<&[u8]> {
        if *pos >= bytes.len() {
            return None;
        }
        let rest = &bytes[*pos..];
        let end = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        *pos += (end + 1).min(rest.len());
        Some(&rest[..end])
    };
    let first = next_line(&mut pos).unwrap_or_default();
    line_no += 1;
    let first = String::from_utf8_lossy(first);
    if !first.trim_end().starts_with("#binvox") {
        return Err(syntax(
            1,
            "not a binvox file (first line must be `#binvox 1`)".into(),
        ));
    }
    let mut dims: Option<[u64; 3]> = None;
    let mut translate = [0.0f64; 3];
    let mut scale = 1.0f64;
    loop {
        let Some(line) = next_line(&mut pos) else {
            return Err(syntax(
                line_no + 1,
                "header ends without a `data` line".into(),
            ));
        };
        line_no += 1;
        let text = String::from_utf8_lossy(line);
        let mut words = text.split_whitespace();
        let Some(key) = words.next() else { continue };
        let values: Vec<&str> = words.collect();
        match key {
            "data" => break,
            "dim" => {
                let d =
                    parse_n::<u64>(&values, 3).map_err(|m| syntax(line_no, format!("dim: {m}")))?;
                if d.contains(&0) {
                    return Err(syntax(line_no, "dim: extents must be positive".into()));
                }
                dims = Some([d[0], d[1], d[2]]);
            }
            "translate" => {
                let t = parse_n::<f64>(&values, 3)
                    .map_err(|m| syntax(line_no, format!("translate: {m}")))?;
                if t.iter().any(|v| !v.is_finite()) {
                    return Err(syntax(line_no, "translate: not finite".into()));
                }
                translate = [t[0], t[1], t[2]];
            }
            "scale" => {
                let s = parse_n::<f64>(&values, 1)
                    .map_err(|m| syntax(line_no, format!("scale: {m}")))?;
                if !(s[0].is_finite() && s[0] > 0.0) {
                    return Err(syntax(line_no, "scale: must be finite and positive".into()));
                }
                scale = s[0];
            }
            _ => {} // binvox readers skip unknown keywords
        }
    }
    let Some([dx, dz, dy]) = dims else {
        return Err(syntax(line_no, "header has no `dim` line".into()));
    };
    let total = dx
        .checked_mul(dy)
        .and_then(|v| v.checked_mul(dz))
        .filter(|&t| t < 1 << 62)
        .ok_or_else(|| FormatError::too_large(format!("grid {dx}×{dz}×{dy} is too large")))?;
    let max_dim = dx.max(dy).max(dz);
    if max_dim > 1 << 21 {
        return Err(FormatError::too_large(format!(
            "grid extent {max_dim} exceeds 2^21"
        )));
    }
    let voxel_size = scale / max_dim as f64;
    // A subnormal size (or one that underflows to 0) cannot be written back or used
    // to place anything: it would make a `.tess` with voxel size 0.
    if !voxel_size.is_normal() {
        return Err(FormatError::corrupt(
            format!("scale {scale:e} over {max_dim} voxels gives a voxel size of {voxel_size:e}, too small to represent"),
        ));
    }
    // Move a whole number of voxels of translate into the integer coordinates.
    let mut shift = [0i64; 3];
    let mut rest = translate;
    for a in 0..3 {
        let q = translate[a] / voxel_size;
        if q.abs() >= 1e15 {
            continue;
        }
        let r = q.round();
        // Whole voxels (within rounding) go entirely into the integer coordinates;
        // otherwise the integer part does and the fraction of a voxel stays behind.
        let whole = if (q - r).abs() <= 1e-6 * q.abs().max(1.0) {
            r
        } else {
            q.floor()
        };
        shift[a] = whole as i64;
        rest[a] = if whole == r && (q - r).abs() <= 1e-6 * q.abs().max(1.0) {
            0.0
        } else {
            translate[a] - whole * voxel_size
        };
    }
    let row = dy;
    let slab = dz * dy;
    // Codes relative to the origin `shift` are the grid coordinates themselves.
    let mut codes: Vec<u64> = Vec::new();
    let mut index = 0u64;
    let data = &bytes[pos..];
    let mut i = 0usize;
    while index < total {
        if i + 1 >= data.len() {
            return Err(FormatError::corrupt(format!(
                "data ends after {index} of {total} voxels (byte {})",
                pos + i
            )));
        }
        let (value, count) = (data[i], u64::from(data[i + 1]));
        if count == 0 || index + count > total {
            return Err(FormatError::corrupt(format!(
                "bad run of {count} at byte {} (voxel {index} of {total})",
                pos + i
            )));
        }
        if value > 1 {
            return Err(FormatError::corrupt(format!(
                "voxel value {value} at byte {} is not 0 or 1",
                pos + i
            )));
        }
        if value == 1 {
            if codes.len() as u64 + count > MAX_DENSE_VOXELS {
                return Err(FormatError::too_large(format!(
                    "more than {MAX_DENSE_VOXELS} filled voxels"
                )));
            }
            for j in index..index + count {
                let x = j / slab;
                let z = (j % slab) / row;
                let y = j % row;
                codes.push(code::encode(x as u32, y as u32, z as u32));
            }
        }
        index += count;
        i += 2;
    }
    let depth = max_dim.next_power_of_two().trailing_zeros() as u8;
    codes.sort_unstable();
    let tree =
        LinearOctree::from_sorted_leaves(depth, shift, codes.into_iter().map(|c| Leaf::new(c, 0)))
            .map_err(FormatError::octree)?;
    Ok(Model::new(tree).with_frame(Frame::new(voxel_size, rest)))
}

fn parse_n<T: std::str::FromStr>(values: &[&str], n: usize) -> Result<Vec<T>, String> {
    if values.len() != n {
        return Err(format!("expected {n} number(s), found {}", values.len()));
    }
    values
        .iter()
        .map(|v| v.parse::<T>().map_err(|_| format!("`{v}` is not a number")))
        .collect()
}

/// Writes `model` to `path` as binvox, over the cube that spans its bounding box.
///
/// # Errors
/// [`FormatError::Unsupported`] when the bounding box is wider than
/// [`MAX_WRITE_DIM`]; [`FormatError::Io`].
pub fn write_file(path: &Path, model: &Model) -> Result<(), FormatError> {
    let bytes = encode(model).map_err(|m| FormatError::unsupported(m).with_path(path))?;
    super::write_atomic(path, |w| w.write_all(&bytes))
}

/// Writes `model` as binvox to `w`.
///
/// # Errors
/// [`io::ErrorKind::InvalidInput`] when the grid would be too large; I/O errors of `w`.
pub fn write(w: &mut dyn Write, model: &Model) -> io::Result<()> {
    let bytes = encode(model).map_err(|m| io::Error::new(io::ErrorKind::InvalidInput, m))?;
    w.write_all(&bytes)
}

/// Encodes `model` as binvox bytes: the grid is the cube of side `max extent` at the
/// bounding box's lowest corner (a 1-voxel grid for an empty tree).
///
/// # Runtime
/// O(Σ over blocks of side² + rows + runs).
///
/// # Errors
/// A message when the grid would exceed [`MAX_WRITE_DIM`].
///
/// ```
/// use tesseral::io::{binvox, Model};
/// use tesseral::linear::LinearOctree;
/// let tree = LinearOctree::from_voxels(3, [0, 0, 0], [[0, 0, 0], [2, 1, 0]]).unwrap();
/// let bytes = binvox::encode(&Model::new(tree.clone())).unwrap();
/// let back = binvox::decode(&bytes).unwrap();
/// assert_eq!(back.tree.voxels().collect::<Vec<_>>(), tree.voxels().collect::<Vec<_>>());
/// ```
pub fn encode(model: &Model) -> Result<Vec<u8>, String> {
    let tree = &model.tree;
    let frame = model.frame;
    let (lo, hi) = tree.bbox().unwrap_or((tree.origin(), tree.origin()));
    let dim = (0..3)
        .map(|a| (hi[a] - lo[a]) as u64 + 1)
        .max()
        .unwrap_or(1);
    if dim > MAX_WRITE_DIM {
        return Err(format!(
            "the octree spans {dim} voxels; binvox output is limited to {MAX_WRITE_DIM}"
        ));
    }
    // One interval of y per (x, z) row touched by each block.
    let mut rows: Vec<(u64, u32, u32)> = Vec::new();
    for b in tree.blocks() {
        let s = b.size() as u64;
        let rel = [0, 1, 2].map(|a| (b.min[a] - lo[a]) as u64);
        for x in rel[0]..rel[0] + s {
            for z in rel[2]..rel[2] + s {
                rows.push((x * dim + z, rel[1] as u32, (rel[1] + s) as u32));
            }
        }
    }
    rows.sort_unstable();
    let mut out = Vec::new();
    let t = [0, 1, 2].map(|a| frame.translate[a] + lo[a] as f64 * frame.voxel_size);
    write!(
        out,
        "#binvox 1\ndim {dim} {dim} {dim}\ntranslate {} {} {}\nscale {}\ndata\n",
        t[0],
        t[1],
        t[2],
        frame.voxel_size * dim as f64
    )
    .expect("Vec write");
    let total = dim * dim * dim;
    // `cursor` is the index up to which runs have been written.
    let mut cursor = 0u64;
    let mut i = 0;
    while i < rows.len() {
        let (r, y0, mut y1) = rows[i];
        i += 1;
        while i < rows.len() && rows[i].0 == r && rows[i].1 <= y1 {
            y1 = y1.max(rows[i].2);
            i += 1;
        }
        let start = r * dim + u64::from(y0);
        let end = r * dim + u64::from(y1);
        put_runs(&mut out, 0, start - cursor);
        put_runs(&mut out, 1, end - start);
        cursor = end;
    }
    put_runs(&mut out, 0, total - cursor);
    Ok(out)
}

/// Appends `n` voxels of `value` as runs of at most 255.
fn put_runs(out: &mut Vec<u8>, value: u8, mut n: u64) {
    while n > 0 {
        let c = n.min(255);
        out.push(value);
        out.push(c as u8);
        n -= c;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Voxel;
    use rand::SeedableRng;
    use std::collections::HashSet;

    #[test]
    fn decodes_the_voxel_order_x_z_y_with_y_fastest() {
        // 2×2×2 grid: ones at indices 1 (y=1) and 2 (z=1) and 4 (x=1).
        let mut bytes = b"#binvox 1\ndim 2 2 2\ntranslate 0 0 0\nscale 2\ndata\n".to_vec();
        bytes.extend_from_slice(&[0, 1, 1, 2, 0, 1, 1, 1, 0, 3]);
        let m = decode(&bytes).unwrap();
        let v: HashSet<Voxel> = m.tree.voxels().collect();
        assert_eq!(v, HashSet::from([[0, 1, 0], [0, 0, 1], [1, 0, 0]]));
        assert_eq!(m.frame.voxel_size, 1.0);
    }

    #[test]
    fn translate_and_scale_survive_a_round_trip() {
        let mut bytes = b"#binvox 1\ndim 4 4 4\ntranslate -0.5 0.25 0.1\nscale 2\ndata\n".to_vec();
        bytes.extend_from_slice(&[0, 5, 1, 3, 0, 56]);
        let m = decode(&bytes).unwrap();
        let f = m.frame;
        assert_eq!(f.voxel_size, 0.5);
        // -0.5 is one whole voxel; 0.25 is half a voxel, so it stays in the frame.
        assert_eq!(m.tree.origin()[0], -1);
        assert_eq!(f.translate[1], 0.25);
        let again = decode(&encode(&m).unwrap()).unwrap();
        assert_eq!(
            again.tree.voxels().collect::<Vec<_>>(),
            m.tree.voxels().collect::<Vec<_>>()
        );
        let g = again.frame;
        assert!((g.voxel_size - 0.5).abs() < 1e-12);
        for a in 0..3 {
            assert!((g.translate[a] - f.translate[a]).abs() < 1e-12);
        }
    }

    #[test]
    fn random_round_trips_match_a_voxel_set() {
        for seed in 0..50u64 {
            let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
            let (origin, voxels) = crate::io::random_voxels(&mut rng, 9, 16, 500);
            let voxels: HashSet<Voxel> = voxels.into_iter().collect();
            let tree = LinearOctree::from_voxels(4, origin, voxels.iter().copied()).unwrap();
            let bytes = encode(&Model::new(tree)).unwrap();
            let back = decode(&bytes).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
            back.tree.assert_valid();
            assert_eq!(
                back.tree.voxels().collect::<HashSet<_>>(),
                voxels,
                "seed {seed}"
            );
        }
    }

    #[test]
    fn bad_files_give_errors() {
        for bad in [
            &b""[..],
            b"#binvox 1\n",
            b"#binvox 1\ndim 2 2\ndata\n",
            b"#binvox 1\ndim 2 2 2\ndata\n\x01\x09",
            b"#binvox 1\ndim 2 2 2\ndata\n\x01\x00",
            b"#binvox 1\ndim 2 2 2\ndata\n\x07\x08",
            b"#binvox 1\ndim 2 2 2\ndata\n\x01\x07",
            b"#binvox 1\ndim 4000000000 4000000000 4000000000\ndata\n\x01\xff",
            b"#binvox 1\ndim 2 2 2\nscale -1\ndata\n\x01\x08",
        ] {
            assert!(decode(bad).is_err(), "{:?}", String::from_utf8_lossy(bad));
        }
    }
}
