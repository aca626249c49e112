//! Linear (pointerless) octrees: the black leaves of a solid as maximal blocks,
//! sorted in tesseral order (Harakal & Chmúrny §2; Gargantini's linear octree).
//!
//! A [`LinearOctree`] spans a cube of `2^depth` voxels per axis whose lowest corner is
//! the integer `origin`, so negative world coordinates work. Its leaves are kept in
//! canonical form: sorted, disjoint, and with no eight black siblings left unmerged.
//! Two equal solids in the same space therefore have equal leaf lists.

mod affine;
mod bbox;
mod box_state;
mod canonical;
use canonical::completes_parent;
pub(crate) use canonical::{is_canonical_stream, push_merging, MergingStream};
mod bricked;
mod bricks;
mod build;
mod enumerate;
pub(crate) mod grow;
mod leaf;
mod mapped;
mod merge;
mod node_list;
mod octet;
mod ops;
mod resample;
pub(crate) mod sort;
mod transform;

pub use crate::code::Axis;
pub(crate) use affine::sin_cos_degrees;
pub use affine::{affine_space, invert_matrix, rotation_matrix, scale_space, whole_translation};
pub use box_state::BoxState;
pub use build::{CellClass, Classifier};
pub use leaf::{Block, Leaf};
pub use node_list::{Node, NodeColour};
pub(crate) use octet::{first_above, gallop};
pub use ops::SetOp;
pub use transform::rotation_labels;

use std::sync::OnceLock;

use crate::code;
use crate::Voxel;
use bricked::Bricked;

/// The deepest linear octree: its codes fit a `u64` ([`code::MAX_DEPTH_U64`]).
pub const MAX_DEPTH: u8 = code::MAX_DEPTH_U64 as u8;

/// What can go wrong when building a [`LinearOctree`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum OctreeError {
    /// The requested depth exceeds [`MAX_DEPTH`].
    #[error("depth {0} exceeds the maximum of {MAX_DEPTH}")]
    DepthTooLarge(u8),
    /// A voxel lies outside the space `[origin, origin + 2^depth)`.
    #[error("voxel ({}, {}, {}) lies outside the octree's space", .0[0], .0[1], .0[2])]
    OutOfBounds(Voxel),
    /// A coordinate or origin left the range of `i64`.
    #[error("a coordinate overflows the 64-bit integer range")]
    Overflow,
    /// The space `[origin, origin + 2^depth)` runs past the range of `i64`.
    #[error(
        "the space of side 2^{depth} from origin ({}, {}, {}) runs past the range of 64-bit coordinates",
        .origin[0], .origin[1], .origin[2]
    )]
    SpaceOverflow {
        /// The depth.
        depth: u8,
        /// The origin.
        origin: Voxel,
    },
    /// A dense bit array is shorter than its dimensions say.
    #[error("a dense array of {dims:?} voxels needs {needed} words of 64 bits, got {got}")]
    DenseTooShort {
        /// The array's dimensions, x fastest.
        dims: [u32; 3],
        /// The number of `u64` words needed.
        needed: usize,
        /// The number of words given.
        got: usize,
    },
    /// A transform's parameters make no solid (a zero scale factor, a singular map).
    #[error("{0}")]
    InvalidArgument(String),
}

