//! Reading a version-2 file's frame: the header, the trailer and the chunk index
//! checked against each other ([`Layout`]), and one chunk's leaves decoded.

use super::{ChunkInfo, CHUNK_HEAD, END_MAGIC, HEADER_LEN, INDEX_ENTRY, TRAILER_LEN};
use crate::io::leafstream::{read_leaves, Reader};
use crate::linear::{Leaf, LinearOctree, MAX_DEPTH};
use crate::Voxel;
/// The parsed frame of a version-2 file: its space, chunks, sections and counts,
/// checked against each other (but not the chunks' contents: see [`chunk_leaves`]).
#[derive(Debug, Clone)]
pub(crate) struct Layout {
    pub(crate) depth: u8,
    pub(crate) origin: Voxel,
    pub(crate) chunks: Vec<ChunkInfo>,
    pub(crate) leaf_count: u64,
    pub(crate) sections: (usize, usize),
    /// The colour index, when the file has one.
    pub(crate) colour_index: Option<crate::io::colour_index::ColourIndex>,
    /// Whether the colour regions' bytes were under the checksum checked at open
    /// (false when [`parse_layout_with`] skipped them: see
    /// [`crate::io::colour_index::verify_crcs`]).
    pub(crate) colours_checked: bool,
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    let mut a = [0u8; 8];
    a.copy_from_slice(&b[at..at + 8]);
    u64::from_le_bytes(a)
}

/// Parses and checks the header, trailer and index of version-2 bytes.
pub(crate) fn parse_layout(bytes: &[u8]) -> Result<Layout, String> {
    parse_layout_with(bytes, &|_, _| {}, false)
}

/// Bytes checksummed between two calls of a reader's `done`.
pub(crate) const RELEASE_STRETCH: usize = 8 << 20;

/// Hashes `bytes[start..stop]` into `crc` a stretch of [`RELEASE_STRETCH`] bytes
/// at a time, calling `done(start, end)` after each so that a mapped reader can
/// let the stretch go.
pub(crate) fn crc_released(
    crc: &mut crc32fast::Hasher,
    bytes: &[u8],
    start: usize,
    stop: usize,
    done: &dyn Fn(usize, usize),
) {
    let mut at = start;
    while at < stop {
        let end = (at + RELEASE_STRETCH).min(stop);
        crc.update(&bytes[at..end]);
        done(at, end);
        at = end;
    }
}

/// An error when the `stored` checksum (`what`) differs from the `actual` one.
pub(crate) fn check_crc(what: &str, stored: u32, actual: u32) -> Result<(), String> {
    if stored == actual {
        return Ok(());
    }
    Err(format!(
        "{what} mismatch (stored {stored:08x}, computed {actual:08x}): the file is truncated or corrupted"
    ))
}

