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

use rayon::prelude::*;

use super::{arith, grow, push_merging, Leaf, LinearOctree, OctreeError};
use crate::code;
use crate::Voxel;

const EMPTY: u32 = 0;
const FULL: u32 = 1;

/// A pointer index of a linear octree: the gray nodes, each with eight child slots
/// (`EMPTY`, `FULL`, or `2 + index` of a gray child).
struct Index {
    nodes: Vec<[u32; 8]>,
    root: u32,
}

impl Index {
    /// Builds the index in one pass over the sorted leaves, keeping the path of open
    /// gray nodes on a stack.
    fn new(leaves: &[Leaf], depth: u8) -> Self {
        let Some(first) = leaves.first() else {
            return Self {
                nodes: Vec::new(),
                root: EMPTY,
            };
        };
        if first.size_log2() >= depth {
            return Self {
                nodes: Vec::new(),
                root: FULL,
            };
        }
        let d = u32::from(depth);
        let mut nodes: Vec<[u32; 8]> = Vec::with_capacity(leaves.len() / 3 + 1);
        nodes.push([EMPTY; 8]);
        let mut stack: Vec<u32> = Vec::with_capacity(usize::from(depth) + 1);
        stack.push(0);
        let mut prev = first.code();
        for leaf in leaves {
            let c = leaf.code();
            let leaf_depth = d - u32::from(leaf.size_log2());
            let diff = c ^ prev;
            let common = if diff == 0 {
                d
            } else {
                d - 1 - (63 - diff.leading_zeros()) / 3
            };
            let keep = common.min(leaf_depth - 1) as usize + 1;
            stack.truncate(keep);
            while (stack.len() as u32) < leaf_depth {
                let parent = *stack.last().expect("root stays on the stack") as usize;
                let digit = (c >> (3 * (d - stack.len() as u32))) & 7;
                let id = nodes.len() as u32;
                nodes.push([EMPTY; 8]);
                nodes[parent][digit as usize] = id + 2;
                stack.push(id);
            }
            let parent = *stack.last().expect("root stays on the stack") as usize;
            let digit = (c >> (3 * (d - leaf_depth))) & 7;
            nodes[parent][digit as usize] = FULL;
            prev = c;
        }
        Self { nodes, root: 2 }
    }

    #[inline]
    fn child(&self, slot: u32, digit: usize) -> u32 {
        if slot < 2 {
            slot
        } else {
            self.nodes[(slot - 2) as usize][digit]
        }
    }

    /// The slot of the input cell of side `2^k` whose lowest voxel is `q · 2^k`
    /// (relative to the input's origin), in an input of depth `depth`.
    fn slot_at(&self, depth: u8, q: [i64; 3], k: u8) -> u32 {
        debug_assert!(k <= depth);
        let side = 1i64 << (depth - k);
        if q.iter().any(|&v| v < 0 || v >= side) {
            return EMPTY;
        }
        let mut slot = self.root;
        for level in (k..depth).rev() {
            if slot < 2 {
                return slot;
            }
            let shift = level - k;
            let digit =
                ((q[0] >> shift) & 1) | (((q[1] >> shift) & 1) << 1) | (((q[2] >> shift) & 1) << 2);
            slot = self.child(slot, digit as usize);
        }
        slot
    }
}

/// For one depth: which parent-window entry and which child digit each of the eight
/// window entries of each of the eight children reads.
type ChildTable = [[(u8, u8); 8]; 8];

fn child_table(r: [i64; 3], k: u8) -> ChildTable {
    // r: the offset of the preimage inside window cell 0 at depth k (side 2^k).
    let half = 1i64 << (k - 1);
    let mut t = [[(0u8, 0u8); 8]; 8];
    for (d, row) in t.iter_mut().enumerate() {
        for (e, entry) in row.iter_mut().enumerate() {
            let (mut parent, mut digit) = (0u8, 0u8);
            for a in 0..3 {
                let da = ((d >> a) & 1) as i64;
                let mut ea = ((e >> a) & 1) as i64;
                // An aligned axis needs one cell: duplicate entry 0.
                if r[a] % half == 0 {
                    ea = 0;
                }
                let u = (r[a] >> (k - 1)) + da + ea;
                parent |= ((u >> 1) as u8) << a;
                digit |= ((u & 1) as u8) << a;
            }
            *entry = (parent, digit);
        }
    }
    t
}

/// Below this output cell size (log2) the recursion runs on one thread.
const PARALLEL_MIN_SIZE_LOG2: u8 = 5;

struct Resampler<'a> {
    index: &'a Index,
    /// `tables[k]` serves the children of an output cell of side `2^k`.
    tables: Vec<ChildTable>,
}

