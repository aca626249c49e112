//! The unbounded dynamic octree of Libes, *Modeling dynamic surfaces with octrees*
//! (§3–5): an octree whose root expands (×8) when a voxel is created outside it and
//! contracts while all content lies inside one of its children, with voxel
//! create/delete, `oct_find` that starts from any node, neighbour finding, and
//! optional bookkeeping of every exposed surface face.
//!
//! # Layout
//! - Coordinates are any `i64`. The root is a cube of side `2^k` (`0 ≤ k ≤ 64`) with
//!   an arbitrary minimum corner; below the root, cells are aligned to the root.
//!   Offsets from the root corner are computed in wrapping `u64` arithmetic, so a root
//!   with `k = 64` covers every `i64` coordinate (the world wraps at ±2^63, as two's
//!   complement does).
//! - Interior nodes live in one pool (`Vec`, `u32` indices, free list). A node holds
//!   eight child slots and a parent index. A slot is *empty*, *full*, or the index of a
//!   stored child: a full slot stands for a full octant of any size (Libes §4: "a
//!   voxel that is one of eight others that share the same parent will be implicitly
//!   stored simply by marking the parent as full").
//! - The lowest level is an 8×8×8 block of voxels stored as 512 bits (eight `u64`, one
//!   per z-slice, bit `x + 8y`), one cache line. So a lookup touches about
//!   `k − 3` nodes and one block, and a stored voxel costs a bit, not a node.
//! - Slot values 0 (empty) and 1 (full) are also real pool entries, *sentinels*: node 0
//!   has eight empty children and node 1 eight full ones, block 0 is all zeros and
//!   block 1 all ones. A search can therefore run down to the block level without
//!   testing what it meets on the way ([`DynamicOctree::contains`] is a straight chain
//!   of loads, with the child indices of up to eight levels read from one interleaved
//!   word). Short chains matter more than anything else here: on a tree larger than
//!   the cache, a random lookup waits for one memory access, and the processor can
//!   only overlap those of consecutive lookups when each lookup is a few instructions.
//! - With [`DynamicOctree::with_faces`], every exposed face is kept in one dense list
//!   with back-pointers (one record of six list positions per surface voxel, found
//!   through a compact hash index), so a random face is drawn
//!   in O(1) and a face is removed by `swap_remove` in O(1) (Libes §5).
//!
//! # Invariants (checked by [`DynamicOctree::assert_valid`])
//! - No stored node or block is all-empty or all-full (those are slots, not nodes).
//! - Parent links point at the node whose slot holds the child.
//! - The root cannot contract: its content does not lie inside one of its children.
//! - The voxel count and the face list (when kept) are exact.
//!
//! ```
//! use tesseral::dynamic::DynamicOctree;
//! let mut t = DynamicOctree::with_faces();
//! assert!(t.insert([0, 0, 0]));
//! assert!(t.insert([1, 0, 0]));
//! assert!(t.contains([1, 0, 0]));
//! assert_eq!(t.face_count(), 10); // two cubes sharing one face
//! assert!(t.insert([-1_000_000, 5, 5])); // the root grows to take it in
//! t.assert_valid();
//! ```

// Loops over the three axes index several per-axis arrays at once.
#![allow(clippy::needless_range_loop)]

mod blocks;
mod convert;
mod directory;
mod edit;
mod faces;
mod grow;
mod pool;
mod search;
mod surface;
mod tess_dyn;
mod validate;

use std::fmt;

pub use crate::lattice::{Direction, Directions, Face, Neighbourhood};
use blocks::*;
use faces::FaceList;
use pool::*;

use crate::linear::{CellClass, Classifier, LinearOctree, OctreeError};
use crate::Voxel;

/// log2 of the side of a leaf block (8×8×8 voxels, 512 bits).
pub(super) const LEAF_LOG2: u32 = 3;
/// An empty slot (and the "no node" parent). Also the index of the empty sentinel in
/// each pool: node 0 has eight empty children, block 0 is all zeros.
pub(super) const EMPTY: u32 = 0;
/// A full slot. Also the index of the full sentinel in each pool: node 1 has eight
/// full children, block 1 is all ones.
pub(super) const FULL: u32 = 1;
/// Tag of a slot (at the block level only) that holds a small block.
pub(super) const SMALL: u32 = 1 << 31;
/// Voxels a small block holds; one more turns it into a bitmap block.
pub(super) const SMALL_CAP: usize = 8;
/// A vacant lane of a small block.
pub(super) const VACANT: u16 = u16::MAX;
/// The most levels the directory skips (8^6 = 262,144 entries, 1 MiB).
pub(super) const DIR_MAX_LEVELS: u32 = 6;
/// No parent: the node is the root.
pub(super) const NONE: u32 = 0;
/// The parent field of a node or block on the free list.
pub(super) const FREED: u32 = u32::MAX;
/// `SPREAD[b]` has bit `i` of `b` at bit `3i`: three lookups interleave eight levels
/// of child indices into one word.
static SPREAD: [u32; 256] = {
    let mut t = [0u32; 256];
    let mut i = 0;
    while i < 256 {
        let mut b = 0;
        while b < 8 {
            t[i] |= ((i as u32 >> b) & 1) << (3 * b);
            b += 1;
        }
        i += 1;
    }
    t
};
pub(super) const ZERO_BLOCK: [u64; 8] = [0; 8];
pub(super) const FULL_BLOCK: [u64; 8] = [!0; 8];

