//! tesseral's native binary format, extension `.tess`: a linear octree as delta-coded
//! varints, with a versioned header and a CRC-32 checksum.
//!
//! Layout (all integers little-endian):
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 8 | magic `89 54 45 53 53 52 4C 0A` (`\x89TESSRL\n`) |
//! | 8 | 2 | version, `1` |
//! | 10 | 2 | flags: which sections follow the leaves (below) |
//! | 12 | 1 | depth D (≤ 21) |
//! | 13 | 3 | zero |
//! | 16 | 24 | origin, three `i64` |
//! | 40 | 8 | leaf count n |
//! | 48 | 8 | payload length p in bytes |
//! | 56 | p | n varints (LEB128): the first packed leaf, then the difference of each packed leaf from the one before |
//! | … | 32 | flag bit 0: the frame, voxel size and translate, four `f64` |
//! | … | … | flag bit 1 (read only, written by older versions): colour count m (`u64`), then m × (varint code delta, 4 bytes RGBA) |
//! | … | … | flag bit 2: colours as regions (a *layer*, below) of 4 bytes RGBA |
//! | … | … | flag bit 3: known-free space, a *leaf stream* |
//! | … | … | flag bit 4: occupancy log-odds as a layer of 4-byte `f32` |
//! | end − 4 | 4 | CRC-32 (IEEE) of every byte before it |
//!
//! A *leaf stream* is a leaf count n (`u64`) then n varints as in the payload. A
//! *layer* is a region count r (`u64`), then per region its value's bytes and a leaf
//! stream of the voxels that hold it; regions are disjoint. Each section is
//! self-delimiting, so a reader can skip what it does not need.
//!
//! A packed leaf ([`crate::linear::Leaf::packed`]) holds the code and the block size, and packed
//! leaves increase strictly, so the deltas are positive and small: one byte for most
//! leaves of a solid. The layout has no pointers, so the file can be memory-mapped
//! and decoded in one pass ([`read`] maps it with `memmap2`).
//!
//! The reader trusts no stored count: it checks the checksum first, allocates no more
//! than the file's own length can justify, validates every leaf (packing, size,
//! bounds, order) and checks that the counts and lengths add up exactly.

use std::io::{self, Write};
use std::path::Path;

use super::leafstream::{put_leaves, read_leaves, Reader};
use super::FormatError;
use crate::linear::{LinearOctree, MAX_DEPTH};
use crate::model::{Frame, Layer, LayerValue, Model};

/// The eight bytes every `.tess` file starts with.
pub const MAGIC: [u8; 8] = *b"\x89TESSRL\n";
/// The version this code writes and reads.
pub const VERSION: u16 = 1;
const FLAG_FRAME: u16 = 1;
const FLAG_COLORS: u16 = 2;
const FLAG_COLOR_LAYER: u16 = 4;
const FLAG_FREE: u16 = 8;
const FLAG_LOG_ODDS: u16 = 16;
const KNOWN_FLAGS: u16 = FLAG_FRAME | FLAG_COLORS | FLAG_COLOR_LAYER | FLAG_FREE | FLAG_LOG_ODDS;
const HEADER_LEN: usize = 56;

/// Reads a `.tess` file by memory-mapping it, falling back to reading it into memory
/// when mapping fails (for example on a pipe).
///
/// # Runtime
/// O(file size + n) for n leaves.
///
/// # Errors
/// [`FormatError::Corrupt`] naming the field for a truncated, corrupted or hostile
/// file; [`FormatError::Io`] when the file cannot be read.
pub fn read(path: &Path) -> Result<Model, FormatError> {
    let file = std::fs::File::open(path).map_err(|e| FormatError::io(e).with_path(path))?;
    // SAFETY: the map is read-only and dropped before we return. Another process
    // truncating or rewriting the file while we decode could change the bytes under
    // us; `decode` treats the slice as untrusted input (every read is bounds-checked
    // against the slice length, taken once), so such a race gives at worst a checksum
    // or format error, or SIGBUS on truncation, which memory-mapped readers accept.
    // `write_atomic` replaces files by rename, so our own writers never do this.
    match unsafe { memmap2::Mmap::map(&file) } {
        Ok(map) => decode(&map).map_err(|e| e.with_path(path)),
        Err(_) => {
            let bytes = super::read_limited(path, super::MAX_FILE_BYTES)?;
            decode(&bytes).map_err(|e| e.with_path(path))
        }
    }
}

