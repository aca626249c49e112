//! A `.tess` file opened for streaming: memory-mapped, its index read, its chunks
//! decoded one at a time on demand, so a reader holds one chunk, not the tree.

use std::path::{Path, PathBuf};

use super::chunked::{chunk_leaves, ChunkInfo, Layout, DEFAULT_CHUNK_LEAVES};
use super::sections::Extras;
use super::FormatError;
use crate::linear::{Leaf, LinearOctree};
use crate::model::{Frame, Model};
use crate::Voxel;

/// Leaves of a file read one at a time, each checked.
pub type LeafIter<'a> = Box<dyn Iterator<Item = Result<Leaf, FormatError>> + 'a>;

pub(super) enum Body {
    /// Version 2: the bytes and their parsed layout.
    Chunked(Bytes, Layout),
    /// Version 1 (one payload): decoded whole, shown as chunks of the decoded leaves.
    Decoded(LinearOctree),
    /// Version 1 opened by [`TessFile::open_streaming`]: the bytes and an index of
    /// the payload in stretches, decoded one at a time.
    Payload(Bytes, super::tess_v1::V1Index),
}

pub(super) enum Bytes {
    Map(memmap2::Mmap),
    Owned(Vec<u8>),
}

impl std::ops::Deref for Bytes {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        match self {
            Bytes::Map(m) => m,
            Bytes::Owned(v) => v,
        }
    }
}

/// A `.tess` file opened for streaming. Version-2 files are memory-mapped and only
/// their header, sections and index are read at [`TessFile::open`]; each chunk is
/// checked (CRC, leaves) when it is read. Version-1 files are decoded whole and
/// served as chunks of [`DEFAULT_CHUNK_LEAVES`] leaves.
///
/// ```
/// use tesseral::io::{write_model, Model, TessFile};
/// use tesseral::linear::LinearOctree;
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("a.tess");
/// let tree = LinearOctree::from_voxels(4, [0, 0, 0], [[1, 2, 3], [9, 9, 9]]).unwrap();
/// write_model(&path, &Model::new(tree.clone())).unwrap();
/// let f = TessFile::open(&path).unwrap();
/// assert_eq!(f.leaf_count(), 2);
/// let leaves: Vec<_> = f.leaves().collect::<Result<_, _>>().unwrap();
/// assert_eq!(leaves, tree.leaves());
/// ```
pub struct TessFile {
    pub(super) path: PathBuf,
    pub(super) body: Body,
    /// Version 1: everything; version 2: the frame only (the layers are decoded
    /// when the model is read, see [`TessFile::to_model`]).
    pub(super) extras: Extras,
    /// Version 2: whether sections past the frame (colours, free space, log-odds)
    /// are present.
    layers: bool,
    /// Whether the colour regions' CRCs were checked (see
    /// [`TessFile::open_lazy_colours`]).
    pub(super) colours_checked: std::sync::OnceLock<Result<(), String>>,
}

impl TessFile {
    /// Opens `path`, reading its header, sections and index.
    ///
    /// # Errors
    /// [`FormatError`] naming the file and the field at fault.
    pub fn open(path: &Path) -> Result<Self, FormatError> {
        let file = std::fs::File::open(path).map_err(|e| FormatError::io(e).with_path(path))?;
        // SAFETY: as in `native::read`: the map is read-only and every access is
        // bounds-checked against its length, so a concurrent rewrite gives a checksum
        // error or SIGBUS, never undefined reads; our writers replace files by rename.
        let bytes = match unsafe { memmap2::Mmap::map(&file) } {
            Ok(m) => Bytes::Map(m),
            Err(_) => Bytes::Owned(super::read_limited(path, super::MAX_FILE_BYTES)?),
        };
        Self::from_body(bytes, path)
    }

    /// As [`TessFile::open`], but a version-1 file is not decoded whole: its
    /// checksum is computed over the mapped bytes, its payload (sorted leaves) is
    /// indexed in one pass in stretches of [`DEFAULT_CHUNK_LEAVES`] leaves that
    /// play the part of chunks, and its colour layer is read as streams
    /// ([`TessFile::colour_streams`]). The file then streams as a version-2 file
    /// does ([`TessFile::is_streamed`]), holding a few bytes per stretch.
    ///
    /// # Errors
    /// As [`TessFile::open`].
    pub fn open_streaming(path: &Path) -> Result<Self, FormatError> {
        let file = std::fs::File::open(path).map_err(|e| FormatError::io(e).with_path(path))?;
        // SAFETY: as in `open`.
        let bytes = match unsafe { memmap2::Mmap::map(&file) } {
            Ok(m) => Bytes::Map(m),
            Err(_) => Bytes::Owned(super::read_limited(path, super::MAX_FILE_BYTES)?),
        };
        Self::from_body_streaming(bytes, path)
    }

