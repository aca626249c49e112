//! The bricked form of a linear octree, on which the set operations run (issue 17):
//! the leaves of side 8 or more as they are, and each 8³ cell that is neither empty
//! nor full (a *brick*) as one 512-bit mask.
//!
//! A brick's mask is in tesseral order: bit `i` (bit `i % 64` of word `i / 64`) is
//! the voxel whose code is the brick's code plus `i`. So a leaf of side 4 inside the
//! brick is one whole word, a leaf of side 2 one byte, a voxel one bit, and the
//! maximal blocks of a mask are read off its full words and full bytes. Since the
//! leaves of a canonical tree are maximal, each 8³ cell is either inside one leaf of
//! side 8 or more, white, or mixed; so the bricked form of a canonical tree is
//! unique too, and two of them are equal exactly when the solids are.
//!
//! Storage: `items` is one sorted list of 8-byte entries. A leaf of side 8 or more
//! is its packed [`Leaf`] (odd: its size marker has at least nine ones); a brick is
//! its code shifted left by one (even), and its mask is the next one in `masks`
//! (one mask per even entry, in order). Every entry starts and ends on a multiple of
//! 512 codes, so the leaf list's galloping searches (`merge::ending_by`,
//! `merge::inside`), asked about such codes, work on entries unchanged, and the
//! sibling merging of `push_merging` never merges a brick.

mod kernels;

pub(crate) use kernels::set_op;

use super::{completes_parent, Leaf, LinearOctree};

/// The voxels of one 8³ cell, in tesseral order (see the module notes).
pub(crate) type Mask = [u64; 8];

/// Every voxel of a brick.
pub(crate) const FULL: Mask = [u64::MAX; 8];

/// The codes of one brick (its voxels).
pub(crate) const BRICK_CODES: u64 = 512;

/// A linear octree's leaves in bricked form (see the module notes).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub(crate) struct Bricked {
    /// Leaves of side 8 or more (odd) and brick entries (even), sorted and disjoint.
    pub(crate) items: Vec<Leaf>,
    /// One mask per brick entry, in the entries' order.
    pub(crate) masks: Vec<Mask>,
}

/// Whether an entry is a brick (its mask being the next in `masks`).
#[inline(always)]
pub(crate) fn is_brick(item: Leaf) -> bool {
    item.packed() & 1 == 0
}

/// The entry of the brick whose lowest voxel has code `code`.
#[inline(always)]
pub(crate) fn brick_item(code: u64) -> Leaf {
    Leaf::from_packed(code << 1)
}

/// The number of brick entries in `items` (how many masks go with them).
#[inline]
pub(crate) fn bricks_in(items: &[Leaf]) -> usize {
    items.iter().filter(|l| is_brick(**l)).count()
}

/// The maximal blocks of a mask: a full word is a leaf of side 4, a full byte one
/// of side 2, any other set bit a voxel. Returns how many leaves that makes.
#[inline]
fn mask_leaf_count(m: &Mask) -> usize {
    m.iter()
        .map(|&w| {
            if w == u64::MAX {
                1
            } else {
                let full = full_bytes(w);
                (full.count_ones() / 8 + (w & !full).count_ones()) as usize
            }
        })
        .sum()
}

/// The bytes of `w` that are all ones, as a mask of those bytes.
#[inline]
fn full_bytes(w: u64) -> u64 {
    const LOW: u64 = 0x0101_0101_0101_0101;
    // A byte is full when its AND-fold down to its low bit is one.
    let mut f = w & (w >> 1);
    f &= f >> 2;
    f &= f >> 4;
    (f & LOW) * 0xFF
}

impl Bricked {
    /// The bricked form of a canonical leaf list.
    ///
    /// # Runtime
    /// O(n), one pass.
    pub(crate) fn from_leaves(leaves: &[Leaf]) -> Self {
        let mut out = Self::default();
        for &l in leaves {
            let k = l.size_log2();
            if k >= 3 {
                out.items.push(l);
                continue;
            }
            let code = l.code();
            let base = code & !(BRICK_CODES - 1);
            let key = brick_item(base);
            if out.items.last() != Some(&key) {
                out.items.push(key);
                out.masks.push([0; 8]);
            }
            let o = code - base;
            let bits = u64::MAX >> (64 - (1u32 << (3 * u32::from(k))));
            if let Some(m) = out.masks.last_mut() {
                m[(o >> 6) as usize] |= bits << (o & 63);
            }
        }
        out.items.shrink_to_fit();
        out.masks.shrink_to_fit();
        out
    }

    /// The canonical leaf list.
    ///
    /// # Runtime
    /// O(n) in the leaves made.
    pub(crate) fn to_leaves(&self) -> Vec<Leaf> {
        let mut out = Vec::with_capacity(self.leaf_count());
        let mut masks = self.masks.iter();
        for &item in &self.items {
            if !is_brick(item) {
                out.push(item);
                continue;
            }
            let base = item.packed() >> 1;
            let m = masks.next().expect("one mask per brick");
            for (wi, &w) in m.iter().enumerate() {
                let wbase = base + 64 * wi as u64;
                if w == u64::MAX {
                    out.push(Leaf::new(wbase, 2));
                    continue;
                }
                let full = full_bytes(w);
                let mut rest = w;
                while rest != 0 {
                    let b = rest.trailing_zeros();
                    if full >> b & 1 == 1 {
                        out.push(Leaf::new(wbase + u64::from(b), 1));
                        rest &= !(0xFF << b);
                    } else {
                        out.push(Leaf::new(wbase + u64::from(b), 0));
                        rest &= rest - 1;
                    }
                }
            }
        }
        out
    }

