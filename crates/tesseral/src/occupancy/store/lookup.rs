//! Reading cells: one at a time ([`Store::get`]) or in batches whose memory
//! accesses are prefetched in passes ([`Store::get_many`]), through the read
//! index ([`super::flat`]) while it is live, else the directory and the tables.

use super::arena::UNIT;
use super::forms::{join4, list_at, DENSE, INLINE, PALETTE, PATCHED, SPARSE};
use super::patched;
use super::probe::{sparse_value, LANES};
use super::{cube_index, join, local, split, BlockKey, Entry, Store, BLOCK_LOG2, TABLE};
use crate::occupancy::prefetch;
use crate::occupancy::sensor::UNKNOWN;

/// Word `k` of an arena's words, which holds it: the stored entries point inside
/// their arena (checked by [`Store::assert_valid`]), and a block's cells and value
/// list inside its units.
#[inline(always)]
fn words_at(words: &[u16], k: usize) -> u16 {
    debug_assert!(k < words.len(), "word {k} of {}", words.len());
    // SAFETY: every entry stored in the tables and the read index points at a block
    // wholly inside its arena (`assert_valid` checks each block's units against the
    // arena's length), and `value` reads only the words of the block's form: a
    // palette's cells and the list entries their numbers give (each number below
    // the list's length, also checked there), a patched palette's words up to its
    // patch's numbers (its ranks and counts also checked), a dense block's cells.
    unsafe { *words.get_unchecked(k) }
}

/// Words `k..k + 4` of an arena's words as one `u64`, word `k + n` in bits
/// `16n..16n + 16`: the value list of a block of two-bit cells, read in one load
/// whose address does not wait for the cell's number.
#[inline(always)]
fn words4_at(words: &[u16], k: usize) -> u64 {
    debug_assert!(
        k + 4 <= words.len(),
        "words {k}..{} of {}",
        k + 4,
        words.len()
    );
    // SAFETY: as in `words_at`: a width-2 palette's list is four words (its
    // `list_words`), and a patched palette's three common values are followed by
    // its patch's width, all inside the block's units.
    join4(unsafe { words.as_ptr().add(k).cast::<[u16; 4]>().read_unaligned() })
}

/// Prefetches word `k` of an arena's words, as [`words_at`] would read it.
#[inline(always)]
fn prefetch_word(words: &[u16], k: usize) {
    debug_assert!(k < words.len(), "word {k} of {}", words.len());
    // SAFETY: as in `words_at`: the word is one that a lookup then reads.
    prefetch(unsafe { words.get_unchecked(k) });
}

/// Palettes of width 1, 2, 4 and 8 (by `tag − PALETTE`), from the high bits down:
/// where the value list starts (after the cells and the count), the log2 of a
/// cell's bits, their mask.
const PALETTES: [u64; 4] = {
    let mut p = [0; 4];
    let mut k = 0;
    while k < 4 {
        let w = 1 << k;
        p[k] = (list_at(w) as u64) << 16 | (k as u64) << 8 | ((1 << w) - 1);
        k += 1;
    }
    p
};

/// The tags read as cells of two bits: width-2 palettes and patched palettes,
/// whose cells and value list lie where a width-2 palette's do.
const TWO_BIT: u32 = {
    assert!(list_at(2) == patched::COMMON);
    1 << (PALETTE + 1) | 1 << PATCHED
};

/// A patched palette's escaped cell `i`, out of line so that the common path
/// falls through.
#[cold]
#[inline(never)]
fn escaped(words: &[u16], at: usize, i: usize) -> i16 {
    patched::escaped_value(|k| words_at(words, k), at, i)
}

/// Cells looked up together by [`Store::get_many`].
pub(crate) const BATCH: usize = 32;

/// The store's bytes above which its batched lookups prefetch in passes (32 MiB,
/// an L3 cache): below, the blocks stay cached and the passes cost more than they
/// save. Measured on an AMD EPYC (Zen 5) VM over 10⁶ random end-point cells, with
/// `OccupancyMap::log_odds_many`: on the real scan's 2.7 MB map the passes took
/// 7.2 ns a cell against 4.9 for a loop of `get`, on the room's 1.2 MB 7.7 against
/// 5.5; on the street's 236 MB, the map's lines not yet cached, 17.9-18.3 against
/// 20.4-21.2 (cached, 15.6 against 14.2).
pub(crate) const PREFETCH_FROM: usize = 32 << 20;

