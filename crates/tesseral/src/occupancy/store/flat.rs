//! The read index: every block's entry in one flat array over the stored blocks'
//! bounding box, so that a lookup goes from a cell straight to its block's entry
//! (index arithmetic, one load) instead of through the superblock directory and a
//! table (two dependent loads).
//!
//! The tables stay the store's authority; the index mirrors their entries. It is
//! *live* only while it is exact: a write inside its box is mirrored, a block made
//! outside it retires it, and lookups then go through the directory until
//! [`Store::settle`] (called after each scan is applied) rebuilds it over the new
//! box.
//!
//! - It is built only while it takes at most half the bytes of the rest of the
//!   store (or [`FLAT_MIN`] bytes): a map whose blocks lie far apart keeps the
//!   directory alone.
//! - And at most [`FLAT_MAX`] bytes: in a map far bigger than the CPU's caches a
//!   lookup misses the cache on the block's entry either way (the table's or the
//!   index's) and again in the block, so the index would save only the directory
//!   slot, which stays cached, while it cost memory (106 MB beside the 236 MB of
//!   the outdoor benchmark's map) and a rebuild (5 % of that map's insertion).
//!   Measured on an AMD EPYC VM with 128 MiB allowed, the outdoor lookups took
//!   10.8-11.0 ns in a warm loop against 12.2-12.5 (16.5-17.7 against 19.2-19.5
//!   in the first): a tenth faster for 45 % more memory, not worth it.
//! - A rebuild waits until the cells updated since the last one number
//!   [`AMORTISE`] times the new box's blocks. A rebuild costs 1 to 5 ns a block
//!   (the latter when its pages are new to the process), an updated cell 15 to
//!   50 ns, so scans that keep growing the box spend a few percent of their time
//!   on rebuilds at most.

use super::{stored, BlockKey, Entry, Store};

/// Bytes the index may always take, whatever the store's size (16 KiB).
const FLAT_MIN: usize = 16 << 10;
/// Bytes the index never passes (8 MiB: two million blocks, a box of 126³ blocks,
/// 50 m a side at 5 cm).
const FLAT_MAX: usize = 8 << 20;
/// The read index is rebuilt once AMORTISE times as many cells were updated since it
/// was last built as it would hold blocks (see [`Store::settle`]).
const AMORTISE: u64 = 2;

#[derive(Debug, Clone, Default)]
pub(crate) struct Flat {
    /// The box's lowest block.
    lo: BlockKey,
    /// The box's sides in blocks (all 0 when the index is not live).
    dims: [u64; 3],
    /// The entries from one block to the next along y and z (`dims[0]`,
    /// `dims[0] * dims[1]`), so that a lookup's two products do not wait on each
    /// other.
    strides: [u64; 2],
    /// Block entries, x fastest (empty when not live).
    entries: Vec<Entry>,
    /// The bounding box of every block ever given an entry (lowest, highest).
    bbox: Option<(BlockKey, BlockKey)>,
}

impl Flat {
    /// Whether the index mirrors every entry (lookups may use it).
    #[inline(always)]
    pub fn live(&self) -> bool {
        self.dims[0] != 0
    }

    /// The position of block `b` in the entries, if inside the box (never when not
    /// live).
    #[inline(always)]
    pub fn index(&self, b: BlockKey) -> Option<usize> {
        // Below `lo`, the difference wraps past every side.
        let d = [0, 1, 2].map(|a| b[a].wrapping_sub(self.lo[a]) as u64);
        (d[0] < self.dims[0] && d[1] < self.dims[1] && d[2] < self.dims[2])
            .then(|| (d[0] + self.strides[0] * d[1] + self.strides[1] * d[2]) as usize)
    }

    /// The entry at position `at`, as [`index`](Self::index) gives it.
    #[inline(always)]
    pub fn entry(&self, at: usize) -> Entry {
        debug_assert!(at < self.entries.len());
        // SAFETY: `index` gives positions below the product of the sides, and while
        // the index is live `entries` holds that many (set together in `rebuild`,
        // cleared together in `retire`; checked by `assert_valid`).
        unsafe { *self.entries.get_unchecked(at) }
    }

    /// The entries, by [`index`](Self::index).
    #[inline(always)]
    pub fn entries(&self) -> &[Entry] {
        &self.entries
    }

    /// Mirrors the write of entry `e` for block `b`: retires the index when `b`
    /// is new and outside its box.
    #[inline]
    pub fn set(&mut self, b: BlockKey, e: Entry) {
        if e != Entry::EMPTY {
            self.bbox = Some(match self.bbox {
                None => (b, b),
                Some((lo, hi)) => (
                    [0, 1, 2].map(|a| lo[a].min(b[a])),
                    [0, 1, 2].map(|a| hi[a].max(b[a])),
                ),
            });
        }
        if let Some(at) = self.index(b) {
            self.entries[at] = e;
        } else if e != Entry::EMPTY && self.live() {
            self.retire();
        }
    }

