//! Rotations by quarter turns, mirroring, scaling by powers of two, cropping, and
//! building from a dense bit array.
//!
//! A quarter turn or a mirror acts on every octal digit of a code alike: it permutes
//! the child labels (Jackins & Tanimoto, cited by Ahuja & Nash §5). Instead of a
//! table lookup per digit, the permutation is applied to all digits at once on the
//! dilated axis components of the code (a rotation swaps two components and
//! complements one). [`rotation_labels`] gives the per-digit table for reference.

// Per-axis loops index several arrays at once.
#![allow(clippy::needless_range_loop)]

use super::{push_merging, sort, Leaf, LinearOctree, OctreeError, MAX_DEPTH};
use crate::code::{Axis, CodeWord};
use crate::Voxel;

/// The x bits of a code: bit `3i` for every digit `i`.
const MASK_X: u64 = <u64 as CodeWord>::X_MASK;

/// The two axes a positive quarter turn about `axis` maps into each other:
/// `(from, to)` with `from` going to `to` (about z: +x goes to +y).
fn turn_axes(axis: Axis) -> (usize, usize) {
    match axis {
        Axis::X => (1, 2),
        Axis::Y => (2, 0),
        Axis::Z => (0, 1),
    }
}

/// The child-label permutation of `turns` positive quarter turns about `axis`:
/// child `d` of a cell becomes child `table[d]` of the rotated cell.
///
/// ```
/// use tesseral::linear::{rotation_labels, Axis};
/// // About z, +x goes to +y: the SE lower child (1) becomes the NE lower child (3).
/// assert_eq!(rotation_labels(Axis::Z, 1)[1], 3);
/// assert_eq!(rotation_labels(Axis::Z, 4), [0, 1, 2, 3, 4, 5, 6, 7]);
/// ```
#[must_use]
pub fn rotation_labels(axis: Axis, turns: i32) -> [u8; 8] {
    let (from, to) = turn_axes(axis);
    std::array::from_fn(|d| {
        let mut b = [(d & 1) as u8, ((d >> 1) & 1) as u8, ((d >> 2) & 1) as u8];
        for _ in 0..turns.rem_euclid(4) {
            // (u, v) -> (1 - v, u) on the (from, to) plane.
            let (u, v) = (b[from], b[to]);
            b[from] = 1 - v;
            b[to] = u;
        }
        b[0] | (b[1] << 1) | (b[2] << 2)
    })
}

impl LinearOctree {
    /// The tree rotated by `turns` quarter turns (negative allowed) about `axis`,
    /// through the centre of its space, which it keeps. Positive turns are right-
    /// handed: about z, +x goes to +y; about x, +y to +z; about y, +z to +x.
    ///
    /// # Runtime
    /// O(n) for n leaves: each code is rewritten in O(1) and the leaves radix-sorted.
    /// The leaf count is unchanged (Ahuja & Nash §5).
    ///
    /// ```
    /// use tesseral::linear::{Axis, LinearOctree};
    /// let a = LinearOctree::from_voxels(2, [0, 0, 0], [[3, 0, 0]]).unwrap();
    /// assert!(a.rotate(Axis::Z, 1).contains([3, 3, 0]));
    /// ```
    #[must_use]
    pub fn rotate(&self, axis: Axis, turns: i32) -> Self {
        let (from, to) = turn_axes(axis);
        let turns = turns.rem_euclid(4);
        if turns == 0 {
            return self.clone();
        }
        self.map_components(|mut c, m| {
            for _ in 0..turns {
                let (u, v) = (c[from], c[to]);
                c[from] = !v & m;
                c[to] = u;
            }
            c
        })
    }