/// A solid as a sorted list of maximal black blocks (a linear octree).
///
/// The tree holds its leaves in one or both of two forms (see ARCHITECTURE.md,
/// "Bricked set operations"): the leaf list that [`LinearOctree::leaves`] returns,
/// and a bricked form (leaves of side 8 or more, and each mixed 8³ cell as a
/// 512-bit mask) on which the set operations run. Each form is made from the other
/// on first use and kept.
///
/// ```
/// use tesseral::linear::LinearOctree;
/// let voxels = (0..2).flat_map(|x| (0..2).flat_map(move |y| (0..2).map(move |z| [x, y, z])));
/// let tree = LinearOctree::from_voxels(3, [0, 0, 0], voxels).unwrap();
/// assert_eq!(tree.leaf_count(), 1); // the eight voxels merge into one block
/// assert_eq!(tree.voxel_count(), 8);
/// assert!(tree.contains([1, 1, 1]) && !tree.contains([2, 0, 0]));
/// ```
#[derive(Debug, Clone)]
pub struct LinearOctree {
    depth: u8,
    origin: Voxel,
    /// The leaf list; set at construction, or made from `bricked` on first use.
    leaves: OnceLock<Vec<Leaf>>,
    /// The bricked form; set by a set operation, or made from `leaves` on first use.
    /// At least one of the two is always set.
    bricked: OnceLock<Bricked>,
}

impl PartialEq for LinearOctree {
    fn eq(&self, other: &Self) -> bool {
        if self.depth != other.depth || self.origin != other.origin {
            return false;
        }
        // Both forms are canonical, so either one compares the solids.
        match (self.bricked.get(), other.bricked.get()) {
            (Some(a), Some(b)) if self.leaves.get().is_none() || other.leaves.get().is_none() => {
                a == b
            }
            _ => self.leaves() == other.leaves(),
        }
    }
}

impl Eq for LinearOctree {}

impl std::hash::Hash for LinearOctree {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.depth.hash(state);
        self.origin.hash(state);
        self.leaves().hash(state);
    }
}

impl LinearOctree {
    /// An empty (all white) tree spanning `2^depth` voxels per axis from `origin`.
    ///
    /// # Errors
    /// [`OctreeError::DepthTooLarge`] when `depth > MAX_DEPTH`.
    pub fn empty(depth: u8, origin: Voxel) -> Result<Self, OctreeError> {
        check_space(depth, origin)?;
        Ok(Self::from_parts(depth, origin, Vec::new()))
    }

    /// A tree whose whole space is black.
    ///
    /// # Errors
    /// [`OctreeError::DepthTooLarge`] when `depth > MAX_DEPTH`.
    pub fn full(depth: u8, origin: Voxel) -> Result<Self, OctreeError> {
        check_space(depth, origin)?;
        Ok(Self::from_parts(depth, origin, vec![Leaf::new(0, depth)]))
    }

    /// Builds a tree from leaves that are already sorted and disjoint (not necessarily
    /// merged); merges them into canonical form.
    ///
    /// # Runtime
    /// O(n) for n leaves.
    ///
    /// # Errors
    /// [`OctreeError::DepthTooLarge`] when `depth > MAX_DEPTH`.
    ///
    /// It is a logic error to pass leaves that are unsorted, overlapping, or outside
    /// the space; [`LinearOctree::assert_valid`] catches it.
    pub fn from_sorted_leaves(
        depth: u8,
        origin: Voxel,
        leaves: impl IntoIterator<Item = Leaf>,
    ) -> Result<Self, OctreeError> {
        check_space(depth, origin)?;
        let mut merged = Vec::new();
        for leaf in leaves {
            push_merging(&mut merged, leaf);
        }
        Ok(Self::from_parts(depth, origin, merged))
    }

    /// Builds a tree from black voxels in world coordinates, in any order, duplicates
    /// allowed.
    ///
    /// # Runtime
    /// O(n) for n voxels: the codes are radix-sorted (a few 8-bit passes).
    ///
    /// # Errors
    /// [`OctreeError::OutOfBounds`] for a voxel outside the space;
    /// [`OctreeError::DepthTooLarge`] when `depth > MAX_DEPTH`.
    pub fn from_voxels(
        depth: u8,
        origin: Voxel,
        voxels: impl IntoIterator<Item = Voxel>,
    ) -> Result<Self, OctreeError> {
        check_space(depth, origin)?;
        let space = Self::from_parts(depth, origin, Vec::new());
        let mut codes = voxels
            .into_iter()
            .map(|v| space.code_of(v).ok_or(OctreeError::OutOfBounds(v)))
            .collect::<Result<Vec<u64>, _>>()?;
        sort::sort_u64(&mut codes);
        codes.dedup();
        Ok(
            Self::from_sorted_leaves(depth, origin, codes.into_iter().map(|c| Leaf::new(c, 0)))?
                .with_bricks(),
        )
    }

