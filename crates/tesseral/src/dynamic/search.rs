//! Search and neighbourhoods (Libes §5): `contains`, `find`, `find_from`, the 27-neighbourhood.

#[allow(unused_imports)]
use super::*;

impl DynamicOctree {
    // ----- search (Libes §5) ----------------------------------------------------------

    /// Whether voxel `v` is black. O(depth), no allocation.
    ///
    /// ```
    /// let mut t = tesseral::dynamic::DynamicOctree::new();
    /// t.insert([-7, 0, 1 << 40]);
    /// assert!(t.contains([-7, 0, 1 << 40]));
    /// assert!(!t.contains([-7, 0, 0]));
    /// ```
    #[inline]
    #[must_use]
    pub fn contains(&self, v: Voxel) -> bool {
        let u = self.offsets(v);
        if !within(u, self.phys_log2()) {
            return false;
        }
        self.block_has(self.block_slot(u), u)
    }

    /// The slot at block level on the path to offsets `u` (inside the root): a stored
    /// block, or the sentinel [`EMPTY`] or [`FULL`] when an empty or full octant holds
    /// `u` (an empty tree's root is [`EMPTY`]). The sentinels make this a straight
    /// chain of loads with no test per level; the child indices of up to eight levels
    /// come from one interleaved word. O(depth).
    #[inline(always)]
    pub(super) fn block_slot(&self, u: [u64; 3]) -> u32 {
        let (mut cur, mut level) = if self.dir_levels > 0 {
            (self.dir[self.dir_index(u)], self.dir_level)
        } else {
            (self.root, self.phys_log2())
        };
        while level > LEAF_LOG2 {
            let n = (level - LEAF_LOG2).min(8);
            level -= n;
            let spread = |x: u64| u64::from(SPREAD[(x >> level & 255) as usize]);
            let path = spread(u[0]) | spread(u[1]) << 1 | spread(u[2]) << 2;
            let mut shift = 3 * n;
            while shift > 0 {
                shift -= 3;
                cur = self.nodes[cur as usize].child[(path >> shift) as usize & 7];
            }
        }
        cur
    }

    /// Descends from slot `cur` at `level` towards offsets `t`, stopping at the first
    /// empty or full slot, or at the block. Returns (slot, level, parent node).
    #[inline]
    pub(super) fn descend(
        &self,
        mut cur: u32,
        mut level: u32,
        mut parent: u32,
        t: [u64; 3],
    ) -> (u32, u32, u32) {
        while level > LEAF_LOG2 && is_index(cur) {
            parent = cur;
            cur = self.nodes[cur as usize].child[child_index(t, level)];
            level -= 1;
        }
        (cur, level, parent)
    }

    /// From stored node `node` at `level`, which contains offsets `probe`, climbs
    /// while `t` lies outside (Libes §5: "we would continue searching in the parent
    /// of the current octant"). Returns the lowest ancestor that contains `t` and its
    /// level; `t` must lie inside the root.
    #[inline]
    pub(super) fn climb(
        &self,
        mut node: u32,
        mut level: u32,
        probe: [u64; 3],
        t: [u64; 3],
    ) -> (u32, u32) {
        while level < 64
            && ((t[0] ^ probe[0]) | (t[1] ^ probe[1]) | (t[2] ^ probe[2])) >> level != 0
        {
            node = self.nodes.parent[node as usize];
            level += 1;
            debug_assert!(node != NONE, "climbed past the root");
        }
        (node, level)
    }

    pub(super) fn octant_of(&self, t: [u64; 3], slot: u32, level: u32, parent: u32) -> Octant {
        let (size_log2, full) = if level > LEAF_LOG2 || !is_index(slot) {
            (level, slot == FULL)
        } else {
            (0, self.block_has(slot, t))
        };
        let mask = if size_log2 >= 64 {
            0
        } else {
            !((1u64 << size_log2) - 1)
        };
        let min = self.world([t[0] & mask, t[1] & mask, t[2] & mask]);
        Octant {
            min,
            size_log2,
            full,
            node: parent,
            node_level: level + 1,
            probe: t,
            version: self.version,
        }
    }

