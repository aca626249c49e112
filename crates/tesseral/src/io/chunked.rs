//! Version 2 of `.tess`: the leaves in chunks, each with its code range, count and
//! CRC-32, then the sections, then an index of the chunks, so that a writer never
//! holds the whole tree ([`TessWriter`]) and a reader can seek to a code range
//! ([`super::TessFile`]). The layout is in [`super::native`].

use std::io::{self, Write};

use super::leafstream::{put_leaves, read_leaves, Reader};
use super::sections::{put_sections, Extras};
use crate::linear::{push_merging, Leaf, LinearOctree, MAX_DEPTH};
use crate::model::Frame;
use crate::Voxel;

/// The version [`TessWriter`] writes.
pub const VERSION_CHUNKED: u16 = 2;
/// The eight bytes every version-2 file ends with.
pub const END_MAGIC: [u8; 8] = *b"TESSIDX\n";
/// Leaves per chunk unless [`TessWriter::with_chunk_leaves`] says otherwise.
pub const DEFAULT_CHUNK_LEAVES: usize = 1 << 16;
pub(crate) const HEADER_LEN: usize = 40;
const CHUNK_HEAD: usize = 32;
const INDEX_ENTRY: usize = 32;
pub(crate) const TRAILER_LEN: usize = 48;
/// Leaves that may still merge into a bigger one: at most seven siblings per level.
pub(crate) const MERGE_TAIL: usize = 7 * (MAX_DEPTH as usize + 1);

/// Where one chunk lies and what it covers: its leaves cover codes in `[lo, hi)`,
/// `lo` the code of its first leaf and `hi` the end of its last.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ChunkInfo {
    /// Byte offset of the chunk in the file.
    pub offset: u64,
    /// The code of the first leaf.
    pub lo: u64,
    /// One past the last voxel code of the last leaf.
    pub hi: u64,
    /// The number of leaves.
    pub count: u64,
}

/// Writes a `.tess` file (version 2) from leaves given in tesseral order, holding
/// at most one chunk of them: leaves are merged into bigger blocks as they come
/// (eight full siblings make their parent), so the file is canonical.
///
/// ```
/// use tesseral::io::{native, TessWriter};
/// use tesseral::linear::{Leaf, LinearOctree};
/// let mut w = TessWriter::new(Vec::new(), 3, [0, 0, 0]).unwrap();
/// for code in 0..8 {
///     w.push(Leaf::new(code, 0)).unwrap(); // eight voxels: one 2x2x2 leaf
/// }
/// let bytes = w.finish(Default::default()).unwrap();
/// let model = native::decode(&bytes).unwrap();
/// assert_eq!(model.tree.leaf_count(), 1);
/// assert_eq!(model.tree.voxel_count(), 8);
/// ```
pub struct TessWriter<W: Write> {
    w: W,
    written: u64,
    depth: u8,
    chunk_leaves: usize,
    pending: Vec<Leaf>,
    last_end: Option<u64>,
    index: Vec<ChunkInfo>,
    header: Vec<u8>,
    leaf_count: u64,
    payload: Vec<u8>,
    /// Leaves per block of the colour index; `None`: no index (as older writers).
    pub(crate) colour_block: Option<u64>,
}

impl<W: Write> TessWriter<W> {
    /// Starts a file for the space of `2^depth` voxels per axis from `origin`.
    ///
    /// # Errors
    /// [`io::ErrorKind::InvalidInput`] for a bad space; any error of `w`.
    pub fn new(mut w: W, depth: u8, origin: Voxel) -> io::Result<Self> {
        LinearOctree::empty(depth, origin)
            .map_err(|e| io::Error::new(io::ErrorKind::InvalidInput, e.to_string()))?;
        let mut header = Vec::with_capacity(HEADER_LEN);
        header.extend_from_slice(&super::native::MAGIC);
        header.extend_from_slice(&VERSION_CHUNKED.to_le_bytes());
        header.extend_from_slice(&[0, 0]);
        header.push(depth);
        header.extend_from_slice(&[0, 0, 0]);
        for o in origin {
            header.extend_from_slice(&o.to_le_bytes());
        }
        w.write_all(&header)?;
        Ok(Self {
            w,
            written: HEADER_LEN as u64,
            depth,
            chunk_leaves: DEFAULT_CHUNK_LEAVES,
            pending: Vec::new(),
            last_end: None,
            index: Vec::new(),
            header,
            leaf_count: 0,
            payload: Vec::new(),
            colour_block: Some(super::colour_index::INDEX_BLOCK),
        })
    }

