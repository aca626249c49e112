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

// Per-axis loops index several arrays at once.
#![allow(clippy::needless_range_loop)]

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
    /// The side (log2) of each gray node's cell.
    levels: Vec<u8>,
    /// For gray nodes of side 4: the occupancy of their 4 × 4 × 4 voxels, bit
    /// `x + 4y + 16z` (filled by [`Index::fill_masks`]).
    masks: Vec<u64>,
    root: u32,
}

impl Index {
    /// Builds the index in one pass over the sorted leaves, keeping the path of open
    /// gray nodes on a stack.
    fn new(leaves: &[Leaf], depth: u8) -> Self {
        let Some(first) = leaves.first() else {
            return Self {
                nodes: Vec::new(),
                levels: Vec::new(),
                masks: Vec::new(),
                root: EMPTY,
            };
        };
        if first.size_log2() >= depth {
            return Self {
                nodes: Vec::new(),
                levels: Vec::new(),
                masks: Vec::new(),
                root: FULL,
            };
        }
        let d = u32::from(depth);
        let mut nodes: Vec<[u32; 8]> = Vec::with_capacity(leaves.len() / 3 + 1);
        let mut levels: Vec<u8> = Vec::with_capacity(leaves.len() / 3 + 1);
        nodes.push([EMPTY; 8]);
        levels.push(depth);
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
                levels.push(depth - stack.len() as u8);
                nodes[parent][digit as usize] = id + 2;
                stack.push(id);
            }
            let parent = *stack.last().expect("root stays on the stack") as usize;
            let digit = (c >> (3 * (d - leaf_depth))) & 7;
            nodes[parent][digit as usize] = FULL;
            prev = c;
        }
        Self {
            nodes,
            levels,
            masks: Vec::new(),
            root: 2,
        }
    }

    /// Computes the 64-bit occupancy of every gray node of side 4.
    fn fill_masks(&mut self) {
        self.masks = vec![0; self.nodes.len()];
        for id in 0..self.nodes.len() {
            if self.levels[id] != 2 {
                continue;
            }
            let mut mask = 0u64;
            for (d, &c) in self.nodes[id].iter().enumerate() {
                let base = octant_shift(d);
                if c == FULL {
                    mask |= OCTANT << base;
                } else if c >= 2 {
                    for (e, &g) in self.nodes[(c - 2) as usize].iter().enumerate() {
                        if g == FULL {
                            mask |= 1 << (base + octant_shift(e) / 2);
                        }
                    }
                }
            }
            self.masks[id] = mask;
        }
    }

    #[inline]
    fn mask(&self, slot: u32) -> u64 {
        match slot {
            EMPTY => 0,
            FULL => u64::MAX,
            _ => self.masks[(slot - 2) as usize],
        }
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

/// The voxels of the 2 × 2 × 2 octant 0 of a 4 × 4 × 4 block, bit `x + 4y + 16z`.
const OCTANT: u64 = 0x0033_0033;

/// The bit offset of octant `d` (label `x + 2y + 4z`) in a 4 × 4 × 4 block; half of
/// it is the offset of voxel `d` within an octant.
#[inline]
fn octant_shift(d: usize) -> u32 {
    (2 * (d & 1) + 8 * ((d >> 1) & 1) + 32 * ((d >> 2) & 1)) as u32
}

/// `n` copies of a `width`-bit pattern, every `width` bits of a u64.
const fn repeat(pattern: u64, width: u32) -> u64 {
    let mut out = 0;
    let mut i = 0;
    while i < 64 {
        out |= pattern << i;
        i += width;
    }
    out
}

/// The 4 × 4 × 4 block at offset `r` (each in 0..4) inside the 8 × 8 × 8 region
/// made of the eight blocks `m` (index `x + 2y + 4z`), all in layout `x + 4y + 16z`.
#[inline]
fn extract(m: [u64; 8], r: [i64; 3]) -> u64 {
    let sx = |a: u64, b: u64| -> u64 {
        let r = r[0] as u32;
        if r == 0 {
            return a;
        }
        let low = repeat((1 << (4 - r)) - 1, 4);
        ((a >> r) & low) | ((b << (4 - r)) & !low)
    };
    let sy = |a: u64, b: u64| -> u64 {
        let r = r[1] as u32;
        if r == 0 {
            return a;
        }
        let low = repeat((1 << (4 * (4 - r))) - 1, 16);
        ((a >> (4 * r)) & low) | ((b << (4 * (4 - r))) & !low)
    };
    let sz = |a: u64, b: u64| -> u64 {
        let r = r[2] as u32;
        if r == 0 {
            return a;
        }
        (a >> (16 * r)) | (b << (16 * (4 - r)))
    };
    let p0 = sy(sx(m[0], m[1]), sx(m[2], m[3]));
    let p1 = sy(sx(m[4], m[5]), sx(m[6], m[7]));
    sz(p0, p1)
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

/// Below this output cell size (log2) the recursion runs on one thread (the top
/// three levels of a depth-9 space give 73 tasks).
const PARALLEL_MIN_SIZE_LOG2: u8 = 7;

struct Resampler<'a> {
    index: &'a Index,
    /// The offset of the preimage in its window at side 4.
    r2: [i64; 3],
    /// `tables[k]` serves the children of an output cell of side `2^k`.
    tables: Vec<ChildTable>,
}

impl Resampler<'_> {
    fn cell(&self, k: u8, window: [u32; 8], code: u64, out: &mut Vec<Leaf>) {
        if window == [FULL; 8] {
            out.push(Leaf::new(code, k));
            return;
        }
        if window == [EMPTY; 8] {
            return;
        }
        debug_assert!(k > 0, "a voxel's window is always full or empty");
        if k == 2 {
            // The last two levels at once, on 64-bit occupancy masks.
            let mut m = [0u64; 8];
            for (mask, &slot) in m.iter_mut().zip(window.iter()) {
                *mask = self.index.mask(slot);
            }
            let block = extract(m, self.r2);
            if block == u64::MAX {
                out.push(Leaf::new(code, 2));
            } else if block != 0 {
                for d in 0..8usize {
                    let oct = OCTANT << octant_shift(d);
                    let c = code + 8 * d as u64;
                    if block & oct == oct {
                        out.push(Leaf::new(c, 1));
                    } else if block & oct != 0 {
                        for e in 0..8usize {
                            if block >> (octant_shift(d) + octant_shift(e) / 2) & 1 == 1 {
                                out.push(Leaf::new(c + e as u64, 0));
                            }
                        }
                    }
                }
            }
            return;
        }
        let table = &self.tables[usize::from(k)];
        let child_cells = 1u64 << (3 * u32::from(k - 1));
        let mut windows = [[EMPTY; 8]; 8];
        for (row, w) in table.iter().zip(windows.iter_mut()) {
            for (&(p, digit), slot) in row.iter().zip(w.iter_mut()) {
                *slot = self.index.child(window[usize::from(p)], usize::from(digit));
            }
        }
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
        let mut index = Index::new(&self.leaves, self.depth);
        // Wrap the input in gray ancestors until it is at least as deep as the
        // output (the input space becomes child 0 of each new root), so windows at
        // every output depth can be read from the index.
        let mut src_depth = self.depth;
        while src_depth < depth {
            let mut node = [EMPTY; 8];
            node[0] = index.root;
            index.nodes.push(node);
            index.levels.push(src_depth + 1);
            index.root = index.nodes.len() as u32 + 1;
            src_depth += 1;
        }
        index.fill_masks();
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
            r2: r(2.min(depth)),
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
    pub(super) fn aligned_shift(
        &self,
        depth: u8,
        delta: [i64; 3],
        all_inside: bool,
    ) -> Option<Vec<Leaf>> {
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
        let mut moved: Vec<Leaf> = if all_inside {
            self.leaves
                .iter()
                .map(|l| Leaf::new(arith::add(l.code(), t), l.size_log2()))
                .collect()
        } else {
            self.leaves
                .iter()
                .filter(|l| inside(l))
                .map(|l| Leaf::new(arith::add(l.code(), t), l.size_log2()))
                .collect()
        };
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
}

fn add_voxel(a: Voxel, b: [i64; 3]) -> Result<Voxel, OctreeError> {
    let mut out = [0; 3];
    for i in 0..3 {
        out[i] = a[i].checked_add(b[i]).ok_or(OctreeError::Overflow)?;
    }
    Ok(out)
}
