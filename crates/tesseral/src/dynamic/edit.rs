//! Voxel create and delete (Libes §4).

#[allow(unused_imports)]
use super::*;

impl DynamicOctree {
    // ----- voxel create / delete (Libes §4) -------------------------------------------

    /// Creates voxel `v`; returns `true` when it was not there before. The root
    /// expands as often as needed (Libes §3). With face bookkeeping, only the faces
    /// around `v` change, in the order of the face-list rule: for each direction
    /// 0..6, a black neighbour gives up its face towards `v` (`swap_remove`),
    /// otherwise `v` gains the face in that direction (push).
    ///
    /// O(depth) plus, with faces, six O(1) face updates.
    ///
    /// ```
    /// let mut t = tesseral::dynamic::DynamicOctree::new();
    /// assert!(t.insert([1, 2, 3]));
    /// assert!(!t.insert([1, 2, 3]));
    /// assert_eq!(t.voxel_count(), 1);
    /// ```
    pub fn insert(&mut self, v: Voxel) -> bool {
        if !self.insert_bit(v) {
            return false;
        }
        if self.faces.is_some() {
            let nb = self.face_neighbours(v);
            self.faces_after_insert(v, nb);
        }
        true
    }

    /// [`insert`](Self::insert) for a caller that already holds `nb`, the
    /// [`neighbourhood`](Self::neighbourhood) of `v` taken since the last change: the
    /// face update then needs no second search. A wrong `nb` corrupts the face list
    /// (debug builds check it). O(depth) plus six O(1) face updates.
    ///
    /// ```
    /// let mut t = tesseral::dynamic::DynamicOctree::with_faces();
    /// t.insert([0, 0, 0]);
    /// let nb = t.neighbourhood([1, 0, 0]);
    /// assert!(t.insert_with_neighbourhood([1, 0, 0], nb));
    /// assert_eq!(t.face_count(), 10);
    /// ```
    pub fn insert_with_neighbourhood(&mut self, v: Voxel, nb: Neighbourhood) -> bool {
        debug_assert_eq!(nb, self.neighbourhood(v), "stale neighbourhood");
        if !self.insert_bit(v) {
            return false;
        }
        if self.faces.is_some() {
            self.faces_after_insert(v, nb.faces());
        }
        true
    }

    /// Sets the bit of `v` and counts it; no face update. True when `v` is new.
    #[inline(always)]
    pub(super) fn insert_bit(&mut self, v: Voxel) -> bool {
        if self.root == EMPTY {
            self.root_min = v;
            self.size_log2 = 0;
            self.root = self.alloc_leaf(NONE, 0);
            self.leaves[self.root as usize].0[0] = 1;
        } else {
            let mut u = self.offsets(v);
            if !within(u, self.size_log2) {
                while !within(u, self.size_log2) {
                    self.expand(v);
                    u = self.offsets(v);
                }
                self.rebuild_dir();
            }
            if !self.set_bit(u) {
                return false;
            }
        }
        self.voxels += 1;
        self.version += 1;
        true
    }

    /// Sets the bit at offsets `u` (inside the root); false when it was already set.
    pub(super) fn set_bit(&mut self, u: [u64; 3]) -> bool {
        // Fast path: the block exists and does not become full.
        let slot = self.block_slot(u);
        if is_small(slot) {
            return match self.small[(slot & !SMALL) as usize].insert(local_index(u)) {
                Some(new) => new,
                None => self.set_bit_slow(u), // it becomes a bitmap block
            };
        }
        let (w, b) = leaf_bit(u);
        let word = self.leaves[slot as usize].0[w];
        if word & b != 0 {
            return false; // also a full octant (the full sentinel block)
        }
        if is_index(slot) && word | b != !0 {
            self.leaves[slot as usize].0[w] = word | b;
            return true;
        }
        self.set_bit_slow(u)
    }

