//! tesseral's native binary format, extension `.tess`: a linear octree as delta-coded
//! varints, with a versioned header and CRC-32 checksums.
//!
//! Version 2 (written since the streaming work) keeps the leaves in *chunks*, in
//! tesseral order, each with its code range, count and CRC, and ends with an index
//! of the chunks, so a writer never holds the whole tree ([`super::TessWriter`]) and
//! a reader seeks to a code range ([`super::TessFile`]). All integers little-endian:
//!
//! | part | size | field |
//! |---|---|---|
//! | header | 8 | magic `89 54 45 53 53 52 4C 0A` (`\x89TESSRL\n`) |
//! | | 2 | version, `2` |
//! | | 2 | zero |
//! | | 1 | depth D (≤ 21) |
//! | | 3 | zero |
//! | | 24 | origin, three `i64` |
//! | chunk (repeated) | 32 | `lo` (first leaf's code), `hi` (end of its last leaf), leaf count c, payload length p: four `u64` |
//! | | p | c varints: the first packed leaf, then each one's difference from the one before |
//! | | 4 | CRC-32 of the chunk's 32 + p bytes |
//! | sections | 2 | flags (below) |
//! | | … | the sections named by the flags, as in version 1 |
//! | index | 32 × chunks | per chunk: offset, `lo`, `hi`, count: four `u64` |
//! | trailer | 32 | sections offset, index offset, chunk count, leaf count: four `u64` |
//! | | 4 | zero |
//! | | 4 | CRC-32 of the header, the sections, the index and the trailer before it |
//! | | 8 | `TESSIDX\n` |
//!
//! Version 1 (still read) holds the leaves in one payload:
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 8 | magic |
//! | 8 | 2 | version, `1` |
//! | 10 | 2 | flags: which sections follow the leaves (below) |
//! | 12 | 1 | depth D (≤ 21) |
//! | 13 | 3 | zero |
//! | 16 | 24 | origin, three `i64` |
//! | 40 | 8 | leaf count n |
//! | 48 | 8 | payload length p in bytes |
//! | 56 | p | n varints (LEB128): the first packed leaf, then the difference of each packed leaf from the one before |
//! | … | … | the sections |
//! | end − 4 | 4 | CRC-32 (IEEE) of every byte before it |
//!
//! The sections, in this order, each present when its flag bit is set:
//!
//! | flag bit | section |
//! |---|---|
//! | 0 | the frame, voxel size and translate, four `f64` |
//! | 1 | (read only, written by older versions) colour count m (`u64`), then m × (varint code delta, 4 bytes RGBA) |
//! | 2 | colours as regions (a *layer*, below) of 4 bytes RGBA |
//! | 3 | known-free space, a *leaf stream* |
//! | 4 | occupancy log-odds as a layer of 4-byte `f32` |
//! | 5 | (version 2 only) the colour index, last (layout in `io/colour_index.rs` and docs/formats.md) |
//!
//! A *leaf stream* is a leaf count n (`u64`) then n varints as in the payload. A
//! *layer* is a region count r (`u64`), then per region its value's bytes and a leaf
//! stream of the voxels that hold it; regions are disjoint. Each section is
//! self-delimiting, so a reader can skip what it does not need.
//!
//! A packed leaf ([`crate::linear::Leaf::packed`]) holds the code and the block size, and packed
//! leaves increase strictly, so the deltas are positive and small: one byte for most
//! leaves of a solid. The layout has no pointers but the index, so the file can be
//! memory-mapped and decoded in one pass ([`read`] maps it with `memmap2`).
//!
//! The reader trusts no stored count: it checks the checksums first, allocates no more
//! than the file's own length can justify, validates every leaf (packing, size,
//! bounds, order) and checks that the counts and lengths add up exactly.

use std::io::{self, Write};
use std::path::Path;

use super::chunked::{chunk_leaves, parse_layout, TessWriter, VERSION_CHUNKED};
use super::colour_index::FLAG_COLOUR_INDEX;
use super::leafstream::{put_leaves, read_leaves, Reader};
use super::sections::{check_parts, put_sections, read_sections, Extras, Sections, KNOWN_FLAGS};
use super::FormatError;
use crate::linear::{LinearOctree, MAX_DEPTH};
use crate::model::Model;

