//! Pools of nodes and blocks: `Vec`s addressed by `u32`, with parent links kept apart and a free list.

#[allow(unused_imports)]
use super::*;

/// Grows a pool by 1/8 (at least 64 entries) when it is full, instead of doubling:
/// the pools are most of the memory, and doubling would leave up to half of it
/// unused. Large reallocations are cheap (glibc moves them with `mremap`), so the
/// amortised cost per push stays O(1).
#[inline]
pub(super) fn grow<T>(v: &mut Vec<T>) {
    if v.len() == v.capacity() {
        v.reserve_exact((v.len() / 8).max(64));
    }
}

/// A pool of entries addressed by `u32`: the entries, a parent link per entry (kept
/// apart, so searches from the root never load it) and a free list. The first
/// `reserved` entries are sentinels, never handed out or released.
#[derive(Clone)]
pub(super) struct Pool<T> {
    pub(super) items: Vec<T>,
    pub(super) parent: Vec<u32>,
    pub(super) free: Vec<u32>,
    pub(super) reserved: usize,
}

impl<T: Copy> Pool<T> {
    pub(super) fn new(sentinels: &[T]) -> Self {
        Pool {
            items: sentinels.to_vec(),
            parent: vec![FREED; sentinels.len()],
            free: Vec::new(),
            reserved: sentinels.len(),
        }
    }

    /// Stores `value` under `parent`; returns its index, below 2^31 (bit 31 of a slot
    /// tags a small block).
    pub(super) fn alloc(&mut self, value: T, parent: u32, what: &str) -> u32 {
        if let Some(i) = self.free.pop() {
            self.items[i as usize] = value;
            self.parent[i as usize] = parent;
            return i;
        }
        let i = u32::try_from(self.items.len())
            .ok()
            .filter(|&i| i < SMALL)
            .unwrap_or_else(|| panic!("DynamicOctree: more than 2^31 {what}s"));
        grow(&mut self.items);
        self.items.push(value);
        grow(&mut self.parent);
        self.parent.push(parent);
        i
    }

    pub(super) fn release(&mut self, i: u32) {
        debug_assert!(i as usize >= self.reserved, "releasing a sentinel");
        self.parent[i as usize] = FREED;
        self.free.push(i);
    }

    /// Entries in use, sentinels not counted.
    pub(super) fn live(&self) -> usize {
        self.items.len() - self.reserved - self.free.len()
    }

    pub(super) fn heap_bytes(&self) -> usize {
        self.items.capacity() * std::mem::size_of::<T>()
            + (self.parent.capacity() + self.free.capacity()) * 4
    }

    pub(super) fn shrink_to_fit(&mut self) {
        self.items.shrink_to_fit();
        self.parent.shrink_to_fit();
        self.free.shrink_to_fit();
    }

    /// Checks the bookkeeping for [`DynamicOctree::assert_valid`]: one parent link per
    /// entry, a free list without repeats or sentinels whose entries are marked freed.
    /// Returns the free entries.
    pub(super) fn check(&self, what: &str) -> std::collections::HashSet<u32> {
        assert_eq!(
            self.items.len(),
            self.parent.len(),
            "{what} parent array length"
        );
        let set: std::collections::HashSet<u32> = self.free.iter().copied().collect();
        assert_eq!(
            set.len(),
            self.free.len(),
            "{what} free list has duplicates"
        );
        for &i in &self.free {
            assert!(
                i as usize >= self.reserved,
                "sentinel {what} {i} on the free list"
            );
            assert_eq!(self.parent[i as usize], FREED, "free {what} {i} not marked");
        }
        set
    }
}

impl<T> std::ops::Index<usize> for Pool<T> {
    type Output = T;
    #[inline(always)]
    fn index(&self, i: usize) -> &T {
        &self.items[i]
    }
}

impl<T> std::ops::IndexMut<usize> for Pool<T> {
    #[inline(always)]
    fn index_mut(&mut self, i: usize) -> &mut T {
        &mut self.items[i]
    }
}

impl DynamicOctree {
    // ----- pools -------------------------------------------------------------------

    pub(super) fn alloc_node(&mut self, parent: u32, fill: u32) -> u32 {
        self.nodes.alloc(Node { child: [fill; 8] }, parent, "node")
    }

    pub(super) fn free_node(&mut self, i: u32) {
        self.nodes.release(i);
    }

    pub(super) fn alloc_leaf(&mut self, parent: u32, fill: u64) -> u32 {
        self.leaves.alloc(Leaf([fill; 8]), parent, "block")
    }

    pub(super) fn free_leaf(&mut self, i: u32) {
        self.leaves.release(i);
    }

    /// Stores a small block; returns its tagged slot.
    pub(super) fn alloc_small(&mut self, parent: u32, block: Small) -> u32 {
        self.small.alloc(block, parent, "small block") | SMALL
    }

    pub(super) fn free_small(&mut self, slot: u32) {
        self.small.release(slot & !SMALL);
    }
}
