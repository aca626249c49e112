//! Blocks of 8×8×8 cells, found through a two-level directory (superblocks of
//! 8×8×8 blocks, each a flat table of 512 block entries) and held in
//! one arena in the smallest of four forms: uniform (in the entry), sparse, palette
//! (1, 2, 4 or 8 bits a cell and a value list) or dense (see [`forms`]). The
//! directory is dense over the superblocks' bounding box while that box is small
//! enough, a hash map otherwise (see [`dir`]); reads are in [`lookup`].

mod arena;
mod dir;
mod flat;
mod forms;
mod fresh;
mod lookup;
mod probe;
mod sparse;
mod valid;
mod visit;

use super::sensor::{Fixed, UNKNOWN};
use arena::{Arena, UNIT};
use dir::Directory;
use flat::Flat;
use forms::{
    apply_masks, choose, decode, palette_single, palette_update, units_of, write_dense,
    write_palette, write_sparse, Census, DENSE, EMPTY, PALETTE, SPARSE, UNIFORM,
};
pub(crate) use lookup::BATCH;

/// Cells per block side (log2).
pub(crate) const BLOCK_LOG2: u32 = 3;
/// Cells per block.
pub(crate) const BLOCK_CELLS: usize = 512;
/// Blocks per superblock.
const TABLE: usize = 512;

/// A block's coordinates: cell >> 3 per axis.
pub(crate) type BlockKey = [i64; 3];

/// The block of a cell and the cell's index in it (`x + 8y + 64z`, as the bit
/// blocks of the dynamic octree).
#[inline]
pub(crate) fn split(cell: [i64; 3]) -> (BlockKey, usize) {
    let b = cell.map(|c| c >> BLOCK_LOG2);
    (b, local(cell))
}

/// The index of a cell in its block, or of a block in its superblock.
#[inline]
fn local(c: [i64; 3]) -> usize {
    let l = c.map(|c| (c & 7) as usize);
    l[0] | l[1] << 3 | l[2] << 6
}

/// The index of block `b` in the cube of `1 << side_log2` blocks a side whose lowest
/// block is `lo` (x fastest), if `b` lies inside.
#[inline(always)]
pub(crate) fn cube_index(lo: BlockKey, side_log2: u32, b: BlockKey) -> Option<usize> {
    // Below `lo`, the difference wraps past every side.
    let d = [0, 1, 2].map(|a| b[a].wrapping_sub(lo[a]) as u64);
    ((d[0] | d[1] | d[2]) >> side_log2 == 0)
        .then(|| (d[0] | d[1] << side_log2 | d[2] << (2 * side_log2)) as usize)
}

/// The block of slot `s` of the tables, whose superblocks' keys are `keys`.
#[inline]
fn block_of(keys: &[BlockKey], s: usize) -> BlockKey {
    join(keys[s / TABLE], s % TABLE)
}

/// The cell at index `i` of block `b` (or the block at index `i` of superblock `b`).
#[inline]
pub(crate) fn join(b: BlockKey, i: usize) -> [i64; 3] {
    [
        b[0] << BLOCK_LOG2 | (i & 7) as i64,
        b[1] << BLOCK_LOG2 | (i >> 3 & 7) as i64,
        b[2] << BLOCK_LOG2 | (i >> 6) as i64,
    ]
}

/// A block's entry in its superblock's table: a tag in the low three bits
/// ([`forms::EMPTY`], uniform, sparse, palette of width 1, 2, 4, 8, dense), then the
/// value of a uniform block (high 16 bits) or the block's offset in the arena, in
/// 16-byte units.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) struct Entry(u32);

/// What an [`Entry`] holds.
#[cfg(test)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    /// All 512 cells clamped to this value.
    Uniform(i16),
    /// Up to six distinct values over the cells listed.
    Sparse,
    /// Cells of this many bits, numbers in a value list.
    Palette(u32),
    /// 512 values.
    Dense,
}

impl Entry {
    const EMPTY: Self = Self(EMPTY);

    fn uniform(v: i16) -> Self {
        Self(UNIFORM | u32::from(v as u16) << 16)
    }

    fn at(tag: u32, at: u32) -> Self {
        Self(tag | at << 3)
    }