impl Store {
    /// The stored value of a cell (`UNKNOWN` when unknown).
    #[inline(always)]
    pub fn get(&self, cell: [i64; 3]) -> i16 {
        let (b, i) = split(cell);
        match self.flat.index(b) {
            Some(at) => self.value(self.flat.entry(at), i),
            None => self.get_outside(cell[0], cell[1], cell[2]),
        }
    }

    /// [`get`](Self::get) of a cell whose block is outside the read index's box:
    /// unknown while the index is live, else found through the directory. Out of
    /// line, so that a loop of lookups keeps its registers for the index's path; the
    /// cell comes as three scalars, in registers (an array would go through memory,
    /// a store and a reload on every lookup).
    #[inline(never)]
    fn get_outside(&self, x: i64, y: i64, z: i64) -> i16 {
        if self.flat.live() {
            return UNKNOWN;
        }
        // A retired index has no box: every block goes through the directory.
        let (b, i) = split([x, y, z]);
        match self.find(b) {
            Some(at) => self.value(self.tables[at], i),
            None => UNKNOWN,
        }
    }

    /// Where block `b`'s entry is read: the read index while it is live (the
    /// entry straight from the block's key), else the tables through the
    /// directory. `None` for a block with no entry.
    #[inline(always)]
    fn locate(&self, b: BlockKey) -> (&[Entry], Option<usize>) {
        if self.flat.live() {
            (self.flat.entries(), self.flat.index(b))
        } else {
            (&self.tables, self.find(b))
        }
    }

    /// The entries that [`locate`](Self::locate) gives positions in.
    #[inline]
    fn read_entries(&self) -> &[Entry] {
        if self.flat.live() {
            self.flat.entries()
        } else {
            &self.tables
        }
    }

    /// The blocks of the cube of `1 << side_log2` blocks a side from `lo` that are
    /// stored uniform at `value` (every cell clamped to it), as a bit set indexed by
    /// [`cube_index`].
    ///
    /// # Runtime
    /// O(t) for the t superblock tables that meet the cube (each entry read once).
    pub fn uniform_in(&self, lo: BlockKey, side_log2: u32, value: i16) -> Vec<u64> {
        let side = 1i64 << side_log2;
        let mut bits = vec![0u64; (1usize << (3 * side_log2)).div_ceil(64)];
        let want = Entry::uniform(value);
        let (s_lo, s_hi) = (
            lo.map(|c| c >> BLOCK_LOG2),
            lo.map(|c| (c + side - 1) >> BLOCK_LOG2),
        );
        for sz in s_lo[2]..=s_hi[2] {
            for sy in s_lo[1]..=s_hi[1] {
                for sx in s_lo[0]..=s_hi[0] {
                    let Some(t) = self.dir.get([sx, sy, sz]) else {
                        continue;
                    };
                    let table = &self.tables[t as usize * TABLE..][..TABLE];
                    for (i, _) in table.iter().enumerate().filter(|(_, &e)| e == want) {
                        if let Some(at) = cube_index(lo, side_log2, join([sx, sy, sz], i)) {
                            bits[at / 64] |= 1 << (at % 64);
                        }
                    }
                }
            }
        }
        bits
    }

    /// The words of entry `e`'s arena and where its block starts in them (the
    /// entry must not be empty or uniform for the position to mean anything).
    #[inline(always)]
    fn block_at(&self, e: Entry) -> (&[u16], usize) {
        (&self.arenas[e.arena()].words, e.offset() as usize * UNIT)
    }

    /// The value of cell `i` of the block of entry `e`.
    #[inline(always)]
    fn value(&self, e: Entry, i: usize) -> i16 {
        let tag = e.tag();
        let (words, at) = self.block_at(e);
        // Cells of two bits first, width-2 and patched palettes: most lookups land
        // on surfaces, and a surface's palette is never narrower (`forms::choose`).
        // Constant shifts, no table; the escape (a patched palette's number 3) out
        // of line. On an AMD EPYC (Zen 4) VM, against the general palette path
        // below for every width: the real scan's random lookups 6.1-6.2 ns against
        // 6.3-6.4, the §8 room's 9.0-9.1 against 9.6, the street's the same.
        if TWO_BIT >> tag & 1 != 0 {
            let patched = usize::from(tag == PATCHED);
            let bit = i << 1;
            // The list's four words loaded beside the cell's word, not after it,
            // and the value shifted out of them: the load no longer waits for the
            // cell's number (the §8 room's lookups, 53 % of them on patched
            // palettes, 10.8-12.9 ns against 13.9-16.9 on the Zen 4 VM, both paths
            // in one process by turns; the real scan's 6.9-7.1 against 7.0-7.3).
            let list = words4_at(words, at + list_at(2));
            let x = words_at(words, at + (bit >> 4)) >> (bit & 15);
            let j = usize::from(x) & 3;
            // Escaped: number `ESCAPE` in a patched palette (one compare, no branch
            // on the tag).
            if (j << 1 | patched) == patched::ESCAPE << 1 | 1 {
                return escaped(words, at, i);
            }
            return (list >> (j << 4)) as u16 as i16;
        }
        // Palettes of width 1, 4 and 8 (and, unreached, 2): no branch on the width.
        if tag.wrapping_sub(PALETTE) < 4 {
            let p = PALETTES[tag as usize - PALETTE as usize];
            let list = at + (p >> 16 & 0xFFFF) as usize;
            // The list lies a line or more past the cell's word: fetch both at once
            // rather than one after the other.
            prefetch_word(words, list);
            let bit = i << (p >> 8 & 0xff);
            let x = words_at(words, at + (bit >> 4)) >> (bit & 15);
            let j = usize::from(x) & (p as usize & 0xff);
            return words_at(words, list + j) as i16;
        }
        self.value_other(e, i)
    }

