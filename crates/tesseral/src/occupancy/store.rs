//! Blocks of 8×8×8 cells in a hash map: uniform blocks as one entry, sparse blocks as
//! their known cells (index and fixed-point log-odds, sorted), dense blocks as 512
//! fixed-point log-odds.

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

/// A stored block: uniform (bit 31 set, value in the low 16 bits), or the index of a
/// sparse (bit 30 set) or dense block in its pool.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Entry(u32);

const UNIFORM: u32 = 1 << 31;
const SPARSE: u32 = 1 << 30;

/// What an [`Entry`] holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    /// All 512 cells clamped to this value.
    Uniform(i16),
    /// The index of a sparse block in its pool.
    Sparse(usize),
    /// The index of a dense block in its pool.
    Dense(usize),
}

impl Entry {
    pub fn uniform(v: i16) -> Self {
        Self(UNIFORM | u32::from(v as u16))
    }
    fn sparse(i: usize) -> Self {
        debug_assert!(i < SPARSE as usize);
        Self(SPARSE | i as u32)
    }
    fn dense(i: usize) -> Self {
        debug_assert!(i < SPARSE as usize);
        Self(i as u32)
    }
    #[inline]
    pub fn kind(self) -> Kind {
        if self.0 & UNIFORM != 0 {
            Kind::Uniform(self.0 as u16 as i16)
        } else if self.0 & SPARSE != 0 {
            Kind::Sparse((self.0 & !SPARSE) as usize)
        } else {
            Kind::Dense(self.0 as usize)
        }
    }
}

/// The cells of a dense block.
pub(crate) type Cells = [i16; BLOCK_CELLS];

/// A sparse block: its known cells, sorted, each `index << 16 | value as u16`.
type Sparse = Box<[u32]>;

/// The most known cells a sparse block holds (4 bytes each); a block with more is
/// dense (2 bytes per cell).
pub(crate) const SPARSE_MAX: usize = 128;

#[inline]
fn sparse_cell(index: usize, v: i16) -> u32 {
    (index as u32) << 16 | u32::from(v as u16)
}

#[inline]
fn sparse_index(e: u32) -> usize {
    (e >> 16) as usize
}

#[inline]
fn sparse_value(e: u32) -> i16 {
    e as u16 as i16
}

/// A pool of blocks of one form, with a free list.
#[derive(Debug, Clone)]
struct Pool<T> {
    items: Vec<T>,
    free: Vec<u32>,
}

impl<T> Default for Pool<T> {
    fn default() -> Self {
        Self {
            items: Vec::new(),
            free: Vec::new(),
        }
    }
}

impl<T> Pool<T> {
    fn alloc(&mut self, item: T) -> usize {
        if let Some(k) = self.free.pop() {
            self.items[k as usize] = item;
            k as usize
        } else {
            self.items.push(item);
            self.items.len() - 1
        }
    }

    /// Frees slot `k`, replacing its item by `empty` (or keeping it for reuse).
    fn release(&mut self, k: usize, empty: Option<T>) {
        if let Some(e) = empty {
            self.items[k] = e;
        }
        self.free.push(k as u32);
    }

    /// Marks the slots in use: `true` for each one not free.
    fn used(&self) -> Vec<bool> {
        let mut used = vec![true; self.items.len()];
        for &k in &self.free {
            assert!(used[k as usize], "pool slot {k} freed twice");
            used[k as usize] = false;
        }
        used
    }
}

#[derive(Debug, Clone, Default)]
pub(crate) struct Store {
    index: FxHashMap<BlockKey, Entry>,
    /// Dense blocks and their keys, packed (a freed slot takes the last block).
    dense: Vec<(BlockKey, Box<Cells>)>,
    sparse: Pool<Sparse>,
}

impl Store {
    /// The stored value of a cell (`UNKNOWN` when unknown).
    #[inline]
    pub fn get(&self, cell: [i64; 3]) -> i16 {
        let (b, i) = split(cell);
        match self.index.get(&b).map(|e| e.kind()) {
            None => UNKNOWN,
            Some(Kind::Uniform(v)) => v,
            Some(Kind::Dense(k)) => self.dense[k].1[i],
            Some(Kind::Sparse(k)) => {
                let cells = &self.sparse.items[k];
                match cells.binary_search_by_key(&i, |&e| sparse_index(e)) {
                    Ok(at) => sparse_value(cells[at]),
                    Err(_) => UNKNOWN,
                }
            }
        }
    }

