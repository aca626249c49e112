//! Version 2 of `.tess`: the leaves in chunks, each with its code range, count and
//! CRC-32, then the sections, then an index of the chunks, so that a writer never
//! holds the whole tree ([`TessWriter`]) and a reader can seek to a code range
//! ([`super::TessFile`]). The layout is in [`super::native`].

use std::io::{self, Write};

use super::leafstream::put_leaves;
use super::sections::{put_sections, Sections};
use crate::linear::{push_merging, Leaf, LinearOctree, MAX_DEPTH};
use crate::model::Frame;
use crate::Voxel;

mod layout;
pub(crate) use layout::{
    check_crc, chunk_leaves, crc_released, parse_layout, parse_layout_with, Layout, RELEASE_STRETCH,
};

/// The version [`TessWriter`] writes.
pub const VERSION_CHUNKED: u16 = 2;
/// The eight bytes every version-2 file ends with.
pub const END_MAGIC: [u8; 8] = *b"TESSIDX\n";
/// Leaves per chunk unless [`TessWriter::with_chunk_leaves`] says otherwise.
pub const DEFAULT_CHUNK_LEAVES: usize = 1 << 16;
pub(crate) const HEADER_LEN: usize = 40;
pub(super) const CHUNK_HEAD: usize = 32;
pub(super) const INDEX_ENTRY: usize = 32;
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
        self.finish_sections(&Sections::frame(frame))
    }

    /// [`finish`](Self::finish) with the sections given (a model's layers).
    pub(crate) fn finish_sections(self, sections: &Sections<'_>) -> io::Result<W> {
        let block = self.colour_block;
        self.finish_with(|emit| {
            let mut meta = vec![0, 0];
            let mut flags = put_sections(&mut meta, sections);
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
