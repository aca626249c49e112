//! Set operations on linear octrees, each one linear merge of the two sorted leaf
//! lists (Harakal & Chmúrny §2 combine solids by union, intersection, difference and
//! negation; this is the linear-octree form of those operations).
//!
//! The merge works on *runs*: consecutive leaves whose code ranges touch form one
//! interval of codes, the two interval lists are swept together, and every output
//! interval is cut back into maximal aligned blocks greedily. The greedy cut of a
//! maximal run is exactly the canonical leaf list, so the output needs no second
//! merging pass. Large inputs are split by octant and merged in parallel with rayon.

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

impl SetOp {
    #[inline]
    fn apply(self, a: bool, b: bool) -> bool {
        match self {
            SetOp::Union => a | b,
            SetOp::Intersection => a & b,
            SetOp::Difference => a & !b,
            SetOp::SymmetricDifference => a ^ b,
        }
    }
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
            let n = rest.partition_point(|l| l.code() < end);
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
        let mut out = Vec::with_capacity(a.len().max(b.len()));
        let cell = (code, code + (1u64 << (3 * u32::from(k))));
        merge_runs(op, runs(a, cell), runs(b, cell), &mut out);
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

/// The runs of black codes of one operand inside `cell`, clamped to it.
fn runs(part: Part<'_>, cell: (u64, u64)) -> Runs<'_> {
    match part {
        Part::Full => Runs {
            leaves: &[],
            i: 0,
            first: Some(cell),
            cell,
        },
        Part::Leaves(leaves) => Runs {
            leaves,
            i: 0,
            first: None,
            cell,
        },
    }
}

/// Coalesces consecutive touching leaves into runs `[start, end)` of codes.
struct Runs<'a> {
    leaves: &'a [Leaf],
    i: usize,
    first: Option<(u64, u64)>,
    cell: (u64, u64),
}

#[inline]
fn bounds(leaf: Leaf) -> (u64, u64) {
    let p = leaf.packed();
    let bits = 3 * (p.trailing_ones() / 3);
    let code = (p >> 1) & !((1u64 << bits) - 1);
    (code, code + (1u64 << bits))
}

impl Iterator for Runs<'_> {
    type Item = (u64, u64);

    #[inline]
    fn next(&mut self) -> Option<(u64, u64)> {
        if let Some(r) = self.first.take() {
            return Some(r);
        }
        let (s, mut e) = bounds(*self.leaves.get(self.i)?);
        self.i += 1;
        while let Some(&l) = self.leaves.get(self.i) {
            let (s2, e2) = bounds(l);
            if s2 != e {
                break;
            }
            e = e2;
            self.i += 1;
        }
        // A single leaf larger than the cell covers it: clamp.
        Some((s.max(self.cell.0), e.min(self.cell.1)))
    }
}

/// Sweeps two sorted run lists together and appends the canonical leaves of
/// `op(a, b)` to `out`.
fn merge_runs(
    op: SetOp,
    mut a: impl Iterator<Item = (u64, u64)>,
    mut b: impl Iterator<Item = (u64, u64)>,
    out: &mut Vec<Leaf>,
) {
    let (mut ra, mut rb) = (a.next(), b.next());
    let mut x = 0u64;
    let mut pending: Option<(u64, u64)> = None;
    loop {
        match (op, ra, rb) {
            (_, None, None)
            | (SetOp::Intersection, None, _)
            | (SetOp::Intersection, _, None)
            | (SetOp::Difference, None, _) => break,
            _ => {}
        }
        let (ina, na) = match ra {
            Some((s, _)) if x < s => (false, s),
            Some((_, e)) => (true, e),
            None => (false, u64::MAX),
        };
        let (inb, nb) = match rb {
            Some((s, _)) if x < s => (false, s),
            Some((_, e)) => (true, e),
            None => (false, u64::MAX),
        };
        let next = na.min(nb);
        if op.apply(ina, inb) {
            pending = match pending {
                Some((s, e)) if e == x => Some((s, next)),
                Some((s, e)) => {
                    emit_run(out, s, e);
                    Some((x, next))
                }
                None => Some((x, next)),
            };
        }
        x = next;
        if ra.is_some_and(|(_, e)| x >= e) {
            ra = a.next();
        }
        if rb.is_some_and(|(_, e)| x >= e) {
            rb = b.next();
        }
    }
    if let Some((s, e)) = pending {
        emit_run(out, s, e);
    }
}

/// Appends the maximal aligned blocks of the code interval `[s, e)`, greedily: at
/// each start the largest block aligned there that fits.
#[inline]
pub(crate) fn emit_run(out: &mut Vec<Leaf>, mut s: u64, e: u64) {
    while s < e {
        let align = s.trailing_zeros().min(63) / 3;
        let fit = (63 - (e - s).leading_zeros()) / 3;
        let k = align.min(fit);
        out.push(Leaf::new(s, k as u8));
        s += 1u64 << (3 * k);
    }
}