/// Reads a `.tess` file into memory with plain reads (the safe fallback of [`read`]).
///
/// # Errors
/// As [`read`].
pub fn read_unmapped(path: &Path) -> Result<Model, FormatError> {
    let bytes = super::read_limited(path, super::MAX_FILE_BYTES)?;
    decode(&bytes).map_err(|e| e.with_path(path))
}

/// Encodes a model into `.tess` bytes.
///
/// ```
/// use tesseral::io::{native, Model};
/// use tesseral::linear::LinearOctree;
/// let tree = LinearOctree::from_voxels(4, [-8, 0, 0], [[-8, 0, 0], [3, 2, 1]]).unwrap();
/// let bytes = native::encode(&Model::new(tree.clone()));
/// let back = native::decode(&bytes).unwrap();
/// assert_eq!(back.tree, tree);
/// ```
#[must_use]
pub fn encode(model: &Model) -> Vec<u8> {
    let mut out = Vec::new();
    write(&mut out, model).expect("writing to a Vec cannot fail");
    out
}

/// Writes a model in the `.tess` format.
///
/// # Runtime
/// O(n) for n leaves (plus the colours).
///
/// # Errors
/// Any I/O error of `w`.
pub fn write(w: &mut dyn Write, model: &Model) -> io::Result<()> {
    let tree = &model.tree;
    let mut payload = Vec::with_capacity(tree.leaf_count() + 16);
    put_leaves(&mut payload, tree.leaves());
    let mut flags = FLAG_FRAME;
    let mut tail = Vec::new();
    tail.extend_from_slice(&model.frame.voxel_size.to_le_bytes());
    for t in model.frame.translate {
        tail.extend_from_slice(&t.to_le_bytes());
    }
    if let Some(colors) = &model.colors {
        flags |= FLAG_COLOR_LAYER;
        put_layer(&mut tail, colors, |c| c.to_vec());
    }
    if let Some(free) = &model.free {
        flags |= FLAG_FREE;
        put_stream(&mut tail, free);
    }
    if let Some(odds) = &model.log_odds {
        flags |= FLAG_LOG_ODDS;
        put_layer(&mut tail, odds, |x| x.to_le_bytes().to_vec());
    }
    let mut header = Vec::with_capacity(HEADER_LEN);
    header.extend_from_slice(&MAGIC);
    header.extend_from_slice(&VERSION.to_le_bytes());
    header.extend_from_slice(&flags.to_le_bytes());
    header.push(tree.depth());
    header.extend_from_slice(&[0, 0, 0]);
    for o in tree.origin() {
        header.extend_from_slice(&o.to_le_bytes());
    }
    header.extend_from_slice(&(tree.leaf_count() as u64).to_le_bytes());
    header.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    let mut crc = crc32fast::Hasher::new();
    for part in [&header, &payload, &tail] {
        crc.update(part);
        w.write_all(part)?;
    }
    w.write_all(&crc.finalize().to_le_bytes())
}

