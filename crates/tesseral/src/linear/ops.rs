//! Set operations on linear octrees, each one linear merge of the two sorted leaf
//! lists (Harakal & Chmúrny §2 combine solids by union, intersection, difference and
//! negation; this is the linear-octree form of those operations).
//!
//! The merge works on *runs*: consecutive leaves whose code ranges touch form one
//! interval of codes, the two interval lists are swept together, and every output
//! interval is cut back into maximal aligned blocks greedily. The greedy cut of a
//! maximal run is exactly the canonical leaf list, so the output needs no second
//! merging pass. Large inputs are split by octant and merged in parallel with rayon.

// Per-axis loops index several arrays at once.
#![allow(clippy::needless_range_loop)]

use rayon::prelude::*;

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
    /// foreign operand costs one [`LinearOctree::resample`] of it.
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
            return Ok(self.leaves == other.leaves);
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
        let leaves = merge_cell(
            SetOp::Difference,
            Part::Leaves(&full),
            Part::Leaves(&self.leaves),
            0,
            self.depth,
        );
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
        let leaves = merge_cell(
            op,
            Part::Leaves(&self.leaves),
            Part::Leaves(&other.leaves),
            0,
            self.depth,
        );
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
fn merge_cell(op: SetOp, a: Part<'_>, b: Part<'_>, code: u64, k: u8) -> Vec<Leaf> {
    let covering = a.covers(code, k) && b.covers(code, k);
    if k == 0 || covering || a.len() + b.len() < PARALLEL_MIN_LEAVES {
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
        let mut out = Vec::with_capacity(sa.len().max(sb.len()) + 8);
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
        .map(|d| merge_cell(op, pa[d], pb[d], code + d as u64 * child, k - 1))
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

/// The code span `[start, end)` of a leaf, read straight off the packed form:
/// `m = p ^ (p + 1)` is the size marker plus the zero bit above it.
#[inline(always)]
fn span2(leaf: Leaf) -> (u64, u64) {
    let p = leaf.packed();
    let m = p ^ (p.wrapping_add(1));
    let start = (p & !m) >> 1;
    (start, start + (m >> 1) + 1)
}

/// Pushes a leaf that follows every leaf in `out`, merging siblings only when the
/// leaf is the last child (label 7) of its parent: the only time a merge can occur.
#[inline(always)]
fn push_m(out: &mut Vec<Leaf>, leaf: Leaf) {
    let p = leaf.packed();
    if p.checked_shr(p.trailing_ones() + 1).unwrap_or(0) & 7 == 7 {
        push_merging(out, leaf);
    } else {
        out.push(leaf);
    }
}

/// Appends the maximal blocks of the code interval `[s, e)`, greedily (the largest
/// block aligned at each start that fits), merging as it goes when asked.
#[inline]
fn emit_gap(out: &mut Vec<Leaf>, mut s: u64, e: u64, merge: bool) {
    while s < e {
        let align = s.trailing_zeros().min(63) / 3;
        let fit = (63 - (e - s).leading_zeros()) / 3;
        let k = align.min(fit);
        let leaf = Leaf::new(s, k as u8);
        if merge {
            push_m(out, leaf);
        } else {
            out.push(leaf);
        }
        s += 1u64 << (3 * k);
    }
}

/// Union of two canonical leaf lists. A leaf nested in a larger one is skipped;
/// siblings coming from both operands may merge.
fn union(a: &[Leaf], b: &[Leaf], out: &mut Vec<Leaf>) {
    let (mut i, mut j) = (0, 0);
    if !a.is_empty() && !b.is_empty() {
        // The current leaves' spans, reloaded only when a cursor moves.
        let ((mut xs, mut xe), (mut ys, mut ye)) = (span2(a[0]), span2(b[0]));
        loop {
            if xe <= ys {
                push_m(out, a[i]);
                i += 1;
                if i == a.len() {
                    break;
                }
                (xs, xe) = span2(a[i]);
            } else if ye <= xs {
                push_m(out, b[j]);
                j += 1;
                if j == b.len() {
                    break;
                }
                (ys, ye) = span2(b[j]);
            } else if xs <= ys && ye <= xe {
                // b's leaf lies in a's: skip every b leaf inside it.
                push_m(out, a[i]);
                i += 1;
                j += 1;
                while j < b.len() && span2(b[j]).0 < xe {
                    j += 1;
                }
                if i == a.len() || j == b.len() {
                    break;
                }
                (xs, xe) = span2(a[i]);
                (ys, ye) = span2(b[j]);
            } else {
                push_m(out, b[j]);
                j += 1;
                i += 1;
                while i < a.len() && span2(a[i]).0 < ye {
                    i += 1;
                }
                if i == a.len() || j == b.len() {
                    break;
                }
                (xs, xe) = span2(a[i]);
                (ys, ye) = span2(b[j]);
            }
        }
    }
    for &l in a[i..].iter().chain(&b[j..]) {
        push_m(out, l);
    }
}

/// Intersection: of two overlapping (hence nested) leaves the smaller is kept.
/// No merge can occur: a full parent in both operands is inside a leaf of each.
fn intersection(a: &[Leaf], b: &[Leaf], out: &mut Vec<Leaf>) {
    let (mut i, mut j) = (0, 0);
    if a.is_empty() || b.is_empty() {
        return;
    }
    let ((mut xs, mut xe), (mut ys, mut ye)) = (span2(a[0]), span2(b[0]));
    loop {
        if xe <= ys {
            i += 1;
            if i == a.len() {
                return;
            }
            (xs, xe) = span2(a[i]);
        } else if ye <= xs {
            j += 1;
            if j == b.len() {
                return;
            }
            (ys, ye) = span2(b[j]);
        } else if xs <= ys && ye <= xe {
            out.push(b[j]);
            j += 1;
            if j == b.len() {
                return;
            }
            (ys, ye) = span2(b[j]);
        } else {
            out.push(a[i]);
            i += 1;
            if i == a.len() {
                return;
            }
            (xs, xe) = span2(a[i]);
        }
    }
}

/// Difference: a leaf of `a` is kept whole, dropped, or cut around the leaves of
/// `b` inside it (the gaps are emitted greedily as maximal blocks, which is
/// canonical: a full parent of the result lies in one leaf of `a`, in one gap).
fn difference(a: &[Leaf], b: &[Leaf], out: &mut Vec<Leaf>) {
    let mut j = 0;
    for (i, &x) in a.iter().enumerate() {
        let (xs, xe) = span2(x);
        while j < b.len() && span2(b[j]).1 <= xs {
            j += 1;
        }
        if j == b.len() {
            out.extend_from_slice(&a[i..]);
            return;
        }
        let (ys, ye) = span2(b[j]);
        if ys >= xe {
            out.push(x);
        } else if ys <= xs && xe <= ye {
            // Inside a leaf of b: dropped.
        } else {
            let mut pos = xs;
            while j < b.len() {
                let (ys, ye) = span2(b[j]);
                if ys >= xe {
                    break;
                }
                emit_gap(out, pos, ys, false);
                pos = ye;
                j += 1;
            }
            emit_gap(out, pos, xe, false);
        }
    }
}

/// Symmetric difference: disjoint leaves pass, a nested pair leaves the larger cut
/// around every leaf of the other operand inside it; siblings may merge.
fn symmetric_difference(a: &[Leaf], b: &[Leaf], out: &mut Vec<Leaf>) {
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        let ((xs, xe), (ys, ye)) = (span2(a[i]), span2(b[j]));
        if xe <= ys {
            push_m(out, a[i]);
            i += 1;
        } else if ye <= xs {
            push_m(out, b[j]);
            j += 1;
        } else {
            // Nested: cut the larger (from `big`) around the leaves of `small`.
            let (big_end, mut pos, small, k) = if xs <= ys && ye <= xe {
                i += 1;
                (xe, xs, b, &mut j)
            } else {
                j += 1;
                (ye, ys, a, &mut i)
            };
            while *k < small.len() {
                let (s, e) = span2(small[*k]);
                if s >= big_end {
                    break;
                }
                emit_gap(out, pos, s, true);
                pos = e;
                *k += 1;
            }
            emit_gap(out, pos, big_end, true);
        }
    }
    for &l in a[i..].iter().chain(&b[j..]) {
        push_m(out, l);
    }
}
