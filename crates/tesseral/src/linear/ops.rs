//! Set operations on linear octrees, each one linear merge of the two sorted leaf
//! lists (Harakal & Chmúrny §2 combine solids by union, intersection, difference and
//! negation; this is the linear-octree form of those operations).
//!
//! The kernels (`merge.rs`) sweep the two leaf lists together: overlapping leaves are
//! nested, so each step keeps, drops, or cuts the larger around the smaller ones
//! (gaps cut greedily into maximal blocks, which is canonical), and stretches that
//! only one operand has are copied or skipped as slices. On one thread the whole
//! space is one merge; on more, large inputs are split by octant and merged in
//! parallel with rayon.
//!
//! When either operand holds its bricked form (`bricked/`), the operation runs on
//! the bricked forms instead, one merge per level with the bottom three levels
//! combined word by word, and returns a tree in bricked form.

// Per-axis loops index several arrays at once.
#![allow(clippy::needless_range_loop)]

use rayon::prelude::*;

use super::bricked::{self, Bricked};
use super::merge::{difference, intersection, symmetric_difference, union};
use super::{grow, push_merging, Leaf, LinearOctree, OctreeError};

/// A Boolean set operation on two solids.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SetOp {
    /// Voxels in either solid.
    Union,
    /// Voxels in both solids.
    Intersection,
    /// Voxels in the first solid and not in the second.
    Difference,
    /// Voxels in exactly one of the two solids.
    SymmetricDifference,
}

/// Below this many leaves (both operands together) a cell is merged on one thread.
const PARALLEL_MIN_LEAVES: usize = 1 << 14;

/// The least leaf count (both operands) of a cell merged as one task: on one thread
/// nothing is split (splitting costs a copy of the output per level); on `t`
/// threads, cells are split until they hold about an eighth of a thread's share.
fn split_min_leaves(total: usize) -> usize {
    match rayon::current_num_threads() {
        1 => usize::MAX,
        t => PARALLEL_MIN_LEAVES.max(total / (8 * t)),
    }
}

impl LinearOctree {
    /// The set operation `op` of `self` and `other`.
    ///
    /// When both trees share a space (depth and origin) the result has that space.
    /// Otherwise `other` is re-expressed in `self`'s lattice first (see
    /// [`LinearOctree::resample`]): for union and symmetric difference the space of
    /// `self` grows by root expansion until it holds `other`'s voxels; for
    /// intersection and difference the result lies in `self`, so `self`'s space is
    /// kept and `other` is cut to it.
    ///
    /// # Runtime
    /// O(n + m) leaves in a shared space, in parallel for large inputs; aligning a
    /// foreign operand costs one [`LinearOctree::resample`] of it. When either
    /// operand holds its bricked form ([`LinearOctree::build_bricks`]; the trees from
    /// [`LinearOctree::from_classifier`], [`LinearOctree::from_voxels`] and scene
    /// builds hold it from the start), the merge
    /// runs on the bricked forms (O(n + m) entries and masks, chunks that only one
    /// operand has passed on without copying) and the result is held in bricked form.
    ///
    /// # Errors
    /// [`OctreeError::DepthTooLarge`] when the grown space would exceed
    /// [`super::MAX_DEPTH`]; [`OctreeError::Overflow`] when coordinates overflow.
    ///
    /// ```
    /// use tesseral::linear::{LinearOctree, SetOp};
    /// let a = LinearOctree::from_voxels(2, [0, 0, 0], [[0, 0, 0], [1, 0, 0]]).unwrap();
    /// let b = LinearOctree::from_voxels(2, [0, 0, 0], [[1, 0, 0], [2, 0, 0]]).unwrap();
    /// assert_eq!(a.set_op(&b, SetOp::Union).unwrap().voxel_count(), 3);
    /// assert_eq!(a.set_op(&b, SetOp::Intersection).unwrap().voxel_count(), 1);
    /// ```
    pub fn set_op(&self, other: &Self, op: SetOp) -> Result<Self, OctreeError> {
        if self.depth == other.depth && self.origin == other.origin {
            return Ok(self.set_op_same_space(other, op));
        }
        let grows = matches!(op, SetOp::Union | SetOp::SymmetricDifference);
        let (depth, origin) = match (grows, other.bbox()) {
            (true, Some((lo, hi))) => grow::grown_space(self.depth, self.origin, lo, hi)?,
            _ => (self.depth, self.origin),
        };
        let a = self.expand_to(depth, origin);
        let (b, _) = other.resample(depth, origin)?;
        if self.has_bricked() || other.has_bricked() {
            a.build_bricks();
        }
        Ok(a.set_op_same_space(&b, op))
    }