    /// The tree mirrored in `axis` within its space: `x` goes to `2·origin + side − 1 − x`.
    ///
    /// # Runtime
    /// O(n), as [`LinearOctree::rotate`].
    ///
    /// ```
    /// use tesseral::linear::{Axis, LinearOctree};
    /// let a = LinearOctree::from_voxels(2, [0, 0, 0], [[0, 1, 2]]).unwrap();
    /// assert!(a.mirror(Axis::X).contains([3, 1, 2]));
    /// ```
    #[must_use]
    pub fn mirror(&self, axis: Axis) -> Self {
        let a = axis.index();
        self.map_components(|mut c, m| {
            c[a] = !c[a] & m;
            c
        })
    }

    /// Applies `f` to the dilated axis components (each in x bit positions) of every
    /// leaf's path digits; `f` gets the mask of those digits.
    fn map_components(&self, f: impl Fn([u64; 3], u64) -> [u64; 3]) -> Self {
        let space = if self.depth >= 21 {
            u64::MAX >> 1
        } else {
            (1u64 << (3 * u32::from(self.depth))) - 1
        };
        let mut leaves: Vec<Leaf> = self
            .leaves()
            .iter()
            .map(|l| {
                let k = u32::from(l.size_log2());
                let m = MASK_X & space & !((1u64 << (3 * k)) - 1);
                let c = l.code();
                let comps = [c & MASK_X, (c >> 1) & MASK_X, (c >> 2) & MASK_X];
                let n = f(comps, m);
                Leaf::new(n[0] | (n[1] << 1) | (n[2] << 2), l.size_log2())
            })
            .collect();
        sort::sort_leaves(&mut leaves);
        Self::from_parts(self.depth, self.origin, leaves)
    }

    /// The tree scaled up by `2^s` about the world origin: voxel `v` becomes the
    /// block `[v·2^s, (v+1)·2^s)`. Exact; the depth grows by `s`.
    ///
    /// # Runtime
    /// O(n).
    ///
    /// # Errors
    /// [`OctreeError::DepthTooLarge`] past [`MAX_DEPTH`]; [`OctreeError::Overflow`].
    ///
    /// ```
    /// use tesseral::linear::LinearOctree;
    /// let a = LinearOctree::from_voxels(1, [0, 0, 0], [[1, 0, 0]]).unwrap();
    /// let b = a.scale_up(2).unwrap();
    /// assert_eq!((b.voxel_count(), b.leaf_count()), (64, 1));
    /// assert!(b.contains([4, 3, 3]) && !b.contains([3, 0, 0]));
    /// ```
    pub fn scale_up(&self, s: u8) -> Result<Self, OctreeError> {
        let depth = self.depth.checked_add(s).filter(|&d| d <= MAX_DEPTH);
        let depth = depth.ok_or(OctreeError::DepthTooLarge(self.depth.saturating_add(s)))?;
        let mut origin = [0; 3];
        for a in 0..3 {
            origin[a] = self.origin[a]
                .checked_mul(1 << s)
                .ok_or(OctreeError::Overflow)?;
        }
        let shift = 3 * u32::from(s);
        let leaves = self
            .leaves()
            .iter()
            .map(|l| Leaf::new(l.code() << shift, l.size_log2() + s))
            .collect();
        Ok(Self::from_parts(depth, origin, leaves))
    }