impl Resampler<'_> {
    fn cell(&self, k: u8, window: [u32; 8], code: u64, out: &mut Vec<Leaf>) {
        if window.iter().all(|&s| s == FULL) {
            out.push(Leaf::new(code, k));
            return;
        }
        if window.iter().all(|&s| s == EMPTY) {
            return;
        }
        debug_assert!(k > 0, "a voxel's window is always full or empty");
        let table = &self.tables[usize::from(k)];
        let child_cells = 1u64 << (3 * u32::from(k - 1));
        let windows: [[u32; 8]; 8] = std::array::from_fn(|d| {
            std::array::from_fn(|e| {
                let (p, digit) = table[d][e];
                self.index.child(window[usize::from(p)], usize::from(digit))
            })
        });
        if k >= PARALLEL_MIN_SIZE_LOG2 {
            let parts: Vec<Vec<Leaf>> = (0..8usize)
                .into_par_iter()
                .map(|d| {
                    let mut part = Vec::new();
                    self.cell(k - 1, windows[d], code + d as u64 * child_cells, &mut part);
                    part
                })
                .collect();
            for part in parts {
                out.extend(part);
            }
        } else {
            for (d, w) in windows.into_iter().enumerate() {
                self.cell(k - 1, w, code + d as u64 * child_cells, out);
            }
        }
        if let Some(last) = out.pop() {
            push_merging(out, last);
        }
    }
}

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
        super::check_depth(depth)?;
        if depth == self.depth && origin == self.origin {
            return Ok((self.clone(), 0));
        }
        let mut delta = [0i64; 3];
        for a in 0..3 {
            delta[a] = origin[a]
                .checked_sub(self.origin[a])
                .ok_or(OctreeError::Overflow)?;
        }
        let leaves = if self.is_empty() {
            Vec::new()
        } else if let Some(leaves) = self.aligned_shift(depth, delta) {
            leaves
        } else {
            self.resample_general(depth, delta)
        };
        let out = Self::from_parts(depth, origin, leaves);
        let dropped = self.voxel_count() - out.voxel_count();
        Ok((out, dropped))
    }

    /// The general top-down resample; `delta` is the new origin minus ours.
    pub(super) fn resample_general(&self, depth: u8, delta: [i64; 3]) -> Vec<Leaf> {
        let mut index = Index::new(&self.leaves, self.depth);
        // Wrap the input in gray ancestors until it is at least as deep as the
        // output (the input space becomes child 0 of each new root), so windows at
        // every output depth can be read from the index.
        let mut src_depth = self.depth;
        while src_depth < depth {
            let mut node = [EMPTY; 8];
            node[0] = index.root;
            index.nodes.push(node);
            index.root = index.nodes.len() as u32 + 1;
            src_depth += 1;
        }
        let side = |k: u8| 1i64 << k;
        let r = |k: u8| -> [i64; 3] { delta.map(|v| v.rem_euclid(side(k))) };
        let tables = (0..=depth)
            .map(|k| {
                if k == 0 {
                    [[(0, 0); 8]; 8]
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
            tables,
        };
        let mut out = Vec::with_capacity(self.leaves.len());
        resampler.cell(depth, window, 0, &mut out);
        out
    }

    /// When the shift between the spaces is a multiple of every leaf's side, every
    /// leaf moves whole: its code is moved by tesseral addition, the leaves outside
    /// the new space are dropped, and the rest are sorted and merged. Returns `None`
    /// when the fast path does not apply.
    pub(super) fn aligned_shift(&self, depth: u8, delta: [i64; 3]) -> Option<Vec<Leaf>> {
        let max_k = self.leaves.iter().map(|l| l.size_log2()).max().unwrap_or(0);
        if delta.iter().any(|&v| v.rem_euclid(1 << max_k) != 0) {
            return None;
        }
        // New relative coordinate = old - delta, kept when inside [0, 2^depth).
        let lo = delta;
        let side = 1i64 << depth;
        // A leaf larger than the new space would be cut: not this path.
        if max_k > depth {
            return None;
        }
        // Kept leaves land inside [0, 2^depth), so the 21-bit modular tesseral sum
        // is exact for them.
        let t = arith::displacement_code([-delta[0], -delta[1], -delta[2]]);
        let inside = |l: &Leaf| {
            let v = code::decode(l.code());
            (0..3).all(|a| {
                let c = i64::from(v[a]) - lo[a];
                c >= 0 && c < side
            })
        };
        let mut moved: Vec<Leaf> = self
            .leaves
            .iter()
            .filter(|l| inside(l))
            .map(|l| Leaf::new(arith::add(l.code(), t), l.size_log2()))
            .collect();
        if !moved.is_sorted() {
            super::sort::sort_leaves(&mut moved);
        }
        let mut out = Vec::with_capacity(moved.len());
        for l in moved {
            push_merging(&mut out, l);
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
        let moved = Self::from_parts(self.depth, moved_origin, self.leaves.clone());
        let (out, dropped) = moved.resample(depth, origin)?;
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
        let moved = Self::from_parts(self.depth, moved_origin, self.leaves.clone());
        moved.resample(self.depth, self.origin)
    }
}

fn add_voxel(a: Voxel, b: [i64; 3]) -> Result<Voxel, OctreeError> {
    let mut out = [0; 3];
    for i in 0..3 {
        out[i] = a[i].checked_add(b[i]).ok_or(OctreeError::Overflow)?;
    }
    Ok(out)
}