    /// Union: [`LinearOctree::set_op`] with [`SetOp::Union`].
    ///
    /// # Errors
    /// As [`LinearOctree::set_op`].
    pub fn union(&self, other: &Self) -> Result<Self, OctreeError> {
        self.set_op(other, SetOp::Union)
    }

    /// Intersection: [`LinearOctree::set_op`] with [`SetOp::Intersection`].
    ///
    /// # Errors
    /// As [`LinearOctree::set_op`].
    pub fn intersection(&self, other: &Self) -> Result<Self, OctreeError> {
        self.set_op(other, SetOp::Intersection)
    }

    /// Difference `self \ other`: [`LinearOctree::set_op`] with [`SetOp::Difference`].
    ///
    /// # Errors
    /// As [`LinearOctree::set_op`].
    pub fn difference(&self, other: &Self) -> Result<Self, OctreeError> {
        self.set_op(other, SetOp::Difference)
    }

    /// Symmetric difference: [`LinearOctree::set_op`] with
    /// [`SetOp::SymmetricDifference`].
    ///
    /// # Errors
    /// As [`LinearOctree::set_op`].
    pub fn symmetric_difference(&self, other: &Self) -> Result<Self, OctreeError> {
        self.set_op(other, SetOp::SymmetricDifference)
    }

    /// Whether the two trees hold the same voxels, whatever their spaces.
    ///
    /// # Errors
    /// As [`LinearOctree::set_op`], when the spaces differ and aligning them fails.
    pub fn same_voxels(&self, other: &Self) -> Result<bool, OctreeError> {
        if self.depth == other.depth && self.origin == other.origin {
            return Ok(self == other);
        }
        if self.voxel_count() != other.voxel_count() {
            return Ok(false);
        }
        Ok(self.symmetric_difference(other)?.is_empty())
    }

    /// The complement within the space: every voxel of the cube that is not black.
    ///
    /// # Runtime
    /// O(n).
    ///
    /// ```
    /// use tesseral::linear::LinearOctree;
    /// let a = LinearOctree::from_voxels(1, [0, 0, 0], [[0, 0, 0]]).unwrap();
    /// let c = a.complement();
    /// assert_eq!(c.voxel_count(), 7);
    /// assert_eq!(c.complement(), a);
    /// ```
    #[must_use]
    pub fn complement(&self) -> Self {
        let full = [Leaf::new(0, self.depth)];
        if self.has_bricked() {
            let full = Bricked::from_leaves(&full);
            let out = bricked::set_op(&full, self.bricked(), SetOp::Difference);
            return Self::from_bricked(self.depth, self.origin, out);
        }
        let leaves = self.leaves();
        let min = split_min_leaves(leaves.len());
        let mut leaves = merge_cell(
            SetOp::Difference,
            Part::Leaves(&full),
            Part::Leaves(leaves),
            0,
            self.depth,
            min,
        );
        leaves.shrink_to_fit();
        Self::from_parts(self.depth, self.origin, leaves)
    }

    /// The set operation on two trees that share a space.
    ///
    /// # Panics
    /// When the spaces differ; [`LinearOctree::set_op`] aligns them instead.
    #[must_use]
    pub fn set_op_same_space(&self, other: &Self, op: SetOp) -> Self {
        assert!(
            self.depth == other.depth && self.origin == other.origin,
            "set_op_same_space on different spaces"
        );
        if self.has_bricked() || other.has_bricked() {
            let out = bricked::set_op(self.bricked(), other.bricked(), op);
            return Self::from_bricked(self.depth, self.origin, out);
        }
        let (a, b) = (self.leaves(), other.leaves());
        let min = split_min_leaves(a.len() + b.len());
        let mut leaves = merge_cell(op, Part::Leaves(a), Part::Leaves(b), 0, self.depth, min);
        leaves.shrink_to_fit();
        Self::from_parts(self.depth, self.origin, leaves)
    }
}