    #[inline]
    fn tag(self) -> u32 {
        self.0 & 7
    }

    /// The arena offset of a block not uniform.
    #[inline]
    fn offset(self) -> u32 {
        self.0 >> 3
    }

    /// Whether the block lives in the arena.
    fn in_arena(self) -> bool {
        self.tag() >= SPARSE
    }

    #[cfg(test)]
    pub fn kind(self) -> Kind {
        match self.tag() {
            UNIFORM => Kind::Uniform((self.0 >> 16) as u16 as i16),
            SPARSE => Kind::Sparse,
            DENSE => Kind::Dense,
            t => Kind::Palette(1 << (t - PALETTE)),
        }
    }
}

/// The cells of a block.
pub(crate) type Cells = [i16; BLOCK_CELLS];

#[derive(Debug, Clone, Default)]
pub(crate) struct Store {
    /// Superblock (block >> 3) to its table's number.
    dir: Directory,
    /// The superblocks' keys, by number.
    keys: Vec<BlockKey>,
    /// The tables, 512 entries each, by number.
    tables: Vec<Entry>,
    /// The blocks that are not uniform.
    arena: Arena,
    /// Every block's entry over the blocks' bounding box, for lookups (see [`flat`]).
    flat: Flat,
    /// Cells updated since the read index was last built (see [`Store::settle`]).
    work: u64,
    /// Blocks stored (entries not empty).
    blocks: usize,
    /// The last superblock updated and its number (scans update blocks in order).
    last: Option<(BlockKey, u32)>,
    /// A merge buffer for sparse updates.
    scratch: Vec<u32>,
    /// Compactions of the arena so far.
    compactions: usize,
    /// Whether a block was refused for want of room in the arena.
    overflowed: bool,
}

impl Store {
    /// The slot of block `b` in the tables, if its superblock has a table.
    #[inline(always)]
    fn find(&self, b: BlockKey) -> Option<usize> {
        let t = self.dir.get(b.map(|c| c >> BLOCK_LOG2))?;
        Some(t as usize * TABLE + local(b))
    }

    /// The slot of block `b`, making its superblock's table when it has none.
    fn slot(&mut self, b: BlockKey) -> usize {
        let s = b.map(|c| c >> BLOCK_LOG2);
        let t = match self.last {
            Some((k, t)) if k == s => t,
            _ => {
                let n = self.keys.len() as u32;
                let t = self.dir.get_or_insert(s, n);
                if t == n {
                    if self.tables.len() == self.tables.capacity() {
                        // A quarter more, not double: the capacity is counted.
                        self.tables
                            .reserve_exact((self.tables.len() / 4).max(TABLE));
                    }
                    self.tables.resize(self.tables.len() + TABLE, Entry::EMPTY);
                    self.keys.push(s);
                }
                self.last = Some((s, t));
                t
            }
        };
        t as usize * TABLE + local(b)
    }

    /// The entry of a block.
    pub fn entry(&self, b: BlockKey) -> Option<Entry> {
        self.find(b)
            .map(|s| self.tables[s])
            .filter(|e| *e != Entry::EMPTY)
    }

    /// The words of an arena block, from its offset to the arena's end.
    fn words_of(&self, e: Entry) -> &[u16] {
        &self.arena.words[e.offset() as usize * UNIT..]
    }

    /// Decodes an entry's 512 values into `out`.
    fn decode_entry(&self, e: Entry, out: &mut Cells) {
        match e.tag() {
            EMPTY => out.fill(UNKNOWN),
            UNIFORM => out.fill((e.0 >> 16) as u16 as i16),
            t => decode(t, self.words_of(e), out),
        }
    }

    /// The 512 values of block `b` (`UNKNOWN` for unknown cells).
    pub fn cells(&self, b: BlockKey) -> Cells {
        let mut c = [UNKNOWN; BLOCK_CELLS];
        if let Some(e) = self.entry(b) {
            self.decode_entry(e, &mut c);
        }
        c
    }

    /// Sets one cell.
    pub fn set(&mut self, cell: [i64; 3], v: i16, fixed: Fixed) {
        self.work = self.work.saturating_add(1);
        let (b, i) = split(cell);
        if self.get(cell) == v {
            return;
        }
        let mut cells = self.cells(b);
        cells[i] = v;
        self.put(b, &cells, fixed);
    }