    /// [`set_bit`](Self::set_bit) that creates the nodes and block on the way down and
    /// collapses a block that becomes full.
    pub(super) fn set_bit_slow(&mut self, u: [u64; 3]) -> bool {
        let mut level = self.phys_log2();
        let mut parent = NONE;
        let mut ci = 0usize;
        let mut cur = self.root;
        while level > LEAF_LOG2 {
            if cur == FULL {
                return false;
            }
            if cur == EMPTY {
                cur = self.alloc_node(parent, EMPTY);
                self.set_slot(parent, ci, cur, level, u);
            }
            ci = child_index(u, level);
            parent = cur;
            cur = self.nodes[cur as usize].child[ci];
            level -= 1;
        }
        if cur == FULL {
            return false;
        }
        if cur == EMPTY && parent != NONE && self.small_blocks {
            // A new block starts small.
            let s = self.alloc_small(parent, Small::one(local_index(u)));
            self.set_slot(parent, ci, s, LEAF_LOG2, u);
            self.check_dir_size();
            return true;
        }
        if cur == EMPTY {
            cur = self.alloc_leaf(parent, 0);
            self.set_slot(parent, ci, cur, LEAF_LOG2, u);
        }
        if is_small(cur) {
            if let Some(new) = self.small[(cur & !SMALL) as usize].insert(local_index(u)) {
                return new;
            }
            cur = self.promote(cur, parent, ci, u);
        }
        let (w, b) = leaf_bit(u);
        let l = &mut self.leaves[cur as usize].0;
        if l[w] & b != 0 {
            return false;
        }
        l[w] |= b;
        if l[w] == !0 && l.iter().all(|&x| x == !0) {
            self.collapse_full(cur, parent, u);
        }
        self.check_dir_size();
        true
    }

    /// A block became full: it turns into a full slot, and so does every ancestor
    /// whose eight children are all full.
    pub(super) fn collapse_full(&mut self, leaf: u32, parent: u32, u: [u64; 3]) {
        self.free_leaf(leaf);
        self.set_slot(parent, child_index(u, LEAF_LOG2 + 1), FULL, LEAF_LOG2, u);
        self.collapse_up(parent, LEAF_LOG2 + 1, u);
    }

    /// From `node` at `level` (on the path to offsets `u`) upwards: a node whose eight
    /// children are all full becomes a full slot in its parent.
    pub(super) fn collapse_up(&mut self, mut node: u32, mut level: u32, u: [u64; 3]) {
        while node != NONE && self.nodes[node as usize].child.iter().all(|&c| c == FULL) {
            let p = self.nodes.parent[node as usize];
            self.free_node(node);
            level += 1;
            let ci = if p != NONE { child_index(u, level) } else { 0 };
            self.set_slot(p, ci, FULL, level - 1, u);
            node = p;
        }
    }

    /// Releases a stored subtree (slot `slot` at `level`).
    pub(super) fn free_subtree(&mut self, slot: u32, level: u32) {
        if !is_index(slot) {
            return;
        }
        if level > LEAF_LOG2 {
            let ch = self.nodes[slot as usize].child;
            for c in ch {
                self.free_subtree(c, level - 1);
            }
            self.free_node(slot);
        } else if is_small(slot) {
            self.free_small(slot);
        } else {
            self.free_leaf(slot);
        }
    }

