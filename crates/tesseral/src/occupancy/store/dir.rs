//! The superblock directory: a superblock's key (block >> 3 per axis) to its
//! table's number.
//!
//! A hash map holds every superblock (keys are unbounded `i64`). Beside it, while
//! the superblocks' bounding box (with some slack to grow into) has at most
//! [`DENSE_PER_SUPERBLOCK`] slots per superblock stored (or [`DENSE_MIN`] slots),
//! a dense array over that box answers lookups with index arithmetic only, no
//! hashing. A map whose superblocks lie far apart (a huge sparse extent) keeps the
//! hash map alone, and tries a dense box again once it has twice as many superblocks.

use rustc_hash::FxHashMap;

use super::BlockKey;

/// Dense slots allowed per superblock stored (4 bytes each, beside a 2 KiB table).
const DENSE_PER_SUPERBLOCK: u64 = 32;
/// Dense slots always allowed (16 KiB).
const DENSE_MIN: u64 = 4096;

#[derive(Debug, Clone, Default)]
pub(crate) struct Directory {
    /// Every superblock and its table's number.
    map: FxHashMap<BlockKey, u32>,
    /// The dense box's lowest superblock.
    lo: [i64; 3],
    /// The dense box's sides in superblocks (all 0 when there is no dense box).
    dims: [u64; 3],
    /// Table number + 1 per superblock of the box (x fastest), 0 for none.
    slots: Vec<u32>,
    /// The bounding box of every superblock (lowest, highest), if any.
    bbox: Option<([i64; 3], [i64; 3])>,
    /// Superblocks at which to try a dense box again (after one was refused).
    retry_at: usize,
}

impl Directory {
    /// The table of superblock `s`.
    #[inline(always)]
    pub fn get(&self, s: BlockKey) -> Option<u32> {
        if self.dims[0] == 0 {
            return self.map.get(&s).copied();
        }
        // Below `lo`, the difference wraps past every side.
        let d = [0, 1, 2].map(|a| s[a].wrapping_sub(self.lo[a]) as u64);
        if d[0] < self.dims[0] && d[1] < self.dims[1] && d[2] < self.dims[2] {
            let at = d[0] + self.dims[0] * (d[1] + self.dims[1] * d[2]);
            self.slots[at as usize].checked_sub(1)
        } else {
            None
        }
    }

    /// The table of `s`, or `next` when `s` is new (then recorded with that number).
    pub fn get_or_insert(&mut self, s: BlockKey, next: u32) -> u32 {
        let t = *self.map.entry(s).or_insert(next);
        if t == next {
            self.added(s, t);
        }
        t
    }

    /// Records new superblock `s` (table `t`) in the bounding box and the dense box.
    fn added(&mut self, s: BlockKey, t: u32) {
        self.bbox = Some(match self.bbox {
            None => (s, s),
            Some((lo, hi)) => (
                [0, 1, 2].map(|a| lo[a].min(s[a])),
                [0, 1, 2].map(|a| hi[a].max(s[a])),
            ),
        });
        if self.dims[0] != 0 {
            if let Some(at) = self.index(s) {
                self.slots[at] = t + 1;
                return;
            }
        }
        if self.dims[0] != 0 || self.map.len() >= self.retry_at {
            self.rebuild();
        }
    }

    /// The slot of `s` in the dense box, if inside.
    fn index(&self, s: BlockKey) -> Option<usize> {
        let d = [0, 1, 2].map(|a| s[a].wrapping_sub(self.lo[a]) as u64);
        (d[0] < self.dims[0] && d[1] < self.dims[1] && d[2] < self.dims[2])
            .then(|| (d[0] + self.dims[0] * (d[1] + self.dims[1] * d[2])) as usize)
    }

    /// The most dense slots allowed now.
    fn budget(&self) -> u64 {
        (self.map.len() as u64)
            .saturating_mul(DENSE_PER_SUPERBLOCK)
            .max(DENSE_MIN)
    }