    /// The entry of a block.
    #[cfg(test)]
    pub fn entry(&self, b: BlockKey) -> Option<Entry> {
        self.index.get(&b).copied()
    }

    /// The 512 values of block `b` (`UNKNOWN` for unknown cells).
    pub fn cells(&self, b: BlockKey) -> Cells {
        match self.index.get(&b).map(|e| e.kind()) {
            None => [UNKNOWN; BLOCK_CELLS],
            Some(Kind::Uniform(v)) => [v; BLOCK_CELLS],
            Some(Kind::Dense(k)) => *self.dense[k].1,
            Some(Kind::Sparse(k)) => {
                let mut c = [UNKNOWN; BLOCK_CELLS];
                for &e in self.sparse.items[k].iter() {
                    c[sparse_index(e)] = sparse_value(e);
                }
                c
            }
        }
    }

    /// Sets one cell.
    pub fn set(&mut self, cell: [i64; 3], v: i16, fixed: Fixed) {
        let (b, i) = split(cell);
        if self.get(cell) == v {
            return;
        }
        let mut cells = self.cells(b);
        cells[i] = v;
        self.put(b, &cells, fixed);
    }

    /// Removes block `b`'s entry and frees its storage.
    fn drop_block(&mut self, b: BlockKey) {
        match self.index.remove(&b).map(|e| e.kind()) {
            Some(Kind::Dense(k)) => {
                self.dense.swap_remove(k);
                if let Some(&(moved, _)) = self.dense.get(k) {
                    self.index.insert(moved, Entry::dense(k));
                }
            }
            Some(Kind::Sparse(k)) => self.sparse.release(k, Some(Box::default())),
            _ => {}
        }
    }

    /// Stores `cells` as block `b`, in the smallest form: nothing when all unknown,
    /// uniform when all clamped to one value, sparse up to [`SPARSE_MAX`] known
    /// cells, dense beyond.
    pub fn put(&mut self, b: BlockKey, cells: &Cells, fixed: Fixed) {
        let known = cells.iter().filter(|&&v| v != UNKNOWN).count();
        let first = cells[0];
        if known == BLOCK_CELLS
            && (first == fixed.min || first == fixed.max)
            && cells.iter().all(|&v| v == first)
        {
            self.drop_block(b);
            self.index.insert(b, Entry::uniform(first));
        } else if known == 0 {
            self.drop_block(b);
        } else if known <= SPARSE_MAX {
            let list: Sparse = cells
                .iter()
                .enumerate()
                .filter(|(_, &v)| v != UNKNOWN)
                .map(|(i, &v)| sparse_cell(i, v))
                .collect();
            self.put_sparse(b, list);
        } else {
            match self.index.get(&b).map(|e| e.kind()) {
                Some(Kind::Dense(k)) => *self.dense[k].1 = *cells,
                _ => {
                    self.drop_block(b);
                    self.dense.push((b, Box::new(*cells)));
                    self.index.insert(b, Entry::dense(self.dense.len() - 1));
                }
            }
        }
    }

    /// Stores a sparse list (sorted, 1 to [`SPARSE_MAX`] cells) as block `b`.
    fn put_sparse(&mut self, b: BlockKey, list: Sparse) {
        match self.index.get(&b).map(|e| e.kind()) {
            Some(Kind::Sparse(k)) => self.sparse.items[k] = list,
            _ => {
                self.drop_block(b);
                let k = self.sparse.alloc(list);
                self.index.insert(b, Entry::sparse(k));
            }
        }
    }

