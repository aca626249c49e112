//! The invariants, checked by `assert_valid`.

#[allow(unused_imports)]
use super::*;

impl DynamicOctree {
    // ----- invariants -------------------------------------------------------------------

    /// Checks every invariant and panics with a message naming the first broken one:
    /// counts (voxels, live nodes), parent links, free lists, that no stored node or
    /// block is all-empty or all-full, that the root cannot contract, and with faces
    /// that every listed face is exposed, its back-pointer is right, and the count is
    /// `6·voxels − 2·(face-adjacent pairs)`. O(voxels · depth).
    pub fn assert_valid(&self) {
        assert_eq!(
            self.nodes[EMPTY as usize].child, [EMPTY; 8],
            "empty sentinel node"
        );
        assert_eq!(
            self.nodes[FULL as usize].child, [FULL; 8],
            "full sentinel node"
        );
        assert_eq!(
            self.leaves[EMPTY as usize].0, ZERO_BLOCK,
            "empty sentinel block"
        );
        assert_eq!(
            self.leaves[FULL as usize].0, FULL_BLOCK,
            "full sentinel block"
        );
        let nfree = self.nodes.check("node");
        let lfree = self.leaves.check("block");
        let sfree = self.small.check("small block");
        if self.root == EMPTY {
            assert_eq!(self.voxels, 0, "empty root with voxels");
            assert_eq!(self.size_log2, 0, "empty tree has root size 1");
            assert_eq!(self.node_count(), 0, "empty tree holds nodes");
            assert_eq!(self.face_count(), 0, "empty tree has faces");
            return;
        }
        assert!(self.size_log2 <= 64, "root size 2^{}", self.size_log2);
        let phys = self.phys_log2();
        if self.size_log2 < LEAF_LOG2 {
            assert!(is_index(self.root), "small root must be a block");
            let m = leaf_axis_masks(&self.leaves[self.root as usize].0);
            for (a, &mask) in m.iter().enumerate() {
                assert_eq!(
                    u32::from(mask) >> (1u32 << self.size_log2),
                    0,
                    "bits outside the logical root on axis {a}"
                );
            }
        }
        let mut count: u128 = 0;
        let mut seen_nodes = 0usize;
        let mut seen_leaves = 0usize;
        let mut seen_small = 0usize;
        let mut stack = vec![(self.root, phys, NONE)];
        while let Some((slot, level, parent)) = stack.pop() {
            match slot {
                EMPTY => {}
                FULL => count = count.saturating_add(1u128 << (3 * level.min(42))),
                _ if level > LEAF_LOG2 => {
                    let n = &self.nodes[slot as usize];
                    assert!(!nfree.contains(&slot), "node {slot} is live and free");
                    assert_eq!(
                        self.nodes.parent[slot as usize], parent,
                        "parent link of node {slot}"
                    );
                    assert!(n.child.iter().any(|&c| c != EMPTY), "node {slot} is empty");
                    assert!(n.child.iter().any(|&c| c != FULL), "node {slot} is full");
                    seen_nodes += 1;
                    for &c in &n.child {
                        stack.push((c, level - 1, slot));
                    }
                }
                _ if is_small(slot) => {
                    let i = slot & !SMALL;
                    let lanes = &self.small[i as usize].0;
                    assert!(!sfree.contains(&i), "small block {i} is live and free");
                    assert_eq!(
                        self.small.parent[i as usize], parent,
                        "parent link of small block {i}"
                    );
                    assert_eq!(level, LEAF_LOG2, "small block {i} above the block level");
                    let keys: Vec<u16> = lanes.iter().copied().filter(|&e| e != VACANT).collect();
                    assert!(
                        lanes[keys.len()..].iter().all(|&e| e == VACANT),
                        "small block {i} has a vacant lane before an occupied one"
                    );
                    assert!(!keys.is_empty(), "small block {i} is empty");
                    assert!(
                        keys.iter().all(|&e| e < 512),
                        "small block {i} lane out of range"
                    );
                    let distinct: std::collections::HashSet<u16> = keys.iter().copied().collect();
                    assert_eq!(
                        distinct.len(),
                        keys.len(),
                        "small block {i} repeats a voxel"
                    );
                    seen_small += 1;
                    count += keys.len() as u128;
                }
                _ => {
                    let l = &self.leaves[slot as usize].0;
                    assert!(!lfree.contains(&slot), "block {slot} is live and free");
                    assert_eq!(
                        self.leaves.parent[slot as usize], parent,
                        "parent link of block {slot}"
                    );
                    assert!(l.iter().any(|&w| w != 0), "block {slot} is empty");
                    assert!(l.iter().any(|&w| w != !0), "block {slot} is full");
                    seen_leaves += 1;
                    count += u128::from(l.iter().map(|w| w.count_ones()).sum::<u32>());
                }
            }
        }
        assert_eq!(count, u128::from(self.voxels), "voxel count");
        // The directory holds exactly the slots at its level.
        assert!(self.dir_levels <= DIR_MAX_LEVELS, "directory too deep");
        if self.dir_levels == 0 {
            assert!(self.dir.is_empty(), "directory without levels");
        } else {
            assert_eq!(self.dir_level + self.dir_levels, phys, "directory level");
            assert_eq!(self.dir.len(), 1 << (3 * self.dir_levels), "directory size");
            assert!(self.dir_level >= LEAF_LOG2, "directory below the blocks");
            let mut fresh = vec![EMPTY; self.dir.len()];
            self.fill_dir(&mut fresh, self.root, phys, 0);
            for (i, (&a, &b)) in self.dir.iter().zip(&fresh).enumerate() {
                assert_eq!(a, b, "directory entry {i}");
            }
            assert!(
                self.dir.len() <= 64 * self.node_count().max(1),
                "directory larger than the tree"
            );
        }
        assert_eq!(seen_nodes, self.nodes.live(), "live node count");
        assert_eq!(seen_leaves, self.leaves.live(), "live block count");
        assert_eq!(seen_small, self.small.live(), "live small block count");
        // The root cannot contract.
        if self.size_log2 > LEAF_LOG2 && self.root != FULL {
            let ch = &self.nodes[self.root as usize].child;
            assert!(
                ch.iter().filter(|&&c| c != EMPTY).count() >= 2,
                "root could contract"
            );
        } else if self.size_log2 > 0 && self.root != FULL {
            let half = 1u32 << (self.size_log2 - 1);
            let m = leaf_axis_masks(&self.leaves[self.root as usize].0);
            let splits = m.iter().any(|&mask| {
                u32::from(mask) & ((1 << half) - 1) != 0 && u32::from(mask) >> half != 0
            });
            assert!(splits, "root block could contract");
        }
        if let Some(f) = &self.faces {
            f.assert_valid();
            for i in 0..f.list.len() {
                let e = f.face(i);
                assert!(self.contains(e.voxel), "face {i} on a white voxel");
                assert!(!self.contains(e.outside()), "face {i} is covered");
            }
            let all = self.voxels();
            let pairs: u64 = all
                .iter()
                .map(|&v| {
                    [Direction::PosX, Direction::PosY, Direction::PosZ]
                        .into_iter()
                        .filter(|&d| self.contains(d.step(v)))
                        .count() as u64
                })
                .sum();
            assert_eq!(
                f.list.len() as u64,
                6 * self.voxels - 2 * pairs,
                "face count is not 6·voxels − 2·pairs"
            );
        }
    }
}
