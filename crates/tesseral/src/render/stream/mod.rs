//! Rendering a `.tess` file or a partitioned dataset without loading it: the rays
//! read only the chunks they reach.
//!
//! The top of the tree comes from the chunk index ([`top`]); a node that meets a
//! single chunk is answered by that chunk's own ray index ([`RayTree`] of its
//! leaves), built when a ray, a beam or a normal estimate first reaches into it and
//! kept in a [`Cache`] under a byte budget. Every traversal is the in-memory one
//! (written once over [`Nodes`]), so the image is the in-memory render's, byte for
//! byte. See `docs/render-stream.md`.

mod cache;
mod colours;
mod modes;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_modes;
mod top;

pub use modes::{contact_sheet_streamed, render_streamed, section_streamed};

use std::path::Path;
use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex, PoisonError};

use cache::{Cache, Cost};
use colours::Colours;
use top::{ChunkRef, Top, TopKid};

use super::index::{RayTree, Root};
use super::nodes::{bounding_box, Kid, NodeId, Nodes, Trace};
use super::trace::rank;
use crate::io::{FormatError, TessFile};
use crate::model::Rgba;
use crate::Voxel;

/// The threads (at most `pool`, at least one) whose decoded chunks, three a
/// thread, fit in two thirds of `chunk_bytes` when a chunk holds `largest` leaves.
fn threads_within(chunk_bytes: u64, largest: u64, pool: usize) -> usize {
    let peak = largest
        .saturating_mul(PEAK_BYTES_PER_LEAF)
        .saturating_add(256);
    let fit = chunk_bytes / 3 * 2 / peak.saturating_mul(3);
    usize::try_from(fit)
        .unwrap_or(usize::MAX)
        .clamp(1, pool.max(1))
}

/// The `src` of the top nodes in a [`NodeId`].
const TOP: u32 = u32::MAX;

/// What decoding a chunk holds at once, a leaf, as the threads' bound estimates it
/// from the largest chunk before any is decoded: the leaf (8 bytes) and the ray
/// index's nodes as a growing vector (8 bytes a node, counted twice), at one node
/// for two leaves. The cache then learns the true peaks as chunks are decoded.
const PEAK_BYTES_PER_LEAF: u64 = 16;

/// A tree read from version-2 `.tess` files (one file, or the parts of a dataset)
/// chunk by chunk as rays reach the chunks, with at most a budget of decoded chunks
/// and colour blocks kept.
///
/// ```
/// use tesseral::io::{write_model, Model};
/// use tesseral::linear::LinearOctree;
/// use tesseral::render::{render, render_streamed, RenderOptions, StreamedTree};
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("a.tess");
/// let tree = LinearOctree::from_voxels(4, [0, 0, 0], [[1, 2, 3], [9, 9, 9]]).unwrap();
/// write_model(&path, &Model::new(tree.clone())).unwrap();
/// let st = StreamedTree::open(&path, 1 << 20).unwrap();
/// let opts = RenderOptions { width: 64, height: 48, ..Default::default() };
/// let img = render_streamed(&st, Default::default(), &opts).unwrap();
/// assert_eq!(img, render(&tree, Default::default(), &opts));
/// ```
pub struct StreamedTree {
    files: Vec<TessFile>,
    /// Each part's code range `[lo, hi)`.
    ranges: Vec<(u64, u64)>,
    chunks: Vec<ChunkRef>,
    top: Top,
    depth: u8,
    origin: Voxel,
    bbox: Option<([i64; 3], [i64; 3])>,
    leaves: u64,
    cache: Cache<RayTree>,
    colours: Option<Colours>,
    /// The threads a drawing runs on (see [`StreamedTree::threads`]).
    threads: usize,
    /// The first error met while rendering (a damaged chunk or colour block).
    error: Mutex<Option<FormatError>>,
}

/// What a streamed render read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StreamStats {
    /// Chunks in the tree.
    pub chunks: u64,
    /// Chunks decoded (a chunk evicted and needed again counts again).
    pub chunks_decoded: u64,
    /// Colour blocks decoded.
    pub colour_blocks_decoded: u64,
    /// Bytes of the colour sections read: the whole section at open for a file
    /// without a colour index, then the bytes of each colour block decoded.
    pub colour_bytes_read: u64,
    /// Bytes of decoded chunks and colour blocks kept now.
    pub cached_bytes: u64,
}