    /// Empties slot `s`, freeing its block's storage.
    fn clear(&mut self, s: usize) {
        let e = self.tables[s];
        if e.in_arena() {
            let units = units_of(e.tag(), self.words_of(e));
            self.arena.release(e.offset(), units);
        }
        if e != Entry::EMPTY {
            self.blocks -= 1;
        }
        self.set_entry(s, Entry::EMPTY);
        // A quarter of the arena free (and more than a few KiB): compact.
        if self.arena.free_units * 4 > self.arena.len_units() && self.arena.free_units > 256 {
            self.compact();
        }
    }

    /// Writes slot `s`'s entry, mirrored in the read index.
    #[inline]
    fn set_entry(&mut self, s: usize, e: Entry) {
        self.tables[s] = e;
        self.flat.set(block_of(&self.keys, s), e);
    }

    /// Makes slot `s` a uniform block of value `v` (a clamp), freeing its storage.
    pub(super) fn set_uniform(&mut self, s: usize, v: i16) {
        self.clear(s);
        self.set_entry(s, Entry::uniform(v));
        self.blocks += 1;
    }

    /// Gives slot `s` (emptied first) a new block of `units` units with this tag;
    /// returns the block's words. `None`, leaving the slot as it was, when the arena
    /// has no room for it (past its limit): then [`Store::overflowed`] tells.
    fn place(&mut self, s: usize, tag: u32, units: usize) -> Option<&mut [u16]> {
        let old = self.tables[s];
        let at = if old.in_arena() && units_of(old.tag(), self.words_of(old)) == units {
            old.offset()
        } else {
            if !self.arena.has_room(units) {
                self.overflowed = true;
                return None;
            }
            self.clear(s);
            self.blocks += 1;
            // Clearing may compact the arena, which only makes room.
            self.arena.alloc(units).expect("room checked")
        };
        self.set_entry(s, Entry::at(tag, at));
        Some(self.arena.get_mut(at, units * UNIT))
    }

    /// Whether a block was refused for want of room in the arena (so that some
    /// updates were dropped), since the store was made.
    pub fn overflowed(&self) -> bool {
        self.overflowed
    }

    /// The arena's limit in bytes.
    pub fn limit_bytes(&self) -> usize {
        self.arena.limit * UNIT * 2
    }

    /// Lowers the arena's limit to `units` units (a test hook: the real limit,
    /// 8 GiB, is too big for a test).
    #[cfg(test)]
    pub fn set_limit_units(&mut self, units: usize) {
        self.arena.limit = units;
    }

    /// Moves every arena block to a new arena, in table order, leaving no free chunk.
    fn compact(&mut self) {
        let used = self.arena.len_units() - self.arena.free_units;
        let mut words = Vec::with_capacity((used + used / 8) * UNIT);
        for (s, e) in self.tables.iter_mut().enumerate() {
            if e.in_arena() {
                let from = e.offset() as usize * UNIT;
                let len = units_of(e.tag(), &self.arena.words[from..]) * UNIT;
                let at = (words.len() / UNIT) as u32;
                words.extend_from_slice(&self.arena.words[from..from + len]);
                *e = Entry::at(e.tag(), at);
                self.flat.set(block_of(&self.keys, s), *e);
            }
        }
        self.arena = Arena {
            words,
            limit: self.arena.limit,
            ..Arena::default()
        };
        self.compactions += 1;
    }

    /// Stores `cells` as block `b`, in the smallest form: nothing when all unknown,
    /// uniform when all clamped to one value, else sparse, palette or dense,
    /// whichever takes the fewest units (a palette on a tie).
    pub fn put(&mut self, b: BlockKey, cells: &Cells, fixed: Fixed) {
        let s = self.slot(b);
        self.put_slot(s, cells, fixed);
    }