    /// As [`TessFile::open_streaming`], for bytes held in memory; `path` names
    /// them in errors.
    ///
    /// # Errors
    /// As [`TessFile::open`].
    pub fn from_bytes_streaming(bytes: Vec<u8>, path: &Path) -> Result<Self, FormatError> {
        Self::from_body_streaming(Bytes::Owned(bytes), path)
    }

    fn from_body_streaming(bytes: Bytes, path: &Path) -> Result<Self, FormatError> {
        let is_v1 = bytes.len() >= 10
            && bytes[..8] == super::native::MAGIC
            && u16::from_le_bytes([bytes[8], bytes[9]]) == super::native::VERSION_1;
        if !is_v1 {
            return Self::from_body(bytes, path);
        }
        let (index, frame) = super::tess_v1::index_v1(&bytes, &|a, b| release_map(&bytes, a, b))
            .map_err(|m| FormatError::corrupt(m).with_path(path))?;
        let layers = index.flags & !super::sections::FLAG_FRAME != 0;
        Ok(Self {
            path: path.to_owned(),
            body: Body::Payload(bytes, index),
            extras: Extras {
                frame,
                ..Extras::default()
            },
            layers,
            colours_checked: std::sync::OnceLock::new(),
        })
    }

    /// Opens `.tess` bytes held in memory; `path` names them in errors.
    ///
    /// # Errors
    /// As [`TessFile::open`].
    pub fn from_bytes(bytes: Vec<u8>, path: &Path) -> Result<Self, FormatError> {
        Self::from_body(Bytes::Owned(bytes), path)
    }

    fn from_body(bytes: Bytes, path: &Path) -> Result<Self, FormatError> {
        Self::from_body_with(bytes, path, false)
    }

    /// As [`TessFile::open`], but a version-2 file whose only layer is colours and
    /// which has a colour index (every file this version writes with colours) is
    /// opened without reading its colour section: its checksum takes the colour
    /// regions' CRCs from the index, and each block of colours is checked when it
    /// is read ([`TessFile::indexed_colour_blocks`]). Reading the regions as streams
    /// ([`TessFile::colour_streams`]) checks their CRCs first, in one pass.
    /// Other files open as with [`TessFile::open`].
    ///
    /// # Errors
    /// As [`TessFile::open`].
    pub fn open_lazy_colours(path: &Path) -> Result<Self, FormatError> {
        let file = std::fs::File::open(path).map_err(|e| FormatError::io(e).with_path(path))?;
        // SAFETY: as in `open`.
        let bytes = match unsafe { memmap2::Mmap::map(&file) } {
            Ok(m) => Bytes::Map(m),
            Err(_) => Bytes::Owned(super::read_limited(path, super::MAX_FILE_BYTES)?),
        };
        Self::from_body_with(bytes, path, true)
    }

    /// As [`TessFile::open_lazy_colours`], for bytes held in memory.
    ///
    /// # Errors
    /// As [`TessFile::open`].
    pub fn from_bytes_lazy_colours(bytes: Vec<u8>, path: &Path) -> Result<Self, FormatError> {
        Self::from_body_with(Bytes::Owned(bytes), path, true)
    }

    fn from_body_with(bytes: Bytes, path: &Path, lazy: bool) -> Result<Self, FormatError> {
        let err = |e: FormatError| e.with_path(path);
        if bytes.len() < 10 || bytes[..8] != super::native::MAGIC {
            return Err(err(super::native::not_a_model(&bytes)));
        }
        let version = u16::from_le_bytes([bytes[8], bytes[9]]);
        if version != super::native::VERSION {
            let model = super::native::decode(&bytes).map_err(err)?;
            let (extras, tree) = Extras::split(model);
            let layers =
                extras.colors.is_some() || extras.free.is_some() || extras.log_odds.is_some();
            return Ok(Self {
                path: path.to_owned(),
                body: Body::Decoded(tree),
                extras,
                layers,
                colours_checked: std::sync::OnceLock::new(),
            });
        }
        // The checksum reads the sections (the colours: about half a big file):
        // let their mapped pages go as it goes, so opening keeps memory flat.
        let layout =
            super::chunked::parse_layout_with(&bytes, &|a, b| release_map(&bytes, a, b), lazy)
                .map_err(|m| err(FormatError::corrupt(m)))?;
        let space =
            LinearOctree::empty(layout.depth, layout.origin).map_err(FormatError::octree)?;
        // The sections are under the index's checksum, checked above; the layers
        // are decoded only when the model is read, so streaming a file's leaves
        // never holds its colours.
        let (flags, frame) = super::native::decode_frame(&bytes, &layout, &space)
            .map_err(|m| err(FormatError::corrupt(m)))?;
        let checked = layout.colours_checked;
        Ok(Self {
            path: path.to_owned(),
            body: Body::Chunked(bytes, layout),
            extras: Extras {
                frame,
                ..Extras::default()
            },
            layers: flags & !super::sections::FLAG_FRAME != 0,
            colours_checked: if checked {
                Ok(()).into()
            } else {
                std::sync::OnceLock::new()
            },
        })
    }