impl StreamedTree {
    /// Opens a version-2 `.tess` file, keeping at most about `cache_bytes` of decoded
    /// chunks and colour blocks, those the rendering threads hold included (for as
    /// many threads as rayon's current pool has; see `docs/render-stream.md` for
    /// the exact bound).
    ///
    /// # Errors
    /// [`FormatError`] naming the file: unreadable, not version 2, layers other than
    /// colours, a damaged index or colour section, or a damaged chunk on the way to
    /// the solid's bounding box.
    pub fn open(path: &Path, cache_bytes: u64) -> Result<Self, FormatError> {
        let f = TessFile::open_lazy_colours(path)?;
        let end = 1u64 << (3 * u32::from(f.depth()));
        Self::from_parts(vec![f], vec![(0, end)], cache_bytes)
    }

    /// The tree made of `files`, the parts of a dataset in order, part `i` holding
    /// the codes `ranges[i]` (all in one space).
    ///
    /// # Errors
    /// As [`StreamedTree::open`]; also parts in different spaces or out of order.
    pub fn from_parts(
        files: Vec<TessFile>,
        ranges: Vec<(u64, u64)>,
        cache_bytes: u64,
    ) -> Result<Self, FormatError> {
        let Some(first) = files.first() else {
            return Err(FormatError::corrupt("no parts to render"));
        };
        let (depth, origin) = (first.depth(), first.origin());
        let mut chunks = Vec::new();
        let mut leaves = 0u64;
        for (p, f) in files.iter().enumerate() {
            if !f.is_streamed() {
                return Err(FormatError::unsupported(
                    "a version-1 .tess file has no chunks to stream (convert it to version 2)",
                )
                .with_path(f.path()));
            }
            if (f.depth(), f.origin()) != (depth, origin) {
                return Err(FormatError::corrupt(
                    "the part is in another space than the first part",
                )
                .with_path(f.path()));
            }
            let (lo, hi) = ranges[p];
            let infos = f.chunks();
            for (i, c) in infos.iter().copied().enumerate() {
                if chunks.last().is_some_and(|l: &ChunkRef| l.hi > c.lo) || c.lo < lo || c.hi > hi {
                    return Err(FormatError::corrupt(format!(
                        "chunk {i}: range [{}, {}) overlaps an earlier part or leaves the part's range",
                        c.lo, c.hi
                    ))
                    .with_path(f.path()));
                }
                chunks.push(ChunkRef {
                    part: p as u32,
                    chunk: i as u32,
                    lo: c.lo,
                    hi: c.hi,
                    count: c.count,
                    bytes: (c.offset, infos.get(i + 1).map_or(u64::MAX, |n| n.offset)),
                });
            }
            leaves += f.leaf_count();
        }
        let top = Top::build(depth, &chunks, |code, k, a, b| {
            covered(&files, &chunks[a..b], code, k)
        })?;
        let chunk_bytes = cache_bytes - cache_bytes / 4;
        let largest = chunks.iter().map(|c| c.count).max().unwrap_or(0);
        let threads = threads_within(chunk_bytes, largest, rayon::current_num_threads());
        let colours = Colours::index(&files, depth, cache_bytes / 4, 2 * threads as u64)?;
        let mut t = StreamedTree {
            files,
            ranges,
            chunks,
            top,
            depth,
            origin,
            bbox: None,
            leaves,
            // A thread's ray reader and cut-face test each hold a chunk, and it
            // may be decoding a third.
            cache: Cache::new(chunk_bytes, 3 * threads as u64),
            colours,
            threads,
            error: Mutex::new(None),
        };
        t.bbox = bounding_box(&t);
        t.take_error().map_or(Ok(t), Err)
    }

    /// The depth of the space.
    #[must_use]
    pub fn depth(&self) -> u8 {
        self.depth
    }

    /// The lowest voxel of the space.
    #[must_use]
    pub fn origin(&self) -> Voxel {
        self.origin
    }

    /// The threads a drawing of this tree runs on: rayon's pool when the tree was
    /// opened, or fewer when its cache could not keep the chunks those threads
    /// decode at once and then more. Each thread holds up to three decoded chunks
    /// outside the cache, which the cache's budget covers (see `cache.rs`); with
    /// more of them than two thirds of the budget hold, the cache would keep
    /// little and, past the whole budget, nothing: every step of a ray would
    /// decode its chunk again (a depth-11 spheroid at 320 × 240 with a 16 MiB
    /// cache: 131 chunks decoded in 0.5 s on three threads, 767 in 1.2 s on
    /// four, over 100 s on five).
    #[must_use]
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// Runs `f` (a drawing) on [`StreamedTree::threads`] threads: in the current
    /// rayon pool when it has no more, else in a pool of that many.
    pub(super) fn on_threads<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R {
        if self.threads >= rayon::current_num_threads() {
            return f();
        }
        match rayon::ThreadPoolBuilder::new()
            .num_threads(self.threads)
            .build()
        {
            Ok(pool) => pool.install(f),
            // No threads to be had: the current pool, with the cache's bound
            // as it is.
            Err(_) => f(),
        }
    }

