//! Blocks of 8×8×8 cells in a hash map: uniform blocks as one entry, mixed blocks as
//! 512 fixed-point log-odds in a pool.

use rustc_hash::FxHashMap;

use super::sensor::{Fixed, UNKNOWN};

/// Cells per block side (log2).
pub(crate) const BLOCK_LOG2: u32 = 3;
/// Cells per block.
pub(crate) const BLOCK_CELLS: usize = 512;

/// A block's coordinates: cell >> 3 per axis.
pub(crate) type BlockKey = [i64; 3];

/// The block of a cell and the cell's index in it (`x + 8y + 64z`, as the bit
/// blocks of the dynamic octree).
#[inline]
pub(crate) fn split(cell: [i64; 3]) -> (BlockKey, usize) {
    let b = cell.map(|c| c >> BLOCK_LOG2);
    let l = cell.map(|c| (c & 7) as usize);
    (b, l[0] | l[1] << 3 | l[2] << 6)
}

/// The cell at index `i` of block `b`.
#[inline]
pub(crate) fn join(b: BlockKey, i: usize) -> [i64; 3] {
    [
        b[0] << BLOCK_LOG2 | (i & 7) as i64,
        b[1] << BLOCK_LOG2 | (i >> 3 & 7) as i64,
        b[2] << BLOCK_LOG2 | (i >> 6) as i64,
    ]
}

/// A stored block: uniform (bit 31 set, value in the low 16 bits) or the index of a
/// mixed block in the pool.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Entry(u32);

const UNIFORM: u32 = 1 << 31;

impl Entry {
    pub fn uniform(v: i16) -> Self {
        Self(UNIFORM | u32::from(v as u16))
    }
    pub fn mixed(i: usize) -> Self {
        debug_assert!(i < UNIFORM as usize);
        Self(i as u32)
    }
    /// `Ok(value)` for a uniform block, `Err(index)` for a mixed one.
    #[inline]
    pub fn get(self) -> Result<i16, usize> {
        if self.0 & UNIFORM != 0 {
            Ok(self.0 as u16 as i16)
        } else {
            Err(self.0 as usize)
        }
    }
}

/// The cells of a mixed block.
pub(crate) type Cells = [i16; BLOCK_CELLS];

#[derive(Debug, Clone, Default)]
pub(crate) struct Store {
    index: FxHashMap<BlockKey, Entry>,
    pool: Vec<Cells>,
    free: Vec<u32>,
}

impl Store {
    /// The stored value of a cell (`UNKNOWN` when unknown).
    #[inline]
    pub fn get(&self, cell: [i64; 3]) -> i16 {
        let (b, i) = split(cell);
        match self.index.get(&b) {
            None => UNKNOWN,
            Some(e) => match e.get() {
                Ok(v) => v,
                Err(k) => self.pool[k][i],
            },
        }
    }

    /// The entry of a block.
    #[inline]
    pub fn entry(&self, b: BlockKey) -> Option<Entry> {
        self.index.get(&b).copied()
    }

    /// Sets one cell.
    pub fn set(&mut self, cell: [i64; 3], v: i16, fixed: Fixed) {
        let (b, i) = split(cell);
        let cells = match self.index.get(&b).map(|e| e.get()) {
            None if v == UNKNOWN => return,
            None => [UNKNOWN; BLOCK_CELLS],
            Some(Ok(u)) if u == v => return,
            Some(Ok(u)) => [u; BLOCK_CELLS],
            Some(Err(k)) => self.pool[k],
        };
        let mut cells = cells;
        cells[i] = v;
        self.put(b, &cells, fixed);
    }

    /// Mutable cells of block `b`, made mixed (filled from its current state).
    pub fn expand(&mut self, b: BlockKey) -> &mut Cells {
        let fill = match self.index.get(&b).map(|e| e.get()) {
            Some(Err(k)) => return &mut self.pool[k],
            Some(Ok(u)) => u,
            None => UNKNOWN,
        };
        let k = self.alloc(fill);
        self.index.insert(b, Entry::mixed(k));
        &mut self.pool[k]
    }

    /// Prunes block `b` if its cells are all one clamped value, drops it if all
    /// unknown.
    pub fn settle(&mut self, b: BlockKey, fixed: Fixed) {
        let Some(Err(k)) = self.index.get(&b).map(|e| e.get()) else {
            return;
        };
        let c = &self.pool[k];
        let first = c[0];
        if !c.iter().all(|&v| v == first) {
            return;
        }
        if first == UNKNOWN {
            self.index.remove(&b);
            self.release(k);
        } else if first == fixed.min || first == fixed.max {
            self.index.insert(b, Entry::uniform(first));
            self.release(k);
        }
    }

