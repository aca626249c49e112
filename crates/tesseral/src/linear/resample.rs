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

use super::{grow, push_merging, Leaf, LinearOctree, OctreeError};
use crate::code::{self, Space};
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
    ///
    /// With `compact` (for depth ≥ 2), the gray nodes of side 4 are the deepest
    /// built: leaves of side 1 and 2 go straight into their 64-bit masks, and no
    /// node of side 2 is made (they are most of the nodes, and only masks are read
    /// at those levels).
    fn new(leaves: &[Leaf], depth: u8, compact: bool) -> Self {
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
        let mut masks: Vec<u64> = Vec::new();
        nodes.push([EMPTY; 8]);
        levels.push(depth);
        if compact {
            masks.reserve(leaves.len() / 6 + 1);
            masks.push(0);
        }
        debug_assert!(!compact || depth >= 2);
        // In compact mode, leaves below side 4 are held by the node of side 4.
        let holder = if compact { d - 1 } else { d + 1 };
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
            let small = leaf_depth >= holder;
            let target = if small { holder } else { leaf_depth };
            let keep = common.min(target - 1) as usize + 1;
            stack.truncate(keep);
            while (stack.len() as u32) < target {
                let parent = *stack.last().expect("root stays on the stack") as usize;
                let digit = (c >> (3 * (d - stack.len() as u32))) & 7;
                let id = nodes.len() as u32;
                nodes.push([EMPTY; 8]);
                levels.push(depth - stack.len() as u8);
                if compact {
                    masks.push(0);
                }
                nodes[parent][digit as usize] = id + 2;
                stack.push(id);
            }
            let parent = *stack.last().expect("root stays on the stack") as usize;
            if small {
                let base = octant_shift(((c >> 3) & 7) as usize);
                masks[parent] |= if leaf.size_log2() == 1 {
                    OCTANT << base
                } else {
                    1 << (base + octant_shift((c & 7) as usize) / 2)
                };
                prev = c;
                continue;
            }
            let digit = (c >> (3 * (d - leaf_depth))) & 7;
            nodes[parent][digit as usize] = FULL;
            prev = c;
        }
        Self {
            nodes,
            levels,
            masks,
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

/// How to cut a 4 × 4 × 4 block at offset `r` (each in 0..4) out of the 8 × 8 × 8
/// region of eight blocks: the shifts and the masks of the bits that come from the
/// lower block on each axis, computed once per resample.
#[derive(Clone, Copy)]
struct Cut {
    r: [u32; 3],
    low_x: u64,
    low_y: u64,
}

impl Cut {
    fn new(r: [i64; 3]) -> Self {
        let r = r.map(|v| v as u32);
        Self {
            r,
            low_x: repeat((1 << (4 - r[0])) - 1, 4),
            low_y: repeat((1 << (4 * (4 - r[1]))) - 1, 16),
        }
    }

    /// The block, from the eight blocks `m` (index `x + 2y + 4z`), all in layout
    /// `x + 4y + 16z`.
    #[inline]
    fn extract(&self, m: [u64; 8]) -> u64 {
        let [rx, ry, rz] = self.r;
        let sx = |a: u64, b: u64| -> u64 {
            if rx == 0 {
                a
            } else {
                ((a >> rx) & self.low_x) | ((b << (4 - rx)) & !self.low_x)
            }
        };
        let sy = |a: u64, b: u64| -> u64 {
            if ry == 0 {
                a
            } else {
                ((a >> (4 * ry)) & self.low_y) | ((b << (4 * (4 - ry))) & !self.low_y)
            }
        };
        let p0 = sy(sx(m[0], m[1]), sx(m[2], m[3]));
        if rz == 0 {
            return p0;
        }
        let p1 = sy(sx(m[4], m[5]), sx(m[6], m[7]));
        (p0 >> (16 * rz)) | (p1 << (16 * (4 - rz)))
    }
}

/// Appends the canonical leaves of a 4 × 4 × 4 block (bit `x + 4y + 16z`) whose
/// lowest voxel has code `code`.
#[inline]
fn emit_block(block: u64, code: u64, out: &mut Vec<Leaf>) {
    if block == u64::MAX {
        out.push(Leaf::new(code, 2));
        return;
    }
    if block == 0 {
        return;
    }
    for d in 0..8usize {
        let x = block >> octant_shift(d);
        // The octant's eight voxels as a byte, bit e for voxel label e.
        let byte = (x & 0x3) | ((x >> 2) & 0xc) | ((x >> 12) & 0x30) | ((x >> 14) & 0xc0);
        let c = code + 8 * d as u64;
        if byte == 0xff {
            out.push(Leaf::new(c, 1));
            continue;
        }
        let mut bits = byte;
        while bits != 0 {
            let e = u64::from(bits.trailing_zeros());
            out.push(Leaf::new(c + e, 0));
            bits &= bits - 1;
        }
    }
}

/// For one depth: which parent-window entry and which child digit each of the eight
/// window entries of each of the eight children reads.
/// Children's windows are drawn from a 3 × 3 × 3 grid of input cells of half the
/// side (the parent window's children that the children's preimages can touch).
#[derive(Clone, Copy)]
struct ChildTable {
    /// For each grid cell: the parent-window entry and the child digit it is.
    grid: [(u8, u8); 27],
    /// For each child and each of its window entries: the grid cell.
    pick: [[u8; 8]; 8],
}

const EMPTY_TABLE: ChildTable = ChildTable {
    grid: [(0, 0); 27],
    pick: [[0; 8]; 8],
};

fn child_table(r: [i64; 3], k: u8) -> ChildTable {
    // r: the offset of the preimage inside window cell 0 at depth k (side 2^k).
    // Along each axis the children's cells are u = base + d + e in the 4-wide grid
    // of the parent window's children, base = r >> (k - 1); g = u - base is 0..=2.
    let half = 1i64 << (k - 1);
    let mut t = EMPTY_TABLE;
    for (g, entry) in t.grid.iter_mut().enumerate() {
        let (mut parent, mut digit) = (0u8, 0u8);
        for (a, ga) in [g % 3, (g / 3) % 3, g / 9].into_iter().enumerate() {
            let u = (r[a] >> (k - 1)) + ga as i64;
            // u can reach 4 only for a grid cell no child picks: clamp it.
            let u = u.min(3);
            parent |= ((u >> 1) as u8) << a;
            digit |= ((u & 1) as u8) << a;
        }
        *entry = (parent, digit);
    }
    for (d, row) in t.pick.iter_mut().enumerate() {
        for (e, entry) in row.iter_mut().enumerate() {
            let mut g = 0;
            for (a, scale) in [1usize, 3, 9].into_iter().enumerate() {
                let da = (d >> a) & 1;
                let mut ea = (e >> a) & 1;
                // An aligned axis needs one cell: duplicate entry 0.
                if r[a] % half == 0 {
                    ea = 0;
                }
                g += (da + ea) * scale;
            }
            *entry = g as u8;
        }
    }
    t
}

/// Below this output cell size (log2) the recursion runs on one thread (the top
/// three levels of a depth-9 space give 73 tasks).
const PARALLEL_MIN_SIZE_LOG2: u8 = 7;

struct Resampler<'a> {
    index: &'a Index,
    /// Cuts a child's 4 × 4 × 4 block out of its window at side 4.
    cut: Cut,
    /// The output depth and the input's leaf count: a guess at each parallel
    /// part's size, so that parts rarely reallocate.
    depth: u8,
    input_leaves: usize,
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
            emit_block(self.cut.extract(m), code, out);
            return;
        }
        let table = &self.tables[usize::from(k)];
        let child_cells = 1u64 << (3 * u32::from(k - 1));
        let mut grid = [EMPTY; 27];
        for (slot, &(p, digit)) in grid.iter_mut().zip(table.grid.iter()) {
            *slot = self.index.child(window[usize::from(p)], usize::from(digit));
        }
        if k == 3 {
            // The children are 4 x 4 x 4 blocks: read the grid's occupancy masks
            // once and cut each child's block out of them directly.
            let mut masks = [0u64; 27];
            for (m, &slot) in masks.iter_mut().zip(grid.iter()) {
                *m = self.index.mask(slot);
            }
            for (d, row) in table.pick.iter().enumerate() {
                let mut m = [0u64; 8];
                for (mask, &g) in m.iter_mut().zip(row.iter()) {
                    *mask = masks[usize::from(g)];
                }
                emit_block(self.cut.extract(m), code + 64 * d as u64, out);
            }
            if let Some(last) = out.pop() {
                push_merging(out, last);
            }
            return;
        }
        let mut windows = [[EMPTY; 8]; 8];
        for (row, w) in table.pick.iter().zip(windows.iter_mut()) {
            for (&g, slot) in row.iter().zip(w.iter_mut()) {
                *slot = grid[usize::from(g)];
            }
        }
        if k >= PARALLEL_MIN_SIZE_LOG2 {
            let parts: Vec<Vec<Leaf>> = (0..8usize)
                .into_par_iter()
                .map(|d| {
                    let share = self.input_leaves >> (3 * u32::from(self.depth - k + 1));
                    let mut part = Vec::with_capacity(share + share / 4 + 16);
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
        let mut index = Index::new(&self.leaves, self.depth, compact);
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
            input_leaves: self.leaves.len(),
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
        let mut rest = &self.leaves[..];
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
        let mut out = Vec::with_capacity(self.leaves.len());
        for (cell, i, j) in runs {
            let part = &self.leaves[i..j];
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
}

fn add_voxel(a: Voxel, b: [i64; 3]) -> Result<Voxel, OctreeError> {
    let mut out = [0; 3];
    for i in 0..3 {
        out[i] = a[i].checked_add(b[i]).ok_or(OctreeError::Overflow)?;
    }
    Ok(out)
}