    /// Builds a tree from black voxels, choosing the smallest space that holds them:
    /// the origin is their lowest corner and the depth the least that spans them.
    ///
    /// # Errors
    /// [`OctreeError::DepthTooLarge`] when the voxels span more than `2^MAX_DEPTH`.
    pub fn from_voxels_fitted(voxels: &[Voxel]) -> Result<Self, OctreeError> {
        let Some(first) = voxels.first() else {
            return Self::empty(0, [0, 0, 0]);
        };
        let (mut lo, mut hi) = (*first, *first);
        for v in voxels {
            for a in 0..3 {
                lo[a] = lo[a].min(v[a]);
                hi[a] = hi[a].max(v[a]);
            }
        }
        let extent = (0..3).map(|a| hi[a].abs_diff(lo[a]) + 1).max().unwrap_or(1);
        let depth = extent.next_power_of_two().trailing_zeros();
        let depth = u8::try_from(depth).unwrap_or(u8::MAX);
        if depth > MAX_DEPTH {
            return Err(OctreeError::DepthTooLarge(depth));
        }
        // Near the top of i64 the space starts lower, so that it ends inside i64.
        let last = (1i64 << depth) - 1;
        let origin = lo.map(|c| c.min(i64::MAX - last));
        Self::from_voxels(depth, origin, voxels.iter().copied())
    }

    /// The tree's depth D: it spans `2^D` voxels per axis.
    #[must_use]
    pub fn depth(&self) -> u8 {
        self.depth
    }

    /// The world coordinates of the space's lowest corner.
    #[must_use]
    pub fn origin(&self) -> Voxel {
        self.origin
    }

    /// The side of the space, in voxels: `2^depth`.
    #[must_use]
    pub fn side(&self) -> u64 {
        1 << self.depth
    }

    /// The black leaves, sorted in tesseral order.
    #[must_use]
    ///
    /// # Runtime
    /// O(1), except on a tree made by a set operation, whose first call makes the
    /// list from the bricked form (O(n), kept).
    pub fn leaves(&self) -> &[Leaf] {
        self.leaves.get_or_init(|| {
            self.bricked
                .get()
                .expect("a tree holds its leaves in at least one form")
                .to_leaves()
        })
    }

    /// The number of black leaves (maximal blocks).
    ///
    /// # Runtime
    /// O(1) when the tree holds its leaf list; otherwise O(n), counted off the
    /// bricked form without making the list.
    #[must_use]
    pub fn leaf_count(&self) -> usize {
        match (self.leaves.get(), self.bricked.get()) {
            (Some(l), _) => l.len(),
            (None, Some(b)) => b.leaf_count(),
            (None, None) => unreachable!("a tree holds its leaves in at least one form"),
        }
    }

    /// The bytes the tree holds on the heap: the leaf list's capacity (8 bytes a
    /// leaf) plus, when it is held, the bricked form's (8 bytes an entry, 64 a mask).
    #[must_use]
    pub fn heap_bytes(&self) -> usize {
        self.leaves
            .get()
            .map_or(0, |l| l.capacity() * std::mem::size_of::<Leaf>())
            + self.bricked.get().map_or(0, Bricked::heap_bytes)
    }

