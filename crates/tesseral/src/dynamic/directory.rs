//! Child slots, parent links and the dense directory of the slots a few levels below the root; offsets from the root corner.

#[allow(unused_imports)]
use super::*;

impl DynamicOctree {
    /// Writes `val` into child slot `ci` of `parent` (the root slot when `parent` is
    /// NONE). The slot is at `level` and contains offsets `u`; the directory follows.
    #[inline]
    pub(super) fn set_slot(&mut self, parent: u32, ci: usize, val: u32, level: u32, u: [u64; 3]) {
        if parent == NONE {
            self.root = val;
        } else {
            self.nodes[parent as usize].child[ci] = val;
        }
        if self.dir_levels > 0 && level >= self.dir_level {
            let i = self.dir_index(u);
            if level == self.dir_level {
                self.dir[i] = val;
            } else if !is_index(val) {
                // A uniform octant above the directory level: all its entries. (A
                // node stored there holds the uniform value it replaced, which the
                // entries already show.)
                let span = 1usize << (3 * (level - self.dir_level));
                let base = i & !(span - 1);
                self.dir[base..base + span].fill(val);
            }
        }
    }

    /// The directory entry of offsets `u` (inside the root).
    #[inline(always)]
    pub(super) fn dir_index(&self, u: [u64; 3]) -> usize {
        let d = self.dir_level;
        let spread = |x: u64| SPREAD[(x >> d & 255) as usize] as usize;
        spread(u[0]) | spread(u[1]) << 1 | spread(u[2]) << 2
    }

    /// Rebuilds the directory after the root changed (expansion, contraction, a new
    /// or emptied tree) or the tree outgrew it or shrank well below it. It skips
    /// `t ≤ DIR_MAX_LEVELS` levels, the most for which `8^t ≤ 8 · stored nodes` and
    /// the directory level stays at or above the blocks. O(8^t), at most 262,144
    /// entries (tens of microseconds).
    pub(super) fn rebuild_dir(&mut self) {
        let live = self.node_count();
        let mut t = 0;
        while t < self.dir_max_levels() && 1usize << (3 * (t + 1)) <= 8 * live {
            t += 1;
        }
        self.dir_levels = t;
        self.dir_level = self.phys_log2() - t;
        let mut dir = Vec::new();
        if t > 0 {
            dir.resize(1 << (3 * t), EMPTY);
            self.fill_dir(&mut dir, self.root, self.phys_log2(), 0);
        }
        self.dir = dir;
    }

    /// The most levels the directory may skip in a root of this size: it stays at or
    /// above the blocks.
    pub(super) fn dir_max_levels(&self) -> u32 {
        (self.phys_log2() - LEAF_LOG2).min(DIR_MAX_LEVELS)
    }

    /// Writes into `dir` (entries of `self.dir_level`) the entries under `slot` at
    /// `level`, from entry `base`.
    pub(super) fn fill_dir(&self, dir: &mut [u32], slot: u32, level: u32, base: usize) {
        if level == self.dir_level || !is_index(slot) {
            let span = 1usize << (3 * (level - self.dir_level));
            dir[base..base + span].fill(slot);
        } else {
            let step = 1usize << (3 * (level - 1 - self.dir_level));
            for (ci, &c) in self.nodes[slot as usize].child.iter().enumerate() {
                self.fill_dir(dir, c, level - 1, base + ci * step);
            }
        }
    }

    /// Rebuilds the directory when the tree has grown eightfold since it was built
    /// (and a deeper one is allowed), or holds less than one stored node per 64
    /// entries.
    #[inline]
    pub(super) fn check_dir_size(&mut self) {
        let live = self.node_count();
        let entries = 1usize << (3 * self.dir_levels);
        let grown = self.dir_levels < self.dir_max_levels() && live >= entries;
        if grown || live < entries / 64 {
            self.rebuild_dir();
        }
    }

    /// Sets the parent link of the stored child `slot` at `level`.
    pub(super) fn set_parent(&mut self, slot: u32, level: u32, parent: u32) {
        if is_index(slot) {
            if level > LEAF_LOG2 {
                self.nodes.parent[slot as usize] = parent;
            } else if is_small(slot) {
                self.small.parent[(slot & !SMALL) as usize] = parent;
            } else {
                self.leaves.parent[slot as usize] = parent;
            }
        }
    }

    #[inline]
    pub(super) fn offsets(&self, v: Voxel) -> [u64; 3] {
        [
            (v[0] as u64).wrapping_sub(self.root_min[0] as u64),
            (v[1] as u64).wrapping_sub(self.root_min[1] as u64),
            (v[2] as u64).wrapping_sub(self.root_min[2] as u64),
        ]
    }

    #[inline]
    pub(super) fn phys_log2(&self) -> u32 {
        self.size_log2.max(LEAF_LOG2)
    }

    #[inline]
    pub(super) fn world(&self, u: [u64; 3]) -> Voxel {
        [
            self.root_min[0].wrapping_add(u[0] as i64),
            self.root_min[1].wrapping_add(u[1] as i64),
            self.root_min[2].wrapping_add(u[2] as i64),
        ]
    }
}