    /// The tree scaled down by `2^s` about the world origin, conservatively: the
    /// voxel `w` of the result is black when any voxel of the block
    /// `[w·2^s, (w+1)·2^s)` is black — Ahuja & Nash §2's rule that a gray block of
    /// minimum size becomes black.
    ///
    /// When the origin is not a multiple of `2^s` the tree is first re-expressed in
    /// an aligned space one level deeper.
    ///
    /// # Runtime
    /// O(n).
    ///
    /// # Errors
    /// [`OctreeError::DepthTooLarge`] when aligning needs a space past [`MAX_DEPTH`].
    ///
    /// ```
    /// use tesseral::linear::LinearOctree;
    /// let a = LinearOctree::from_voxels(2, [0, 0, 0], [[3, 3, 3]]).unwrap();
    /// let b = a.scale_down(1).unwrap();
    /// assert_eq!(b.voxels().collect::<Vec<_>>(), vec![[1, 1, 1]]);
    /// ```
    pub fn scale_down(&self, s: u8) -> Result<Self, OctreeError> {
        if s == 0 {
            return Ok(self.clone());
        }
        let cell = 1i128 << s.min(100);
        let aligned_origin: Voxel = std::array::from_fn(|a| {
            let o = i128::from(self.origin[a]);
            (o.div_euclid(cell) * cell).clamp(i128::from(i64::MIN), i128::from(i64::MAX)) as i64
        });
        let mut depth = self.depth;
        while (0..3).any(|a| {
            i128::from(aligned_origin[a]) + (1i128 << depth)
                < i128::from(self.origin[a]) + (1i128 << self.depth)
        }) {
            depth += 1;
        }
        let src = if depth == self.depth && aligned_origin == self.origin {
            self.clone()
        } else {
            let (t, dropped) = self.resample(depth, aligned_origin)?;
            debug_assert_eq!(dropped, 0);
            t
        };
        let new_depth = depth.saturating_sub(s);
        let shift = 3 * u32::from(s);
        let origin = aligned_origin.map(|o| (i128::from(o).div_euclid(cell)) as i64);
        let mut out: Vec<Leaf> = Vec::with_capacity(src.leaves().len());
        for l in src.leaves() {
            let code = l.code().checked_shr(shift).unwrap_or(0);
            let k = l.size_log2().saturating_sub(s);
            if out.last().is_some_and(|p| p.contains_code(code)) {
                continue;
            }
            push_merging(&mut out, Leaf::new(code, k));
        }
        Ok(Self::from_parts(new_depth, origin, out))
    }

    /// The voxels of the tree inside the inclusive world box `[lo, hi]`, in the same
    /// space.
    ///
    /// # Runtime
    /// O(n) plus the leaves cut by the box's faces, times the depth.
    ///
    /// ```
    /// use tesseral::linear::LinearOctree;
    /// let a = LinearOctree::full(2, [0, 0, 0]).unwrap();
    /// let b = a.crop([1, 1, 1], [2, 2, 5]);
    /// assert_eq!(b.voxel_count(), 2 * 2 * 3);
    /// ```
    #[must_use]
    pub fn crop(&self, lo: Voxel, hi: Voxel) -> Self {
        let side = 1i128 << self.depth;
        let mut rel_lo = [0i64; 3];
        let mut rel_hi = [0i64; 3];
        for a in 0..3 {
            let l = (i128::from(lo[a]) - i128::from(self.origin[a])).max(0);
            let h = (i128::from(hi[a]) - i128::from(self.origin[a])).min(side - 1);
            if l > h {
                return Self::from_parts(self.depth, self.origin, Vec::new());
            }
            rel_lo[a] = l as i64;
            rel_hi[a] = h as i64;
        }
        let mut out = Vec::new();
        crop_cell(
            self.leaves(),
            [0; 3],
            self.depth,
            0,
            rel_lo,
            rel_hi,
            &mut out,
        );
        Self::from_parts(self.depth, self.origin, out)
    }