    /// Whether no voxel is black.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        match (self.leaves.get(), self.bricked.get()) {
            (Some(l), _) => l.is_empty(),
            (None, Some(b)) => b.is_empty(),
            (None, None) => unreachable!("a tree holds its leaves in at least one form"),
        }
    }

    /// The number of black voxels.
    ///
    /// # Runtime
    /// O(n) in the number of leaves.
    #[must_use]
    pub fn voxel_count(&self) -> u64 {
        match (self.leaves.get(), self.bricked.get()) {
            (Some(l), _) => l.iter().map(|l| l.voxel_count()).sum(),
            (None, Some(b)) => b.voxel_count(),
            (None, None) => unreachable!("a tree holds its leaves in at least one form"),
        }
    }

    /// The number of leaves at each depth, index 0 being the root.
    #[must_use]
    pub fn leaves_by_depth(&self) -> Vec<u64> {
        let mut counts = vec![0; usize::from(self.depth) + 1];
        for l in self.leaves() {
            counts[usize::from(self.depth - l.size_log2())] += 1;
        }
        counts
    }

    /// Whether world voxel `v` is black.
    ///
    /// # Runtime
    /// O(log n): a binary search over the leaves.
    #[must_use]
    pub fn contains(&self, v: Voxel) -> bool {
        let Some(c) = self.code_of(v) else {
            return false;
        };
        let leaves = self.leaves();
        let i = leaves.partition_point(|l| l.code() <= c);
        i > 0 && leaves[i - 1].contains_code(c)
    }

    /// The tesseral code of world voxel `v` relative to the origin, or `None` when `v`
    /// lies outside the space.
    #[must_use]
    pub fn code_of(&self, v: Voxel) -> Option<u64> {
        let side = self.side();
        let mut rel = [0u32; 3];
        for a in 0..3 {
            let d = v[a].checked_sub(self.origin[a])?;
            if d < 0 || d as u64 >= side {
                return None;
            }
            rel[a] = d as u32;
        }
        Some(code::encode(rel[0], rel[1], rel[2]))
    }

    /// The world voxel whose relative tesseral code is `code`.
    #[must_use]
    pub fn voxel_of(&self, code: u64) -> Voxel {
        let r = code::decode(code);
        [
            self.origin[0] + i64::from(r[0]),
            self.origin[1] + i64::from(r[1]),
            self.origin[2] + i64::from(r[2]),
        ]
    }

    /// The black blocks in tesseral order, in world coordinates.
    pub fn blocks(&self) -> impl ExactSizeIterator<Item = Block> + '_ {
        self.leaves().iter().map(|l| Block {
            min: self.voxel_of(l.code()),
            size_log2: l.size_log2(),
        })
    }

    /// Every black voxel, in tesseral order.
    pub fn voxels(&self) -> impl Iterator<Item = Voxel> + '_ {
        self.leaves()
            .iter()
            .flat_map(|l| (l.code()..l.end()).map(|c| self.voxel_of(c)))
    }

    pub(crate) fn from_parts(depth: u8, origin: Voxel, leaves: Vec<Leaf>) -> Self {
        Self {
            depth,
            origin,
            leaves: OnceLock::from(leaves),
            bricked: OnceLock::new(),
        }
    }

    /// A tree held in the bricked form only (its leaf list made on first use).
    pub(crate) fn from_bricked(depth: u8, origin: Voxel, bricked: Bricked) -> Self {
        Self {
            depth,
            origin,
            leaves: OnceLock::new(),
            bricked: OnceLock::from(bricked),
        }
    }
}

/// Checks the depth, and that the space `[origin, origin + 2^depth)` lies inside
/// `i64` on every axis (so no voxel of the tree wraps).
fn check_space(depth: u8, origin: Voxel) -> Result<(), OctreeError> {
    if depth > MAX_DEPTH {
        return Err(OctreeError::DepthTooLarge(depth));
    }
    let last = (1i64 << depth) - 1;
    if origin.iter().any(|o| o.checked_add(last).is_none()) {
        return Err(OctreeError::SpaceOverflow { depth, origin });
    }
    Ok(())
}

#[cfg(test)]
pub(crate) mod tests;
#[cfg(test)]
mod tests_affine;
#[cfg(test)]
pub(crate) mod tests_merge;
#[cfg(test)]
pub(crate) mod tests_ops;