/// One operand inside one cell: either black all over, or leaves that lie inside the
/// cell (possibly a single leaf covering it).
#[derive(Clone, Copy)]
enum Part<'a> {
    Full,
    Leaves(&'a [Leaf]),
}

impl<'a> Part<'a> {
    fn len(self) -> usize {
        match self {
            Part::Full => 1,
            Part::Leaves(l) => l.len(),
        }
    }

    /// Whether this operand is black over the whole cell `(code, k)`.
    fn covers(self, code: u64, k: u8) -> bool {
        match self {
            Part::Full => true,
            Part::Leaves(l) => l.len() == 1 && l[0].size_log2() >= k && l[0].contains_code(code),
        }
    }

    /// Splits the part among the eight children of cell `(code, k)`.
    fn split(self, code: u64, k: u8) -> [Part<'a>; 8] {
        if self.covers(code, k) {
            return [Part::Full; 8];
        }
        let Part::Leaves(leaves) = self else {
            unreachable!()
        };
        let child = 1u64 << (3 * u32::from(k - 1));
        let mut parts = [Part::Leaves(&[][..]); 8];
        let mut rest = leaves;
        for (d, part) in parts.iter_mut().enumerate().take(7) {
            let end = code + (d as u64 + 1) * child;
            // Packed leaves sort as codes, and a leaf ends by `end` exactly when
            // its packed form is below `end << 1`.
            let n = rest.partition_point(|l| l.packed() < end << 1);
            *part = Part::Leaves(&rest[..n]);
            rest = &rest[n..];
        }
        parts[7] = Part::Leaves(rest);
        parts
    }
}

/// Merges the operands inside cell `(code, k)` and returns the canonical leaves.
fn merge_cell(op: SetOp, a: Part<'_>, b: Part<'_>, code: u64, k: u8, min: usize) -> Vec<Leaf> {
    let covering = a.covers(code, k) && b.covers(code, k);
    if k == 0 || covering || a.len() + b.len() < min {
        let full = [Leaf::new(code, k)];
        let clamp = |p: Part<'_>| -> bool {
            match p {
                Part::Full => true,
                Part::Leaves(l) => l.len() == 1 && l[0].size_log2() > k,
            }
        };
        let sa: &[Leaf] = match a {
            Part::Leaves(l) if !clamp(a) => l,
            _ => &full,
        };
        let sb: &[Leaf] = match b {
            Part::Leaves(l) if !clamp(b) => l,
            _ => &full,
        };
        // Union and intersection keep at most every input leaf; a difference may
        // cut more and grows. Pages never written are never touched, and the top
        // level gives back the unused tail.
        let mut out = Vec::with_capacity(sa.len() + sb.len() + 8);
        match op {
            SetOp::Union => union(sa, sb, &mut out),
            SetOp::Intersection => intersection(sa, sb, &mut out),
            SetOp::Difference => difference(sa, sb, &mut out),
            SetOp::SymmetricDifference => symmetric_difference(sa, sb, &mut out),
        }
        return out;
    }
    let (pa, pb) = (a.split(code, k), b.split(code, k));
    let child = 1u64 << (3 * u32::from(k - 1));
    let parts: Vec<Vec<Leaf>> = (0..8usize)
        .into_par_iter()
        .map(|d| merge_cell(op, pa[d], pb[d], code + d as u64 * child, k - 1, min))
        .collect();
    let mut out = Vec::with_capacity(parts.iter().map(Vec::len).sum());
    for (d, part) in parts.into_iter().enumerate() {
        if part.len() == 1 && part[0] == Leaf::new(code + d as u64 * child, k - 1) {
            push_merging(&mut out, part[0]);
        } else {
            out.extend(part);
        }
    }
    out
}