    /// [`value`](Self::value) of a block not a palette. Out of line, as
    /// [`get_outside`](Self::get_outside).
    #[inline(never)]
    fn value_other(&self, e: Entry, i: usize) -> i16 {
        let (words, at) = self.block_at(e);
        match e.tag() {
            INLINE => e.uniform_value().unwrap_or(UNKNOWN),
            // Compares, not a binary search (see `probe`).
            SPARSE => sparse_value(words, at, i),
            // DENSE: the cells are the values.
            _ => words_at(words, at + i) as i16,
        }
    }

    /// Whether [`get_many`](Self::get_many) should prefetch in passes: the store
    /// is larger than [`PREFETCH_FROM`] bytes.
    pub(crate) fn prefetches(&self) -> bool {
        self.bytes() > PREFETCH_FROM
    }

    /// The values of `cells` into `out` (as many), as [`get`](Self::get) would give
    /// them. With `passes` (see [`prefetches`](Self::prefetches)), in three passes
    /// that each prefetch what the next one reads (the table entries, then the
    /// blocks' words in the arena), so that the cache misses of up to [`BATCH`]
    /// cells overlap rather than follow one another; without, one `get` a cell.
    ///
    /// # Panics
    /// When `cells` and `out` differ in length.
    pub fn get_many(&self, cells: &[[i64; 3]], out: &mut [i16], passes: bool) {
        assert_eq!(cells.len(), out.len(), "as many values as cells");
        if !passes {
            for (o, &c) in out.iter_mut().zip(cells) {
                *o = self.get(c);
            }
            return;
        }
        let mut slots = [usize::MAX; BATCH];
        let mut entries = [Entry::EMPTY; BATCH];
        let from = self.read_entries();
        for (cells, out) in cells.chunks(BATCH).zip(out.chunks_mut(BATCH)) {
            for (s, &c) in slots.iter_mut().zip(cells) {
                *s = self.locate(split(c).0).1.unwrap_or(usize::MAX);
                if let Some(e) = from.get(*s) {
                    prefetch(e);
                }
            }
            for ((e, &s), &c) in entries.iter_mut().zip(&slots).zip(cells) {
                *e = from.get(s).copied().unwrap_or(Entry::EMPTY);
                self.prefetch_cell(*e, local(c));
            }
            for ((o, &e), &c) in out.iter_mut().zip(&entries).zip(cells) {
                *o = self.value(e, local(c));
            }
        }
    }

    /// Prefetches the arena words that [`value`](Self::value) reads for cell `i` of
    /// the block of entry `e`.
    #[inline]
    fn prefetch_cell(&self, e: Entry, i: usize) {
        let tag = e.tag();
        if tag == INLINE {
            return;
        }
        let (words, at) = self.block_at(e);
        let (a, b) = match tag {
            // The header and the cells that `sparse_value` compares at once: the
            // first and last of its lines (the middle one is most often fetched
            // with its neighbours by the hardware prefetcher).
            SPARSE => (at, at + UNIT + LANES - 1),
            DENSE => (at + i, at + i),
            PATCHED => (at + ((i * 2) >> 4), at + patched::COMMON),
            t => {
                let w = 1 << (t - PALETTE);
                (at + ((i * w) >> 4), at + list_at(w as u32))
            }
        };
        for k in [a, b] {
            if let Some(x) = words.get(k) {
                prefetch(x);
            }
        }
    }
}
