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

mod faces;

use std::fmt;

use faces::FaceList;
pub use faces::{opposite, step, Face};

use crate::linear::{CellClass, Classifier, LinearOctree, OctreeError};
use crate::Voxel;

/// log2 of the side of a leaf block (8×8×8 voxels, 512 bits).
const LEAF_LOG2: u32 = 3;
/// An empty slot (and the "no node" parent). Also the index of the empty sentinel in
/// each pool: node 0 has eight empty children, block 0 is all zeros.
const EMPTY: u32 = 0;
/// A full slot. Also the index of the full sentinel in each pool: node 1 has eight
/// full children, block 1 is all ones.
const FULL: u32 = 1;
/// Tag of a slot (at the block level only) that holds a small block.
const SMALL: u32 = 1 << 31;
/// Voxels a small block holds; one more turns it into a bitmap block.
const SMALL_CAP: usize = 8;
/// A vacant lane of a small block.
const VACANT: u16 = u16::MAX;
/// The most levels the directory skips (8^6 = 262,144 entries, 1 MiB).
const DIR_MAX_LEVELS: u32 = 6;
/// No parent: the node is the root.
const NONE: u32 = 0;
/// The parent field of a node or block on the free list.
const FREED: u32 = u32::MAX;
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
const ZERO_BLOCK: [u64; 8] = [0; 8];
const FULL_BLOCK: [u64; 8] = [!0; 8];
/// All 27 bits of a 3×3×3 neighbourhood.
pub const NEIGHBOURHOOD_ALL: u32 = (1 << 27) - 1;
/// Bit of the 27-bit neighbourhood for each face direction 0..6 (−x, +x, −y, +y, −z, +z).
pub const NEIGHBOUR_BIT: [u32; 6] = [12, 14, 10, 16, 4, 22];
/// Bit of the 27-bit neighbourhood for the centre voxel.
pub const CENTRE_BIT: u32 = 13;

/// Eight child slots, 32 bytes aligned to 32, so a node never straddles two cache
/// lines; its parent link lives in a separate array (`Pool::parent`), which searches
/// from the root never touch.
#[derive(Clone, Copy)]
#[repr(C, align(32))]
struct Node {
    child: [u32; 8],
}

/// 8×8×8 voxels: word `z`, bit `x + 8y`.
#[derive(Clone, Copy)]
#[repr(C, align(64))]
struct Leaf([u64; 8]);

/// A sparse 8×8×8 block: up to eight voxels as local indices `x + 8y + 64z` (the
/// bit numbers of a [`Leaf`]) in the first lanes, in any order, then vacant lanes
/// ([`VACANT`]). 16 bytes, a
/// quarter of a bitmap block: sparse content (scattered points, thin structures)
/// takes a quarter of the memory, and more of it stays in the cache.
#[derive(Clone, Copy)]
#[repr(C, align(16))]
struct Small([u16; SMALL_CAP]);

impl Small {
    /// A block holding the one voxel `key`.
    fn one(key: u16) -> Self {
        let mut lanes = [VACANT; SMALL_CAP];
        lanes[0] = key;
        Small(lanes)
    }
    /// The voxels of `words` (at most [`SMALL_CAP`]) as a small block.
    fn from_words(words: &[u64; 8]) -> Self {
        let mut lanes = [VACANT; SMALL_CAP];
        let mut k = 0;
        for (z, &word) in words.iter().enumerate() {
            let mut rest = word;
            while rest != 0 {
                lanes[k] = (z as u16) << 6 | rest.trailing_zeros() as u16;
                k += 1;
                rest &= rest - 1;
            }
        }
        Small(lanes)
    }
    /// Whether lane value `key` is present. Branch-free (all eight lanes are
    /// compared), so a hit does not mispredict a loop exit.
    #[inline(always)]
    fn has(&self, key: u16) -> bool {
        self.0.iter().fold(false, |found, &e| found | (e == key))
    }
    /// Occupied lanes (they come first). Branch-free.
    #[inline(always)]
    fn count(&self) -> usize {
        self.0.iter().map(|&e| usize::from(e != VACANT)).sum()
    }
    /// Adds `key`: `Some(true)` when it is new, `Some(false)` when it was there, `None`
    /// when the block is full (it must become a bitmap block first).
    #[inline]
    fn insert(&mut self, key: u16) -> Option<bool> {
        if self.has(key) {
            return Some(false);
        }
        let n = self.count();
        if n == SMALL_CAP {
            return None;
        }
        self.0[n] = key;
        Some(true)
    }
    /// Removes `key` (the last occupied lane fills its place); false when absent.
    #[inline]
    fn remove(&mut self, key: u16) -> bool {
        let Some(lane) = self.0.iter().position(|&e| e == key) else {
            return false;
        };
        let last = self.count() - 1;
        self.0[lane] = self.0[last];
        self.0[last] = VACANT;
        true
    }
    fn words(&self) -> [u64; 8] {
        let mut l = [0u64; 8];
        for &e in &self.0 {
            if e != VACANT {
                l[usize::from(e >> 6)] |= 1 << (e & 63);
            }
        }
        l
    }
}

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

/// Grows a pool by 1/8 (at least 64 entries) when it is full, instead of doubling:
/// the pools are most of the memory, and doubling would leave up to half of it
/// unused. Large reallocations are cheap (glibc moves them with `mremap`), so the
/// amortised cost per push stays O(1).
#[inline]
fn grow<T>(v: &mut Vec<T>) {
    if v.len() == v.capacity() {
        v.reserve_exact((v.len() / 8).max(64));
    }
}

/// A pool of entries addressed by `u32`: the entries, a parent link per entry (kept
/// apart, so searches from the root never load it) and a free list. The first
/// `reserved` entries are sentinels, never handed out or released.
#[derive(Clone)]
struct Pool<T> {
    items: Vec<T>,
    parent: Vec<u32>,
    free: Vec<u32>,
    reserved: usize,
}

impl<T: Copy> Pool<T> {
    fn new(sentinels: &[T]) -> Self {
        Pool {
            items: sentinels.to_vec(),
            parent: vec![FREED; sentinels.len()],
            free: Vec::new(),
            reserved: sentinels.len(),
        }
    }

    /// Stores `value` under `parent`; returns its index, below 2^31 (bit 31 of a slot
    /// tags a small block).
    fn alloc(&mut self, value: T, parent: u32, what: &str) -> u32 {
        if let Some(i) = self.free.pop() {
            self.items[i as usize] = value;
            self.parent[i as usize] = parent;
            return i;
        }
        let i = u32::try_from(self.items.len())
            .ok()
            .filter(|&i| i < SMALL)
            .unwrap_or_else(|| panic!("DynamicOctree: more than 2^31 {what}s"));
        grow(&mut self.items);
        self.items.push(value);
        grow(&mut self.parent);
        self.parent.push(parent);
        i
    }

    fn release(&mut self, i: u32) {
        debug_assert!(i as usize >= self.reserved, "releasing a sentinel");
        self.parent[i as usize] = FREED;
        self.free.push(i);
    }

    /// Entries in use, sentinels not counted.
    fn live(&self) -> usize {
        self.items.len() - self.reserved - self.free.len()
    }

    fn heap_bytes(&self) -> usize {
        self.items.capacity() * std::mem::size_of::<T>()
            + (self.parent.capacity() + self.free.capacity()) * 4
    }

    fn shrink_to_fit(&mut self) {
        self.items.shrink_to_fit();
        self.parent.shrink_to_fit();
        self.free.shrink_to_fit();
    }

    /// Checks the bookkeeping for [`DynamicOctree::assert_valid`]: one parent link per
    /// entry, a free list without repeats or sentinels whose entries are marked freed.
    /// Returns the free entries.
    fn check(&self, what: &str) -> std::collections::HashSet<u32> {
        assert_eq!(
            self.items.len(),
            self.parent.len(),
            "{what} parent array length"
        );
        let set: std::collections::HashSet<u32> = self.free.iter().copied().collect();
        assert_eq!(
            set.len(),
            self.free.len(),
            "{what} free list has duplicates"
        );
        for &i in &self.free {
            assert!(
                i as usize >= self.reserved,
                "sentinel {what} {i} on the free list"
            );
            assert_eq!(self.parent[i as usize], FREED, "free {what} {i} not marked");
        }
        set
    }
}

impl<T> std::ops::Index<usize> for Pool<T> {
    type Output = T;
    #[inline(always)]
    fn index(&self, i: usize) -> &T {
        &self.items[i]
    }
}

impl<T> std::ops::IndexMut<usize> for Pool<T> {
    #[inline(always)]
    fn index_mut(&mut self, i: usize) -> &mut T {
        &mut self.items[i]
    }
}

#[inline]
fn within(u: [u64; 3], log2: u32) -> bool {
    log2 >= 64 || (u[0] | u[1] | u[2]) >> log2 == 0
}

#[inline]
fn child_index(u: [u64; 3], level: u32) -> usize {
    let s = level - 1;
    ((u[0] >> s) & 1 | ((u[1] >> s) & 1) << 1 | ((u[2] >> s) & 1) << 2) as usize
}