    /// Stores `cells` as block `b` (uniform, mixed or nothing).
    pub fn put(&mut self, b: BlockKey, cells: &Cells, fixed: Fixed) {
        let m = self.expand(b);
        *m = *cells;
        self.settle(b, fixed);
    }

    fn alloc(&mut self, fill: i16) -> usize {
        if let Some(k) = self.free.pop() {
            self.pool[k as usize] = [fill; BLOCK_CELLS];
            k as usize
        } else {
            self.pool.push([fill; BLOCK_CELLS]);
            self.pool.len() - 1
        }
    }

    fn release(&mut self, k: usize) {
        self.free.push(k as u32);
    }

    /// Reserves room for `n` more blocks in the index.
    pub fn reserve(&mut self, n: usize) {
        self.index.reserve(n);
    }

    /// Counts the known cells whose value passes `f`.
    pub fn count(&self, f: impl Fn(i16) -> bool) -> u64 {
        let mut n = 0u64;
        for e in self.index.values() {
            match e.get() {
                Ok(v) => n += if f(v) { BLOCK_CELLS as u64 } else { 0 },
                Err(k) => {
                    n += self.pool[k]
                        .iter()
                        .filter(|&&v| v != UNKNOWN && f(v))
                        .count() as u64
                }
            }
        }
        n
    }

    pub fn leaf_count(&self) -> u64 {
        let mut n = 0u64;
        for e in self.index.values() {
            match e.get() {
                Ok(_) => n += 1,
                Err(k) => n += self.pool[k].iter().filter(|&&v| v != UNKNOWN).count() as u64,
            }
        }
        n
    }

    pub fn block_count(&self) -> usize {
        self.index.len()
    }

    /// Every block: key and entry, in no order.
    pub fn blocks(&self) -> impl Iterator<Item = (BlockKey, Entry)> + '_ {
        self.index.iter().map(|(b, e)| (*b, *e))
    }

    /// Calls `f` on every known cell, in no order.
    pub fn for_each(&self, mut f: impl FnMut([i64; 3], i16)) {
        for (b, e) in self.blocks() {
            match e.get() {
                Ok(v) => (0..BLOCK_CELLS).for_each(|i| f(join(b, i), v)),
                Err(k) => {
                    for (i, &v) in self.pool[k].iter().enumerate() {
                        if v != UNKNOWN {
                            f(join(b, i), v);
                        }
                    }
                }
            }
        }
    }

    pub fn bytes(&self) -> usize {
        // hashbrown: key + value per bucket, plus one control byte.
        let bucket = std::mem::size_of::<(BlockKey, Entry)>() + 1;
        self.index.capacity() * bucket
            + self.pool.capacity() * std::mem::size_of::<Cells>()
            + self.free.capacity() * 4
    }

    pub fn assert_valid(&self, fixed: Fixed) {
        let mut used = vec![false; self.pool.len()];
        for (b, e) in self.blocks() {
            match e.get() {
                Ok(v) => assert!(
                    v == fixed.min || v == fixed.max,
                    "uniform block {b:?} holds {v}, not a clamp"
                ),
                Err(k) => {
                    assert!(k < self.pool.len(), "block {b:?}: index {k} past the pool");
                    assert!(!used[k], "pool entry {k} used twice");
                    used[k] = true;
                    let c = &self.pool[k];
                    assert!(
                        c.iter().any(|&v| v != UNKNOWN),
                        "mixed block {b:?} is all unknown"
                    );
                    assert!(
                        !(c.iter().all(|&v| v == c[0]) && (c[0] == fixed.min || c[0] == fixed.max)),
                        "mixed block {b:?} is uniformly clamped: it should be pruned"
                    );
                    for &v in c {
                        assert!(
                            v == UNKNOWN || (fixed.min..=fixed.max).contains(&v),
                            "block {b:?}: value {v} outside the clamps"
                        );
                    }
                }
            }
        }
        for &k in &self.free {
            assert!(!used[k as usize], "pool entry {k} both used and free");
            used[k as usize] = true;
        }
        assert!(
            used.iter().all(|&u| u),
            "a pool entry is neither used nor free"
        );
    }
}
