//! Blocks of 8×8×8 cells, found through a two-level directory (superblocks of
//! 8×8×8 blocks, each a flat table of 512 block entries) and held in the smallest
//! of five forms: uniform (in the entry), sparse, palette (1, 2, 4 or 8 bits a cell
//! and a value list), patched palette (2 bits a cell and a patch list, see
//! [`patched`]) or dense (see [`forms`]). The directory is dense over the
//! superblocks' bounding box while that box is small enough, a hash map otherwise
//! (see [`dir`]); reads are in [`lookup`].
//!
//! The blocks not uniform live in two arenas: those that list an occupied value
//! (the surfaces the sensor hit) in one, the others (free space seen not yet
//! clamped, most of a big map's bytes) in the other. Lookups land mostly on
//! surfaces (a scan's end points, collision checks, rays cast to render), and in
//! their own arena those blocks lie together in a few megabytes, a few hundred
//! pages, instead of scattered one to a page over the whole arena.

mod arena;
mod census;
mod dir;
mod flat;
mod forms;
mod fresh;
mod lookup;
mod patched;
mod place;
mod probe;
mod sparse;
#[cfg(test)]
mod tests_forms;
mod valid;
mod visit;

use super::sensor::{Fixed, UNKNOWN};
use arena::{Arena, UNIT};
use census::Census;
use dir::Directory;
use flat::Flat;
use forms::{
    any_occupied, apply_masks, choose, decode, lists_occupied, palette_single, palette_update,
    units_of, wide, write_dense, write_palette, write_sparse, DENSE, INLINE, PALETTE, PATCHED,
    SPARSE,
};
pub(crate) use lookup::BATCH;
use patched::Patch;

/// Cells per block side (log2).
pub(crate) const BLOCK_LOG2: u32 = 3;
/// Cells per block.
pub(crate) const BLOCK_CELLS: usize = 512;
/// Blocks per superblock.
const TABLE: usize = 512;

/// The arena of the blocks that list no occupied value.
const OPEN: usize = 0;
/// The arena of the blocks that list an occupied value (see [`lists_occupied`]).
const OCCUPIED: usize = 1;

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

/// Every stored block and its entry (entries not empty), in the tables' order, for
/// the superblocks' `keys` and their `tables`.
fn stored<'a>(
    keys: &'a [BlockKey],
    tables: &'a [Entry],
) -> impl Iterator<Item = (BlockKey, Entry)> + 'a {
    tables
        .iter()
        .enumerate()
        .filter(|(_, &e)| e != Entry::EMPTY)
        .map(|(s, &e)| (block_of(keys, s), e))
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
/// ([`forms::INLINE`], sparse, palette of width 1, 2, 4, 8, patched, dense). Then,
/// for a block in an arena, the arena (bit 3: [`OCCUPIED`] or [`OPEN`]) and the
/// block's offset there in 16-byte units (bits 4 to 31). An inline entry is empty
/// (0), or uniform: bit 3 set and the value in the high 16 bits.
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
    /// Cells of 2 bits, the fourth number's values in a patch.
    Patched,
    /// 512 values.
    Dense,
}

impl Entry {
    const EMPTY: Self = Self(0);

    /// Bit 3 of an inline entry: uniform.
    const UNIFORM: u32 = 1 << 3;

    fn uniform(v: i16) -> Self {
        Self(INLINE | Self::UNIFORM | u32::from(v as u16) << 16)
    }

    /// The value of a uniform block's cells (`None` for any other entry).
    #[inline]
    fn uniform_value(self) -> Option<i16> {
        (self.0 & 0xF == INLINE | Self::UNIFORM).then_some((self.0 >> 16) as u16 as i16)
    }

    fn at(tag: u32, arena: usize, at: u32) -> Self {
        Self(tag | (arena as u32) << 3 | at << 4)
    }

    #[inline]
    fn tag(self) -> u32 {
        self.0 & 7
    }