    /// Applies one scan's updates to block `b`: the cells of `miss` get a miss, those
    /// of `hit` a hit (the masks are disjoint; bit `x + 8y` of word `z`).
    pub fn update(&mut self, b: BlockKey, miss: &[u64; 8], hit: &[u64; 8], fixed: Fixed) {
        let kind = self.index.get(&b).map(|e| e.kind());
        let n_hit: u32 = hit.iter().map(|w| w.count_ones()).sum();
        let n_miss: u32 = miss.iter().map(|w| w.count_ones()).sum();
        match kind {
            Some(Kind::Uniform(v)) => {
                // A clamped block that the updates only push further: unchanged.
                if (v == fixed.min && n_hit == 0) || (v == fixed.max && n_miss == 0) {
                    return;
                }
                let mut cells = [v; BLOCK_CELLS];
                apply_masks(&mut cells, miss, hit, fixed);
                self.put(b, &cells, fixed);
            }
            Some(Kind::Dense(k)) => {
                let cells = &mut self.dense[k].1;
                apply_masks(cells, miss, hit, fixed);
                let first = cells[0];
                if (first == fixed.min || first == fixed.max) && cells.iter().all(|&v| v == first) {
                    self.drop_block(b);
                    self.index.insert(b, Entry::uniform(first));
                }
            }
            None | Some(Kind::Sparse(_)) => {
                let old: &[u32] = match kind {
                    Some(Kind::Sparse(k)) => &self.sparse.items[k],
                    _ => &[],
                };
                // Merge the sorted old cells with the updated ones, in index order.
                let mut out: Vec<u32> = Vec::with_capacity(old.len() + (n_hit + n_miss) as usize);
                let mut at = 0;
                for w in 0..8 {
                    let mut bits = miss[w] | hit[w];
                    while bits != 0 {
                        let i = w << 6 | bits.trailing_zeros() as usize;
                        let bit = bits & bits.wrapping_neg();
                        bits ^= bit;
                        while at < old.len() && sparse_index(old[at]) < i {
                            out.push(old[at]);
                            at += 1;
                        }
                        let v = if at < old.len() && sparse_index(old[at]) == i {
                            at += 1;
                            sparse_value(old[at - 1])
                        } else {
                            UNKNOWN
                        };
                        let v = if hit[w] & bit != 0 {
                            fixed.apply_hit(v)
                        } else {
                            fixed.apply_miss(v)
                        };
                        out.push(sparse_cell(i, v));
                    }
                }
                out.extend_from_slice(&old[at..]);
                if out.len() <= SPARSE_MAX {
                    self.put_sparse(b, out.into_boxed_slice());
                } else {
                    let mut cells = [UNKNOWN; BLOCK_CELLS];
                    for &e in &out {
                        cells[sparse_index(e)] = sparse_value(e);
                    }
                    self.put(b, &cells, fixed);
                }
            }
        }
    }

    /// Reserves room for `n` more blocks in the index.
    pub fn reserve(&mut self, n: usize) {
        self.index.reserve(n);
    }

    /// Calls `f` on every block's known cells: `(index in block, value)`, or once
    /// with `None` and the value of a uniform block.
    fn visit(&self, mut f: impl FnMut(BlockKey, Option<usize>, i16)) {
        for (&b, e) in &self.index {
            match e.kind() {
                Kind::Uniform(v) => f(b, None, v),
                Kind::Dense(k) => {
                    for (i, &v) in self.dense[k].1.iter().enumerate() {
                        if v != UNKNOWN {
                            f(b, Some(i), v);
                        }
                    }
                }
                Kind::Sparse(k) => {
                    for &e in self.sparse.items[k].iter() {
                        f(b, Some(sparse_index(e)), sparse_value(e));
                    }
                }
            }
        }
    }

    /// Counts the known cells whose value passes `f`.
    pub fn count(&self, f: impl Fn(i16) -> bool) -> u64 {
        let mut n = 0u64;
        self.visit(|_, i, v| {
            if f(v) {
                n += if i.is_some() { 1 } else { BLOCK_CELLS as u64 };
            }
        });
        n
    }

    pub fn leaf_count(&self) -> u64 {
        let mut n = 0u64;
        self.visit(|_, _, _| n += 1);
        n
    }

    pub fn block_count(&self) -> usize {
        self.index.len()
    }

    /// Calls `f` on every known cell, in no order.
    pub fn for_each(&self, mut f: impl FnMut([i64; 3], i16)) {
        self.visit(|b, i, v| match i {
            Some(i) => f(join(b, i), v),
            None => (0..BLOCK_CELLS).for_each(|i| f(join(b, i), v)),
        });
    }

