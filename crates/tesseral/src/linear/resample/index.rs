//! A pointer index of a linear octree's leaves, read by the resampler.

use super::blocks::{octant_shift, OCTANT};
use crate::linear::Leaf;

pub(super) const EMPTY: u32 = 0;
pub(super) const FULL: u32 = 1;

/// A pointer index of a linear octree: the gray nodes, each with eight child slots
/// (`EMPTY`, `FULL`, or `2 + index` of a gray child).
pub(super) struct Index {
    pub(super) nodes: Vec<[u32; 8]>,
    /// The side (log2) of each gray node's cell.
    pub(super) levels: Vec<u8>,
    /// For gray nodes of side 4: the occupancy of their 4 × 4 × 4 voxels, bit
    /// `x + 4y + 16z` (filled by [`Index::fill_masks`]).
    pub(super) masks: Vec<u64>,
    pub(super) root: u32,
}

impl Index {
    /// Builds the index in one pass over the sorted leaves, keeping the path of open
    /// gray nodes on a stack.
    ///
    /// With `compact` (for depth ≥ 2), the gray nodes of side 4 are the deepest
    /// built: leaves of side 1 and 2 go straight into their 64-bit masks, and no
    /// node of side 2 is made (they are most of the nodes, and only masks are read
    /// at those levels).
    pub(super) fn new(leaves: &[Leaf], depth: u8, compact: bool) -> Self {
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
    pub(super) fn fill_masks(&mut self) {
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
    pub(super) fn mask(&self, slot: u32) -> u64 {
        match slot {
            EMPTY => 0,
            FULL => u64::MAX,
            _ => self.masks[(slot - 2) as usize],
        }
    }

    #[inline]
    pub(super) fn child(&self, slot: u32, digit: usize) -> u32 {
        if slot < 2 {
            slot
        } else {
            self.nodes[(slot - 2) as usize][digit]
        }
    }

    /// The slot of the input cell of side `2^k` whose lowest voxel is `q · 2^k`
    /// (relative to the input's origin), in an input of depth `depth`.
    pub(super) fn slot_at(&self, depth: u8, q: [i64; 3], k: u8) -> u32 {
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