    /// Stops mirroring and frees the entries.
    pub fn retire(&mut self) {
        self.dims = [0; 3];
        self.strides = [0; 2];
        self.entries = Vec::new();
    }

    /// The box a rebuild would cover: the bounding box grown by a 32nd of its side
    /// each way (so that a growing map rebuilds rarely), as (lowest block, sides,
    /// blocks), if it takes at most `budget` bytes (or [`FLAT_MIN`]).
    pub fn plan(&self, budget: usize) -> Option<(BlockKey, [u64; 3], usize)> {
        let (lo, hi) = self.bbox?;
        let limit = (budget.max(FLAT_MIN) / std::mem::size_of::<Entry>()) as u128;
        let mut new_lo = [0i64; 3];
        let mut dims = [0u64; 3];
        let mut volume: u128 = 1;
        for a in 0..3 {
            // In i128: a map may span the whole i64 range of blocks.
            let side = i128::from(hi[a]) - i128::from(lo[a]) + 1;
            let slack = side / 32;
            let l = (i128::from(lo[a]) - slack).max(i128::from(i64::MIN));
            let h = (i128::from(hi[a]) + slack).min(i128::from(i64::MAX));
            let n = (h - l + 1) as u128;
            volume = volume.saturating_mul(n);
            if volume > limit {
                return None;
            }
            new_lo[a] = l as i64;
            dims[a] = n as u64;
        }
        Some((new_lo, dims, volume as usize))
    }

    /// Rebuilds the index over the box of [`plan`](Self::plan); `fill` then writes
    /// every entry with [`set`](Self::set).
    ///
    /// # Runtime
    /// O(v) for the box's v blocks, plus `fill`.
    pub fn rebuild(
        &mut self,
        (lo, dims, volume): (BlockKey, [u64; 3], usize),
        fill: impl FnOnce(&mut Self),
    ) {
        self.lo = lo;
        self.dims = dims;
        self.strides = [dims[0], dims[0] * dims[1]];
        self.entries = vec![Entry::EMPTY; volume];
        fill(self);
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        self.entries.capacity() * std::mem::size_of::<Entry>()
    }

    /// Checks that the index, if live, holds exactly the entries `all` gives
    /// (block, entry; every entry not empty), and that the bounding box holds
    /// them.
    ///
    /// # Panics
    /// When they disagree.
    pub fn assert_valid(&self, all: impl Iterator<Item = (BlockKey, Entry)>) {
        let mut n = 0;
        for (b, e) in all {
            let (lo, hi) = self.bbox.expect("a bounding box");
            assert!(
                (0..3).all(|a| lo[a] <= b[a] && b[a] <= hi[a]),
                "block {b:?} outside the read index's bounding box"
            );
            if self.live() {
                let at = self.index(b).expect("a block outside the read index");
                assert_eq!(self.entries[at], e, "the read index's entry of {b:?}");
            }
            n += 1;
        }
        if self.live() {
            let volume = self.dims.iter().map(|&d| d as usize).product::<usize>();
            assert_eq!(self.entries.len(), volume, "the read index's length");
            let held = self.entries.iter().filter(|&&e| e != Entry::EMPTY).count();
            assert_eq!(held, n, "entries in the read index");
        } else {
            assert!(self.entries.is_empty(), "entries in a retired read index");
        }
    }
}

impl Store {
    /// Counts `cells` updated by a scan, towards the read index's next rebuild.
    pub fn worked(&mut self, cells: u64) {
        self.work = self.work.saturating_add(cells);
    }

    /// Rebuilds the read index when a block was made outside its box since it was
    /// built (see the module docs), if it fits its budget and the work since the last
    /// rebuild pays for it: a rebuild waits until [`AMORTISE`] times as many cells
    /// were updated since the last one ([`Store::worked`], [`Store::set`]) as the
    /// new box holds blocks. Scans that keep making blocks outside the box (a robot
    /// exploring) then spend at most a few percent of their time on rebuilds, and
    /// their lookups go through the directory meanwhile. Cheap when it is live.
    ///
    /// # Runtime
    /// O(1) when live, over budget or waiting; else O(v + t) for the index's v
    /// blocks and the t table entries.
    pub fn settle(&mut self) {
        if self.flat.live() {
            return;
        }
        let Some(plan) = self.flat.plan((self.bytes() / 2).min(FLAT_MAX)) else {
            return;
        };
        if self.work < (plan.2 as u64).saturating_mul(AMORTISE) {
            return;
        }

        self.work = 0;
        let (keys, tables) = (&self.keys, &self.tables);
        self.flat.rebuild(plan, |flat| {
            for (b, e) in stored(keys, tables) {
                flat.set(b, e);
            }
        });
    }

    /// Whether lookups go through the read index.
    #[cfg(test)]
    pub fn flat_live(&self) -> bool {
        self.flat.live()
    }
}