    /// The arena offset of a block not uniform.
    #[inline]
    fn offset(self) -> u32 {
        self.0 >> 4
    }

    /// The arena of a block not uniform: [`OPEN`] or [`OCCUPIED`].
    #[inline]
    fn arena(self) -> usize {
        (self.0 >> 3 & 1) as usize
    }

    /// Whether the block lives in the arena.
    fn in_arena(self) -> bool {
        self.tag() != INLINE
    }

    #[cfg(test)]
    pub fn kind(self) -> Kind {
        if let Some(v) = self.uniform_value() {
            return Kind::Uniform(v);
        }
        match self.tag() {
            SPARSE => Kind::Sparse,
            PATCHED => Kind::Patched,
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
    /// The blocks that are not uniform: `arenas[OCCUPIED]` those that list an
    /// occupied value, `arenas[OPEN]` the others.
    arenas: [Arena; 2],
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
    /// Whether a block stayed in the wrong arena because the other was full.
    crowded: bool,
    /// Slots whose block a scan's update left as a palette of 4 or 8 bits or
    /// dense, which a patched palette may hold in fewer units: made patched by
    /// [`Store::repatch`] at the end of a batch of scans, not on every update (a
    /// patched palette is re-encoded on update, a palette updated in place).
    pending: Vec<u32>,
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
                    if self.tables.capacity() - self.tables.len() < TABLE {
                        // A quarter more, not double: the capacity is counted. (Room
                        // for less than a table would let `resize` double it.)
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

    /// The words of an arena block, from its offset to its arena's end.
    fn words_of(&self, e: Entry) -> &[u16] {
        &self.arenas[e.arena()].words[e.offset() as usize * UNIT..]
    }

    /// Decodes an entry's 512 values into `out`.
    fn decode_entry(&self, e: Entry, out: &mut Cells) {
        match (e.tag(), e.uniform_value()) {
            (INLINE, v) => out.fill(v.unwrap_or(UNKNOWN)),
            (t, _) => decode(t, self.words_of(e), out),
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

    /// Stores `cells` as block `b`, in the smallest form: nothing when all unknown,
    /// uniform when all clamped to one value, else sparse, palette, patched
    /// palette or dense, whichever takes the fewest units (see [`choose`]).
    pub fn put(&mut self, b: BlockKey, cells: &Cells, fixed: Fixed) {
        let s = self.slot(b);
        self.put_slot(s, cells, fixed, true);
    }

    /// [`put`](Self::put) in slot `s`; a patched palette considered only when
    /// `may_patch` (else the slot noted for [`Store::repatch`] where one may do).
    fn put_slot(&mut self, s: usize, cells: &Cells, fixed: Fixed, may_patch: bool) {
        self.put_census(s, cells, &Census::of(cells), fixed, may_patch);
    }

    /// [`put_slot`](Self::put_slot) of `cells`, whose census is `census`.
    fn put_census(
        &mut self,
        s: usize,
        cells: &Cells,
        census: &Census,
        fixed: Fixed,
        may_patch: bool,
    ) {
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
        let occupied = any_occupied(census.values.iter().copied(), fixed);
        // A scan's update leaves the patch to `repatch`: not even counted here.
        let patch = if may_patch { Patch::of(census) } else { None };
        let (tag, units) = choose(
            census.known,
            census.values.len(),
            census.known_values(),
            occupied,
            patch.as_ref(),
        );
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
                if let Some(words) = self.place(s, tag, units, occupied) {
                    write_sparse(words, &list);
                }
                self.scratch = list;
            }
            DENSE => {
                if let Some(words) = self.place(s, tag, units, occupied) {
                    write_dense(words, cells);
                }
            }
            PATCHED => {
                let patch = patch.expect("a patch chosen");
                if let Some(words) = self.place(s, tag, units, occupied) {
                    patched::write(words, census, &patch);
                }
            }
            t => {
                if let Some(words) = self.place(s, t, units, occupied) {
                    write_palette(words, 1 << (t - PALETTE), census);
                }
            }
        }
        // (A sparse block among them only while a patched palette might be smaller.)
        if !may_patch
            && (wide(tag) || tag == SPARSE && Patch::may_take_fewer(census.values.len(), units))
        {
            self.note_pending(s);
        }
    }

    /// Applies one scan's updates to block `b`: the cells of `miss` get a miss, those
    /// of `hit` a hit (the masks are disjoint; bit `x + 8y` of word `z`). Gives
    /// whether the block was clamped free before (its misses changed nothing).
    pub fn update(&mut self, b: BlockKey, miss: &[u64; 8], hit: &[u64; 8], fixed: Fixed) -> bool {
        let s = self.slot(b);
        let e = self.tables[s];
        if let Some(v) = e.uniform_value() {
            // A clamped block that the updates only push further: unchanged.
            let none = |m: &[u64; 8]| m.iter().all(|&w| w == 0);
            let clamped_free = v == fixed.min;
            if !(clamped_free && none(hit) || v == fixed.max && none(miss)) {
                let mut cells = [v; BLOCK_CELLS];
                apply_masks(&mut cells, miss, hit, fixed);
                self.put_slot(s, &cells, fixed, false);
            }
            return clamped_free;
        }
        match e.tag() {
            INLINE => self.update_empty(s, miss, hit, fixed),
            SPARSE => self.update_sparse(s, e, miss, hit, fixed),
            // Decoded, updated and stored again.
            t @ (DENSE | PATCHED) => {
                let mut cells = [0i16; BLOCK_CELLS];
                decode(t, self.words_of(e), &mut cells);
                apply_masks(&mut cells, miss, hit, fixed);
                self.put_slot(s, &cells, fixed, false);
            }
            t => {
                let w = 1 << (t - PALETTE);
                let at = e.offset();
                let units = units_of(t, self.words_of(e));
                let words = self.arenas[e.arena()].get_mut(at, units * UNIT);
                if palette_update(words, w, miss, hit, fixed) {
                    match palette_single(words, w) {
                        Some(v) if v == fixed.min || v == fixed.max => self.set_uniform(s, v),
                        // An update in place only appends to the value list: a block
                        // with the surfaces stays, one without may have gained one.
                        _ if e.arena() == OPEN && lists_occupied(t, words, fixed) => {
                            self.relocate(s, e);
                        }
                        _ => {}
                    }
                    if wide(t) {
                        self.note_pending(s);
                    }
                } else {
                    let mut cells = [0i16; BLOCK_CELLS];
                    decode(t, self.words_of(e), &mut cells);
                    apply_masks(&mut cells, miss, hit, fixed);
                    self.put_slot(s, &cells, fixed, false);
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

    /// Whether block `b` lies in the arena of blocks that list an occupied value
    /// (`None` for a block not in an arena).
    #[cfg(test)]
    pub fn in_occupied_arena(&self, b: BlockKey) -> Option<bool> {
        self.entry(b)
            .filter(|e| e.in_arena())
            .map(|e| e.arena() == OCCUPIED)
    }

    /// Units in each arena (in use or free).
    #[cfg(test)]
    pub fn arena_units(&self) -> [usize; 2] {
        self.arenas.each_ref().map(Arena::len_units)
    }

    /// Compactions of the arena so far.
    #[cfg(test)]
    pub fn compactions(&self) -> usize {
        self.compactions
    }

    /// Bytes held: the directory, tables and keys, the arena, the read index
    /// (capacities), the merge buffer and the slots noted for `repatch`.
    pub fn bytes(&self) -> usize {
        self.dir.bytes()
            + self.keys.capacity() * std::mem::size_of::<BlockKey>()
            + self.tables.capacity() * std::mem::size_of::<Entry>()
            + self.arenas.iter().map(Arena::bytes).sum::<usize>()
            + self.flat.bytes()
            + self.scratch.capacity() * 4
            + self.pending.capacity() * 4
    }
}