    /// The number of leaves (from the index).
    #[must_use]
    pub fn leaf_count(&self) -> u64 {
        self.leaves
    }

    /// The inclusive bounding box of the black voxels (as
    /// [`crate::linear::LinearOctree::bbox`]), found at [`StreamedTree::open`] by
    /// reading only the chunks at the solid's extreme faces.
    #[must_use]
    pub fn bbox(&self) -> Option<([i64; 3], [i64; 3])> {
        self.bbox
    }

    /// The number of black voxels: every chunk read once, one at a time (not
    /// cached; a render does not need it), its mapped pages let go after it.
    ///
    /// # Errors
    /// A damaged chunk, naming the file and the chunk.
    pub fn voxel_count(&self) -> Result<u64, FormatError> {
        let mut n = 0u64;
        for c in &self.chunks {
            let f = &self.files[c.part as usize];
            for l in f.chunk(c.chunk as usize)? {
                n += l.end() - l.code();
            }
            f.release(c.bytes.0..c.bytes.1);
        }
        Ok(n)
    }

    /// Whether the files carry colours.
    #[must_use]
    pub fn has_colours(&self) -> bool {
        self.colours.is_some()
    }

    /// The stored colour of voxel `v`, if it has one (as
    /// [`crate::model::Layer::get`] on the whole model). A damaged colour block is
    /// recorded (see [`StreamedTree::take_error`]) and reads as no colour.
    #[must_use]
    pub fn colour(&self, v: Voxel) -> Option<Rgba> {
        let c = self.colours.as_ref()?;
        let side = 1i64 << self.depth;
        let rel = [0, 1, 2].map(|i| v[i] - self.origin[i]);
        if rel.iter().any(|&x| x < 0 || x >= side) {
            return None;
        }
        let code = crate::code::encode(rel[0] as u32, rel[1] as u32, rel[2] as u32);
        let part = self.ranges.partition_point(|r| r.1 <= code);
        if part >= self.ranges.len() || self.ranges[part].0 > code {
            return None;
        }
        match c.get(&self.files, part, code) {
            Ok(found) => found,
            Err(e) => {
                self.record(e);
                None
            }
        }
    }

    /// What was read so far.
    #[must_use]
    pub fn stats(&self) -> StreamStats {
        let colour = self.colours.as_ref();
        StreamStats {
            chunks: self.chunks.len() as u64,
            chunks_decoded: self.cache.loads.load(Ordering::Relaxed),
            colour_blocks_decoded: colour.map_or(0, |c| c.cache.loads.load(Ordering::Relaxed)),
            colour_bytes_read: colour.map_or(0, |c| c.bytes_read.load(Ordering::Relaxed)),
            cached_bytes: self.cache.used() + colour.map_or(0, |c| c.cache.used()),
        }
    }

    /// The first error met since the last call (a damaged chunk or colour block,
    /// naming the file and the chunk), if any.
    pub fn take_error(&self) -> Option<FormatError> {
        self.error
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .take()
    }

    fn record(&self, e: FormatError) {
        let mut g = self.error.lock().unwrap_or_else(PoisonError::into_inner);
        if g.is_none() {
            *g = Some(e);
        }
    }

    /// The ray index of chunk `c`, decoded if it is not kept; `None` (recorded) for
    /// a damaged chunk.
    fn chunk_tree(&self, c: u32) -> Option<Arc<RayTree>> {
        let r = self.chunks[c as usize];
        let got = self.cache.get(u64::from(c), || {
            let f = &self.files[r.part as usize];
            let leaves = f.chunk(r.chunk as usize)?;
            // The chunk's mapped pages leave resident memory: the cache holds
            // what was decoded from them.
            f.release(r.bytes.0..r.bytes.1);
            let mut rt = RayTree::from_leaves(self.depth, self.origin, &leaves);
            // The index keeps its nodes, at their length; decoding held the leaves
            // and the nodes at once, as a growing vector (up to twice their length).
            rt.nodes.shrink_to_fit();
            let nodes = std::mem::size_of_val(rt.nodes.as_slice()) as u64;
            let cost = Cost {
                kept: nodes + 256,
                peak: std::mem::size_of_val(leaves.as_slice()) as u64 + 2 * nodes + 256,
            };
            Ok::<_, FormatError>((rt, cost))
        });
        match got {
            Ok(rt) => Some(rt),
            Err(e) => {
                self.record(e);
                None
            }
        }
    }
}