/// Decodes `.tess` bytes; `path` names the source in errors.
///
/// # Runtime
/// O(len + n).
///
/// # Errors
/// [`FormatError::Corrupt`] naming the field at fault.
pub fn decode(bytes: &[u8]) -> Result<Model, FormatError> {
    let bad = |m: String| FormatError::corrupt(m);
    if bytes.len() < 8 || bytes[..8] != MAGIC {
        return Err(bad("not a tesseral .tess file (bad magic number)".into()));
    }
    if bytes.len() < HEADER_LEN + 4 {
        return Err(bad(format!(
            "truncated: {} bytes, a header needs {}",
            bytes.len(),
            HEADER_LEN + 4
        )));
    }
    let version = u16::from_le_bytes([bytes[8], bytes[9]]);
    if version != VERSION {
        return Err(FormatError::unsupported(format!(
            "format version {version}; this build reads version {VERSION}"
        )));
    }
    let (body, stored) = bytes.split_at(bytes.len() - 4);
    let stored = u32::from_le_bytes([stored[0], stored[1], stored[2], stored[3]]);
    let actual = crc32fast::hash(body);
    if stored != actual {
        return Err(bad(format!(
            "checksum mismatch (stored {stored:08x}, computed {actual:08x}): the file is truncated or corrupted"
        )));
    }
    let mut r = Reader {
        bytes: body,
        pos: 10,
    };
    let flags = r.u16().map_err(&bad)?;
    if flags & !KNOWN_FLAGS != 0 {
        return Err(FormatError::unsupported(format!(
            "unknown flags {flags:#06x}"
        )));
    }
    let depth = r.u8().map_err(&bad)?;
    if depth > MAX_DEPTH {
        return Err(bad(format!(
            "depth {depth} exceeds the maximum {MAX_DEPTH}"
        )));
    }
    r.pos += 3;
    let origin = [
        r.i64().map_err(&bad)?,
        r.i64().map_err(&bad)?,
        r.i64().map_err(&bad)?,
    ];
    let leaf_count = r.u64().map_err(&bad)?;
    let payload_len = r.u64().map_err(&bad)?;
    let payload_end = usize::try_from(payload_len)
        .ok()
        .and_then(|p| p.checked_add(HEADER_LEN))
        .filter(|&e| e <= body.len())
        .ok_or_else(|| {
            bad(format!(
                "payload length {payload_len} runs past the end of the file"
            ))
        })?;
    // Every leaf takes at least one byte, so the payload length bounds the count.
    if leaf_count > payload_len {
        return Err(bad(format!(
            "leaf count {leaf_count} cannot fit in a payload of {payload_len} bytes"
        )));
    }
    let space_end = 1u64 << (3 * u32::from(depth));
    let mut payload = Reader {
        bytes: &body[..payload_end],
        pos: HEADER_LEN,
    };
    let leaves = read_leaves(&mut payload, leaf_count, depth, "leaf").map_err(&bad)?;
    if payload.pos != payload_end {
        return Err(bad(format!(
            "payload has {} byte(s) after the last of {leaf_count} leaves",
            payload_end - payload.pos
        )));
    }
    let tree =
        LinearOctree::from_sorted_leaves(depth, origin, leaves).map_err(FormatError::octree)?;
    let mut tail = Reader {
        bytes: body,
        pos: payload_end,
    };
    let frame = if flags & FLAG_FRAME != 0 {
        let voxel_size = tail.f64().map_err(&bad)?;
        let translate = [
            tail.f64().map_err(&bad)?,
            tail.f64().map_err(&bad)?,
            tail.f64().map_err(&bad)?,
        ];
        if !(voxel_size.is_normal() && voxel_size > 0.0) || translate.iter().any(|t| !t.is_finite())
        {
            return Err(bad(format!("frame: voxel size {voxel_size} or translate {translate:?} is not finite and positive")));
        }
        Frame::new(voxel_size, translate)
    } else {
        Frame::default()
    };
    let mut colors = None;
    if flags & FLAG_COLORS != 0 {
        let count = tail.u64().map_err(&bad)?;
        let remaining = (body.len() - tail.pos) as u64;
        if count > remaining / 5 {
            return Err(bad(format!(
                "colour count {count} cannot fit in {remaining} bytes"
            )));
        }
        let mut pairs = Vec::with_capacity(count as usize);
        let mut code = 0u64;
        for index in 0..count {
            let delta = tail
                .varint()
                .map_err(|m| bad(format!("colour {index}: {m}")))?;
            code = code
                .checked_add(delta)
                .filter(|&c| c < space_end && (index == 0 || delta > 0))
                .ok_or_else(|| bad(format!("colour {index}: bad voxel code")))?;
            let rgba = tail.take(4).map_err(&bad)?;
            pairs.push((tree.voxel_of(code), [rgba[0], rgba[1], rgba[2], rgba[3]]));
        }
        colors = Some(Layer::from_voxels(depth, origin, pairs).map_err(FormatError::octree)?);
    }
    if flags & FLAG_COLOR_LAYER != 0 {
        colors = Some(
            read_layer(&mut tail, depth, origin, "colour", |b| {
                [b[0], b[1], b[2], b[3]]
            })
            .map_err(&bad)?,
        );
    }
    let free = if flags & FLAG_FREE != 0 {
        Some(read_stream(&mut tail, depth, origin, "free leaf").map_err(&bad)?)
    } else {
        None
    };
    let log_odds = if flags & FLAG_LOG_ODDS != 0 {
        Some(
            read_layer(&mut tail, depth, origin, "log-odds", |b| {
                f32::from_le_bytes([b[0], b[1], b[2], b[3]])
            })
            .map_err(&bad)?,
        )
    } else {
        None
    };
    if tail.pos != body.len() {
        return Err(bad(format!(
            "{} unexpected byte(s) before the checksum",
            body.len() - tail.pos
        )));
    }
    let model = Model {
        tree,
        frame,
        colors,
        free,
        log_odds,
    };
    check_parts(&model).map_err(bad)?;
    Ok(model)
}