    /// Whether the file is read chunk by chunk: version 2, or version 1 opened
    /// by [`TessFile::open_streaming`].
    #[must_use]
    pub fn is_streamed(&self) -> bool {
        matches!(self.body, Body::Chunked(..) | Body::Payload(..))
    }

    /// The depth of the space.
    #[must_use]
    pub fn depth(&self) -> u8 {
        match &self.body {
            Body::Chunked(_, l) => l.depth,
            Body::Payload(_, x) => x.depth,
            Body::Decoded(t) => t.depth(),
        }
    }

    /// The lowest voxel of the space.
    #[must_use]
    pub fn origin(&self) -> Voxel {
        match &self.body {
            Body::Chunked(_, l) => l.origin,
            Body::Payload(_, x) => x.origin,
            Body::Decoded(t) => t.origin(),
        }
    }

    /// The frame (voxel size and placement).
    #[must_use]
    pub fn frame(&self) -> Frame {
        self.extras.frame
    }

    /// Whether the file carries colours, free space or log-odds.
    #[must_use]
    pub fn has_layers(&self) -> bool {
        self.layers
    }

    /// The number of black leaves.
    #[must_use]
    pub fn leaf_count(&self) -> u64 {
        match &self.body {
            Body::Chunked(_, l) => l.leaf_count,
            Body::Payload(_, x) => x.leaf_count,
            Body::Decoded(t) => t.leaf_count() as u64,
        }
    }

    /// The chunks, in tesseral order.
    #[must_use]
    pub fn chunks(&self) -> Vec<ChunkInfo> {
        match &self.body {
            Body::Chunked(_, l) => l.chunks.clone(),
            Body::Payload(_, x) => x.chunks.clone(),
            Body::Decoded(t) => t
                .leaves()
                .chunks(DEFAULT_CHUNK_LEAVES)
                .map(|c| ChunkInfo {
                    offset: 0,
                    lo: c[0].code(),
                    hi: c[c.len() - 1].end(),
                    count: c.len() as u64,
                })
                .collect(),
        }
    }

    /// The mapped bytes of a version-2 file (for resuming colour regions).
    pub(crate) fn mapped(&self) -> Option<&[u8]> {
        match &self.body {
            Body::Chunked(b, _) | Body::Payload(b, _) => Some(b),
            Body::Decoded(_) => None,
        }
    }

    /// The file's path.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The leaves of chunk `i` (of [`TessFile::chunks`]), checked.
    ///
    /// They are the file's leaves as stored. A file from another writer may hold
    /// eight siblings that were never merged into their parent; they come out as
    /// eight leaves here (and from [`leaves`](Self::leaves)), while
    /// [`to_model`](Self::to_model) merges them.
    ///
    /// # Errors
    /// [`FormatError::Corrupt`] for a bad chunk.
    ///
    /// # Panics
    /// When `i` is not a chunk's index.
    pub fn chunk(&self, i: usize) -> Result<Vec<Leaf>, FormatError> {
        match &self.body {
            Body::Chunked(b, l) => {
                chunk_leaves(b, l, i).map_err(|m| FormatError::corrupt(m).with_path(&self.path))
            }
            Body::Payload(b, x) => {
                super::tess_v1::v1_chunk(b, x, i).map_err(|e| e.with_path(&self.path))
            }
            Body::Decoded(t) => Ok(t
                .leaves()
                .chunks(DEFAULT_CHUNK_LEAVES)
                .nth(i)
                .expect("chunk index")
                .to_vec()),
        }
    }