/// As [`parse_layout`], calling `done(start, end)` after each stretch of the
/// checksummed sections, and of the chunks whose heads are checked, is read, so
/// that a mapped reader can let it go. With `lazy_colours`, a file whose only
/// layer is colours and which has a colour index has its index read and checked
/// ([`Layout::colour_index`]) and its colour regions' bytes are not read: the
/// checksum takes their CRCs from the index (each block is checked when it is
/// decoded, see [`crate::io::colour_index::decode_block`]).
pub(crate) fn parse_layout_with(
    bytes: &[u8],
    done: &dyn Fn(usize, usize),
    lazy_colours: bool,
) -> Result<Layout, String> {
    let len = bytes.len();
    if len < HEADER_LEN + TRAILER_LEN {
        return Err(format!(
            "truncated: {len} bytes, a version-2 file needs at least {}",
            HEADER_LEN + TRAILER_LEN
        ));
    }
    if bytes[len - 8..] != END_MAGIC {
        return Err("truncated: the file does not end with its index trailer".into());
    }
    let t = len - TRAILER_LEN;
    let (sections_offset, index_offset, chunk_count, leaf_count) = (
        u64_at(bytes, t),
        u64_at(bytes, t + 8),
        u64_at(bytes, t + 16),
        u64_at(bytes, t + 24),
    );
    let stored = u32::from_le_bytes([bytes[t + 36], bytes[t + 37], bytes[t + 38], bytes[t + 39]]);
    let index_len = chunk_count
        .checked_mul(INDEX_ENTRY as u64)
        .ok_or_else(|| format!("chunk count {chunk_count} is impossible"))?;
    if index_offset.checked_add(index_len) != Some(t as u64) {
        return Err(format!(
            "index at byte {index_offset} with {chunk_count} chunks does not end at the trailer (byte {t})"
        ));
    }
    if sections_offset < HEADER_LEN as u64
        || sections_offset
            .checked_add(2)
            .is_none_or(|e| e > index_offset)
    {
        return Err(format!(
            "sections offset {sections_offset} lies outside the file's body"
        ));
    }
    let (sections_offset, index_offset) = (sections_offset as usize, index_offset as usize);
    // The colour index is read whenever it is flagged (its regions let a streamed
    // reader find the colour regions without scanning them). Its errors are
    // reported after the checksum's, which name damage first.
    let flags = u16::from_le_bytes([bytes[sections_offset], bytes[sections_offset + 1]]);
    let (colour_index, index_error) = if flags & crate::io::colour_index::FLAG_COLOUR_INDEX != 0 {
        match crate::io::colour_index::parse(
            bytes,
            (sections_offset, index_offset),
            bytes[12].min(MAX_DEPTH),
        ) {
            Ok(ix) => (ix, None),
            Err(e) => (None, Some(e)),
        }
    } else {
        (None, None)
    };
    let skips = match &colour_index {
        Some(ix)
            if lazy_colours
                && flags
                    & !(crate::io::sections::FLAG_FRAME
                        | crate::io::sections::FLAG_COLOR_LAYER
                        | crate::io::colour_index::FLAG_COLOUR_INDEX)
                    == 0 =>
        {
            crate::io::colour_index::skips(ix)
        }
        _ => Vec::new(),
    };
    let mut crc = crc32fast::Hasher::new();
    crc.update(&bytes[..HEADER_LEN]);
    let mut at = sections_offset;
    let mut skip = skips.iter().peekable();
    while at < len - 12 {
        if let Some(&&(s, e, c)) = skip.peek() {
            if s == at {
                crc.combine(&crc32fast::Hasher::new_with_initial_len(c, (e - s) as u64));
                at = e;
                skip.next();
                continue;
            }
        }
        let stop = skip.peek().map_or(len - 12, |s| s.0);
        crc_released(&mut crc, bytes, at, stop, done);
        at = stop;
    }
    check_crc("index checksum", stored, crc.finalize())?;
    if bytes[10..12] != [0, 0] || bytes[13..16] != [0, 0, 0] || bytes[t + 32..t + 36] != [0; 4] {
        return Err("reserved bytes are not zero".into());
    }
    let depth = bytes[12];
    if depth > MAX_DEPTH {
        return Err(format!("depth {depth} exceeds the maximum {MAX_DEPTH}"));
    }
    if let Some(e) = index_error {
        return Err(e);
    }
    let origin = [
        u64_at(bytes, 16) as i64,
        u64_at(bytes, 24) as i64,
        u64_at(bytes, 32) as i64,
    ];
    LinearOctree::empty(depth, origin).map_err(|e| e.to_string())?;
    let space_end = 1u64 << (3 * u32::from(depth));
    let mut chunks = Vec::with_capacity(chunk_count as usize);
    let mut expected = HEADER_LEN;
    let mut total = 0u64;
    let mut prev_hi = 0u64;
    // Each chunk's head is read to check it against the index: a page fault per
    // chunk, which maps the pages around it too (fault-around). Let them go as the
    // heads are read, or a big file's opening maps a window per chunk (64 KiB
    // each: 0.9 GB for a depth-15 scene's 14 k chunks).
    let mut released = 0usize;
    for i in 0..chunk_count as usize {
        if expected - released >= RELEASE_STRETCH {
            done(released, expected);
            released = expected;
        }
        let e = index_offset + i * INDEX_ENTRY;
        let info = ChunkInfo {
            offset: u64_at(bytes, e),
            lo: u64_at(bytes, e + 8),
            hi: u64_at(bytes, e + 16),
            count: u64_at(bytes, e + 24),
        };
        if info.offset != expected as u64 || expected + CHUNK_HEAD > sections_offset {
            return Err(format!(
                "chunk {i}: offset {} where byte {expected} was expected",
                info.offset
            ));
        }
        let head = [0, 8, 16, 24].map(|k| u64_at(bytes, expected + k));
        if head[..3] != [info.lo, info.hi, info.count] {
            return Err(format!("chunk {i}: its header disagrees with the index"));
        }
        let end = usize::try_from(head[3])
            .ok()
            .and_then(|p| (expected + CHUNK_HEAD).checked_add(p))
            .and_then(|p| p.checked_add(4))
            .filter(|&p| p <= sections_offset)
            .ok_or_else(|| format!("chunk {i}: payload length {} runs past the leaves", head[3]))?;
        if info.count == 0 || info.count > head[3] || info.lo >= info.hi || info.hi > space_end {
            return Err(format!(
                "chunk {i}: range [{}, {}) or count {} is impossible",
                info.lo, info.hi, info.count
            ));
        }
        if i > 0 && info.lo < prev_hi {
            return Err(format!(
                "chunk {i}: overlaps or precedes the chunk before it"
            ));
        }
        prev_hi = info.hi;
        total = total
            .checked_add(info.count)
            .ok_or_else(|| format!("chunk {i}: counts overflow"))?;
        chunks.push(info);
        expected = end;
    }
    done(released, expected);
    if expected != sections_offset {
        return Err(format!(
            "{} byte(s) between the last chunk and the sections",
            sections_offset - expected
        ));
    }
    if total != leaf_count {
        return Err(format!(
            "leaf count {leaf_count} disagrees with the chunks' {total}"
        ));
    }
    Ok(Layout {
        depth,
        origin,
        chunks,
        leaf_count,
        sections: (sections_offset, index_offset),
        colours_checked: skips.is_empty(),
        colour_index,
    })
}