#[inline]
fn leaf_bit(u: [u64; 3]) -> (usize, u64) {
    ((u[2] & 7) as usize, 1u64 << ((u[0] & 7) + 8 * (u[1] & 7)))
}

#[inline]
fn is_index(slot: u32) -> bool {
    slot != EMPTY && slot != FULL
}

/// Whether a block-level slot holds a small block.
#[inline(always)]
fn is_small(slot: u32) -> bool {
    slot & SMALL != 0
}

/// The lane value of offsets `u` in a small block: `x + 8y + 64z` of the local cell.
#[inline(always)]
fn local_index(u: [u64; 3]) -> u16 {
    ((u[0] & 7) | (u[1] & 7) << 3 | (u[2] & 7) << 6) as u16
}

/// Moves the content of a block by `s` cells along `axis`, up or down. The caller
/// guarantees that no set bit leaves the block (or wraps into the next row).
fn shift_leaf(l: &mut [u64; 8], axis: usize, s: u64, up: bool) {
    match axis {
        0 | 1 => {
            let sh = if axis == 0 { s } else { 8 * s };
            for w in l.iter_mut() {
                *w = if up { *w << sh } else { *w >> sh };
            }
        }
        _ => {
            let s = s as usize;
            if up {
                for z in (0..8).rev() {
                    l[z] = if z >= s { l[z - s] } else { 0 };
                }
            } else {
                for z in 0..8 {
                    l[z] = if z + s < 8 { l[z + s] } else { 0 };
                }
            }
        }
    }
}

/// Per-axis occupancy masks of a block: bit `i` of mask `a` is set when some voxel
/// has coordinate `i` along axis `a`.
fn leaf_axis_masks(l: &[u64; 8]) -> [u8; 3] {
    let mut rows = 0u64;
    let mut zm = 0u8;
    for (z, &w) in l.iter().enumerate() {
        rows |= w;
        if w != 0 {
            zm |= 1 << z;
        }
    }
    let mut xm = 0u8;
    let mut ym = 0u8;
    for y in 0..8 {
        let b = (rows >> (8 * y)) as u8;
        xm |= b;
        if b != 0 {
            ym |= 1 << y;
        }
    }
    [xm, ym, zm]
}

/// The 27-bit neighbourhood of local voxel `u & 7` inside one block; needs every local
/// coordinate in 1..=6.
#[inline]
fn extract27(l: &[u64; 8], u: [u64; 3]) -> u32 {
    let (lx, ly, lz) = (
        (u[0] & 7) as usize,
        (u[1] & 7) as usize,
        (u[2] & 7) as usize,
    );
    let sh = lx - 1 + 8 * (ly - 1);
    let mut r = 0u32;
    for dz in 0..3 {
        let w = l[lz - 1 + dz] >> sh;
        let plane = (w & 7) | ((w >> 8) & 7) << 3 | ((w >> 16) & 7) << 6;
        r |= (plane as u32) << (9 * dz);
    }
    r
}

/// The 27-bit neighbourhood of offsets `u` from the up to eight blocks around it:
/// `word(b, z)` is word `z` of block `b` (bit `i` of `b` selects the upper block along
/// axis `i`; `lo`/`hi` are the block coordinates of `u − 1` and `u + 1`). Row by row:
/// the three cells (x−1, x, x+1) of a row come from one block word, or from two when
/// the row crosses a block boundary in x.
#[inline(always)]
fn rows27(u: [u64; 3], lo: [u64; 3], hi: [u64; 3], word: impl Fn(usize, usize) -> u64) -> u32 {
    let lx = u[0] & 7;
    let mut r = 0u32;
    for dz in 0..3u64 {
        let cz = u[2].wrapping_add(dz).wrapping_sub(1);
        let bz = usize::from(cz >> 3 != lo[2]) << 2;
        let lz = (cz & 7) as usize;
        for dy in 0..3u64 {
            let cy = u[1].wrapping_add(dy).wrapping_sub(1);
            let b = usize::from(cy >> 3 != lo[1]) << 1 | bz;
            let sh = 8 * (cy & 7);
            let row = if lo[0] == hi[0] {
                (word(b, lz) >> (sh + lx - 1)) & 7
            } else {
                let wl = word(b, lz) >> sh;
                let wh = word(b | 1, lz) >> sh;
                if lx == 0 {
                    (wl >> 7 & 1) | (wh & 3) << 1
                } else {
                    (wl >> 6 & 3) | (wh & 1) << 2
                }
            };
            r |= (row as u32) << (3 * dy + 9 * dz);
        }
    }
    r
}

