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
//! Storage, in two levels of one shape ([`Level`]): a sorted list of 8-byte
//! entries, each a leaf (its packed [`Leaf`], odd) or a mixed cell (its code shifted
//! left by one, even), and one payload per mixed cell, in order.
//! - The top level holds the leaves of side 64 or more and one entry per mixed
//!   64³ cell (a *chunk*), whose payload is the chunk's own level, shared
//!   (`Arc`): a set operation that meets a chunk of one operand only (a union away
//!   from the other solid) hands it on without copying it.
//! - A chunk's level holds its leaves of side 8 to 32 and its bricks, each with its
//!   512-bit mask.
//!
//! At each level every entry starts and ends on a multiple of the cell's codes, so
//! the leaf list's galloping searches (`merge::ending_by`, `merge::inside`), asked
//! about such codes, work on entries unchanged, and the sibling merging of
//! `push_merging` never merges a mixed cell. The kernels (`kernels.rs`) are generic
//! over the payload.

mod kernels;

use std::sync::Arc;

use kernels::{level_op, Combined, Payload};

use super::{completes_parent, Leaf, LinearOctree, SetOp};

/// The voxels of one 8³ cell, in tesseral order (see the module notes).
pub(crate) type Mask = [u64; 8];

/// Every voxel of a brick.
pub(crate) const FULL: Mask = [u64::MAX; 8];

/// The side of a chunk, log2.
pub(crate) const CHUNK_LOG2: u8 = 6;

/// One level of the bricked form (see the module notes).
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Level<P> {
    /// Leaves (odd) and mixed cells (even), sorted and disjoint.
    pub(crate) items: Vec<Leaf>,
    /// One payload per mixed cell, in the entries' order.
    pub(crate) payloads: Vec<P>,
}

impl<P> Default for Level<P> {
    fn default() -> Self {
        Self {
            items: Vec::new(),
            payloads: Vec::new(),
        }
    }
}

/// A chunk's level: leaves of side 8 to 32 and bricks.
pub(crate) type Chunk = Level<Mask>;

/// A linear octree's leaves in bricked form (see the module notes).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub(crate) struct Bricked {
    top: Level<Arc<Chunk>>,
}

/// Whether an entry is a mixed cell (its payload being the next one).
#[inline(always)]
pub(crate) fn is_brick(item: Leaf) -> bool {
    item.packed() & 1 == 0
}

/// The entry of the mixed cell whose lowest voxel has code `code`.
#[inline(always)]
pub(crate) fn brick_item(code: u64) -> Leaf {
    Leaf::from_packed(code << 1)
}

/// The number of mixed cells in `items` (how many payloads go with them).
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

impl Payload for Mask {
    const LOG2: u8 = 3;

    #[inline(always)]
    fn combine(op: SetOp, _code: u64, a: &Self, b: &Self) -> Combined<Self> {
        let m: Mask = std::array::from_fn(|w| match op {
            SetOp::Union => a[w] | b[w],
            SetOp::Intersection => a[w] & b[w],
            SetOp::Difference => a[w] & !b[w],
            SetOp::SymmetricDifference => a[w] ^ b[w],
        });
        if m == FULL {
            Combined::Full
        } else if m == [0; 8] {
            Combined::Empty
        } else {
            Combined::Mixed(m)
        }
    }

    #[inline(always)]
    fn complement(&self, _code: u64) -> Self {
        self.map(|w| !w)
    }
}

impl Payload for Arc<Chunk> {
    const LOG2: u8 = CHUNK_LOG2;

    fn combine(op: SetOp, code: u64, a: &Self, b: &Self) -> Combined<Self> {
        let out = level_op(a, b, op);
        if out.items.is_empty() {
            Combined::Empty
        } else if out.items == [Leaf::new(code, CHUNK_LOG2)] {
            Combined::Full
        } else {
            Combined::Mixed(Arc::new(out))
        }
    }

    fn complement(&self, code: u64) -> Self {
        let full = Chunk {
            items: vec![Leaf::new(code, CHUNK_LOG2)],
            payloads: Vec::new(),
        };
        Arc::new(level_op(&full, self, SetOp::Difference))
    }
}