    /// Builds a tree from a dense bit array of `dims` voxels whose lowest voxel is
    /// `origin`: voxel `(x, y, z)` (relative) is bit `i = x + dims[0]·(y + dims[1]·z)`,
    /// that is bit `i % 64` of word `i / 64`. The space has depth `depth`.
    ///
    /// # Runtime
    /// O(voxels of the array).
    ///
    /// # Errors
    /// [`OctreeError::OutOfBounds`] when the array does not fit the space;
    /// [`OctreeError::DenseTooShort`] when `bits` is too short;
    /// [`OctreeError::DepthTooLarge`].
    ///
    /// ```
    /// use tesseral::linear::LinearOctree;
    /// // A 2 x 1 x 1 array with both voxels set.
    /// let t = LinearOctree::from_dense(1, [0, 0, 0], [2, 1, 1], &[0b11]).unwrap();
    /// assert_eq!(t.voxel_count(), 2);
    /// ```
    pub fn from_dense(
        depth: u8,
        origin: Voxel,
        dims: [u32; 3],
        bits: &[u64],
    ) -> Result<Self, OctreeError> {
        super::check_space(depth, origin)?;
        let side = 1u64 << depth;
        if let Some(a) = (0..3).find(|&a| u64::from(dims[a]) > side) {
            let mut v = origin;
            v[a] = v[a].saturating_add(side as i64);
            return Err(OctreeError::OutOfBounds(v));
        }
        let total = dims.iter().map(|&d| d as usize).product::<usize>();
        let needed = total.div_ceil(64);
        if bits.len() < needed {
            return Err(OctreeError::DenseTooShort {
                dims,
                needed,
                got: bits.len(),
            });
        }
        let mut out = Vec::new();
        if total > 0 {
            dense_cell(bits, dims, [0; 3], depth, 0, &mut out);
        }
        Ok(Self::from_parts(depth, origin, out))
    }
}

fn dense_cell(bits: &[u64], dims: [u32; 3], min: [u32; 3], k: u8, code: u64, out: &mut Vec<Leaf>) {
    if (0..3).any(|a| min[a] >= dims[a]) {
        return;
    }
    if k == 0 {
        let i = min[0] as usize
            + dims[0] as usize * (min[1] as usize + dims[1] as usize * min[2] as usize);
        if (bits[i / 64] >> (i % 64)) & 1 == 1 {
            out.push(Leaf::new(code, 0));
        }
        return;
    }
    let half = 1u32 << (k - 1);
    let child = 1u64 << (3 * u32::from(k - 1));
    for d in 0..8u32 {
        let m = [
            min[0] + (d & 1) * half,
            min[1] + ((d >> 1) & 1) * half,
            min[2] + ((d >> 2) & 1) * half,
        ];
        dense_cell(bits, dims, m, k - 1, code + u64::from(d) * child, out);
    }
    if let Some(last) = out.pop() {
        push_merging(out, last);
    }
}

/// Appends the leaves of `leaves` (all inside the cell `(min, k)`, or one leaf
/// covering it) cut to the inclusive relative box `[lo, hi]`.
fn crop_cell(
    leaves: &[Leaf],
    min: [i64; 3],
    k: u8,
    code: u64,
    lo: [i64; 3],
    hi: [i64; 3],
    out: &mut Vec<Leaf>,
) {
    if leaves.is_empty() {
        return;
    }
    let size = 1i64 << k;
    if (0..3).any(|a| min[a] > hi[a] || min[a] + size - 1 < lo[a]) {
        return;
    }
    let covered = leaves.len() == 1 && leaves[0].size_log2() >= k;
    if (0..3).all(|a| lo[a] <= min[a] && min[a] + size - 1 <= hi[a]) {
        if covered {
            out.push(Leaf::new(code, k));
        } else {
            out.extend_from_slice(leaves);
        }
        return;
    }
    // k > 0 here: a voxel is either inside or outside the box.
    let half = size / 2;
    let child = 1u64 << (3 * u32::from(k - 1));
    let mut rest = leaves;
    for d in 0..8u64 {
        let m = [
            min[0] + (d & 1) as i64 * half,
            min[1] + ((d >> 1) & 1) as i64 * half,
            min[2] + ((d >> 2) & 1) as i64 * half,
        ];
        let c = code + d * child;
        let part = if covered {
            leaves
        } else {
            let n = rest.partition_point(|l| l.code() < c + child);
            let (p, r) = rest.split_at(n);
            rest = r;
            p
        };
        crop_cell(part, m, k - 1, c, lo, hi, out);
    }
}