    fn put_slot(&mut self, s: usize, cells: &Cells, fixed: Fixed) {
        let census = Census::of(cells);
        if census.known == 0 {
            self.clear(s);
            return;
        }
        if let [v] = census.values[..] {
            if v == fixed.min || v == fixed.max {
                self.set_uniform(s, v);
                return;
            }
        }
        let (tag, units) = choose(census.known, census.values.len(), census.known_values());
        match tag {
            SPARSE => {
                let mut list = std::mem::take(&mut self.scratch);
                list.clear();
                list.extend(
                    cells
                        .iter()
                        .enumerate()
                        .filter(|(_, &v)| v != UNKNOWN)
                        .map(|(i, &v)| (i as u32) << 16 | u32::from(v as u16)),
                );
                if let Some(words) = self.place(s, tag, units) {
                    write_sparse(words, &list);
                }
                self.scratch = list;
            }
            DENSE => {
                if let Some(words) = self.place(s, tag, units) {
                    write_dense(words, cells);
                }
            }
            t => {
                if let Some(words) = self.place(s, t, units) {
                    write_palette(words, 1 << (t - PALETTE), &census);
                }
            }
        }
    }

    /// Applies one scan's updates to block `b`: the cells of `miss` get a miss, those
    /// of `hit` a hit (the masks are disjoint; bit `x + 8y` of word `z`). Gives
    /// whether the block was clamped free before (its misses changed nothing).
    pub fn update(&mut self, b: BlockKey, miss: &[u64; 8], hit: &[u64; 8], fixed: Fixed) -> bool {
        let s = self.slot(b);
        let e = self.tables[s];
        match e.tag() {
            UNIFORM => {
                let v = (e.0 >> 16) as u16 as i16;
                // A clamped block that the updates only push further: unchanged.
                let none = |m: &[u64; 8]| m.iter().all(|&w| w == 0);
                let clamped_free = v == fixed.min;
                if !(clamped_free && none(hit) || v == fixed.max && none(miss)) {
                    let mut cells = [v; BLOCK_CELLS];
                    apply_masks(&mut cells, miss, hit, fixed);
                    self.put_slot(s, &cells, fixed);
                }
                return clamped_free;
            }
            EMPTY => self.update_empty(s, miss, hit, fixed),
            SPARSE => self.update_sparse(s, e, miss, hit, fixed),
            DENSE => {
                let at = e.offset();
                let mut cells = [0i16; BLOCK_CELLS];
                decode(DENSE, self.arena.get(at, BLOCK_CELLS), &mut cells);
                apply_masks(&mut cells, miss, hit, fixed);
                self.put_slot(s, &cells, fixed);
            }
            t => {
                let w = 1 << (t - PALETTE);
                let at = e.offset();
                let units = units_of(t, self.words_of(e));
                let words = self.arena.get_mut(at, units * UNIT);
                if palette_update(words, w, miss, hit, fixed) {
                    if let Some(v) = palette_single(words, w) {
                        if v == fixed.min || v == fixed.max {
                            self.set_uniform(s, v);
                        }
                    }
                } else {
                    let mut cells = [0i16; BLOCK_CELLS];
                    decode(t, self.words_of(e), &mut cells);
                    apply_masks(&mut cells, miss, hit, fixed);
                    self.put_slot(s, &cells, fixed);
                }
            }
        }
        false
    }

    /// Reserves room for `n` more blocks.
    pub fn reserve(&mut self, n: usize) {
        self.dir.reserve(n / TABLE);
    }

    /// Whether lookups go through the dense directory (not the hash map).
    #[cfg(test)]
    pub fn dense_directory(&self) -> bool {
        self.dir.is_dense()
    }

    /// Units in the arena (in use or free).
    #[cfg(test)]
    pub fn arena_units(&self) -> usize {
        self.arena.len_units()
    }

    /// Compactions of the arena so far.
    #[cfg(test)]
    pub fn compactions(&self) -> usize {
        self.compactions
    }

    /// Bytes held: the directory, tables and keys, the arena, the read index
    /// (capacities) and the merge buffer.
    pub fn bytes(&self) -> usize {
        self.dir.bytes()
            + self.keys.capacity() * std::mem::size_of::<BlockKey>()
            + self.tables.capacity() * std::mem::size_of::<Entry>()
            + self.arena.bytes()
            + self.flat.bytes()
            + self.scratch.capacity() * 4
    }
}