/// Eight child slots, 32 bytes aligned to 32, so a node never straddles two cache
/// lines; its parent link lives in a separate array (`Pool::parent`), which searches
/// from the root never touch.
#[derive(Clone, Copy)]
#[repr(C, align(32))]
pub(super) struct Node {
    child: [u32; 8],
}

/// 8×8×8 voxels: word `z`, bit `x + 8y`.
#[derive(Clone, Copy)]
#[repr(C, align(64))]
pub(super) struct Leaf(pub(super) [u64; 8]);

/// An unbounded octree of voxels (Libes §3–5). See the [module docs](self).
///
/// Every operation costs O(log n) where n is the extent of the content (the depth of
/// the root), and space is O(|S|): blocks of 8³ voxels along the surface plus the
/// nodes above them; full octants cost nothing below their parent's slot.
#[derive(Clone)]
pub struct DynamicOctree {
    /// Slot of the root, at level `max(size_log2, 3)`.
    root: u32,
    /// World coordinates of the root's minimum corner.
    root_min: Voxel,
    /// log2 of the root's side, 0..=64. Below 3 the root is the low corner of a block.
    size_log2: u32,
    nodes: Pool<Node>,
    leaves: Pool<Leaf>,
    small: Pool<Small>,
    /// Whether new blocks start small (see [`DynamicOctree::set_small_blocks`]).
    small_blocks: bool,
    voxels: u64,
    expansions: u64,
    contractions: u64,
    /// Bumped by every change; makes stale [`Octant`] handles harmless.
    version: u64,
    /// The directory: the slots at level `dir_level = phys − dir_levels`, densely, in
    /// tesseral order of the root's cells at that level, so a search starts there
    /// instead of at the root. Empty when `dir_levels == 0`. Sized to the tree: built
    /// with at most eight entries per stored node and block (4 bytes each, against
    /// their 16–64), rebuilt larger when the tree has grown eightfold and smaller
    /// when it holds less than one stored node per 64 entries, and never more than
    /// `8^DIR_MAX_LEVELS` entries.
    dir: Vec<u32>,
    dir_levels: u32,
    dir_level: u32,
    faces: Option<FaceList>,
}

/// The smallest uniform octant that contains a voxel, as found by
/// [`DynamicOctree::find`]: an implicit empty or full octant, or the voxel itself
/// (size 1) inside a stored block. It also remembers the node the search ended in, so
/// that [`DynamicOctree::find_from`] can start there (Libes §5).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Octant {
    min: Voxel,
    size_log2: u32,
    full: bool,
    /// The deepest stored node on the path (NONE: the root slot itself).
    node: u32,
    node_level: u32,
    /// Offsets (from the root corner at `version`) of a point inside `node`.
    probe: [u64; 3],
    version: u64,
}

impl Octant {
    /// World coordinates of the octant's minimum corner.
    #[must_use]
    pub fn min(&self) -> Voxel {
        self.min
    }
    /// log2 of the octant's side (0 for a single voxel).
    #[must_use]
    pub fn size_log2(&self) -> u32 {
        self.size_log2
    }
    /// Whether the octant is full (black); otherwise it is empty (white).
    #[must_use]
    pub fn is_full(&self) -> bool {
        self.full
    }
}

impl Default for DynamicOctree {
    fn default() -> Self {
        Self::new()
    }
}

impl fmt::Debug for DynamicOctree {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("DynamicOctree")
            .field("voxels", &self.voxels)
            .field("root_min", &self.root_min)
            .field("root_size_log2", &self.size_log2)
            .field("nodes", &self.node_count())
            .field("faces", &self.faces.as_ref().map(|f| f.list.len()))
            .finish()
    }
}

impl DynamicOctree {
    /// An empty tree without face bookkeeping (the occupancy-map use). O(1).
    ///
    /// ```
    /// let t = tesseral::dynamic::DynamicOctree::new();
    /// assert_eq!(t.voxel_count(), 0);
    /// assert_eq!(t.face_count(), 0);
    /// ```
    #[must_use]
    pub fn new() -> Self {
        DynamicOctree {
            root: EMPTY,
            root_min: [0; 3],
            size_log2: 0,
            nodes: Pool::new(&[Node { child: [EMPTY; 8] }, Node { child: [FULL; 8] }]),
            leaves: Pool::new(&[Leaf(ZERO_BLOCK), Leaf(FULL_BLOCK)]),
            small: Pool::new(&[]),
            small_blocks: true,
            voxels: 0,
            expansions: 0,
            contractions: 0,
            version: 0,
            dir: Vec::new(),
            dir_levels: 0,
            dir_level: 0,
            faces: None,
        }
    }