    /// Builds the dense box over the bounding box grown by a quarter of its side
    /// each way (so that a growing map rebuilds it rarely), or drops it when that
    /// box is over budget.
    fn rebuild(&mut self) {
        let Some((lo, hi)) = self.bbox else { return };
        let mut new_lo = [0i64; 3];
        let mut dims = [0u64; 3];
        let mut volume: u64 = 1;
        for a in 0..3 {
            // Sides in i128: a map may span the whole i64 range of superblocks.
            let side = i128::from(hi[a]) - i128::from(lo[a]) + 1;
            let slack = side / 4 + 1;
            let l = (i128::from(lo[a]) - slack).max(i128::from(i64::MIN));
            let h = (i128::from(hi[a]) + slack).min(i128::from(i64::MAX));
            let n = h - l + 1;
            match u64::try_from(n).ok().and_then(|n| volume.checked_mul(n)) {
                Some(v) => volume = v,
                None => volume = u64::MAX,
            }
            new_lo[a] = l as i64;
            dims[a] = u64::try_from(n).unwrap_or(u64::MAX);
        }
        if volume > self.budget() {
            self.dims = [0; 3];
            self.slots = Vec::new();
            self.retry_at = self.map.len() * 2;
            return;
        }
        self.lo = new_lo;
        self.dims = dims;
        self.slots.clear();
        self.slots.shrink_to(volume as usize);
        self.slots.resize(volume as usize, 0);
        for (&s, &t) in &self.map {
            let at = self.index(s).expect("inside the box");
            self.slots[at] = t + 1;
        }
    }

    /// Reserves room for `n` more superblocks.
    pub fn reserve(&mut self, n: usize) {
        self.map.reserve(n);
    }

    /// Bytes held: the hash map's buckets and the dense slots.
    pub fn bytes(&self) -> usize {
        // hashbrown: key + value per bucket, plus one control byte.
        let bucket = std::mem::size_of::<(BlockKey, u32)>() + 1;
        self.map.capacity() * bucket + self.slots.capacity() * 4
    }

    /// Whether lookups go through the dense box.
    #[cfg(test)]
    pub fn is_dense(&self) -> bool {
        self.dims[0] != 0
    }

    /// Checks that the hash map numbers the superblocks `keys` in order, that the
    /// bounding box holds them, and that the dense box, if any, agrees with the map
    /// slot for slot.
    ///
    /// # Panics
    /// When they disagree.
    pub fn assert_valid(&self, keys: &[BlockKey]) {
        assert_eq!(keys.len(), self.map.len(), "one key per table");
        for (t, k) in keys.iter().enumerate() {
            assert_eq!(self.map.get(k), Some(&(t as u32)), "superblock {k:?}");
            let (lo, hi) = self.bbox.expect("a bounding box");
            assert!(
                (0..3).all(|a| lo[a] <= k[a] && k[a] <= hi[a]),
                "superblock {k:?} outside the bounding box"
            );
            assert_eq!(self.get(*k), Some(t as u32), "lookup of superblock {k:?}");
        }
        if self.dims[0] == 0 {
            assert!(self.slots.is_empty(), "dense slots without a box");
            assert!(self.dims.iter().all(|&d| d == 0), "a box with a side 0");
            return;
        }
        assert!(
            self.dims.iter().all(|&d| d > 0),
            "a dense box with a side 0"
        );
        let volume = self.dims.iter().product::<u64>();
        assert_eq!(self.slots.len() as u64, volume, "dense slots");
        assert!(volume <= self.budget(), "the dense box is over budget");
        let filled = self.slots.iter().filter(|&&t| t != 0).count();
        assert_eq!(filled, keys.len(), "dense slots filled");
        for (t, k) in keys.iter().enumerate() {
            let at = self.index(*k).expect("a superblock outside the dense box");
            assert_eq!(self.slots[at], t as u32 + 1, "dense slot of {k:?}");
        }
    }
}