/// The six face-neighbour bits (bit `dir`) of a 27-bit neighbourhood.
#[inline]
fn six(n: u32) -> u8 {
    let mut m = 0u8;
    for (dir, &bit) in NEIGHBOUR_BIT.iter().enumerate() {
        m |= ((n >> bit & 1) as u8) << dir;
    }
    m
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

    // ----- pools -------------------------------------------------------------------

    fn alloc_node(&mut self, parent: u32, fill: u32) -> u32 {
        self.nodes.alloc(Node { child: [fill; 8] }, parent, "node")
    }

    fn free_node(&mut self, i: u32) {
        self.nodes.release(i);
    }

    fn alloc_leaf(&mut self, parent: u32, fill: u64) -> u32 {
        self.leaves.alloc(Leaf([fill; 8]), parent, "block")
    }

    fn free_leaf(&mut self, i: u32) {
        self.leaves.release(i);
    }

    /// Stores a small block; returns its tagged slot.
    fn alloc_small(&mut self, parent: u32, block: Small) -> u32 {
        self.small.alloc(block, parent, "small block") | SMALL
    }

    fn free_small(&mut self, slot: u32) {
        self.small.release(slot & !SMALL);
    }

    /// Turns the small block in `slot` (child `ci` of `parent`, containing offsets
    /// `u`) into a bitmap block; returns the new block.
    fn promote(&mut self, slot: u32, parent: u32, ci: usize, u: [u64; 3]) -> u32 {
        let words = self.small[(slot & !SMALL) as usize].words();
        self.free_small(slot);
        let big = self.alloc_leaf(parent, 0);
        self.leaves[big as usize].0 = words;
        self.set_slot(parent, ci, big, LEAF_LOG2, u);
        big
    }

    /// Whether the block in `slot` (block level, sentinels included) holds the voxel
    /// at offsets `u`.
    #[inline(always)]
    fn block_has(&self, slot: u32, u: [u64; 3]) -> bool {
        if is_small(slot) {
            self.small[(slot & !SMALL) as usize].has(local_index(u))
        } else {
            let (w, b) = leaf_bit(u);
            self.leaves[slot as usize].0[w] & b != 0
        }
    }

    /// The 512 bits of the block in `slot` (block level, sentinels included).
    #[inline]
    fn block_words(&self, slot: u32) -> [u64; 8] {
        if is_small(slot) {
            self.small[(slot & !SMALL) as usize].words()
        } else {
            self.leaves[slot as usize].0
        }
    }

    /// Writes `val` into child slot `ci` of `parent` (the root slot when `parent` is
    /// NONE). The slot is at `level` and contains offsets `u`; the directory follows.
    #[inline]
    fn set_slot(&mut self, parent: u32, ci: usize, val: u32, level: u32, u: [u64; 3]) {
        if parent == NONE {
            self.root = val;
        } else {
            self.nodes[parent as usize].child[ci] = val;
        }
        if self.dir_levels > 0 && level >= self.dir_level {
            let i = self.dir_index(u);
            if level == self.dir_level {
                self.dir[i] = val;
            } else if !is_index(val) {
                // A uniform octant above the directory level: all its entries. (A
                // node stored there holds the uniform value it replaced, which the
                // entries already show.)
                let span = 1usize << (3 * (level - self.dir_level));
                let base = i & !(span - 1);
                self.dir[base..base + span].fill(val);
            }
        }
    }

    /// The directory entry of offsets `u` (inside the root).
    #[inline(always)]
    fn dir_index(&self, u: [u64; 3]) -> usize {
        let d = self.dir_level;
        let spread = |x: u64| SPREAD[(x >> d & 255) as usize] as usize;
        spread(u[0]) | spread(u[1]) << 1 | spread(u[2]) << 2
    }

    /// Rebuilds the directory after the root changed (expansion, contraction, a new
    /// or emptied tree) or the tree outgrew it or shrank well below it. It skips
    /// `t ≤ DIR_MAX_LEVELS` levels, the most for which `8^t ≤ 8 · stored nodes` and
    /// the directory level stays at or above the blocks. O(8^t), at most 262,144
    /// entries (tens of microseconds).
    fn rebuild_dir(&mut self) {
        let live = self.node_count();
        let mut t = 0;
        while t < self.dir_max_levels() && 1usize << (3 * (t + 1)) <= 8 * live {
            t += 1;
        }
        self.dir_levels = t;
        self.dir_level = self.phys_log2() - t;
        let mut dir = Vec::new();
        if t > 0 {
            dir.resize(1 << (3 * t), EMPTY);
            self.fill_dir(&mut dir, self.root, self.phys_log2(), 0);
        }
        self.dir = dir;
    }

    /// The most levels the directory may skip in a root of this size: it stays at or
    /// above the blocks.
    fn dir_max_levels(&self) -> u32 {
        (self.phys_log2() - LEAF_LOG2).min(DIR_MAX_LEVELS)
    }

    /// Writes into `dir` (entries of `self.dir_level`) the entries under `slot` at
    /// `level`, from entry `base`.
    fn fill_dir(&self, dir: &mut [u32], slot: u32, level: u32, base: usize) {
        if level == self.dir_level || !is_index(slot) {
            let span = 1usize << (3 * (level - self.dir_level));
            dir[base..base + span].fill(slot);
        } else {
            let step = 1usize << (3 * (level - 1 - self.dir_level));
            for (ci, &c) in self.nodes[slot as usize].child.iter().enumerate() {
                self.fill_dir(dir, c, level - 1, base + ci * step);
            }
        }
    }

    /// Rebuilds the directory when the tree has grown eightfold since it was built
    /// (and a deeper one is allowed), or holds less than one stored node per 64
    /// entries.
    #[inline]
    fn check_dir_size(&mut self) {
        let live = self.node_count();
        let entries = 1usize << (3 * self.dir_levels);
        let grown = self.dir_levels < self.dir_max_levels() && live >= entries;
        if grown || live < entries / 64 {
            self.rebuild_dir();
        }
    }

    /// Sets the parent link of the stored child `slot` at `level`.
    fn set_parent(&mut self, slot: u32, level: u32, parent: u32) {
        if is_index(slot) {
            if level > LEAF_LOG2 {
                self.nodes.parent[slot as usize] = parent;
            } else if is_small(slot) {
                self.small.parent[(slot & !SMALL) as usize] = parent;
            } else {
                self.leaves.parent[slot as usize] = parent;
            }
        }
    }

    #[inline]
    fn offsets(&self, v: Voxel) -> [u64; 3] {
        [
            (v[0] as u64).wrapping_sub(self.root_min[0] as u64),
            (v[1] as u64).wrapping_sub(self.root_min[1] as u64),
            (v[2] as u64).wrapping_sub(self.root_min[2] as u64),
        ]
    }

    #[inline]
    fn phys_log2(&self) -> u32 {
        self.size_log2.max(LEAF_LOG2)
    }

    #[inline]
    fn world(&self, u: [u64; 3]) -> Voxel {
        [
            self.root_min[0].wrapping_add(u[0] as i64),
            self.root_min[1].wrapping_add(u[1] as i64),
            self.root_min[2].wrapping_add(u[2] as i64),
        ]
    }

    // ----- root expansion and contraction (Libes §3) ---------------------------------

    /// Grows the root ×8 towards `v`: the old root becomes a child of the new one.
    fn expand(&mut self, v: Voxel) {
        let k = self.size_log2;
        debug_assert!(k < 64);
        let size = 1u64 << k;
        let mut ci = 0usize;
        for a in 0..3 {
            if v[a] < self.root_min[a] {
                self.root_min[a] = self.root_min[a].wrapping_sub(size as i64);
                ci |= 1 << a;
            }
        }
        if k >= LEAF_LOG2 {
            let old = self.root;
            let n = self.alloc_node(NONE, EMPTY);
            self.nodes[n as usize].child[ci] = old;
            self.set_parent(old, k, n);
            self.root = n;
        } else {
            // The logical root is the low corner of the root block: growing towards −
            // moves the content up inside the block.
            let l = &mut self.leaves[self.root as usize].0;
            for a in 0..3 {
                if ci >> a & 1 == 1 {
                    shift_leaf(l, a, size, true);
                }
            }
        }
        self.size_log2 = k + 1;
        self.expansions += 1;
    }

    /// Shrinks the root while all content lies inside one of its children.
    /// Returns whether it did.
    fn contract(&mut self) -> bool {
        let mut changed = false;
        loop {
            let k = self.size_log2;
            if k == 0 || self.root == FULL || self.root == EMPTY {
                return changed;
            }
            let half = 1u64 << (k - 1);
            if k > LEAF_LOG2 {
                let n = self.root as usize;
                let ch = self.nodes[n].child;
                let mut only = 0;
                let mut count = 0;
                for (i, &c) in ch.iter().enumerate() {
                    if c != EMPTY {
                        count += 1;
                        only = i;
                    }
                }
                if count != 1 {
                    return changed;
                }
                for a in 0..3 {
                    if only >> a & 1 == 1 {
                        self.root_min[a] = self.root_min[a].wrapping_add(half as i64);
                    }
                }
                let c = ch[only];
                self.free_node(n as u32);
                self.root = c;
                self.set_parent(c, k - 1, NONE);
                if k - 1 == LEAF_LOG2 && is_small(c) {
                    // A root block is always a bitmap block (it shifts inside).
                    self.promote(c, NONE, 0, [0; 3]);
                }
            } else {
                let l = &mut self.leaves[self.root as usize].0;
                let masks = leaf_axis_masks(l);
                let low = (1u16 << half) - 1;
                let mut oct = [false; 3];
                for a in 0..3 {
                    let m = u16::from(masks[a]);
                    let (lo, hi) = (m & low != 0, m >> half != 0);
                    if lo && hi {
                        return changed;
                    }
                    oct[a] = hi;
                }
                for a in 0..3 {
                    if oct[a] {
                        shift_leaf(l, a, half, false);
                        self.root_min[a] = self.root_min[a].wrapping_add(half as i64);
                    }
                }
            }
            self.size_log2 = k - 1;
            self.contractions += 1;
            changed = true;
        }
    }

    // ----- voxel create / delete (Libes §4) -------------------------------------------

    /// Creates voxel `v`; returns `true` when it was not there before. The root
    /// expands as often as needed (Libes §3). With face bookkeeping, only the faces
    /// around `v` change, in the order of the face-list rule: for each direction
    /// 0..6, a black neighbour gives up its face towards `v` (`swap_remove`),
    /// otherwise `v` gains the face in that direction (push).
    ///
    /// O(depth) plus, with faces, six O(1) face updates.
    ///
    /// ```
    /// let mut t = tesseral::dynamic::DynamicOctree::new();
    /// assert!(t.insert([1, 2, 3]));
    /// assert!(!t.insert([1, 2, 3]));
    /// assert_eq!(t.voxel_count(), 1);
    /// ```
    pub fn insert(&mut self, v: Voxel) -> bool {
        if !self.insert_bit(v) {
            return false;
        }
        if self.faces.is_some() {
            let nb = self.face_neighbours(v);
            self.faces_after_insert(v, nb);
        }
        true
    }

    /// [`insert`](Self::insert) for a caller that already holds `nb`, the
    /// [`neighbourhood`](Self::neighbourhood) of `v` taken since the last change: the
    /// face update then needs no second search. A wrong `nb` corrupts the face list
    /// (debug builds check it). O(depth) plus six O(1) face updates.
    ///
    /// ```
    /// let mut t = tesseral::dynamic::DynamicOctree::with_faces();
    /// t.insert([0, 0, 0]);
    /// let nb = t.neighbourhood([1, 0, 0]);
    /// assert!(t.insert_with_neighbourhood([1, 0, 0], nb));
    /// assert_eq!(t.face_count(), 10);
    /// ```
    pub fn insert_with_neighbourhood(&mut self, v: Voxel, nb: u32) -> bool {
        debug_assert_eq!(nb, self.neighbourhood(v), "stale neighbourhood");
        if !self.insert_bit(v) {
            return false;
        }
        if self.faces.is_some() {
            self.faces_after_insert(v, six(nb));
        }
        true
    }

    /// Sets the bit of `v` and counts it; no face update. True when `v` is new.
    #[inline(always)]
    fn insert_bit(&mut self, v: Voxel) -> bool {
        if self.root == EMPTY {
            self.root_min = v;
            self.size_log2 = 0;
            self.root = self.alloc_leaf(NONE, 0);
            self.leaves[self.root as usize].0[0] = 1;
        } else {
            let mut u = self.offsets(v);
            if !within(u, self.size_log2) {
                while !within(u, self.size_log2) {
                    self.expand(v);
                    u = self.offsets(v);
                }
                self.rebuild_dir();
            }
            if !self.set_bit(u) {
                return false;
            }
        }
        self.voxels += 1;
        self.version += 1;
        true
    }

    /// Sets the bit at offsets `u` (inside the root); false when it was already set.
    fn set_bit(&mut self, u: [u64; 3]) -> bool {
        // Fast path: the block exists and does not become full.
        let slot = self.block_slot(u);
        if is_small(slot) {
            return match self.small[(slot & !SMALL) as usize].insert(local_index(u)) {
                Some(new) => new,
                None => self.set_bit_slow(u), // it becomes a bitmap block
            };
        }
        let (w, b) = leaf_bit(u);
        let word = self.leaves[slot as usize].0[w];
        if word & b != 0 {
            return false; // also a full octant (the full sentinel block)
        }
        if is_index(slot) && word | b != !0 {
            self.leaves[slot as usize].0[w] = word | b;
            return true;
        }
        self.set_bit_slow(u)
    }

    /// [`set_bit`](Self::set_bit) that creates the nodes and block on the way down and
    /// collapses a block that becomes full.
    fn set_bit_slow(&mut self, u: [u64; 3]) -> bool {
        let mut level = self.phys_log2();
        let mut parent = NONE;
        let mut ci = 0usize;
        let mut cur = self.root;
        while level > LEAF_LOG2 {
            if cur == FULL {
                return false;
            }
            if cur == EMPTY {
                cur = self.alloc_node(parent, EMPTY);
                self.set_slot(parent, ci, cur, level, u);
            }
            ci = child_index(u, level);
            parent = cur;
            cur = self.nodes[cur as usize].child[ci];
            level -= 1;
        }
        if cur == FULL {
            return false;
        }
        if cur == EMPTY && parent != NONE && self.small_blocks {
            // A new block starts small.
            let s = self.alloc_small(parent, Small::one(local_index(u)));
            self.set_slot(parent, ci, s, LEAF_LOG2, u);
            self.check_dir_size();
            return true;
        }
        if cur == EMPTY {
            cur = self.alloc_leaf(parent, 0);
            self.set_slot(parent, ci, cur, LEAF_LOG2, u);
        }
        if is_small(cur) {
            if let Some(new) = self.small[(cur & !SMALL) as usize].insert(local_index(u)) {
                return new;
            }
            cur = self.promote(cur, parent, ci, u);
        }
        let (w, b) = leaf_bit(u);
        let l = &mut self.leaves[cur as usize].0;
        if l[w] & b != 0 {
            return false;
        }
        l[w] |= b;
        if l[w] == !0 && l.iter().all(|&x| x == !0) {
            self.collapse_full(cur, parent, u);
        }
        self.check_dir_size();
        true
    }

    /// A block became full: it turns into a full slot, and so does every ancestor
    /// whose eight children are all full.
    fn collapse_full(&mut self, leaf: u32, parent: u32, u: [u64; 3]) {
        self.free_leaf(leaf);
        self.set_slot(parent, child_index(u, LEAF_LOG2 + 1), FULL, LEAF_LOG2, u);
        self.collapse_up(parent, LEAF_LOG2 + 1, u);
    }

    /// From `node` at `level` (on the path to offsets `u`) upwards: a node whose eight
    /// children are all full becomes a full slot in its parent.
    fn collapse_up(&mut self, mut node: u32, mut level: u32, u: [u64; 3]) {
        while node != NONE && self.nodes[node as usize].child.iter().all(|&c| c == FULL) {
            let p = self.nodes.parent[node as usize];
            self.free_node(node);
            level += 1;
            let ci = if p != NONE { child_index(u, level) } else { 0 };
            self.set_slot(p, ci, FULL, level - 1, u);
            node = p;
        }
    }

    /// Releases a stored subtree (slot `slot` at `level`).
    fn free_subtree(&mut self, slot: u32, level: u32) {
        if !is_index(slot) {
            return;
        }
        if level > LEAF_LOG2 {
            let ch = self.nodes[slot as usize].child;
            for c in ch {
                self.free_subtree(c, level - 1);
            }
            self.free_node(slot);
        } else if is_small(slot) {
            self.free_small(slot);
        } else {
            self.free_leaf(slot);
        }
    }

    /// Makes the aligned cube of side `2^s` at offsets `u` full (no voxel count or
    /// face update: the caller keeps those).
    fn fill_aligned(&mut self, u: [u64; 3], s: u32) {
        let target = s.max(LEAF_LOG2);
        let mut level = self.phys_log2();
        let mut parent = NONE;
        let mut ci = 0usize;
        let mut cur = self.root;
        while level > target {
            if cur == FULL {
                return;
            }
            if cur == EMPTY {
                cur = self.alloc_node(parent, EMPTY);
                self.set_slot(parent, ci, cur, level, u);
            }
            ci = child_index(u, level);
            parent = cur;
            cur = self.nodes[cur as usize].child[ci];
            level -= 1;
        }
        if cur == FULL {
            return;
        }
        if s >= LEAF_LOG2 {
            self.free_subtree(cur, level);
            self.set_slot(parent, ci, FULL, level, u);
            self.collapse_up(parent, level + 1, u);
            return;
        }
        if cur == EMPTY {
            cur = self.alloc_leaf(parent, 0);
            self.set_slot(parent, ci, cur, LEAF_LOG2, u);
        }
        if is_small(cur) {
            cur = self.promote(cur, parent, ci, u);
        }
        let side = 1u64 << s;
        let (x0, y0, z0) = (u[0] & 7, u[1] & 7, u[2] & 7);
        let row = ((1u64 << side) - 1) << x0;
        let plane = (y0..y0 + side).fold(0u64, |p, y| p | row << (8 * y));
        let l = &mut self.leaves[cur as usize].0;
        for z in z0..z0 + side {
            l[z as usize] |= plane;
        }
        if l.iter().all(|&w| w == !0) {
            self.collapse_full(cur, parent, u);
        }
    }

    /// Deletes voxel `v`; returns `true` when it was there. A full octant around `v`
    /// is instantiated on the way down; blocks and nodes left empty are released all
    /// the way up, and the root contracts while its content fits one child (Libes §3,
    /// §4). With face bookkeeping: for each direction 0..6, a black neighbour gains
    /// its face towards `v` (push), otherwise `v`'s face there is removed
    /// (`swap_remove`).
    ///
    /// O(depth) plus, with faces, six O(1) face updates.
    ///
    /// ```
    /// let mut t = tesseral::dynamic::DynamicOctree::new();
    /// t.insert([1, 2, 3]);
    /// assert!(t.remove([1, 2, 3]));
    /// assert!(!t.remove([1, 2, 3]));
    /// assert_eq!(t.voxel_count(), 0);
    /// ```
    pub fn remove(&mut self, v: Voxel) -> bool {
        if !self.remove_bit(v) {
            return false;
        }
        if self.faces.is_some() {
            let nb = self.face_neighbours(v);
            self.faces_after_remove(v, nb);
        }
        true
    }

    /// [`remove`](Self::remove) for a caller that already holds `nb`, the
    /// [`neighbourhood`](Self::neighbourhood) of `v` taken since the last change: the
    /// face update then needs no second search. A wrong `nb` corrupts the face list
    /// (debug builds check it). O(depth) plus six O(1) face updates.
    ///
    /// ```
    /// let mut t = tesseral::dynamic::DynamicOctree::with_faces();
    /// t.insert([0, 0, 0]);
    /// t.insert([1, 0, 0]);
    /// let nb = t.neighbourhood([1, 0, 0]);
    /// assert!(t.remove_with_neighbourhood([1, 0, 0], nb));
    /// assert_eq!(t.face_count(), 6);
    /// ```
    pub fn remove_with_neighbourhood(&mut self, v: Voxel, nb: u32) -> bool {
        debug_assert_eq!(nb, self.neighbourhood(v), "stale neighbourhood");
        if !self.remove_bit(v) {
            return false;
        }
        if self.faces.is_some() {
            self.faces_after_remove(v, six(nb));
        }
        true
    }

    /// Clears the bit of `v`, counts it and contracts the root; no face update. True
    /// when `v` was black.
    #[inline(always)]
    fn remove_bit(&mut self, v: Voxel) -> bool {
        if self.root == EMPTY {
            return false;
        }
        let u = self.offsets(v);
        if !within(u, self.size_log2) || !self.clear_bit(u) {
            return false;
        }
        self.voxels -= 1;
        self.version += 1;
        if self.voxels == 0 {
            debug_assert_eq!(self.root, EMPTY);
            self.root = EMPTY;
            self.size_log2 = 0;
            self.root_min = [0; 3];
            self.rebuild_dir();
        } else if self.contract() {
            self.rebuild_dir();
        }
        true
    }

    /// Clears the bit at offsets `u` (inside the root); false when it was clear.
    fn clear_bit(&mut self, u: [u64; 3]) -> bool {
        // Fast path: the block exists and does not become empty.
        let slot = self.block_slot(u);
        if is_small(slot) {
            let small = &mut self.small[(slot & !SMALL) as usize];
            if small.count() > 1 || !small.has(local_index(u)) {
                return small.remove(local_index(u));
            }
            return self.clear_bit_slow(u); // the block goes
        }
        let (w, b) = leaf_bit(u);
        let word = self.leaves[slot as usize].0[w];
        if word & b == 0 {
            return false; // also an empty octant (the empty sentinel block)
        }
        if is_index(slot) && word & !b != 0 {
            self.leaves[slot as usize].0[w] = word & !b;
            self.maybe_demote(slot, u);
            return true;
        }
        self.clear_bit_slow(u)
    }

    /// A bitmap block (not the root block) left with at most half a small block's
    /// voxels becomes a small block again, in a tree whose new blocks start small.
    /// (The gap between four and nine voxels keeps a block from switching back and
    /// forth.)
    fn maybe_demote(&mut self, slot: u32, u: [u64; 3]) {
        if !self.small_blocks {
            return;
        }
        let words = self.leaves[slot as usize].0;
        let count: u32 = words.iter().map(|w| w.count_ones()).sum();
        let parent = self.leaves.parent[slot as usize];
        if count as usize > SMALL_CAP / 2 || parent == NONE {
            return;
        }
        self.free_leaf(slot);
        let small = self.alloc_small(parent, Small::from_words(&words));
        self.set_slot(parent, child_index(u, LEAF_LOG2 + 1), small, LEAF_LOG2, u);
    }

    /// [`clear_bit`](Self::clear_bit) that instantiates a full octant on the way down
    /// and releases a block that becomes empty, and its emptied ancestors.
    fn clear_bit_slow(&mut self, u: [u64; 3]) -> bool {
        let mut level = self.phys_log2();
        let mut parent = NONE;
        let mut ci = 0usize;
        let mut cur = self.root;
        while level > LEAF_LOG2 {
            if cur == EMPTY {
                return false;
            }
            if cur == FULL {
                cur = self.alloc_node(parent, FULL);
                self.set_slot(parent, ci, cur, level, u);
            }
            ci = child_index(u, level);
            parent = cur;
            cur = self.nodes[cur as usize].child[ci];
            level -= 1;
        }
        if cur == EMPTY {
            return false;
        }
        if cur == FULL {
            cur = self.alloc_leaf(parent, !0);
            self.set_slot(parent, ci, cur, LEAF_LOG2, u);
        }
        let emptied = if is_small(cur) {
            let small = &mut self.small[(cur & !SMALL) as usize];
            if !small.remove(local_index(u)) {
                return false;
            }
            let emptied = small.count() == 0;
            if emptied {
                self.free_small(cur);
            }
            emptied
        } else {
            let (w, b) = leaf_bit(u);
            let l = &mut self.leaves[cur as usize].0;
            if l[w] & b == 0 {
                return false;
            }
            l[w] &= !b;
            let emptied = l[w] == 0 && l.iter().all(|&x| x == 0);
            if emptied {
                self.free_leaf(cur);
            } else {
                self.maybe_demote(cur, u);
            }
            emptied
        };
        if emptied {
            let mut level = LEAF_LOG2 + 1;
            self.set_slot(parent, child_index(u, level), EMPTY, LEAF_LOG2, u);
            let mut node = parent;
            while node != NONE && self.nodes[node as usize].child.iter().all(|&c| c == EMPTY) {
                let p = self.nodes.parent[node as usize];
                self.free_node(node);
                level += 1;
                let ci = if p != NONE { child_index(u, level) } else { 0 };
                self.set_slot(p, ci, EMPTY, level - 1, u);
                node = p;
            }
        }
        self.check_dir_size();
        true
    }

    // ----- search (Libes §5) ----------------------------------------------------------

    /// Whether voxel `v` is black. O(depth), no allocation.
    ///
    /// ```
    /// let mut t = tesseral::dynamic::DynamicOctree::new();
    /// t.insert([-7, 0, 1 << 40]);
    /// assert!(t.contains([-7, 0, 1 << 40]));
    /// assert!(!t.contains([-7, 0, 0]));
    /// ```
    #[inline]
    #[must_use]
    pub fn contains(&self, v: Voxel) -> bool {
        let u = self.offsets(v);
        if !within(u, self.phys_log2()) {
            return false;
        }
        self.block_has(self.block_slot(u), u)
    }

    /// The slot at block level on the path to offsets `u` (inside the root): a stored
    /// block, or the sentinel [`EMPTY`] or [`FULL`] when an empty or full octant holds
    /// `u` (an empty tree's root is [`EMPTY`]). The sentinels make this a straight
    /// chain of loads with no test per level; the child indices of up to eight levels
    /// come from one interleaved word. O(depth).
    #[inline(always)]
    fn block_slot(&self, u: [u64; 3]) -> u32 {
        let (mut cur, mut level) = if self.dir_levels > 0 {
            (self.dir[self.dir_index(u)], self.dir_level)
        } else {
            (self.root, self.phys_log2())
        };
        while level > LEAF_LOG2 {
            let n = (level - LEAF_LOG2).min(8);
            level -= n;
            let spread = |x: u64| u64::from(SPREAD[(x >> level & 255) as usize]);
            let path = spread(u[0]) | spread(u[1]) << 1 | spread(u[2]) << 2;
            let mut shift = 3 * n;
            while shift > 0 {
                shift -= 3;
                cur = self.nodes[cur as usize].child[(path >> shift) as usize & 7];
            }
        }
        cur
    }

    /// Descends from slot `cur` at `level` towards offsets `t`, stopping at the first
    /// empty or full slot, or at the block. Returns (slot, level, parent node).
    #[inline]
    fn descend(
        &self,
        mut cur: u32,
        mut level: u32,
        mut parent: u32,
        t: [u64; 3],
    ) -> (u32, u32, u32) {
        while level > LEAF_LOG2 && is_index(cur) {
            parent = cur;
            cur = self.nodes[cur as usize].child[child_index(t, level)];
            level -= 1;
        }
        (cur, level, parent)
    }

    /// From stored node `node` at `level`, which contains offsets `probe`, climbs
    /// while `t` lies outside (Libes §5: "we would continue searching in the parent
    /// of the current octant"). Returns the lowest ancestor that contains `t` and its
    /// level; `t` must lie inside the root.
    #[inline]
    fn climb(&self, mut node: u32, mut level: u32, probe: [u64; 3], t: [u64; 3]) -> (u32, u32) {
        while level < 64
            && ((t[0] ^ probe[0]) | (t[1] ^ probe[1]) | (t[2] ^ probe[2])) >> level != 0
        {
            node = self.nodes.parent[node as usize];
            level += 1;
            debug_assert!(node != NONE, "climbed past the root");
        }
        (node, level)
    }

    fn octant_of(&self, t: [u64; 3], slot: u32, level: u32, parent: u32) -> Octant {
        let (size_log2, full) = if level > LEAF_LOG2 || !is_index(slot) {
            (level, slot == FULL)
        } else {
            (0, self.block_has(slot, t))
        };
        let mask = if size_log2 >= 64 {
            0
        } else {
            !((1u64 << size_log2) - 1)
        };
        let min = self.world([t[0] & mask, t[1] & mask, t[2] & mask]);
        Octant {
            min,
            size_log2,
            full,
            node: parent,
            node_level: level + 1,
            probe: t,
            version: self.version,
        }
    }

    /// `oct_find` from the root (Libes §5): the smallest uniform octant containing
    /// `v`, or `None` when `v` lies outside the root. O(depth).
    ///
    /// ```
    /// let mut t = tesseral::dynamic::DynamicOctree::new();
    /// for x in 0..8 { for y in 0..8 { for z in 0..8 { t.insert([x, y, z]); } } }
    /// t.insert([8, 0, 0]);
    /// let o = t.find([3, 3, 3]).unwrap();
    /// assert!(o.is_full());
    /// assert_eq!((o.min(), o.size_log2()), ([0, 0, 0], 3)); // an implicit full octant
    /// ```
    #[must_use]
    pub fn find(&self, v: Voxel) -> Option<Octant> {
        let t = self.offsets(v);
        let phys = self.phys_log2();
        if self.root == EMPTY || !within(t, phys) {
            return None;
        }
        let (slot, level, parent) = self.descend(self.root, phys, NONE, t);
        Some(self.octant_of(t, slot, level, parent))
    }

    /// `oct_find` that starts at the node where an earlier search ended: it climbs
    /// through parent links while `v` lies outside, then descends (Libes §5). Near
    /// `start` this costs O(levels climbed) instead of O(depth). A handle from before
    /// the latest change is not trusted: the search then starts at the root.
    ///
    /// ```
    /// let mut t = tesseral::dynamic::DynamicOctree::new();
    /// t.insert([0, 0, 0]);
    /// t.insert([100, 0, 0]);
    /// let a = t.find([0, 0, 0]).unwrap();
    /// let b = t.find_from(&a, [100, 0, 0]).unwrap();
    /// assert!(b.is_full());
    /// assert_eq!(t.find_from(&b, [99, 0, 0]), t.find([99, 0, 0]));
    /// ```
    #[must_use]
    pub fn find_from(&self, start: &Octant, v: Voxel) -> Option<Octant> {
        if start.version != self.version || start.node == NONE {
            return self.find(v);
        }
        let t = self.offsets(v);
        if !within(t, self.phys_log2()) {
            return None;
        }
        let (node, level) = self.climb(start.node, start.node_level, start.probe, t);
        let (slot, level, parent) = self.descend(node, level, NONE, t);
        let parent = if parent == NONE { node } else { parent };
        Some(self.octant_of(t, slot, level, parent))
    }

    /// The 3×3×3 occupancy around `v` as 27 bits: bit `(dx+1) + 3(dy+1) + 9(dz+1)`
    /// for `dx, dy, dz` in −1..=1 (bit 13 is `v` itself).
    ///
    /// Finds `v`'s block once; when the 3×3×3 block lies inside it (or inside an
    /// implicit empty or full octant), all 27 bits come from there. Otherwise the
    /// neighbouring blocks are found from `v`'s own node by climbing to the nearest
    /// common ancestor and descending (Libes §5), never from the root.
    /// O(depth) worst case, O(1) after the descent in the common case.
    ///
    /// ```
    /// use tesseral::dynamic::{DynamicOctree, CENTRE_BIT, NEIGHBOUR_BIT};
    /// let mut t = DynamicOctree::new();
    /// t.insert([0, 0, 0]);
    /// t.insert([1, 0, 0]);
    /// let n = t.neighbourhood([0, 0, 0]);
    /// assert_eq!(n, 1 << CENTRE_BIT | 1 << NEIGHBOUR_BIT[1]);
    /// ```
    #[must_use]
    pub fn neighbourhood(&self, v: Voxel) -> u32 {
        if self.root == EMPTY {
            return 0;
        }
        let u = self.offsets(v);
        let phys = self.phys_log2();
        if !within(u, phys) {
            return self.neighbourhood_slow(u, NONE, 0, EMPTY);
        }
        // The common case: the 3×3×3 block lies inside `v`'s block (the sentinels
        // stand for uniform octants).
        if (0..3).all(|a| (u[a] & 7).wrapping_sub(1) < 6) {
            let slot = self.block_slot(u);
            return if is_small(slot) {
                extract27(&self.block_words(slot), u)
            } else {
                extract27(&self.leaves[slot as usize].0, u)
            };
        }
        // Find `v`'s own node, starting at the directory when its entry is a node.
        let start = if self.dir_levels > 0 && self.dir_level > LEAF_LOG2 {
            let entry = self.dir[self.dir_index(u)];
            is_index(entry).then_some((entry, self.dir_level))
        } else {
            None
        };
        let (cur, level, parent) = match start {
            Some((node, level)) => self.descend(node, level, NONE, u),
            None => self.descend(self.root, phys, NONE, u),
        };
        let m = if level >= 64 {
            u64::MAX
        } else {
            (1u64 << level) - 1
        };
        let inner = |a: usize| {
            let l = u[a] & m;
            l >= 1 && l < m
        };
        if inner(0) && inner(1) && inner(2) {
            return match cur {
                EMPTY => 0,
                FULL => NEIGHBOURHOOD_ALL,
                _ => extract27(&self.block_words(cur), u),
            };
        }
        // The block of `u` itself is the one just found (a uniform octant stands for
        // every block inside it, and its sentinel block for it): the slow path
        // reuses it.
        self.neighbourhood_slow(u, parent, level + 1, cur)
    }

    /// The block-level slot (sentinels standing for uniform octants) of the block
    /// whose minimum corner has offsets `t`, found from node `start` at `start_level`
    /// (which contains offsets `u`), or from the root when `start` is NONE.
    fn block_slot_from(&self, t: [u64; 3], u: [u64; 3], start: u32, start_level: u32) -> u32 {
        let phys = self.phys_log2();
        if !within(t, phys) {
            return EMPTY;
        }
        let (cur, level) = if start == NONE {
            (self.root, phys)
        } else {
            self.climb(start, start_level, u, t)
        };
        let (slot, _, _) = self.descend(cur, level, NONE, t);
        slot
    }

    #[inline(never)]
    fn neighbourhood_slow(&self, u: [u64; 3], start: u32, start_level: u32, own: u32) -> u32 {
        let home = [u[0] >> 3, u[1] >> 3, u[2] >> 3];
        let lo = [
            u[0].wrapping_sub(1) >> 3,
            u[1].wrapping_sub(1) >> 3,
            u[2].wrapping_sub(1) >> 3,
        ];
        let hi = [
            u[0].wrapping_add(1) >> 3,
            u[1].wrapping_add(1) >> 3,
            u[2].wrapping_add(1) >> 3,
        ];
        // Bit `a` of a block number selects the upper block along axis `a`; only the
        // blocks the 3×3×3 cube touches are looked up.
        let spans = usize::from(lo[0] != hi[0])
            | usize::from(lo[1] != hi[1]) << 1
            | usize::from(lo[2] != hi[2]) << 2;
        // Blocks in the same 16³ cell as `v`'s are siblings: children of `v`'s node.
        let siblings = start != NONE && start_level == LEAF_LOG2 + 1;
        let mut blocks = [EMPTY; 8];
        for i in 0..8usize {
            if i & !spans != 0 {
                continue;
            }
            let b = [
                if i & 1 == 0 { lo[0] } else { hi[0] },
                if i & 2 == 0 { lo[1] } else { hi[1] },
                if i & 4 == 0 { lo[2] } else { hi[2] },
            ];
            blocks[i] = if b == home {
                own
            } else if siblings && (b[0] ^ home[0]) | (b[1] ^ home[1]) | (b[2] ^ home[2]) < 2 {
                let ci = (b[0] & 1) | (b[1] & 1) << 1 | (b[2] & 1) << 2;
                self.nodes[start as usize].child[ci as usize]
            } else {
                self.block_slot_from([b[0] << 3, b[1] << 3, b[2] << 3], u, start, start_level)
            };
        }
        if blocks.iter().any(|&slot| is_small(slot)) {
            let words: [[u64; 8]; 8] = std::array::from_fn(|i| self.block_words(blocks[i]));
            rows27(u, lo, hi, |b, z| words[b][z])
        } else {
            rows27(u, lo, hi, |b, z| self.leaves[blocks[b] as usize].0[z])
        }
    }

    /// The six face-neighbours of `v` as a mask: bit `dir` is set when the neighbour
    /// in direction `dir` (0 = −x, 1 = +x, 2 = −y, 3 = +y, 4 = −z, 5 = +z) is black.
    /// O(depth), from `v`'s own node.
    ///
    /// ```
    /// let mut t = tesseral::dynamic::DynamicOctree::new();
    /// t.insert([0, 0, 0]);
    /// assert_eq!(t.face_neighbours([0, 0, 1]), 1 << 4);
    /// ```
    #[must_use]
    pub fn face_neighbours(&self, v: Voxel) -> u8 {
        six(self.neighbourhood(v))
    }

    // ----- faces (Libes §4, §5) -------------------------------------------------------

    /// Face passing after `v` was created; `nb` is its face-neighbour mask.
    fn faces_after_insert(&mut self, v: Voxel, nb: u8) {
        let f = self.faces.as_mut().expect("face bookkeeping");
        let mut own = None;
        for dir in 0..6u8 {
            if nb >> dir & 1 == 1 {
                let n = step(v, dir);
                let r = f.existing_record(n);
                f.remove(r, n, opposite(dir));
            } else {
                let r = *own.get_or_insert_with(|| f.record_of(v));
                f.push(r, dir);
            }
        }
    }

    /// Face passing after `v` was deleted; `nb` is its face-neighbour mask.
    fn faces_after_remove(&mut self, v: Voxel, nb: u8) {
        let f = self.faces.as_mut().expect("face bookkeeping");
        // A black voxel with a white neighbour has a record; one with six black
        // neighbours has no face to remove.
        let own = if nb & 0b11_1111 != 0b11_1111 {
            f.existing_record(v)
        } else {
            0
        };
        for dir in 0..6u8 {
            if nb >> dir & 1 == 1 {
                let n = step(v, dir);
                let r = f.record_of(n);
                f.push(r, opposite(dir));
            } else {
                f.remove(own, v, dir);
            }
        }
    }

    /// The number of exposed faces (the surface area in unit squares); exact.
    /// 0 without face bookkeeping. O(1).
    #[must_use]
    pub fn face_count(&self) -> usize {
        self.faces.as_ref().map_or(0, |f| f.list.len())
    }

    /// The number of exposed faces (the surface area), whether or not the face list
    /// is kept: `face_count()` with face bookkeeping, otherwise
    /// `6·voxels − 2·(face-adjacent pairs)` counted now in O(voxels · depth).
    ///
    /// ```
    /// let t = tesseral::dynamic::DynamicOctree::from_voxels([[0, 0, 0], [0, 1, 0]]);
    /// assert_eq!(t.exposed_faces(), 10);
    /// ```
    #[must_use]
    pub fn exposed_faces(&self) -> u64 {
        if let Some(f) = &self.faces {
            return f.list.len() as u64;
        }
        let mut pairs = 0u64;
        for v in self.voxels() {
            pairs += u64::from((self.face_neighbours(v) & 0b10_1010).count_ones());
        }
        6 * self.voxels - 2 * pairs
    }

    /// The `i`-th face of the face list. O(1).
    ///
    /// # Panics
    /// When `i >= face_count()`.
    #[must_use]
    pub fn face(&self, i: usize) -> Face {
        let n = self.face_count();
        assert!(i < n, "face index {i} out of range (face_count {n})");
        self.faces.as_ref().expect("face bookkeeping").face(i)
    }

    /// The whole face list, in face-list order (empty without face bookkeeping).
    /// O(faces).
    #[must_use]
    pub fn faces(&self) -> Vec<Face> {
        self.faces
            .as_ref()
            .map_or_else(Vec::new, |f| (0..f.list.len()).map(|i| f.face(i)).collect())
    }

    /// A uniformly random exposed face, or `None` when there is none. O(1).
    ///
    /// ```
    /// use rand::SeedableRng;
    /// let mut t = tesseral::dynamic::DynamicOctree::with_faces();
    /// t.insert([0, 0, 0]);
    /// let mut rng = rand_pcg::Pcg64::seed_from_u64(1);
    /// assert_eq!(t.random_face(&mut rng).unwrap().voxel, [0, 0, 0]);
    /// ```
    pub fn random_face<R: rand::Rng + ?Sized>(&self, rng: &mut R) -> Option<Face> {
        let n = self.face_count();
        (n > 0).then(|| self.face(rng.random_range(0..n)))
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

    // ----- conversions ------------------------------------------------------------------

    /// Calls `f(min_offsets, size_log2, full_block)` for every uniform full octant
    /// (`full_block = None`) and every stored block (`Some(bits)`), in tesseral order.
    fn visit<F: FnMut([u64; 3], u32, Option<&[u64; 8]>)>(&self, mut f: F) {
        if self.root == EMPTY {
            return;
        }
        let mut stack = vec![(self.root, self.phys_log2(), [0u64; 3])];
        while let Some((slot, level, base)) = stack.pop() {
            match slot {
                EMPTY => {}
                FULL => f(base, level, None),
                _ if level > LEAF_LOG2 => {
                    let ch = &self.nodes[slot as usize].child;
                    let h = level - 1;
                    for ci in (0..8).rev() {
                        if ch[ci] != EMPTY {
                            let b = [
                                base[0] | ((ci as u64 & 1) << h),
                                base[1] | ((ci as u64 >> 1 & 1) << h),
                                base[2] | ((ci as u64 >> 2 & 1) << h),
                            ];
                            stack.push((ch[ci], h, b));
                        }
                    }
                }
                _ => f(base, LEAF_LOG2, Some(&self.block_words(slot))),
            }
        }
    }

    /// Every black voxel, in tesseral (Morton) order relative to the root corner.
    /// O(voxels + nodes): full octants are enumerated voxel by voxel, so for large
    /// solids prefer [`DynamicOctree::to_linear`], whose cost follows the surface.
    ///
    /// ```
    /// let t = tesseral::dynamic::DynamicOctree::from_voxels([[1, 0, 0], [0, 0, 0]]);
    /// assert_eq!(t.voxels(), vec![[0, 0, 0], [1, 0, 0]]);
    /// ```
    #[must_use]
    pub fn voxels(&self) -> Vec<Voxel> {
        let mut out = Vec::with_capacity(usize::try_from(self.voxels.min(1 << 24)).unwrap_or(0));
        self.visit(|base, level, bits| match bits {
            None => {
                let side = 1u64 << level;
                for ci in 0..side * side * side {
                    let [x, y, z] = crate::code::decode(ci);
                    out.push(self.world([
                        base[0] + u64::from(x),
                        base[1] + u64::from(y),
                        base[2] + u64::from(z),
                    ]));
                }
            }
            Some(l) => {
                for ci in 0..512u64 {
                    let [x, y, z] = crate::code::decode(ci);
                    if l[z as usize] >> (x + 8 * y) & 1 == 1 {
                        out.push(self.world([
                            base[0] + u64::from(x),
                            base[1] + u64::from(y),
                            base[2] + u64::from(z),
                        ]));
                    }
                }
            }
        });
        out
    }

    /// Builds a tree (without face bookkeeping) from a linear octree: each black leaf
    /// becomes a full slot (or bits of a block), so a solid costs its surface, not its
    /// volume. O(leaves · depth).
    ///
    /// ```
    /// use tesseral::{dynamic::DynamicOctree, linear::LinearOctree};
    /// let cube = (0..4).flat_map(|x| (0..4).flat_map(move |y| (0..4).map(move |z| [x, y, z])));
    /// let lin = LinearOctree::from_voxels(5, [-8, -8, -8], cube).unwrap();
    /// let t = DynamicOctree::from_linear(&lin);
    /// assert_eq!(t.voxel_count(), 64);
    /// assert_eq!((t.root_min(), t.root_size_log2()), ([0, 0, 0], 2));
    /// t.assert_valid();
    /// ```
    #[must_use]
    pub fn from_linear(lin: &LinearOctree) -> Self {
        let mut t = Self::new();
        let count = lin.voxel_count();
        if count == 0 {
            return t;
        }
        t.root_min = lin.origin();
        t.size_log2 = u32::from(lin.depth());
        for leaf in lin.leaves() {
            let [x, y, z] = crate::code::decode(leaf.code());
            t.fill_aligned(
                [u64::from(x), u64::from(y), u64::from(z)],
                u32::from(leaf.size_log2()),
            );
        }
        t.voxels = count;
        t.contract();
        t.rebuild_dir();
        t
    }

    /// The voxels of this tree inside the window `[origin, origin + 2^depth)³` as a
    /// linear octree. Built top-down with [`LinearOctree::from_classifier`], each cell
    /// classified by [`DynamicOctree::classify`], so the cost follows the surface.
    ///
    /// # Errors
    /// [`OctreeError::DepthTooLarge`] when `depth` exceeds [`crate::linear::MAX_DEPTH`].
    ///
    /// ```
    /// use tesseral::dynamic::DynamicOctree;
    /// let t = DynamicOctree::from_voxels([[0, 0, 0], [1, 0, 0], [100, 0, 0]]);
    /// let lin = t.to_linear(2, [-1, -1, -1]).unwrap(); // a 4³ window: [100, 0, 0] is cut
    /// assert_eq!(lin.voxel_count(), 2);
    /// ```
    pub fn to_linear(&self, depth: u8, origin: Voxel) -> Result<LinearOctree, OctreeError> {
        LinearOctree::from_classifier(depth, origin, self)
    }

    /// Whether the cube `[min, min + 2^size_log2)³` (any alignment) is all black
    /// (`Inside`), all white (`Outside`) or mixed (`Partial`). A stored node always
    /// holds both colours, so the search stops at every node that lies wholly inside
    /// the cube: the cost follows the cube's boundary. A single voxel is never
    /// `Partial`.
    ///
    /// ```
    /// use tesseral::{dynamic::DynamicOctree, linear::CellClass};
    /// let t = DynamicOctree::from_voxels([[0, 0, 0], [1, 0, 0]]);
    /// assert_eq!(t.classify([0, 0, 0], 0), CellClass::Inside);
    /// assert_eq!(t.classify([0, 0, 0], 1), CellClass::Partial);
    /// assert_eq!(t.classify([2, 0, 0], 1), CellClass::Outside);
    /// ```
    #[must_use]
    pub fn classify(&self, min: Voxel, size_log2: u8) -> CellClass {
        if self.root == EMPTY {
            return CellClass::Outside;
        }
        let side = 1i128 << size_log2.min(64);
        let k = self.size_log2;
        let modulus = 1i128 << 64;
        // Per axis: the cube's intervals in root offsets, clipped to the root
        // (a k = 64 root wraps, so an interval may split in two).
        let mut spans: [[(u128, u128); 2]; 3] = [[(0, 0); 2]; 3];
        let mut nspans = [0usize; 3];
        let mut outside = false;
        for a in 0..3 {
            let lo = i128::from(min[a]) - i128::from(self.root_min[a]);
            let hi = lo + side;
            if k >= 64 {
                let lo = lo.rem_euclid(modulus);
                let hi = lo + side.min(modulus);
                if hi <= modulus {
                    spans[a][0] = (lo as u128, hi as u128);
                    nspans[a] = 1;
                } else {
                    spans[a][0] = (lo as u128, modulus as u128);
                    spans[a][1] = (0, (hi - modulus) as u128);
                    nspans[a] = 2;
                }
            } else {
                let root = 1i128 << k;
                let (clo, chi) = (lo.max(0), hi.min(root));
                if lo < 0 || hi > root {
                    outside = true;
                }
                if clo < chi {
                    spans[a][0] = (clo as u128, chi as u128);
                    nspans[a] = 1;
                }
            }
        }
        let (mut black, mut white) = (false, outside);
        'boxes: for i in 0..nspans[0] {
            for j in 0..nspans[1] {
                for l in 0..nspans[2] {
                    let b = [spans[0][i], spans[1][j], spans[2][l]];
                    let (bl, wh) = self.probe(self.root, self.phys_log2(), [0; 3], b);
                    black |= bl;
                    white |= wh;
                    if black && white {
                        break 'boxes;
                    }
                }
            }
        }
        match (black, white) {
            (true, false) => CellClass::Inside,
            (false, _) => CellClass::Outside,
            (true, true) => CellClass::Partial,
        }
    }

    /// (any black, any white) in the intersection of cell (`slot`, `level`, `base`)
    /// with the box `b` (half-open offset intervals per axis).
    fn probe(&self, slot: u32, level: u32, base: [u128; 3], b: [(u128, u128); 3]) -> (bool, bool) {
        let size = 1u128 << level;
        let mut inside = true;
        for a in 0..3 {
            let (lo, hi) = (b[a].0.max(base[a]), b[a].1.min(base[a] + size));
            if lo >= hi {
                return (false, false);
            }
            inside &= lo == base[a] && hi == base[a] + size;
        }
        match slot {
            EMPTY => (false, true),
            FULL => (true, false),
            // A stored node or block holds both colours (checked by assert_valid).
            _ if inside => (true, true),
            _ if level > LEAF_LOG2 => {
                let ch = &self.nodes[slot as usize].child;
                let h = size >> 1;
                let (mut black, mut white) = (false, false);
                for (ci, &c) in ch.iter().enumerate() {
                    let cb = [
                        base[0] + (ci as u128 & 1) * h,
                        base[1] + (ci as u128 >> 1 & 1) * h,
                        base[2] + (ci as u128 >> 2 & 1) * h,
                    ];
                    let (bl, wh) = self.probe(c, level - 1, cb, b);
                    black |= bl;
                    white |= wh;
                    if black && white {
                        break;
                    }
                }
                (black, white)
            }
            _ => {
                let l = self.block_words(slot);
                let r: [(u128, u128); 3] = std::array::from_fn(|a| {
                    (
                        b[a].0.max(base[a]) - base[a],
                        b[a].1.min(base[a] + 8) - base[a],
                    )
                });
                let row = ((1u64 << (r[0].1 - r[0].0)) - 1) << r[0].0;
                let plane = (r[1].0..r[1].1).fold(0u64, |p, y| p | row << (8 * y));
                let (mut black, mut white) = (false, false);
                for z in r[2].0..r[2].1 {
                    let w = l[z as usize] & plane;
                    black |= w != 0;
                    white |= w != plane;
                }
                (black, white)
            }
        }
    }

    // ----- invariants -------------------------------------------------------------------

    /// Checks every invariant and panics with a message naming the first broken one:
    /// counts (voxels, live nodes), parent links, free lists, that no stored node or
    /// block is all-empty or all-full, that the root cannot contract, and with faces
    /// that every listed face is exposed, its back-pointer is right, and the count is
    /// `6·voxels − 2·(face-adjacent pairs)`. O(voxels · depth).
    pub fn assert_valid(&self) {
        assert_eq!(
            self.nodes[EMPTY as usize].child, [EMPTY; 8],
            "empty sentinel node"
        );
        assert_eq!(
            self.nodes[FULL as usize].child, [FULL; 8],
            "full sentinel node"
        );
        assert_eq!(
            self.leaves[EMPTY as usize].0, ZERO_BLOCK,
            "empty sentinel block"
        );
        assert_eq!(
            self.leaves[FULL as usize].0, FULL_BLOCK,
            "full sentinel block"
        );
        let nfree = self.nodes.check("node");
        let lfree = self.leaves.check("block");
        let sfree = self.small.check("small block");
        if self.root == EMPTY {
            assert_eq!(self.voxels, 0, "empty root with voxels");
            assert_eq!(self.size_log2, 0, "empty tree has root size 1");
            assert_eq!(self.node_count(), 0, "empty tree holds nodes");
            assert_eq!(self.face_count(), 0, "empty tree has faces");
            return;
        }
        assert!(self.size_log2 <= 64, "root size 2^{}", self.size_log2);
        let phys = self.phys_log2();
        if self.size_log2 < LEAF_LOG2 {
            assert!(is_index(self.root), "small root must be a block");
            let m = leaf_axis_masks(&self.leaves[self.root as usize].0);
            for (a, &mask) in m.iter().enumerate() {
                assert_eq!(
                    u32::from(mask) >> (1u32 << self.size_log2),
                    0,
                    "bits outside the logical root on axis {a}"
                );
            }
        }
        let mut count: u128 = 0;
        let mut seen_nodes = 0usize;
        let mut seen_leaves = 0usize;
        let mut seen_small = 0usize;
        let mut stack = vec![(self.root, phys, NONE)];
        while let Some((slot, level, parent)) = stack.pop() {
            match slot {
                EMPTY => {}
                FULL => count = count.saturating_add(1u128 << (3 * level.min(42))),
                _ if level > LEAF_LOG2 => {
                    let n = &self.nodes[slot as usize];
                    assert!(!nfree.contains(&slot), "node {slot} is live and free");
                    assert_eq!(
                        self.nodes.parent[slot as usize], parent,
                        "parent link of node {slot}"
                    );
                    assert!(n.child.iter().any(|&c| c != EMPTY), "node {slot} is empty");
                    assert!(n.child.iter().any(|&c| c != FULL), "node {slot} is full");
                    seen_nodes += 1;
                    for &c in &n.child {
                        stack.push((c, level - 1, slot));
                    }
                }
                _ if is_small(slot) => {
                    let i = slot & !SMALL;
                    let lanes = &self.small[i as usize].0;
                    assert!(!sfree.contains(&i), "small block {i} is live and free");
                    assert_eq!(
                        self.small.parent[i as usize], parent,
                        "parent link of small block {i}"
                    );
                    assert_eq!(level, LEAF_LOG2, "small block {i} above the block level");
                    let keys: Vec<u16> = lanes.iter().copied().filter(|&e| e != VACANT).collect();
                    assert!(
                        lanes[keys.len()..].iter().all(|&e| e == VACANT),
                        "small block {i} has a vacant lane before an occupied one"
                    );
                    assert!(!keys.is_empty(), "small block {i} is empty");
                    assert!(
                        keys.iter().all(|&e| e < 512),
                        "small block {i} lane out of range"
                    );
                    let distinct: std::collections::HashSet<u16> = keys.iter().copied().collect();
                    assert_eq!(
                        distinct.len(),
                        keys.len(),
                        "small block {i} repeats a voxel"
                    );
                    seen_small += 1;
                    count += keys.len() as u128;
                }
                _ => {
                    let l = &self.leaves[slot as usize].0;
                    assert!(!lfree.contains(&slot), "block {slot} is live and free");
                    assert_eq!(
                        self.leaves.parent[slot as usize], parent,
                        "parent link of block {slot}"
                    );
                    assert!(l.iter().any(|&w| w != 0), "block {slot} is empty");
                    assert!(l.iter().any(|&w| w != !0), "block {slot} is full");
                    seen_leaves += 1;
                    count += u128::from(l.iter().map(|w| w.count_ones()).sum::<u32>());
                }
            }
        }
        assert_eq!(count, u128::from(self.voxels), "voxel count");
        // The directory holds exactly the slots at its level.
        assert!(self.dir_levels <= DIR_MAX_LEVELS, "directory too deep");
        if self.dir_levels == 0 {
            assert!(self.dir.is_empty(), "directory without levels");
        } else {
            assert_eq!(self.dir_level + self.dir_levels, phys, "directory level");
            assert_eq!(self.dir.len(), 1 << (3 * self.dir_levels), "directory size");
            assert!(self.dir_level >= LEAF_LOG2, "directory below the blocks");
            let mut fresh = vec![EMPTY; self.dir.len()];
            self.fill_dir(&mut fresh, self.root, phys, 0);
            for (i, (&a, &b)) in self.dir.iter().zip(&fresh).enumerate() {
                assert_eq!(a, b, "directory entry {i}");
            }
            assert!(
                self.dir.len() <= 64 * self.node_count().max(1),
                "directory larger than the tree"
            );
        }
        assert_eq!(seen_nodes, self.nodes.live(), "live node count");
        assert_eq!(seen_leaves, self.leaves.live(), "live block count");
        assert_eq!(seen_small, self.small.live(), "live small block count");
        // The root cannot contract.
        if self.size_log2 > LEAF_LOG2 && self.root != FULL {
            let ch = &self.nodes[self.root as usize].child;
            assert!(
                ch.iter().filter(|&&c| c != EMPTY).count() >= 2,
                "root could contract"
            );
        } else if self.size_log2 > 0 && self.root != FULL {
            let half = 1u32 << (self.size_log2 - 1);
            let m = leaf_axis_masks(&self.leaves[self.root as usize].0);
            let splits = m.iter().any(|&mask| {
                u32::from(mask) & ((1 << half) - 1) != 0 && u32::from(mask) >> half != 0
            });
            assert!(splits, "root block could contract");
        }
        if let Some(f) = &self.faces {
            f.assert_valid();
            for i in 0..f.list.len() {
                let e = f.face(i);
                assert!(self.contains(e.voxel), "face {i} on a white voxel");
                assert!(!self.contains(e.outside()), "face {i} is covered");
            }
            let all = self.voxels();
            let pairs: u64 = all
                .iter()
                .map(|&v| {
                    (0..3u8)
                        .filter(|&a| self.contains(step(v, 2 * a + 1)))
                        .count() as u64
                })
                .sum();
            assert_eq!(
                f.list.len() as u64,
                6 * self.voxels - 2 * pairs,
                "face count is not 6·voxels − 2·pairs"
            );
        }
    }
}

/// A dynamic octree classifies cells for [`LinearOctree::from_classifier`] (and so for
/// CSG scenes) through [`DynamicOctree::classify`].
impl Classifier for DynamicOctree {
    fn classify(&self, min: Voxel, size_log2: u8) -> CellClass {
        DynamicOctree::classify(self, min, size_log2)
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