    /// An empty tree that tracks every exposed face (Libes §4) in a dense list, for
    /// O(1) uniform sampling of surface faces. O(1).
    ///
    /// ```
    /// let mut t = tesseral::dynamic::DynamicOctree::with_faces();
    /// t.insert([3, -4, 5]);
    /// assert_eq!(t.face_count(), 6);
    /// ```
    #[must_use]
    pub fn with_faces() -> Self {
        let mut t = Self::new();
        t.faces = Some(FaceList::default());
        t.small_blocks = false;
        t
    }

    /// Builds a tree (without face bookkeeping) from a list of voxels; duplicates are
    /// ignored. O(n log n).
    ///
    /// ```
    /// let t = tesseral::dynamic::DynamicOctree::from_voxels([[0, 0, 0], [5, 5, 5], [0, 0, 0]]);
    /// assert_eq!(t.voxel_count(), 2);
    /// ```
    pub fn from_voxels<I: IntoIterator<Item = Voxel>>(voxels: I) -> Self {
        let mut t = Self::new();
        t.extend(voxels);
        t
    }

    /// Chooses whether blocks created from now on start *small* (up to eight voxels
    /// in 16 bytes, a bitmap block of 64 bytes once a ninth arrives) or as bitmap
    /// blocks. Small blocks cut the memory of sparse content (scattered points: the
    /// occupancy-map use) to about a third, and its lookups gain because more of the
    /// tree stays in the cache; dense surfaces fill their blocks anyway and read
    /// their neighbourhoods faster from bitmaps. On by default; off for
    /// [`with_faces`](Self::with_faces) trees (random surfaces). While it is on, a
    /// bitmap block that deletions leave with four or fewer voxels turns small again.
    /// Existing blocks keep their form. O(1).
    ///
    /// ```
    /// let mut t = tesseral::dynamic::DynamicOctree::new();
    /// t.set_small_blocks(false);
    /// t.insert([1, 2, 3]);
    /// assert!(t.contains([1, 2, 3]));
    /// ```
    pub fn set_small_blocks(&mut self, on: bool) {
        self.small_blocks = on;
    }

    /// Whether this tree keeps the face list.
    #[must_use]
    pub fn tracks_faces(&self) -> bool {
        self.faces.is_some()
    }

    // ----- counts -----------------------------------------------------------------------

    /// The number of black voxels. O(1).
    #[must_use]
    pub fn voxel_count(&self) -> u64 {
        self.voxels
    }

    /// Whether there are no voxels. O(1).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.voxels == 0
    }

    /// log2 of the root's side.
    #[must_use]
    pub fn root_size_log2(&self) -> u32 {
        self.size_log2
    }

    /// World coordinates of the root's minimum corner (`[0, 0, 0]` when empty).
    #[must_use]
    pub fn root_min(&self) -> Voxel {
        self.root_min
    }

    /// How many times the root has grown ×8 since the tree was made.
    #[must_use]
    pub fn expansions(&self) -> u64 {
        self.expansions
    }

    /// How many times the root has shrunk to one of its children.
    #[must_use]
    pub fn contractions(&self) -> u64 {
        self.contractions
    }

    /// Stored nodes: interior nodes plus 8³ blocks (bitmap and small). O(1).
    #[must_use]
    pub fn node_count(&self) -> usize {
        self.nodes.live() + self.leaves.live() + self.small.live()
    }

    /// Bytes of memory held: the struct plus every heap allocation at its capacity
    /// (node pool, block pool, parent links, free lists, and with faces the face list
    /// and its back-pointer table). O(1).
    #[must_use]
    pub fn bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + self.nodes.heap_bytes()
            + self.leaves.heap_bytes()
            + self.small.heap_bytes()
            + self.dir.capacity() * 4
            + self.faces.as_ref().map_or(0, FaceList::heap_bytes)
    }

    /// Releases unused pool capacity (after a bulk build or many deletions the
    /// pools may hold up to twice what they need). O(size).
    pub fn shrink_to_fit(&mut self) {
        self.nodes.shrink_to_fit();
        self.leaves.shrink_to_fit();
        self.small.shrink_to_fit();
        self.dir.shrink_to_fit();
        if let Some(f) = &mut self.faces {
            f.list.shrink_to_fit();
            f.owners.shrink_to_fit();
            f.records.shrink_to_fit();
            f.free.shrink_to_fit();
        }
    }
}

impl Extend<Voxel> for DynamicOctree {
    fn extend<I: IntoIterator<Item = Voxel>>(&mut self, iter: I) {
        for v in iter {
            self.insert(v);
        }
    }
}

impl FromIterator<Voxel> for DynamicOctree {
    fn from_iter<I: IntoIterator<Item = Voxel>>(iter: I) -> Self {
        Self::from_voxels(iter)
    }
}

#[cfg(test)]
mod tests;