    /// Sets the number of leaves per chunk (at least one).
    #[must_use]
    pub fn with_chunk_leaves(mut self, n: usize) -> Self {
        self.chunk_leaves = n.max(1);
        self
    }

    /// Sets the leaves per block of the colour index (`None`: no index, a file as
    /// older versions wrote it, which builds before the index read).
    #[must_use]
    pub fn with_colour_index(mut self, block: Option<u64>) -> Self {
        self.colour_block = block;
        self
    }

    /// Adds the next leaf: it must lie in the space and start at or after the end of
    /// the leaf before it.
    ///
    /// # Errors
    /// [`io::ErrorKind::InvalidInput`] for a leaf out of order or outside the space;
    /// any error of the underlying writer.
    pub fn push(&mut self, leaf: Leaf) -> io::Result<()> {
        let bad = |m: String| io::Error::new(io::ErrorKind::InvalidInput, m);
        if leaf.size_log2() > self.depth || leaf.end() > 1u64 << (3 * u32::from(self.depth)) {
            return Err(bad(format!(
                "leaf {:#o} (size 2^{}) lies outside the depth-{} space",
                leaf.code(),
                leaf.size_log2(),
                self.depth
            )));
        }
        if let Some(end) = self.last_end {
            if leaf.code() < end {
                return Err(bad(format!(
                    "leaf {:#o} comes before the end of the leaf before it ({end:#o}): leaves must be in tesseral order",
                    leaf.code()
                )));
            }
        }
        self.last_end = Some(leaf.end());
        push_merging(&mut self.pending, leaf);
        if self.pending.len() >= self.chunk_leaves + MERGE_TAIL {
            let chunk: Vec<Leaf> = self.pending.drain(..self.chunk_leaves).collect();
            self.write_chunk(&chunk)?;
        }
        Ok(())
    }

    /// The leaves pushed so far, after merging (those still held included).
    #[must_use]
    pub fn leaf_count(&self) -> u64 {
        self.leaf_count + self.pending.len() as u64
    }

    fn write_chunk(&mut self, leaves: &[Leaf]) -> io::Result<()> {
        let (Some(first), Some(last)) = (leaves.first(), leaves.last()) else {
            return Ok(());
        };
        self.payload.clear();
        put_leaves(&mut self.payload, leaves);
        let info = ChunkInfo {
            offset: self.written,
            lo: first.code(),
            hi: last.end(),
            count: leaves.len() as u64,
        };
        let mut head = [0u8; CHUNK_HEAD];
        for (i, v) in [info.lo, info.hi, info.count, self.payload.len() as u64]
            .into_iter()
            .enumerate()
        {
            head[8 * i..8 * i + 8].copy_from_slice(&v.to_le_bytes());
        }
        let mut crc = crc32fast::Hasher::new();
        crc.update(&head);
        crc.update(&self.payload);
        self.w.write_all(&head)?;
        self.w.write_all(&self.payload)?;
        self.w.write_all(&crc.finalize().to_le_bytes())?;
        self.written += (CHUNK_HEAD + self.payload.len() + 4) as u64;
        self.leaf_count += info.count;
        self.index.push(info);
        Ok(())
    }

    /// Writes the remaining leaves, the frame, the index and the trailer, and gives
    /// the writer back.
    ///
    /// # Errors
    /// Any error of the underlying writer.
    pub fn finish(self, frame: Frame) -> io::Result<W> {
        self.finish_extras(&Extras {
            frame,
            ..Extras::default()
        })
    }