    /// The number of leaves of the canonical leaf list.
    pub(crate) fn leaf_count(&self) -> usize {
        self.items.len() - self.masks.len() + self.masks.iter().map(mask_leaf_count).sum::<usize>()
    }

    /// The number of black voxels.
    pub(crate) fn voxel_count(&self) -> u64 {
        let blocks: u64 = self
            .items
            .iter()
            .filter(|l| !is_brick(**l))
            .map(|l| l.voxel_count())
            .sum();
        let bits: u64 = self
            .masks
            .iter()
            .map(|m| m.iter().map(|w| u64::from(w.count_ones())).sum::<u64>())
            .sum();
        blocks + bits
    }

    /// Whether no voxel is black.
    pub(crate) fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// The bytes held on the heap (the capacities).
    pub(crate) fn heap_bytes(&self) -> usize {
        self.items.capacity() * std::mem::size_of::<Leaf>()
            + self.masks.capacity() * std::mem::size_of::<Mask>()
    }

    /// Panics at the first broken invariant of the bricked form of a tree of depth
    /// `depth`: entries sorted, disjoint, aligned, inside the space; leaves of side 8
    /// or more and canonically merged; one mask per brick, neither empty nor full,
    /// and white outside a space smaller than a brick.
    pub(crate) fn assert_valid(&self, depth: u8) {
        let space_end = 1u64 << (3 * u32::from(depth));
        assert_eq!(
            bricks_in(&self.items),
            self.masks.len(),
            "one mask per brick entry"
        );
        let mut masks = self.masks.iter();
        let mut prev_end = 0;
        for (i, &item) in self.items.iter().enumerate() {
            let (start, end) = if is_brick(item) {
                let code = item.packed() >> 1;
                assert_eq!(code % BRICK_CODES, 0, "brick {i} not aligned");
                let m = masks.next().expect("counted above");
                assert!(*m != [0; 8], "brick {i} is empty");
                assert!(*m != FULL, "brick {i} is full");
                if depth < 3 {
                    let space_bits = 1u32 << (3 * u32::from(depth));
                    assert_eq!(m[0] >> (space_bits - 1) >> 1, 0, "brick {i} past the space");
                    assert!(m[1..].iter().all(|w| *w == 0), "brick {i} past the space");
                }
                (code, (code + BRICK_CODES).min(space_end))
            } else {
                let k = item.size_log2();
                assert!(k >= 3, "entry {i} is a leaf of side below 8");
                assert!(k <= depth, "entry {i} larger than the space");
                assert_eq!(item.code() % item.voxel_count(), 0, "entry {i} unaligned");
                (item.code(), item.end())
            };
            assert!(end <= space_end, "entry {i} outside the space");
            assert!(
                i == 0 || prev_end <= start,
                "entries {} and {i} unsorted or overlapping",
                i.wrapping_sub(1)
            );
            prev_end = end;
            if i >= 7 {
                let run = &self.items[i - 7..=i];
                assert!(
                    run.iter().any(|l| is_brick(*l)) || !completes_parent(run),
                    "entries {}..={i} are eight unmerged siblings",
                    i - 7
                );
            }
        }
    }
}

impl LinearOctree {
    /// Makes and keeps the bricked form of the tree (once; later calls do nothing),
    /// so that set operations on it run on bricks. Returns the tree.
    ///
    /// A set operation runs on the bricked forms when either operand holds one (the
    /// other is made and kept) and returns a tree in bricked form, whose leaf list
    /// [`LinearOctree::leaves`] makes on first use; otherwise it merges the leaf
    /// lists. So a chain of operations stays bricked once one tree is.
    ///
    /// # Runtime
    /// O(n), one pass over the leaves; it adds 8 bytes per leaf of side 8 or more
    /// and 72 per mixed 8³ cell to [`LinearOctree::heap_bytes`].
    ///
    /// ```
    /// use tesseral::linear::{LinearOctree, SetOp};
    /// let a = LinearOctree::from_voxels(4, [0; 3], [[0, 0, 0], [9, 9, 9]]).unwrap();
    /// let b = LinearOctree::from_voxels(4, [0; 3], [[9, 9, 9]]).unwrap();
    /// let d = a.build_bricks().set_op(&b, SetOp::Difference).unwrap();
    /// assert_eq!(d.voxels().collect::<Vec<_>>(), vec![[0, 0, 0]]);
    /// ```
    pub fn build_bricks(&self) -> &Self {
        self.bricked();
        self
    }

    /// Whether the tree holds its bricked form.
    pub(crate) fn has_bricked(&self) -> bool {
        self.bricked.get().is_some()
    }

    /// The bricked form, made from the leaves on first use and kept.
    pub(crate) fn bricked(&self) -> &Bricked {
        self.bricked.get_or_init(|| {
            Bricked::from_leaves(
                self.leaves
                    .get()
                    .expect("a tree holds its leaves in at least one form"),
            )
        })
    }
}

#[cfg(test)]
mod tests;
