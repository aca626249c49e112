//! Translation and re-expression of a linear octree in another space.
//!
//! Everything here rests on one primitive, [`LinearOctree::resample`]: the voxels of
//! a tree written into a space with another origin or depth. Translation is a
//! resample of the tree with its origin moved; aligning two operands of a set
//! operation is a resample of one into the other's lattice.
//!
//! # How it works
//! The output is built top-down, like [`LinearOctree::from_classifier`]. An output
//! cell of side `2^k` covers, in the input, an unaligned cube that overlaps at most
//! 2 × 2 × 2 input cells of the same side. Those eight input cells (the *window*) are
//! kept as slots of a small pointer index of the input (empty, full, or a gray node
//! with eight child slots). The offset of the cube inside its window is the same for
//! every cell at one depth (it is the displacement modulo `2^k`), so a child's window
//! is read off its parent's window's children through a table computed once per
//! depth. A cell whose window is all full is a black leaf, all empty is white, and
//! anything else is split. Only cells whose window touches a gray input cell are
//! split, so the work is proportional to the input's nodes plus the output's leaves,
//! never to the voxels. Children's tesseral codes follow by code addition, and when
//! the displacement is aligned to every leaf the codes are moved directly by tesseral
//! addition (Ahuja & Nash §3.1, Table 2 carries in parallel over all digits).
//!
//! `index.rs` holds the pointer index of the input, `blocks.rs` the 4 × 4 × 4
//! occupancy masks of the last two levels, `resampler.rs` the top-down recursion.

// Per-axis loops index several arrays at once.
#![allow(clippy::needless_range_loop)]

mod blocks;
mod index;
mod resampler;

use super::{grow, push_merging, Leaf, LinearOctree, OctreeError};
use crate::code::{self, Space};
use crate::Voxel;
use blocks::Cut;
use index::{Index, EMPTY};
use resampler::{child_table, Resampler, EMPTY_TABLE};

impl LinearOctree {
    /// The same voxels written into another space, `(depth, origin)`: the result's
    /// voxels are this tree's voxels that lie in the new space. Also returns how many
    /// voxels fell outside it and were dropped.
    ///
    /// The new space may have any origin and depth; its lattice need not match this
    /// tree's (an unaligned origin shatters and re-merges blocks as needed).
    ///
    /// # Runtime
    /// O(n + m) for n input leaves and m output leaves (times a small constant per
    /// tree depth), not proportional to voxels; in parallel with rayon.
    ///
    /// # Errors
    /// [`OctreeError::DepthTooLarge`] when `depth > MAX_DEPTH`;
    /// [`OctreeError::Overflow`] when the two origins are too far apart for `i64`.
    ///
    /// ```
    /// use tesseral::linear::LinearOctree;
    /// let a = LinearOctree::from_voxels(2, [0, 0, 0], [[0, 0, 0], [3, 3, 3]]).unwrap();
    /// let (b, dropped) = a.resample(2, [1, 1, 1]).unwrap();
    /// assert_eq!((b.voxel_count(), dropped), (1, 1));
    /// assert!(b.contains([3, 3, 3]));
    /// ```
    pub fn resample(&self, depth: u8, origin: Voxel) -> Result<(Self, u64), OctreeError> {
        super::check_space(depth, origin)?;
        if depth == self.depth && origin == self.origin {
            return Ok((self.clone(), 0));
        }
        self.resample_moved(self.origin, None, depth, origin)
    }

    /// [`LinearOctree::resample`] of this tree's leaves taken as if its origin were
    /// `src_origin`; `bbox` is their bounding box there when the caller knows it.
    fn resample_moved(
        &self,
        src_origin: Voxel,
        bbox: Option<(Voxel, Voxel)>,
        depth: u8,
        origin: Voxel,
    ) -> Result<(Self, u64), OctreeError> {
        let mut delta = [0i64; 3];
        for a in 0..3 {
            delta[a] = origin[a]
                .checked_sub(src_origin[a])
                .ok_or(OctreeError::Overflow)?;
        }
        let Some((blo, bhi)) = bbox.or_else(|| {
            let (lo, hi) = self.bbox()?;
            let mv = |v: Voxel| -> Voxel {
                std::array::from_fn(|a| {
                    (i128::from(v[a]) - i128::from(self.origin[a]) + i128::from(src_origin[a]))
                        .clamp(i128::from(i64::MIN), i128::from(i64::MAX))
                        as i64
                })
            };
            Some((mv(lo), mv(hi)))
        }) else {
            return Ok((Self::from_parts(depth, origin, Vec::new()), 0));
        };
        // Does the whole input land inside the new space?
        let side = 1i128 << depth;
        let all_inside = (0..3).all(|a| {
            i128::from(blo[a]) >= i128::from(origin[a])
                && i128::from(bhi[a]) < i128::from(origin[a]) + side
        });
        let leaves = if let Some(leaves) = self.aligned_shift(depth, delta, all_inside) {
            leaves
        } else {
            self.resample_general(depth, delta)
        };
        let out = Self::from_parts(depth, origin, leaves);
        let dropped = if all_inside {
            0
        } else {
            self.voxel_count() - out.voxel_count()
        };
        Ok((out, dropped))
    }