    pub(crate) fn finish_extras(self, extras: &Extras) -> io::Result<W> {
        let block = self.colour_block;
        self.finish_with(|emit| {
            let mut meta = vec![0, 0];
            let mut flags = put_sections(&mut meta, extras);
            let ix = block.and_then(|b| super::colour_index::index_of_sections(&meta, flags, b));
            if let Some(ix) = ix {
                meta.extend_from_slice(&ix);
                flags |= super::colour_index::FLAG_COLOUR_INDEX;
            }
            meta[..2].copy_from_slice(&flags.to_le_bytes());
            emit(&meta)
        })
    }

    /// Writes the remaining leaves, then the sections that `sections` emits (their
    /// flags first), then the index and the trailer, the checksum taken as the bytes
    /// go: the sections need not be held in memory.
    pub(crate) fn finish_with(
        mut self,
        sections: impl FnOnce(&mut dyn FnMut(&[u8]) -> io::Result<()>) -> io::Result<()>,
    ) -> io::Result<W> {
        let pending = std::mem::take(&mut self.pending);
        for chunk in pending.chunks(self.chunk_leaves) {
            self.write_chunk(chunk)?;
        }
        let mut crc = crc32fast::Hasher::new();
        crc.update(&self.header);
        let sections_offset = self.written;
        let mut len = 0u64;
        {
            let w = &mut self.w;
            let crc = &mut crc;
            let len = &mut len;
            sections(&mut |b: &[u8]| {
                crc.update(b);
                *len += b.len() as u64;
                w.write_all(b)
            })?;
        }
        let mut meta = Vec::new();
        let index_offset = sections_offset + len;
        for c in &self.index {
            for v in [c.offset, c.lo, c.hi, c.count] {
                meta.extend_from_slice(&v.to_le_bytes());
            }
        }
        for v in [
            sections_offset,
            index_offset,
            self.index.len() as u64,
            self.leaf_count,
        ] {
            meta.extend_from_slice(&v.to_le_bytes());
        }
        meta.extend_from_slice(&[0; 4]);
        crc.update(&meta);
        meta.extend_from_slice(&crc.finalize().to_le_bytes());
        meta.extend_from_slice(&END_MAGIC);
        self.w.write_all(&meta)?;
        self.w.flush()?;
        Ok(self.w)
    }
}

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
    pub(crate) colour_index: Option<super::colour_index::ColourIndex>,
    /// Whether the colour regions' bytes were under the checksum checked at open
    /// (false when [`parse_layout_with`] skipped them: see
    /// [`super::colour_index::verify_crcs`]).
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

/// As [`parse_layout`], calling `done(start, end)` after each stretch of the
/// checksummed sections, and of the chunks whose heads are checked, is read, so
/// that a mapped reader can let it go. With `lazy_colours`, a file whose only
/// layer is colours and which has a colour index has its index read and checked
/// ([`Layout::colour_index`]) and its colour regions' bytes are not read: the
/// checksum takes their CRCs from the index (each block is checked when it is
/// decoded, see [`super::colour_index::decode_block`]).
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
    let (colour_index, index_error) = if flags & super::colour_index::FLAG_COLOUR_INDEX != 0 {
        match super::colour_index::parse(
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
                    & !(super::sections::FLAG_FRAME
                        | super::sections::FLAG_COLOR_LAYER
                        | super::colour_index::FLAG_COLOUR_INDEX)
                    == 0 =>
        {
            super::colour_index::skips(ix)
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
        let end = (at + RELEASE_STRETCH).min(stop);
        crc.update(&bytes[at..end]);
        done(at, end);
        at = end;
    }
    let actual = crc.finalize();
    if stored != actual {
        return Err(format!(
            "index checksum mismatch (stored {stored:08x}, computed {actual:08x}): the file is truncated or corrupted"
        ));
    }
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