    /// Every leaf in tesseral order, one chunk decoded at a time.
    pub fn leaves(&self) -> impl Iterator<Item = Result<Leaf, FormatError>> + '_ {
        self.leaves_in(0, u64::MAX)
    }

    /// The leaves that meet the code range `[lo, hi)` (whole, not clipped), reading
    /// only the chunks whose ranges meet it (found by binary search of the index).
    pub fn leaves_in(
        &self,
        lo: u64,
        hi: u64,
    ) -> impl Iterator<Item = Result<Leaf, FormatError>> + '_ {
        let chunks = self.chunks();
        let first = chunks.partition_point(|c| c.hi <= lo);
        let last = chunks.partition_point(|c| c.lo < hi);
        (first..last.max(first)).flat_map(move |i| {
            let (ok, err) = match self.chunk(i) {
                Ok(v) => (v, None),
                Err(e) => (Vec::new(), Some(Err(e))),
            };
            err.into_iter().chain(
                ok.into_iter()
                    .filter(move |l| l.end() > lo && l.code() < hi)
                    .map(Ok),
            )
        })
    }

    /// Tells the system that the file's bytes in `bytes` (offsets, as
    /// [`ChunkInfo::offset`] gives them) will not be read again soon: a mapped
    /// file's pages there leave the process's resident memory. They stay in the
    /// system's page cache, so reading them again costs a page fault, not a disk
    /// read. A reader that walks a big file this way keeps its resident memory
    /// flat; nothing changes for files held in memory. The release reaches up to
    /// 2 MiB before `bytes.start` too, over pages that a fault at the start of
    /// `bytes` mapped around it (so a reader releasing stretch after stretch keeps
    /// none behind it). Advice only: errors are ignored.
    pub fn release(&self, bytes: std::ops::Range<u64>) {
        if let Body::Chunked(b, _) | Body::Payload(b, _) = &self.body {
            let len = b.len() as u64;
            release_map(
                b,
                bytes.start.min(len) as usize,
                bytes.end.min(len) as usize,
            );
        }
    }

    /// The whole model, read chunk by chunk (as [`super::native::read`]).
    ///
    /// # Errors
    /// As [`TessFile::chunk`].
    pub fn to_model(&self) -> Result<Model, FormatError> {
        if let Body::Payload(bytes, _) = &self.body {
            return super::native::decode(bytes).map_err(|e| e.with_path(&self.path));
        }
        let mut leaves = Vec::with_capacity(self.leaf_count() as usize);
        for l in self.leaves() {
            leaves.push(l?);
        }
        let tree = LinearOctree::from_sorted_leaves(self.depth(), self.origin(), leaves)
            .map_err(FormatError::octree)?;
        let extras = match &self.body {
            Body::Chunked(bytes, layout) => {
                let space = LinearOctree::empty(layout.depth, layout.origin)
                    .map_err(FormatError::octree)?;
                super::native::decode_sections(bytes, layout, &space)
                    .map_err(|m| FormatError::corrupt(m).with_path(&self.path))?
            }
            Body::Decoded(_) | Body::Payload(..) => self.extras.clone(),
        };
        let model = extras.into_model(tree);
        super::sections::check_parts(&model)
            .map_err(|m| FormatError::corrupt(m).with_path(&self.path))?;
        Ok(model)
    }
}

/// How far before a released range [`release_map`] reaches: a page fault maps the
/// pages around the faulting one that are in the page cache (Linux's fault-around
/// window, 64 KiB by default, or a whole large folio of the page cache, up to
/// 2 MiB). So reading the start of one stretch after releasing the stretch before
/// it maps that stretch's tail again; a sequential reader releasing stretch after
/// stretch would keep a window per stretch (measured: 64 KiB a chunk, 0.9 GB over a
/// depth-15 file's chunks) unless each release reaches back over it.
const FAULT_AROUND: usize = 2 << 20;

/// Lets the mapped pages of `bytes[start..end]`, and of the [`FAULT_AROUND`] bytes
/// before it, leave resident memory (see [`TessFile::release`]); nothing for bytes
/// held in memory.
pub(super) fn release_map(bytes: &Bytes, start: usize, end: usize) {
    if let Bytes::Map(m) = bytes {
        let start = start.saturating_sub(FAULT_AROUND);
        if start < end && end <= m.len() {
            // SAFETY: the map is read-only and nothing writes through it, so
            // MADV_DONTNEED only drops this process's page-table entries: the next
            // access reads the same bytes from the page cache (or the file, with
            // the caveat of `open` about a file rewritten under us). No slice of the
            // map is invalidated.
            let _ = unsafe {
                m.unchecked_advise_range(memmap2::UncheckedAdvice::DontNeed, start, end - start)
            };
        }
    }
}