/// The eight bytes every `.tess` file starts with.
pub const MAGIC: [u8; 8] = *b"\x89TESSRL\n";
/// The eight bytes an occupancy map's own `.tess` starts with: a map too wide for a
/// model (past 2^21 cells on an axis), written by
/// [`OccupancyMap::write_file`](crate::occupancy::OccupancyMap::write_file) and read
/// by [`OccupancyMap::read_file`](crate::occupancy::OccupancyMap::read_file).
pub const MAP_MAGIC: [u8; 8] = *b"\x89TESSOM\n";
/// The eight bytes an unbounded dynamic octree's own `.tess` starts with: an octree
/// too wide for a model (past 2^21 voxels on an axis), written by
/// [`DynamicOctree::write_file`](crate::dynamic::DynamicOctree::write_file) and read
/// by [`DynamicOctree::read_file`](crate::dynamic::DynamicOctree::read_file).
pub const DYN_MAGIC: [u8; 8] = *b"\x89TESSDY\n";

/// The error for bytes that do not start with [`MAGIC`]: a map's or a dynamic
/// octree's own `.tess` is named as such (it holds more than a model can).
pub(crate) fn not_a_model(bytes: &[u8]) -> FormatError {
    if bytes.starts_with(&MAP_MAGIC) {
        FormatError::unsupported(
            "an occupancy map wider than a model holds (2^21 cells on an axis), in the map's \
             own .tess: read it as a map (OccupancyMap::read_file, Python \
             tesseral.OccupancyMap.read)",
        )
    } else if bytes.starts_with(&DYN_MAGIC) {
        FormatError::unsupported(
            "an unbounded dynamic octree wider than a model holds (2^21 voxels on an axis), \
             in the dynamic octree's own .tess (written by tesseral replay -o): read it as a \
             dynamic octree (DynamicOctree::read_file, Python tesseral.DynamicOctree.read; \
             tesseral info describes it)",
        )
    } else {
        FormatError::corrupt("not a tesseral .tess file (bad magic number)")
    }
}
/// The version this code writes: chunked, with an index.
pub const VERSION: u16 = VERSION_CHUNKED;
/// The first version, with the leaves in one payload: still read, and written by
/// [`write_v1`].
pub const VERSION_1: u16 = 1;
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

/// Writes a model in the `.tess` format (version 2, chunked).
///
/// # Runtime
/// O(n) for n leaves (plus the colours).
///
/// # Errors
/// Any I/O error of `w`.
pub fn write(w: &mut dyn Write, model: &Model) -> io::Result<()> {
    let tree = &model.tree;
    let mut tw = TessWriter::new(w, tree.depth(), tree.origin())?;
    for &leaf in tree.leaves() {
        tw.push(leaf)?;
    }
    tw.finish_sections(&Sections::of(model))?;
    Ok(())
}