/// Whether the leaves of `chunks` cover the node `(code, k)` (see [`Top::build`]).
fn covered(files: &[TessFile], chunks: &[ChunkRef], code: u64, k: u8) -> Result<bool, FormatError> {
    let size = 1u64 << (3 * u32::from(k));
    let mut sum = 0u64;
    for c in chunks {
        for l in files[c.part as usize].chunk(c.chunk as usize)? {
            if l.code() >= code && l.end() <= code + size {
                sum += l.end() - l.code();
            }
        }
    }
    Ok(sum == size)
}

/// A reader of a [`StreamedTree`]'s nodes: it keeps the chunk it is in.
pub(crate) struct Cursor<'a> {
    t: &'a StreamedTree,
    cur: Option<(u32, Arc<RayTree>)>,
}

impl Cursor<'_> {
    fn chunk(&mut self, c: u32) -> Option<&RayTree> {
        if self.cur.as_ref().is_none_or(|(id, _)| *id != c) {
            self.cur = self.t.chunk_tree(c).map(|rt| (c, rt));
        }
        self.cur.as_ref().map(|(_, rt)| &**rt)
    }

    /// The node `(path, k)` in chunk `c`'s index: a descent from its root.
    fn resolve(&mut self, c: u32, path: u64, k: u8) -> Kid {
        let depth = self.t.depth;
        let Some(rt) = self.chunk(c) else {
            return Kid::White;
        };
        match rt.root {
            Root::White => return Kid::White,
            Root::Black => return Kid::Black,
            Root::Gray => {}
        }
        let mut node = rt.nodes[rt.root_node as usize];
        let mut s = depth;
        loop {
            s -= 1;
            let bit = 1u8 << ((path >> (3 * u32::from(s - k))) & 7);
            if node.black & bit != 0 {
                return Kid::Black;
            }
            if node.gray & bit == 0 {
                return Kid::White;
            }
            let at = node.first + rank(node.gray, bit);
            if s == k {
                return Kid::Gray(NodeId { src: c, node: at });
            }
            node = rt.nodes[at as usize];
        }
    }
}

impl Nodes for Cursor<'_> {
    fn maybe(&mut self, id: NodeId, label: u8) -> bool {
        if id.src == TOP {
            return self.t.top.nodes[id.node as usize][usize::from(label)] != TopKid::White;
        }
        self.chunk(id.src).is_some_and(|rt| {
            let n = rt.nodes[id.node as usize];
            (n.black | n.gray) & (1 << label) != 0
        })
    }

    fn kid(&mut self, id: NodeId, label: u8, path: u64, k: u8) -> Kid {
        if id.src == TOP {
            return match self.t.top.nodes[id.node as usize][usize::from(label)] {
                TopKid::White => Kid::White,
                TopKid::Black => Kid::Black,
                TopKid::Top(i) => Kid::Gray(NodeId { src: TOP, node: i }),
                TopKid::Chunk(c) => self.resolve(c, path, k),
            };
        }
        let src = id.src;
        let Some(rt) = self.chunk(src) else {
            return Kid::White;
        };
        let n = rt.nodes[id.node as usize];
        let bit = 1u8 << label;
        if n.black & bit != 0 {
            Kid::Black
        } else if n.gray & bit != 0 {
            Kid::Gray(NodeId {
                src,
                node: n.first + rank(n.gray, bit),
            })
        } else {
            Kid::White
        }
    }
}

impl Trace for StreamedTree {
    type Cursor<'a> = Cursor<'a>;

    fn cursor(&self) -> Cursor<'_> {
        Cursor { t: self, cur: None }
    }

    fn space(&self) -> (u8, [i64; 3]) {
        (self.depth, self.origin)
    }

    fn root(&self) -> (Root, NodeId) {
        (
            self.top.root,
            NodeId {
                src: TOP,
                node: self.top.root_node,
            },
        )
    }

    fn bbox(&self) -> Option<([i64; 3], [i64; 3])> {
        self.bbox
    }
}