    /// Bytes held: the index's buckets, the pools' capacities, each block's own
    /// allocation (rounded up to 16 bytes, plus 8 bytes of allocator header).
    pub fn bytes(&self) -> usize {
        // hashbrown: key + value per bucket, plus one control byte.
        let bucket = std::mem::size_of::<(BlockKey, Entry)>() + 1;
        let sparse_cells: usize = self
            .sparse
            .items
            .iter()
            .filter(|s| !s.is_empty())
            .map(|s| (s.len() * 4 + 8).div_ceil(16) * 16)
            .sum();
        let dense_cells = self.dense.len() * (std::mem::size_of::<Cells>() + 8).div_ceil(16) * 16;
        self.index.capacity() * bucket
            + self.dense.capacity() * std::mem::size_of::<(BlockKey, Box<Cells>)>()
            + dense_cells
            + self.sparse.items.capacity() * std::mem::size_of::<Sparse>()
            + sparse_cells
            + self.sparse.free.capacity() * 4
    }

    pub fn assert_valid(&self, fixed: Fixed) {
        let mut dense_used = vec![true; self.dense.len()];
        let mut sparse_used = self.sparse.used();
        let in_clamps = |b: BlockKey, v: i16| {
            assert!(
                (fixed.min..=fixed.max).contains(&v),
                "block {b:?}: value {v} outside the clamps"
            );
        };
        for (&b, e) in &self.index {
            match e.kind() {
                Kind::Uniform(v) => assert!(
                    v == fixed.min || v == fixed.max,
                    "uniform block {b:?} holds {v}, not a clamp"
                ),
                Kind::Dense(k) => {
                    assert!(
                        dense_used.get(k) == Some(&true),
                        "block {b:?}: dense slot {k} not in use"
                    );
                    dense_used[k] = false;
                    assert_eq!(self.dense[k].0, b, "dense slot {k} names another block");
                    let c = &self.dense[k].1;
                    let known = c.iter().filter(|&&v| v != UNKNOWN).count();
                    assert!(
                        known > SPARSE_MAX,
                        "dense block {b:?} holds {known} cells: it should be sparse"
                    );
                    assert!(
                        !(c.iter().all(|&v| v == c[0]) && (c[0] == fixed.min || c[0] == fixed.max)),
                        "dense block {b:?} is uniformly clamped: it should be pruned"
                    );
                    c.iter()
                        .filter(|&&v| v != UNKNOWN)
                        .for_each(|&v| in_clamps(b, v));
                }
                Kind::Sparse(k) => {
                    assert!(
                        sparse_used.get(k) == Some(&true),
                        "block {b:?}: sparse slot {k} not in use"
                    );
                    sparse_used[k] = false;
                    let c = &self.sparse.items[k];
                    assert!(
                        (1..=SPARSE_MAX).contains(&c.len()),
                        "sparse block {b:?} holds {} cells",
                        c.len()
                    );
                    assert!(
                        c.windows(2)
                            .all(|w| sparse_index(w[0]) < sparse_index(w[1])),
                        "sparse block {b:?} is not sorted"
                    );
                    assert!(
                        sparse_index(c[c.len() - 1]) < BLOCK_CELLS,
                        "sparse block {b:?}: index past the block"
                    );
                    c.iter().for_each(|&e| in_clamps(b, sparse_value(e)));
                }
            }
        }
        assert!(dense_used.iter().all(|&u| !u), "a dense slot has no block");
        assert!(
            sparse_used.iter().all(|&u| !u),
            "a sparse slot is in use but no block has it"
        );
    }
}

/// Applies disjoint miss and hit masks to a block's 512 values.
fn apply_masks(cells: &mut Cells, miss: &[u64; 8], hit: &[u64; 8], fixed: Fixed) {
    for w in 0..8 {
        let mut bits = miss[w];
        while bits != 0 {
            let i = w << 6 | bits.trailing_zeros() as usize;
            cells[i] = fixed.apply_miss(cells[i]);
            bits &= bits - 1;
        }
        let mut bits = hit[w];
        while bits != 0 {
            let i = w << 6 | bits.trailing_zeros() as usize;
            cells[i] = fixed.apply_hit(cells[i]);
            bits &= bits - 1;
        }
    }
}
