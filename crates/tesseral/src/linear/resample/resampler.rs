//! The top-down recursion over output cells, each with its window of input slots.

use rayon::prelude::*;

use super::blocks::{emit_block, Cut};
use super::index::{Index, EMPTY, FULL};
use crate::linear::{push_merging, Leaf};

/// For one depth: which parent-window entry and which child digit each of the eight
/// window entries of each of the eight children reads.
/// Children's windows are drawn from a 3 × 3 × 3 grid of input cells of half the
/// side (the parent window's children that the children's preimages can touch).
#[derive(Clone, Copy)]
pub(super) struct ChildTable {
    /// For each grid cell: the parent-window entry and the child digit it is.
    grid: [(u8, u8); 27],
    /// For each child and each of its window entries: the grid cell.
    pick: [[u8; 8]; 8],
}

pub(super) const EMPTY_TABLE: ChildTable = ChildTable {
    grid: [(0, 0); 27],
    pick: [[0; 8]; 8],
};

pub(super) fn child_table(r: [i64; 3], k: u8) -> ChildTable {
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

pub(super) struct Resampler<'a> {
    pub(super) index: &'a Index,
    /// Cuts a child's 4 × 4 × 4 block out of its window at side 4.
    pub(super) cut: Cut,
    /// The output depth and the input's leaf count: a guess at each parallel
    /// part's size, so that parts rarely reallocate.
    pub(super) depth: u8,
    pub(super) input_leaves: usize,
    /// `tables[k]` serves the children of an output cell of side `2^k`.
    pub(super) tables: Vec<ChildTable>,
}

impl Resampler<'_> {
    pub(super) fn cell(&self, k: u8, window: [u32; 8], code: u64, out: &mut Vec<Leaf>) {
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