/// Checks what the sections claim against each other: colours on black voxels, free
/// space disjoint from them, log-odds on known voxels.
fn check_parts(m: &Model) -> Result<(), String> {
    use crate::linear::SetOp;
    if let Some(c) = &m.colors {
        if !c
            .domain()
            .set_op_same_space(&m.tree, SetOp::Difference)
            .is_empty()
        {
            return Err("colour section: colours on voxels that are not black".into());
        }
    }
    if let Some(f) = &m.free {
        if !f.set_op_same_space(&m.tree, SetOp::Intersection).is_empty() {
            return Err("free section: free voxels that are also black".into());
        }
    }
    if let Some(l) = &m.log_odds {
        if !l
            .domain()
            .set_op_same_space(&m.known(), SetOp::Difference)
            .is_empty()
        {
            return Err("log-odds section: values on unknown voxels".into());
        }
    }
    Ok(())
}

fn put_stream(out: &mut Vec<u8>, tree: &LinearOctree) {
    out.extend_from_slice(&(tree.leaf_count() as u64).to_le_bytes());
    put_leaves(out, tree.leaves());
}

fn put_layer<T: LayerValue>(out: &mut Vec<u8>, layer: &Layer<T>, bytes: impl Fn(&T) -> Vec<u8>) {
    out.extend_from_slice(&(layer.region_count() as u64).to_le_bytes());
    for (x, t) in layer.regions() {
        out.extend_from_slice(&bytes(x));
        put_stream(out, t);
    }
}

fn read_stream(
    r: &mut Reader<'_>,
    depth: u8,
    origin: crate::Voxel,
    what: &str,
) -> Result<LinearOctree, String> {
    let count = r.u64()?;
    let leaves = read_leaves(r, count, depth, what)?;
    LinearOctree::from_sorted_leaves(depth, origin, leaves).map_err(|e| format!("{what}: {e}"))
}