impl Chunk {
    /// The chunk level of canonical leaves of side below 64, all in one chunk.
    fn from_leaves(leaves: &[Leaf]) -> Self {
        let mut out = Self::default();
        for &l in leaves {
            let k = l.size_log2();
            if k >= 3 {
                out.items.push(l);
                continue;
            }
            let code = l.code();
            let base = code & !(<Mask as Payload>::CODES - 1);
            let key = brick_item(base);
            if out.items.last() != Some(&key) {
                out.items.push(key);
                out.payloads.push([0; 8]);
            }
            let o = code - base;
            let bits = u64::MAX >> (64 - (1u32 << (3 * u32::from(k))));
            if let Some(m) = out.payloads.last_mut() {
                m[(o >> 6) as usize] |= bits << (o & 63);
            }
        }
        out.items.shrink_to_fit();
        out.payloads.shrink_to_fit();
        out
    }

    /// Appends the canonical leaves of the chunk.
    fn leaves_into(&self, out: &mut Vec<Leaf>) {
        let mut masks = self.payloads.iter();
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
    }

    fn leaf_count(&self) -> usize {
        self.items.len() - self.payloads.len()
            + self.payloads.iter().map(mask_leaf_count).sum::<usize>()
    }

    fn voxel_count(&self) -> u64 {
        let blocks: u64 = self
            .items
            .iter()
            .filter(|l| !is_brick(**l))
            .map(|l| l.voxel_count())
            .sum();
        let bits: u64 = self
            .payloads
            .iter()
            .map(|m| m.iter().map(|w| u64::from(w.count_ones())).sum::<u64>())
            .sum();
        blocks + bits
    }

    fn heap_bytes(&self) -> usize {
        self.items.capacity() * std::mem::size_of::<Leaf>()
            + self.payloads.capacity() * std::mem::size_of::<Mask>()
    }
}

impl Bricked {
    /// The bricked form of a canonical leaf list.
    ///
    /// # Runtime
    /// O(n), one pass.
    pub(crate) fn from_leaves(leaves: &[Leaf]) -> Self {
        let chunk_codes = <Arc<Chunk> as Payload>::CODES;
        let mut top = Level::default();
        let mut i = 0;
        while i < leaves.len() {
            let l = leaves[i];
            if l.size_log2() >= CHUNK_LOG2 {
                top.items.push(l);
                i += 1;
                continue;
            }
            let base = l.code() & !(chunk_codes - 1);
            let n = leaves[i..].partition_point(|l| l.code() < base + chunk_codes);
            top.items.push(brick_item(base));
            top.payloads
                .push(Arc::new(Chunk::from_leaves(&leaves[i..i + n])));
            i += n;
        }
        top.items.shrink_to_fit();
        top.payloads.shrink_to_fit();
        Self { top }
    }

    /// The canonical leaf list.
    ///
    /// # Runtime
    /// O(n) in the leaves made.
    pub(crate) fn to_leaves(&self) -> Vec<Leaf> {
        let mut out = Vec::with_capacity(self.leaf_count());
        let mut chunks = self.top.payloads.iter();
        for &item in &self.top.items {
            if is_brick(item) {
                chunks
                    .next()
                    .expect("one chunk per entry")
                    .leaves_into(&mut out);
            } else {
                out.push(item);
            }
        }
        out
    }

    /// The number of leaves of the canonical leaf list.
    pub(crate) fn leaf_count(&self) -> usize {
        self.top.items.len() - self.top.payloads.len()
            + self
                .top
                .payloads
                .iter()
                .map(|c| c.leaf_count())
                .sum::<usize>()
    }

    /// The number of black voxels.
    pub(crate) fn voxel_count(&self) -> u64 {
        let blocks: u64 = self
            .top
            .items
            .iter()
            .filter(|l| !is_brick(**l))
            .map(|l| l.voxel_count())
            .sum();
        blocks
            + self
                .top
                .payloads
                .iter()
                .map(|c| c.voxel_count())
                .sum::<u64>()
    }

    /// Whether no voxel is black.
    pub(crate) fn is_empty(&self) -> bool {
        self.top.items.is_empty()
    }