    /// The general top-down resample; `delta` is the new origin minus ours.
    pub(super) fn resample_general(&self, depth: u8, delta: [i64; 3]) -> Vec<Leaf> {
        let compact = self.depth >= 2 && depth >= 2;
        let mut index = Index::new(self.leaves(), self.depth, compact);
        // Wrap the input in gray ancestors until it is at least as deep as the
        // output (the input space becomes child 0 of each new root), so windows at
        // every output depth can be read from the index.
        let mut src_depth = self.depth;
        while src_depth < depth {
            let mut node = [EMPTY; 8];
            node[0] = index.root;
            index.nodes.push(node);
            index.levels.push(src_depth + 1);
            if compact {
                index.masks.push(0);
            }
            index.root = index.nodes.len() as u32 + 1;
            src_depth += 1;
        }
        if !compact {
            index.fill_masks();
        }
        let side = |k: u8| 1i64 << k;
        let r = |k: u8| -> [i64; 3] { delta.map(|v| v.rem_euclid(side(k))) };
        let tables = (0..=depth)
            .map(|k| {
                if k == 0 {
                    EMPTY_TABLE
                } else {
                    child_table(r(k), k)
                }
            })
            .collect();
        let q = delta.map(|v| v.div_euclid(side(depth)));
        let rk = r(depth);
        let window: [u32; 8] = std::array::from_fn(|e| {
            let mut cell = q;
            for a in 0..3 {
                if (e >> a) & 1 == 1 && rk[a] != 0 {
                    cell[a] += 1;
                }
            }
            index.slot_at(src_depth, cell, depth)
        });
        let resampler = Resampler {
            index: &index,
            cut: Cut::new(r(2.min(depth))),
            depth,
            input_leaves: self.leaves().len(),
            tables,
        };
        let mut out = Vec::with_capacity(self.leaves().len());
        resampler.cell(depth, window, 0, &mut out);
        out
    }

    /// When the shift between the spaces is a multiple of every leaf's side, every
    /// leaf moves whole: its code is moved by tesseral addition, the leaves outside
    /// the new space are dropped, and the rest are sorted and merged. Returns `None`
    /// when the fast path does not apply.
    pub(super) fn aligned_shift(
        &self,
        depth: u8,
        delta: [i64; 3],
        all_inside: bool,
    ) -> Option<Vec<Leaf>> {
        let max_k = self
            .leaves()
            .iter()
            .map(|l| l.size_log2())
            .max()
            .unwrap_or(0);
        // Cells of side 2^a move whole: a is the displacement's alignment, capped
        // by the new space; every leaf must fit in such a cell.
        let align = delta
            .iter()
            .map(|&v| if v == 0 { 64 } else { v.trailing_zeros() })
            .min()
            .unwrap_or(64);
        let a = align.min(u32::from(depth)) as u8;
        if max_k > a {
            return None;
        }
        let side = 1i64 << depth;
        // The tesseral sum is taken modulo 2^21 per axis; kept cells land inside
        // [0, 2^depth), where it is exact. The displacement's low `a` digits are
        // zero, so a leaf's digits below `a` ride along unchanged.
        let space = Space::<u64>::full();
        let t = space.encode_wrapping([-delta[0], -delta[1], -delta[2]]);
        let shift = 3 * u32::from(a);
        let low = (1u64 << shift) - 1;
        let inside = |cell: u64| {
            let v = code::decode(cell);
            (0..3).all(|i| {
                let c = i64::from(v[i]) - delta[i];
                c >= 0 && c < side
            })
        };
        // Runs of leaves sharing a cell, with the cell's new code.
        let mut runs: Vec<(u64, usize, usize)> = Vec::new();
        let mut rest = self.leaves();
        let mut start = 0;
        while let Some(first) = rest.first() {
            let cell = first.code() & !low;
            let end_code = cell + low + 1;
            let n = rest.partition_point(|l| l.packed() < end_code << 1);
            if all_inside || inside(cell) {
                runs.push((space.add(cell, t), start, start + n));
            }
            start += n;
            rest = &rest[n..];
        }
        if !runs.is_sorted_by_key(|r| r.0) {
            runs.sort_unstable_by_key(|r| r.0);
        }
        let mut out = Vec::with_capacity(self.leaves().len());
        for (cell, i, j) in runs {
            let part = &self.leaves()[i..j];
            if part.len() == 1 && part[0].size_log2() == a {
                // A full cell: it may complete a parent with its new neighbours.
                push_merging(&mut out, Leaf::new(cell, a));
            } else {
                // Partly full: canonical inside, and no parent can be completed.
                out.extend(
                    part.iter()
                        .map(|l| Leaf::new(cell | (l.code() & low), l.size_log2())),
                );
            }
        }
        Some(out)
    }