fn read_layer<T: LayerValue>(
    r: &mut Reader<'_>,
    depth: u8,
    origin: crate::Voxel,
    what: &str,
    value: impl Fn(&[u8]) -> T,
) -> Result<Layer<T>, String> {
    let count = r.u64()?;
    let remaining = (r.bytes.len() - r.pos) as u64;
    // A region takes at least 4 + 8 bytes.
    if count > remaining / 12 {
        return Err(format!(
            "{what} region count {count} cannot fit in {remaining} bytes"
        ));
    }
    let mut regions = Vec::with_capacity(count as usize);
    let mut keys = std::collections::HashSet::new();
    for i in 0..count {
        let x = value(r.take(4)?);
        if !keys.insert(x.key()) {
            return Err(format!("{what} region {i}: repeats a value"));
        }
        regions.push((
            x,
            read_stream(r, depth, origin, &format!("{what} region {i} leaf"))?,
        ));
    }
    let layer = Layer::from_regions(depth, origin, regions).map_err(|e| e.to_string())?;
    let total: u64 = layer.regions().iter().map(|(_, t)| t.voxel_count()).sum();
    if layer.domain().voxel_count() != total {
        return Err(format!("{what} section: regions overlap"));
    }
    Ok(layer)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::leafstream::put_varint;
    use rand::{Rng, SeedableRng};

    fn random_tree(seed: u64) -> LinearOctree {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let depth = rng.random_range(0..=6u8);
        let side = 1i64 << depth;
        let origin = [rng.random_range(-100..100), rng.random_range(-100..100), 7];
        let n = rng.random_range(0..300);
        let blob = rng.random_bool(0.5);
        let voxels: Vec<_> = (0..n)
            .map(|_| {
                let r = if blob { side / 2 + 1 } else { side };
                [
                    origin[0] + rng.random_range(0..r),
                    origin[1] + rng.random_range(0..r),
                    origin[2] + rng.random_range(0..r),
                ]
            })
            .collect();
        LinearOctree::from_voxels(depth, origin, voxels).unwrap()
    }

    #[test]
    fn round_trips_random_trees_with_frame_and_colours() {
        for seed in 0..200 {
            let tree = random_tree(seed);
            let pairs = tree
                .voxels()
                .step_by(3)
                .map(|v| (v, [v[0] as u8, v[1] as u8, 9, 255]));
            let colors = Layer::from_voxels(tree.depth(), tree.origin(), pairs).unwrap();
            // Free space: the voxels of the space's first octant that are not black.
            let octant = LinearOctree::full(tree.depth().saturating_sub(1), tree.origin()).unwrap();
            let free = octant.difference(&tree).unwrap();
            let known = tree.union(&free).unwrap();
            let odds = Layer::from_voxels(
                tree.depth(),
                tree.origin(),
                known
                    .voxels()
                    .map(|v| (v, if v[0] % 2 == 0 { 0.85f32 } else { -0.4 })),
            )
            .unwrap();
            let frame = if seed % 2 == 0 {
                Frame::new(0.05, [1.5, -2.0, 0.25])
            } else {
                Frame::default()
            };
            let model = Model::from_parts(
                tree.clone(),
                frame,
                (seed % 3 == 0).then_some(colors),
                (seed % 4 < 2).then_some(free),
                (seed % 4 == 0).then_some(odds),
            )
            .unwrap();
            model.assert_valid();
            let bytes = encode(&model);
            let back = decode(&bytes).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
            back.assert_valid();
            assert_eq!(back, model, "seed {seed}");
        }
    }

    #[test]
    fn every_truncation_and_bit_flip_is_an_error() {
        let tree = random_tree(7);
        let bytes = encode(&Model::new(tree));
        for len in 0..bytes.len() {
            assert!(decode(&bytes[..len]).is_err(), "truncated to {len}");
        }
        for i in 0..bytes.len() {
            for bit in 0..8 {
                let mut b = bytes.clone();
                b[i] ^= 1 << bit;
                assert!(decode(&b).is_err(), "flip byte {i} bit {bit}");
            }
        }
    }

    #[test]
    fn hostile_counts_with_valid_checksums_are_refused() {
        // A forged header claiming 2^60 leaves, with a correct checksum.
        let tree = LinearOctree::from_voxels(3, [0, 0, 0], [[1, 1, 1]]).unwrap();
        let mut bytes = encode(&Model::new(tree));
        bytes[40..48].copy_from_slice(&(1u64 << 60).to_le_bytes());
        let n = bytes.len();
        let crc = crc32fast::hash(&bytes[..n - 4]);
        bytes[n - 4..].copy_from_slice(&crc.to_le_bytes());
        let err = decode(&bytes).unwrap_err().to_string();
        assert!(err.contains("leaf count"), "{err}");
        // Depth beyond the limit.
        let mut bytes = encode(&Model::new(LinearOctree::empty(2, [0; 3]).unwrap()));
        bytes[12] = 40;
        let crc = crc32fast::hash(&bytes[..bytes.len() - 4]);
        let n = bytes.len();
        bytes[n - 4..].copy_from_slice(&crc.to_le_bytes());
        let err = decode(&bytes).unwrap_err().to_string();
        assert!(err.contains("depth 40"), "{err}");
    }

    #[test]
    fn varint_round_trip_and_overflow() {
        for v in [0, 1, 127, 128, 300, u64::MAX >> 1, u64::MAX] {
            let mut out = Vec::new();
            put_varint(&mut out, v);
            assert_eq!(
                Reader {
                    bytes: &out,
                    pos: 0
                }
                .varint(),
                Ok(v)
            );
        }
        let over = [0xffu8; 10];
        assert!(Reader {
            bytes: &over,
            pos: 0
        }
        .varint()
        .is_err());
    }

    #[test]
    fn mapped_and_unmapped_reads_agree() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.tess");
        let model = Model::new(random_tree(3));
        crate::io::write_model(&path, &model).unwrap();
        assert_eq!(read(&path).unwrap(), model);
        assert_eq!(read_unmapped(&path).unwrap(), model);
        assert_eq!(crate::io::read_octree(&path).unwrap(), model.tree);
    }
}