    /// Makes the aligned cube of side `2^s` at offsets `u` full (no voxel count or
    /// face update: the caller keeps those).
    pub(super) fn fill_aligned(&mut self, u: [u64; 3], s: u32) {
        let target = s.max(LEAF_LOG2);
        let mut level = self.phys_log2();
        let mut parent = NONE;
        let mut ci = 0usize;
        let mut cur = self.root;
        while level > target {
            if cur == FULL {
                return;
            }
            if cur == EMPTY {
                cur = self.alloc_node(parent, EMPTY);
                self.set_slot(parent, ci, cur, level, u);
            }
            ci = child_index(u, level);
            parent = cur;
            cur = self.nodes[cur as usize].child[ci];
            level -= 1;
        }
        if cur == FULL {
            return;
        }
        if s >= LEAF_LOG2 {
            self.free_subtree(cur, level);
            self.set_slot(parent, ci, FULL, level, u);
            self.collapse_up(parent, level + 1, u);
            return;
        }
        if cur == EMPTY {
            cur = self.alloc_leaf(parent, 0);
            self.set_slot(parent, ci, cur, LEAF_LOG2, u);
        }
        if is_small(cur) {
            cur = self.promote(cur, parent, ci, u);
        }
        let side = 1u64 << s;
        let (x0, y0, z0) = (u[0] & 7, u[1] & 7, u[2] & 7);
        let row = ((1u64 << side) - 1) << x0;
        let plane = (y0..y0 + side).fold(0u64, |p, y| p | row << (8 * y));
        let l = &mut self.leaves[cur as usize].0;
        for z in z0..z0 + side {
            l[z as usize] |= plane;
        }
        if l.iter().all(|&w| w == !0) {
            self.collapse_full(cur, parent, u);
        }
    }

    /// Deletes voxel `v`; returns `true` when it was there. A full octant around `v`
    /// is instantiated on the way down; blocks and nodes left empty are released all
    /// the way up, and the root contracts while its content fits one child (Libes §3,
    /// §4). With face bookkeeping: for each direction 0..6, a black neighbour gains
    /// its face towards `v` (push), otherwise `v`'s face there is removed
    /// (`swap_remove`).
    ///
    /// O(depth) plus, with faces, six O(1) face updates.
    ///
    /// ```
    /// let mut t = tesseral::dynamic::DynamicOctree::new();
    /// t.insert([1, 2, 3]);
    /// assert!(t.remove([1, 2, 3]));
    /// assert!(!t.remove([1, 2, 3]));
    /// assert_eq!(t.voxel_count(), 0);
    /// ```
    pub fn remove(&mut self, v: Voxel) -> bool {
        if !self.remove_bit(v) {
            return false;
        }
        if self.faces.is_some() {
            let nb = self.face_neighbours(v);
            self.faces_after_remove(v, nb);
        }
        true
    }

    /// [`remove`](Self::remove) for a caller that already holds `nb`, the
    /// [`neighbourhood`](Self::neighbourhood) of `v` taken since the last change: the
    /// face update then needs no second search. A wrong `nb` corrupts the face list
    /// (debug builds check it). O(depth) plus six O(1) face updates.
    ///
    /// ```
    /// let mut t = tesseral::dynamic::DynamicOctree::with_faces();
    /// t.insert([0, 0, 0]);
    /// t.insert([1, 0, 0]);
    /// let nb = t.neighbourhood([1, 0, 0]);
    /// assert!(t.remove_with_neighbourhood([1, 0, 0], nb));
    /// assert_eq!(t.face_count(), 6);
    /// ```
    pub fn remove_with_neighbourhood(&mut self, v: Voxel, nb: Neighbourhood) -> bool {
        debug_assert_eq!(nb, self.neighbourhood(v), "stale neighbourhood");
        if !self.remove_bit(v) {
            return false;
        }
        if self.faces.is_some() {
            self.faces_after_remove(v, nb.faces());
        }
        true
    }

    /// Clears the bit of `v`, counts it and contracts the root; no face update. True
    /// when `v` was black.
    #[inline(always)]
    pub(super) fn remove_bit(&mut self, v: Voxel) -> bool {
        if self.root == EMPTY {
            return false;
        }
        let u = self.offsets(v);
        if !within(u, self.size_log2) || !self.clear_bit(u) {
            return false;
        }
        self.voxels -= 1;
        self.version += 1;
        if self.voxels == 0 {
            debug_assert_eq!(self.root, EMPTY);
            self.root = EMPTY;
            self.size_log2 = 0;
            self.root_min = [0; 3];
            self.rebuild_dir();
        } else if self.contract() {
            self.rebuild_dir();
        }
        true
    }