    /// Re-expresses the tree in a larger space that contains its own as an aligned
    /// cell (the result of root expansion); codes move by a constant, order kept.
    pub(crate) fn expand_to(&self, depth: u8, origin: Voxel) -> Self {
        if depth == self.depth && origin == self.origin {
            return self.clone();
        }
        match self.resample(depth, origin) {
            Ok((t, 0)) => t,
            _ => unreachable!("expand_to: the grown space holds the old one"),
        }
    }

    /// The tree translated by `by`, in the same lattice. The space is kept when the
    /// result fits in it; otherwise it grows by root expansion (the old root becoming
    /// a child of a new, larger root) until it does, so no voxel is ever lost.
    ///
    /// The displacement may be any integer vector, negative or not aligned to the
    /// blocks; see the module notes for the algorithm.
    ///
    /// # Runtime
    /// O(n + m) in input and output leaves (not voxels); in parallel with rayon.
    ///
    /// # Errors
    /// [`OctreeError::DepthTooLarge`] when the grown space would exceed
    /// [`super::MAX_DEPTH`]; [`OctreeError::Overflow`] when a coordinate overflows.
    ///
    /// ```
    /// use tesseral::linear::LinearOctree;
    /// let a = LinearOctree::from_voxels(2, [0, 0, 0], [[0, 0, 0], [1, 1, 1]]).unwrap();
    /// let b = a.translate([3, 0, -1]).unwrap();
    /// assert!(b.contains([3, 0, -1]) && b.contains([4, 1, 0]));
    /// assert_eq!(b.voxel_count(), 2);
    /// ```
    pub fn translate(&self, by: [i64; 3]) -> Result<Self, OctreeError> {
        let Some((lo, hi)) = self.bbox() else {
            return Ok(self.clone());
        };
        let moved_origin = add_voxel(self.origin, by)?;
        let (lo, hi) = (add_voxel(lo, by)?, add_voxel(hi, by)?);
        let (depth, origin) = grow::grown_space(self.depth, self.origin, lo, hi)?;
        let (out, dropped) = self.resample_moved(moved_origin, Some((lo, hi)), depth, origin)?;
        debug_assert_eq!(dropped, 0);
        Ok(out)
    }

    /// The tree translated by `by` within its own space: voxels that leave the
    /// space are dropped, and their number is returned with the result.
    ///
    /// # Runtime
    /// As [`LinearOctree::translate`].
    ///
    /// # Errors
    /// [`OctreeError::Overflow`] when a coordinate overflows.
    ///
    /// ```
    /// use tesseral::linear::LinearOctree;
    /// let a = LinearOctree::from_voxels(2, [0, 0, 0], [[0, 0, 0], [3, 0, 0]]).unwrap();
    /// let (b, dropped) = a.translate_clipped([1, 0, 0]).unwrap();
    /// assert_eq!((b.voxel_count(), dropped), (1, 1));
    /// ```
    pub fn translate_clipped(&self, by: [i64; 3]) -> Result<(Self, u64), OctreeError> {
        let moved_origin = add_voxel(self.origin, by)?;
        self.resample_moved(moved_origin, None, self.depth, self.origin)
    }

    /// The tree translated by `by` and written into the space `(depth, origin)`:
    /// voxels that land outside it are dropped, and their number is returned. One
    /// pass (no intermediate space); a partitioned translation moves each part
    /// straight into the whole result's space this way.
    ///
    /// # Runtime
    /// As [`LinearOctree::translate`].
    ///
    /// # Errors
    /// [`OctreeError::DepthTooLarge`] for a bad space; [`OctreeError::Overflow`]
    /// when a coordinate overflows.
    ///
    /// ```
    /// use tesseral::linear::LinearOctree;
    /// let a = LinearOctree::from_voxels(2, [0, 0, 0], [[0, 0, 0], [3, 0, 0]]).unwrap();
    /// let (b, dropped) = a.translate_into([1, 0, 0], 3, [0, 0, 0]).unwrap();
    /// assert_eq!((b.depth(), b.voxel_count(), dropped), (3, 2, 0));
    /// assert!(b.contains([4, 0, 0]));
    /// ```
    pub fn translate_into(
        &self,
        by: [i64; 3],
        depth: u8,
        origin: Voxel,
    ) -> Result<(Self, u64), OctreeError> {
        super::check_space(depth, origin)?;
        let moved_origin = add_voxel(self.origin, by)?;
        self.resample_moved(moved_origin, None, depth, origin)
    }
}

fn add_voxel(a: Voxel, b: [i64; 3]) -> Result<Voxel, OctreeError> {
    let mut out = [0; 3];
    for i in 0..3 {
        out[i] = a[i].checked_add(b[i]).ok_or(OctreeError::Overflow)?;
    }
    Ok(out)
}