    /// `oct_find` from the root (Libes §5): the smallest uniform octant containing
    /// `v`, or `None` when `v` lies outside the root. O(depth).
    ///
    /// ```
    /// let mut t = tesseral::dynamic::DynamicOctree::new();
    /// for x in 0..8 { for y in 0..8 { for z in 0..8 { t.insert([x, y, z]); } } }
    /// t.insert([8, 0, 0]);
    /// let o = t.find([3, 3, 3]).unwrap();
    /// assert!(o.is_full());
    /// assert_eq!((o.min(), o.size_log2()), ([0, 0, 0], 3)); // an implicit full octant
    /// ```
    #[must_use]
    pub fn find(&self, v: Voxel) -> Option<Octant> {
        let t = self.offsets(v);
        let phys = self.phys_log2();
        if self.root == EMPTY || !within(t, phys) {
            return None;
        }
        let (slot, level, parent) = self.descend(self.root, phys, NONE, t);
        Some(self.octant_of(t, slot, level, parent))
    }

    /// `oct_find` that starts at the node where an earlier search ended: it climbs
    /// through parent links while `v` lies outside, then descends (Libes §5). Near
    /// `start` this costs O(levels climbed) instead of O(depth). A handle from before
    /// the latest change is not trusted: the search then starts at the root.
    ///
    /// ```
    /// let mut t = tesseral::dynamic::DynamicOctree::new();
    /// t.insert([0, 0, 0]);
    /// t.insert([100, 0, 0]);
    /// let a = t.find([0, 0, 0]).unwrap();
    /// let b = t.find_from(&a, [100, 0, 0]).unwrap();
    /// assert!(b.is_full());
    /// assert_eq!(t.find_from(&b, [99, 0, 0]), t.find([99, 0, 0]));
    /// ```
    #[must_use]
    pub fn find_from(&self, start: &Octant, v: Voxel) -> Option<Octant> {
        if start.version != self.version || start.node == NONE {
            return self.find(v);
        }
        let t = self.offsets(v);
        if !within(t, self.phys_log2()) {
            return None;
        }
        let (node, level) = self.climb(start.node, start.node_level, start.probe, t);
        let (slot, level, parent) = self.descend(node, level, NONE, t);
        let parent = if parent == NONE { node } else { parent };
        Some(self.octant_of(t, slot, level, parent))
    }

    /// The 3×3×3 occupancy around `v`: the cell at offset `(dx, dy, dz)` is bit
    /// `(dx+1) + 3(dy+1) + 9(dz+1)` of the [`Neighbourhood`] (bit 13 is `v` itself).
    ///
    /// Finds `v`'s block once; when the 3×3×3 block lies inside it (or inside an
    /// implicit empty or full octant), all 27 bits come from there. Otherwise the
    /// neighbouring blocks are found from `v`'s own node by climbing to the nearest
    /// common ancestor and descending (Libes §5), never from the root.
    /// O(depth) worst case, O(1) after the descent in the common case.
    ///
    /// ```
    /// use tesseral::dynamic::{DynamicOctree, Neighbourhood};
    /// let mut t = DynamicOctree::new();
    /// t.insert([0, 0, 0]);
    /// t.insert([1, 0, 0]);
    /// let n = t.neighbourhood([0, 0, 0]);
    /// assert_eq!(n, Neighbourhood::EMPTY.with([0, 0, 0]).with([1, 0, 0]));
    /// ```
    #[must_use]
    #[inline]
    pub fn neighbourhood(&self, v: Voxel) -> Neighbourhood {
        Neighbourhood::from_bits(self.neighbourhood_bits(v))
    }

    /// [`neighbourhood`](Self::neighbourhood) as bare bits.
    fn neighbourhood_bits(&self, v: Voxel) -> u32 {
        if self.root == EMPTY {
            return 0;
        }
        let u = self.offsets(v);
        let phys = self.phys_log2();
        if !within(u, phys) {
            return self.neighbourhood_slow(u, NONE, 0, EMPTY);
        }
        // The common case: the 3×3×3 block lies inside `v`'s block (the sentinels
        // stand for uniform octants).
        if (0..3).all(|a| (u[a] & 7).wrapping_sub(1) < 6) {
            let slot = self.block_slot(u);
            return if is_small(slot) {
                extract27(&self.block_words(slot), u)
            } else {
                extract27(&self.leaves[slot as usize].0, u)
            };
        }
        // Find `v`'s own node, starting at the directory when its entry is a node.
        let start = if self.dir_levels > 0 && self.dir_level > LEAF_LOG2 {
            let entry = self.dir[self.dir_index(u)];
            is_index(entry).then_some((entry, self.dir_level))
        } else {
            None
        };
        let (cur, level, parent) = match start {
            Some((node, level)) => self.descend(node, level, NONE, u),
            None => self.descend(self.root, phys, NONE, u),
        };
        let m = if level >= 64 {
            u64::MAX
        } else {
            (1u64 << level) - 1
        };
        let inner = |a: usize| {
            let l = u[a] & m;
            l >= 1 && l < m
        };
        if inner(0) && inner(1) && inner(2) {
            return match cur {
                EMPTY => 0,
                FULL => Neighbourhood::FULL.bits(),
                _ => extract27(&self.block_words(cur), u),
            };
        }
        // The block of `u` itself is the one just found (a uniform octant stands for
        // every block inside it, and its sentinel block for it): the slow path
        // reuses it.
        self.neighbourhood_slow(u, parent, level + 1, cur)
    }