    /// Clears the bit at offsets `u` (inside the root); false when it was clear.
    pub(super) fn clear_bit(&mut self, u: [u64; 3]) -> bool {
        // Fast path: the block exists and does not become empty.
        let slot = self.block_slot(u);
        if is_small(slot) {
            let small = &mut self.small[(slot & !SMALL) as usize];
            if small.count() > 1 || !small.has(local_index(u)) {
                return small.remove(local_index(u));
            }
            return self.clear_bit_slow(u); // the block goes
        }
        let (w, b) = leaf_bit(u);
        let word = self.leaves[slot as usize].0[w];
        if word & b == 0 {
            return false; // also an empty octant (the empty sentinel block)
        }
        if is_index(slot) && word & !b != 0 {
            self.leaves[slot as usize].0[w] = word & !b;
            self.maybe_demote(slot, u);
            return true;
        }
        self.clear_bit_slow(u)
    }

    /// A bitmap block (not the root block) left with at most half a small block's
    /// voxels becomes a small block again, in a tree whose new blocks start small.
    /// (The gap between four and nine voxels keeps a block from switching back and
    /// forth.)
    pub(super) fn maybe_demote(&mut self, slot: u32, u: [u64; 3]) {
        if !self.small_blocks {
            return;
        }
        let words = self.leaves[slot as usize].0;
        let count: u32 = words.iter().map(|w| w.count_ones()).sum();
        let parent = self.leaves.parent[slot as usize];
        if count as usize > SMALL_CAP / 2 || parent == NONE {
            return;
        }
        self.free_leaf(slot);
        let small = self.alloc_small(parent, Small::from_words(&words));
        self.set_slot(parent, child_index(u, LEAF_LOG2 + 1), small, LEAF_LOG2, u);
    }

    /// [`clear_bit`](Self::clear_bit) that instantiates a full octant on the way down
    /// and releases a block that becomes empty, and its emptied ancestors.
    pub(super) fn clear_bit_slow(&mut self, u: [u64; 3]) -> bool {
        let mut level = self.phys_log2();
        let mut parent = NONE;
        let mut ci = 0usize;
        let mut cur = self.root;
        while level > LEAF_LOG2 {
            if cur == EMPTY {
                return false;
            }
            if cur == FULL {
                cur = self.alloc_node(parent, FULL);
                self.set_slot(parent, ci, cur, level, u);
            }
            ci = child_index(u, level);
            parent = cur;
            cur = self.nodes[cur as usize].child[ci];
            level -= 1;
        }
        if cur == EMPTY {
            return false;
        }
        if cur == FULL {
            cur = self.alloc_leaf(parent, !0);
            self.set_slot(parent, ci, cur, LEAF_LOG2, u);
        }
        let emptied = if is_small(cur) {
            let small = &mut self.small[(cur & !SMALL) as usize];
            if !small.remove(local_index(u)) {
                return false;
            }
            let emptied = small.count() == 0;
            if emptied {
                self.free_small(cur);
            }
            emptied
        } else {
            let (w, b) = leaf_bit(u);
            let l = &mut self.leaves[cur as usize].0;
            if l[w] & b == 0 {
                return false;
            }
            l[w] &= !b;
            let emptied = l[w] == 0 && l.iter().all(|&x| x == 0);
            if emptied {
                self.free_leaf(cur);
            } else {
                self.maybe_demote(cur, u);
            }
            emptied
        };
        if emptied {
            let mut level = LEAF_LOG2 + 1;
            self.set_slot(parent, child_index(u, level), EMPTY, LEAF_LOG2, u);
            let mut node = parent;
            while node != NONE && self.nodes[node as usize].child.iter().all(|&c| c == EMPTY) {
                let p = self.nodes.parent[node as usize];
                self.free_node(node);
                level += 1;
                let ci = if p != NONE { child_index(u, level) } else { 0 };
                self.set_slot(p, ci, EMPTY, level - 1, u);
                node = p;
            }
        }
        self.check_dir_size();
        true
    }
}