    /// The bytes held on the heap (the capacities; a chunk shared with another
    /// tree is counted in each).
    pub(crate) fn heap_bytes(&self) -> usize {
        self.top.items.capacity() * std::mem::size_of::<Leaf>()
            + self.top.payloads.capacity() * std::mem::size_of::<Arc<Chunk>>()
            + self
                .top
                .payloads
                .iter()
                .map(|c| c.heap_bytes() + std::mem::size_of::<Chunk>() + 16)
                .sum::<usize>()
    }

    /// Panics at the first broken invariant of the bricked form of a tree of depth
    /// `depth`: at each level, entries sorted, disjoint, aligned, inside their cell
    /// and the space, leaves of the level's sides and canonically merged, one
    /// payload per mixed cell, neither empty nor full; bricks white outside a space
    /// smaller than a brick.
    pub(crate) fn assert_valid(&self, depth: u8) {
        let space_end = 1u64 << (3 * u32::from(depth));
        let chunk_codes = <Arc<Chunk> as Payload>::CODES;
        assert_level(&self.top, (0, space_end), (CHUNK_LOG2, depth), "top");
        for (item, chunk) in self
            .top
            .items
            .iter()
            .filter(|l| is_brick(**l))
            .zip(&self.top.payloads)
        {
            let code = item.packed() >> 1;
            assert!(!chunk.items.is_empty(), "chunk {code} is empty");
            assert!(
                chunk.items != [Leaf::new(code, CHUNK_LOG2)],
                "chunk {code} is full"
            );
            let end = (code + chunk_codes).min(space_end);
            assert_level(chunk, (code, end), (3, CHUNK_LOG2 - 1), "chunk");
            for m in &chunk.payloads {
                assert!(*m != [0; 8], "a brick of chunk {code} is empty");
                assert!(*m != FULL, "a brick of chunk {code} is full");
                if depth < 3 {
                    let space_bits = 1u32 << (3 * u32::from(depth));
                    assert_eq!(m[0] >> (space_bits - 1) >> 1, 0, "a brick past the space");
                    assert!(m[1..].iter().all(|w| *w == 0), "a brick past the space");
                }
            }
        }
    }
}

/// The invariants of one level whose entries lie in codes `[lo, hi)`, its leaves of
/// sides `2^k` for `k` in `ks` (inclusive) and its cells of side `2^P::LOG2`.
fn assert_level<P: Payload>(level: &Level<P>, (lo, hi): (u64, u64), ks: (u8, u8), what: &str) {
    assert_eq!(
        bricks_in(&level.items),
        level.payloads.len(),
        "{what}: one payload per mixed cell"
    );
    let mut prev_end = lo;
    for (i, &item) in level.items.iter().enumerate() {
        let (start, end) = if is_brick(item) {
            let code = item.packed() >> 1;
            assert_eq!(code % P::CODES, 0, "{what}: cell {i} not aligned");
            (code, (code + P::CODES).min(hi))
        } else {
            let k = item.size_log2();
            assert!(ks.0 <= k && k <= ks.1, "{what}: leaf {i} of side 2^{k}");
            assert_eq!(
                item.code() % item.voxel_count(),
                0,
                "{what}: leaf {i} unaligned"
            );
            (item.code(), item.end())
        };
        assert!(
            prev_end <= start,
            "{what}: entry {i} unsorted, overlapping or before its cell"
        );
        assert!(end <= hi, "{what}: entry {i} outside its cell or the space");
        prev_end = end;
        if i >= 7 {
            let run = &level.items[i - 7..=i];
            assert!(
                run.iter().any(|l| is_brick(*l)) || !completes_parent(run),
                "{what}: entries {}..={i} are eight unmerged siblings",
                i - 7
            );
        }
    }
}

/// The set operation `op` of two bricked forms of one space.
pub(crate) fn set_op(a: &Bricked, b: &Bricked, op: SetOp) -> Bricked {
    Bricked {
        top: level_op(&a.top, &b.top, op),
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

    /// `self` with its bricked form made: what the constructors of new solids
    /// (`from_classifier`, `from_voxels`, a scene's build) return, so that set
    /// operations on the trees a user builds run on bricks from the first one.
    #[must_use]
    pub(crate) fn with_bricks(self) -> Self {
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