/// Decodes chunk `i` of a parsed layout, checking its CRC and every leaf.
pub(crate) fn chunk_leaves(bytes: &[u8], layout: &Layout, i: usize) -> Result<Vec<Leaf>, String> {
    let info = layout.chunks[i];
    let start = info.offset as usize;
    let plen = u64_at(bytes, start + 24) as usize;
    let end = start + CHUNK_HEAD + plen;
    let stored = u32::from_le_bytes([bytes[end], bytes[end + 1], bytes[end + 2], bytes[end + 3]]);
    let actual = crc32fast::hash(&bytes[start..end]);
    if stored != actual {
        return Err(format!(
            "chunk {i}: checksum mismatch (stored {stored:08x}, computed {actual:08x})"
        ));
    }
    let mut r = Reader {
        bytes: &bytes[..end],
        pos: start + CHUNK_HEAD,
    };
    let leaves = read_leaves(&mut r, info.count, layout.depth, &format!("chunk {i} leaf"))?;
    if r.pos != end {
        return Err(format!(
            "chunk {i}: {} byte(s) after its leaves",
            end - r.pos
        ));
    }
    let (first, last) = (leaves[0], leaves[leaves.len() - 1]);
    if first.code() != info.lo || last.end() != info.hi {
        return Err(format!("chunk {i}: its leaves do not span its range"));
    }
    Ok(leaves)
}