/// Writes a model in version 1 of the `.tess` format (one payload, one checksum),
/// which older builds read.
///
/// # Errors
/// Any I/O error of `w`.
pub fn write_v1(w: &mut dyn Write, model: &Model) -> io::Result<()> {
    let tree = &model.tree;
    let mut payload = Vec::with_capacity(tree.leaf_count() + 16);
    put_leaves(&mut payload, tree.leaves());
    let mut tail = Vec::new();
    let flags = put_sections(&mut tail, &Sections::of(model));
    let mut header = Vec::with_capacity(HEADER_LEN);
    header.extend_from_slice(&MAGIC);
    header.extend_from_slice(&VERSION_1.to_le_bytes());
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

/// Decodes `.tess` bytes of either version.
///
/// # Runtime
/// O(len + n).
///
/// # Errors
/// [`FormatError::Corrupt`] naming the field at fault.
pub fn decode(bytes: &[u8]) -> Result<Model, FormatError> {
    let bad = |m: String| FormatError::corrupt(m);
    if bytes.len() < 8 || bytes[..8] != MAGIC {
        return Err(not_a_model(bytes));
    }
    if bytes.len() < 10 {
        return Err(bad("truncated: no version after the magic number".into()));
    }
    match u16::from_le_bytes([bytes[8], bytes[9]]) {
        VERSION_1 => decode_v1(bytes),
        VERSION_CHUNKED => decode_v2(bytes),
        version => Err(FormatError::unsupported(format!(
            "format version {version}; this build reads versions {VERSION_1} and {VERSION}"
        ))),
    }
}

/// Decodes version-2 bytes: the layout, every chunk, the sections.
fn decode_v2(bytes: &[u8]) -> Result<Model, FormatError> {
    let bad = |m: String| FormatError::corrupt(m);
    let layout = parse_layout(bytes).map_err(bad)?;
    let mut leaves = Vec::with_capacity(layout.leaf_count as usize);
    for i in 0..layout.chunks.len() {
        leaves.extend(chunk_leaves(bytes, &layout, i).map_err(bad)?);
    }
    let tree = LinearOctree::from_sorted_leaves(layout.depth, layout.origin, leaves)
        .map_err(FormatError::octree)?;
    let extras = decode_sections(bytes, &layout, &tree).map_err(bad)?;
    let model = extras.into_model(tree);
    check_parts(&model).map_err(bad)?;
    Ok(model)
}

/// The sections of a version-2 file, read exactly to the index.
pub(crate) fn decode_sections(
    bytes: &[u8],
    layout: &super::chunked::Layout,
    space: &LinearOctree,
) -> Result<Extras, String> {
    let (start, end) = layout.sections;
    let mut r = Reader {
        bytes: &bytes[..end],
        pos: start,
    };
    let flags = r.u16()?;
    if flags & !(KNOWN_FLAGS | FLAG_COLOUR_INDEX) != 0 {
        return Err(format!("unknown section flags {flags:#06x}"));
    }
    let extras = read_sections(&mut r, flags & !FLAG_COLOUR_INDEX, space)?;
    if let Some(ix) = &layout.colour_index {
        // Read in full, the colour section is checked against the whole index, so
        // that a file reads the same in memory and streamed.
        if r.pos != ix.start {
            return Err(format!(
                "colour index: starts at byte {} where the sections before it end at {}",
                ix.start, r.pos
            ));
        }
        super::colour_index::verify_blocks(bytes, ix, space.depth())?;
        r.pos = end;
    }
    if r.pos != end {
        return Err(format!(
            "{} unexpected byte(s) before the index",
            end - r.pos
        ));
    }
    Ok(extras)
}

/// The section flags and the frame of version-2 bytes, without the layers that
/// follow the frame (see [`decode_sections`]).
pub(crate) fn decode_frame(
    bytes: &[u8],
    layout: &super::chunked::Layout,
    space: &LinearOctree,
) -> Result<(u16, crate::model::Frame), String> {
    let (start, end) = layout.sections;
    let mut r = Reader {
        bytes: &bytes[..end],
        pos: start,
    };
    let flags = r.u16()?;
    if flags & !(KNOWN_FLAGS | FLAG_COLOUR_INDEX) != 0 {
        return Err(format!("unknown section flags {flags:#06x}"));
    }
    let frame = read_sections(&mut r, flags & super::sections::FLAG_FRAME, space)?.frame;
    Ok((flags, frame))
}

/// Decodes version-1 bytes.
fn decode_v1(bytes: &[u8]) -> Result<Model, FormatError> {
    let bad = |m: String| FormatError::corrupt(m);
    if bytes.len() < HEADER_LEN + 4 {
        return Err(bad(format!(
            "truncated: {} bytes, a header needs {}",
            bytes.len(),
            HEADER_LEN + 4
        )));
    }
    let body = super::leafstream::crc_checked(bytes).map_err(bad)?;
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
    let extras = read_sections(&mut tail, flags, &tree).map_err(&bad)?;
    if tail.pos != body.len() {
        return Err(bad(format!(
            "{} unexpected byte(s) before the checksum",
            body.len() - tail.pos
        )));
    }
    let model = extras.into_model(tree);
    check_parts(&model).map_err(bad)?;
    Ok(model)
}

#[cfg(test)]
#[path = "native_tests.rs"]
pub(crate) mod tests;
