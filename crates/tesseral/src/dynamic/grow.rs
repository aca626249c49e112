//! Root expansion and contraction (Libes §3).

#[allow(unused_imports)]
use super::*;

impl DynamicOctree {
    // ----- root expansion and contraction (Libes §3) ---------------------------------

    /// Grows the root ×8 towards `v`: the old root becomes a child of the new one.
    pub(super) fn expand(&mut self, v: Voxel) {
        let k = self.size_log2;
        debug_assert!(k < 64);
        let size = 1u64 << k;
        let mut ci = 0usize;
        for a in 0..3 {
            if v[a] < self.root_min[a] {
                self.root_min[a] = self.root_min[a].wrapping_sub(size as i64);
                ci |= 1 << a;
            }
        }
        if k >= LEAF_LOG2 {
            let old = self.root;
            let n = self.alloc_node(NONE, EMPTY);
            self.nodes[n as usize].child[ci] = old;
            self.set_parent(old, k, n);
            self.root = n;
        } else {
            // The logical root is the low corner of the root block: growing towards −
            // moves the content up inside the block.
            let l = &mut self.leaves[self.root as usize].0;
            for a in 0..3 {
                if ci >> a & 1 == 1 {
                    shift_leaf(l, a, size, true);
                }
            }
        }
        self.size_log2 = k + 1;
        self.expansions += 1;
    }

    /// Shrinks the root while all content lies inside one of its children.
    /// Returns whether it did.
    pub(super) fn contract(&mut self) -> bool {
        let mut changed = false;
        loop {
            let k = self.size_log2;
            if k == 0 || self.root == FULL || self.root == EMPTY {
                return changed;
            }
            let half = 1u64 << (k - 1);
            if k > LEAF_LOG2 {
                let n = self.root as usize;
                let ch = self.nodes[n].child;
                let mut only = 0;
                let mut count = 0;
                for (i, &c) in ch.iter().enumerate() {
                    if c != EMPTY {
                        count += 1;
                        only = i;
                    }
                }
                if count != 1 {
                    return changed;
                }
                for a in 0..3 {
                    if only >> a & 1 == 1 {
                        self.root_min[a] = self.root_min[a].wrapping_add(half as i64);
                    }
                }
                let c = ch[only];
                self.free_node(n as u32);
                self.root = c;
                self.set_parent(c, k - 1, NONE);
                if k - 1 == LEAF_LOG2 && is_small(c) {
                    // A root block is always a bitmap block (it shifts inside).
                    self.promote(c, NONE, 0, [0; 3]);
                }
            } else {
                let l = &mut self.leaves[self.root as usize].0;
                let masks = leaf_axis_masks(l);
                let low = (1u16 << half) - 1;
                let mut oct = [false; 3];
                for a in 0..3 {
                    let m = u16::from(masks[a]);
                    let (lo, hi) = (m & low != 0, m >> half != 0);
                    if lo && hi {
                        return changed;
                    }
                    oct[a] = hi;
                }
                for a in 0..3 {
                    if oct[a] {
                        shift_leaf(l, a, half, false);
                        self.root_min[a] = self.root_min[a].wrapping_add(half as i64);
                    }
                }
            }
            self.size_log2 = k - 1;
            self.contractions += 1;
            changed = true;
        }
    }
}