    /// The block-level slot (sentinels standing for uniform octants) of the block
    /// whose minimum corner has offsets `t`, found from node `start` at `start_level`
    /// (which contains offsets `u`), or from the root when `start` is NONE.
    pub(super) fn block_slot_from(
        &self,
        t: [u64; 3],
        u: [u64; 3],
        start: u32,
        start_level: u32,
    ) -> u32 {
        let phys = self.phys_log2();
        if !within(t, phys) {
            return EMPTY;
        }
        let (cur, level) = if start == NONE {
            (self.root, phys)
        } else {
            self.climb(start, start_level, u, t)
        };
        let (slot, _, _) = self.descend(cur, level, NONE, t);
        slot
    }

    #[inline(never)]
    pub(super) fn neighbourhood_slow(
        &self,
        u: [u64; 3],
        start: u32,
        start_level: u32,
        own: u32,
    ) -> u32 {
        let home = [u[0] >> 3, u[1] >> 3, u[2] >> 3];
        let lo = [
            u[0].wrapping_sub(1) >> 3,
            u[1].wrapping_sub(1) >> 3,
            u[2].wrapping_sub(1) >> 3,
        ];
        let hi = [
            u[0].wrapping_add(1) >> 3,
            u[1].wrapping_add(1) >> 3,
            u[2].wrapping_add(1) >> 3,
        ];
        // Bit `a` of a block number selects the upper block along axis `a`; only the
        // blocks the 3×3×3 cube touches are looked up.
        let spans = usize::from(lo[0] != hi[0])
            | usize::from(lo[1] != hi[1]) << 1
            | usize::from(lo[2] != hi[2]) << 2;
        // Blocks in the same 16³ cell as `v`'s are siblings: children of `v`'s node.
        let siblings = start != NONE && start_level == LEAF_LOG2 + 1;
        let mut blocks = [EMPTY; 8];
        for i in 0..8usize {
            if i & !spans != 0 {
                continue;
            }
            let b = [
                if i & 1 == 0 { lo[0] } else { hi[0] },
                if i & 2 == 0 { lo[1] } else { hi[1] },
                if i & 4 == 0 { lo[2] } else { hi[2] },
            ];
            blocks[i] = if b == home {
                own
            } else if siblings && (b[0] ^ home[0]) | (b[1] ^ home[1]) | (b[2] ^ home[2]) < 2 {
                let ci = (b[0] & 1) | (b[1] & 1) << 1 | (b[2] & 1) << 2;
                self.nodes[start as usize].child[ci as usize]
            } else {
                self.block_slot_from([b[0] << 3, b[1] << 3, b[2] << 3], u, start, start_level)
            };
        }
        if blocks.iter().any(|&slot| is_small(slot)) {
            let words: [[u64; 8]; 8] = std::array::from_fn(|i| self.block_words(blocks[i]));
            rows27(u, lo, hi, |b, z| words[b][z])
        } else {
            rows27(u, lo, hi, |b, z| self.leaves[blocks[b] as usize].0[z])
        }
    }

    /// The directions in which `v`'s face neighbour is black. O(depth), from `v`'s
    /// own node.
    ///
    /// ```
    /// use tesseral::dynamic::{Direction, Directions, DynamicOctree};
    /// let mut t = DynamicOctree::new();
    /// t.insert([0, 0, 0]);
    /// assert_eq!(t.face_neighbours([0, 0, 1]), Directions::EMPTY.with(Direction::NegZ));
    /// ```
    #[must_use]
    pub fn face_neighbours(&self, v: Voxel) -> Directions {
        self.neighbourhood(v).faces()
    }
}
