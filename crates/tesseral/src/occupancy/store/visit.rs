//! Reading the whole store: every block's known cells, counts of them.

use super::arena::UNIT;
use super::forms::{
    bits_words, decode, list_at, palette_numbers, DENSE, INLINE, PALETTE, PATCHED, SPARSE,
    SPARSE_VALUES,
};
use super::patched;
use super::{join, stored, BlockKey, Cells, Entry, Store, BLOCK_CELLS, BLOCK_LOG2};
use crate::code;
use crate::linear::sort::sort_by_u64;
use crate::linear::Leaf;
use crate::occupancy::sensor::UNKNOWN;
use crate::occupancy::CellCounts;

impl CellCounts {
    /// Counts `n` cells of value `v`, stored as `entries` entries (none when
    /// unknown).
    #[inline]
    fn add(&mut self, v: i16, n: u64, entries: u64, threshold: i16) {
        if v != UNKNOWN {
            if v >= threshold {
                self.occupied += n;
            } else {
                self.free += n;
            }
            self.leaves += entries;
        }
    }
}

impl Store {
    /// Calls `f` on every block's known cells: `(index in block, value)`, or once
    /// with `None` and the value of a uniform block.
    fn visit(&self, mut f: impl FnMut(BlockKey, Option<usize>, i16)) {
        let mut cells = [UNKNOWN; BLOCK_CELLS];
        for (b, e) in stored(&self.keys, &self.tables) {
            match e.uniform_value() {
                Some(v) => f(b, None, v),
                None => {
                    decode(e.tag(), self.words_of(e), &mut cells);
                    for (i, &v) in cells.iter().enumerate() {
                        if v != UNKNOWN {
                            f(b, Some(i), v);
                        }
                    }
                }
            }
        }
    }

    /// The known cells at or above `threshold` (occupied) and below it (free),
    /// and the entries (one per uniform block, one per known cell of another
    /// block), counted form by form in one pass without decoding a block: a
    /// palette's cells are counted per number by popcounts of its bit planes, a
    /// sparse block's per number of its list.
    ///
    /// # Runtime
    /// O(t + k) for t table slots and k stored cells; a palette block of width 1
    /// or 2 costs 8 or 16 popcounts per number.
    pub fn census(&self, threshold: i16) -> CellCounts {
        let mut tally = CellCounts::default();
        let mut n = [0u64; 256];
        for &e in &self.tables {
            let (values, k) = match e.tag() {
                INLINE => {
                    // One entry for the whole block.
                    if let Some(v) = e.uniform_value() {
                        tally.add(v, BLOCK_CELLS as u64, 1, threshold);
                    }
                    continue;
                }
                PATCHED => {
                    let words = self.words_of(e);
                    let mut common = [0; 3];
                    patched::numbers(words, &mut n, &mut common);
                    let (values, patch) = patched::values(words);
                    for (&v, &c) in values.iter().zip(&common) {
                        tally.add(v as i16, c, c, threshold);
                    }
                    (patch, patch.len())
                }
                DENSE => {
                    for &v in &self.words_of(e)[..BLOCK_CELLS] {
                        tally.add(v as i16, 1, 1, threshold);
                    }
                    continue;
                }
                SPARSE => {
                    let words = self.words_of(e);
                    n[..SPARSE_VALUES].fill(0);
                    for &c in &words[UNIT..UNIT + words[0] as usize] {
                        n[usize::from(c & 7)] += 1;
                    }
                    // Unused value slots are counted 0.
                    (&words[2..2 + SPARSE_VALUES], SPARSE_VALUES)
                }
                tag => {
                    let w = 1 << (tag - PALETTE);
                    let words = self.words_of(e);
                    let k = usize::from(words[bits_words(w)]);
                    palette_numbers(words, w, &mut n);
                    (&words[list_at(w)..], k)
                }
            };
            for (j, &v) in values[..k].iter().enumerate() {
                tally.add(v as i16, n[j], n[j], threshold);
            }
        }
        tally
    }

    pub fn block_count(&self) -> usize {
        self.blocks
    }

    /// The lowest and highest cells of the stored blocks' bounding box (whole
    /// blocks: multiples of 8, and 7 past them; `None` when no block is stored).
    pub fn cell_bounds(&self) -> Option<([i64; 3], [i64; 3])> {
        let mut bounds: Option<(BlockKey, BlockKey)> = None;
        for (b, _) in stored(&self.keys, &self.tables) {
            let (lo, hi) = bounds.get_or_insert((b, b));
            for a in 0..3 {
                lo[a] = lo[a].min(b[a]);
                hi[a] = hi[a].max(b[a]);
            }
        }
        bounds.map(|(lo, hi)| (lo.map(|b| b << BLOCK_LOG2), hi.map(|b| b << BLOCK_LOG2 | 7)))
    }

    /// Calls `f` on every known cell as a leaf of the space of side `2^depth` from
    /// `origin` (a multiple of 8 on each axis, `depth` at least 3, holding every
    /// block), in tesseral order: a uniform block as one leaf of 8³ cells, another
    /// block's known cells one by one. Every leaf is then in place for
    /// [`LinearOctree::from_sorted_leaves`](crate::linear::LinearOctree::from_sorted_leaves),
    /// with no sort of the cells.
    ///
    /// # Runtime
    /// O(b log b + k) for b blocks (sorted by code) and k cells of blocks not uniform.
    pub fn for_each_in_order(&self, origin: [i64; 3], depth: u8, mut f: impl FnMut(Leaf, i16)) {
        debug_assert!(depth >= 3 && origin.iter().all(|c| c.rem_euclid(8) == 0));
        let lo = origin.map(|c| c >> BLOCK_LOG2);
        let mut blocks: Vec<(u64, Entry)> = stored(&self.keys, &self.tables)
            .map(|(b, e)| {
                let r = [0, 1, 2].map(|a| (b[a] - lo[a]) as u32);
                debug_assert!(r.iter().all(|&r| u64::from(r) < 1 << (depth - 3)));
                (code::encode(r[0], r[1], r[2]), e)
            })
            .collect();
        sort_by_u64(&mut blocks, |&(c, _)| c);
        // The cells of a block in tesseral order: its codes 0..512, each a local index.
        let order: [u16; BLOCK_CELLS] = std::array::from_fn(|m| {
            let [x, y, z] = code::decode(m as u64);
            (x | y << 3 | z << 6) as u16
        });
        let mut cells = [UNKNOWN; BLOCK_CELLS];
        for (c, e) in blocks {
            let at = c << 9;
            if let Some(v) = e.uniform_value() {
                f(Leaf::new(at, 3), v);
                continue;
            }
            decode(e.tag(), self.words_of(e), &mut cells);
            for (m, &i) in order.iter().enumerate() {
                let v = cells[usize::from(i)];
                if v != UNKNOWN {
                    f(Leaf::new(at | m as u64, 0), v);
                }
            }
        }
    }

    /// Calls `f` on every stored block and its 512 values (`UNKNOWN` for unknown
    /// cells), in increasing key order (x, then y, then z).
    ///
    /// # Runtime
    /// O(b log b + 512 b) for b blocks.
    pub fn for_each_block(&self, mut f: impl FnMut(BlockKey, &Cells)) {
        let mut blocks: Vec<(BlockKey, Entry)> = stored(&self.keys, &self.tables).collect();
        blocks.sort_unstable_by_key(|&(b, _)| b);
        let mut cells = [UNKNOWN; BLOCK_CELLS];
        for (b, e) in blocks {
            self.decode_entry(e, &mut cells);
            f(b, &cells);
        }
    }

    /// Calls `f` on every known cell, in no order.
    pub fn for_each(&self, mut f: impl FnMut([i64; 3], i16)) {
        self.visit(|b, i, v| match i {
            Some(i) => f(join(b, i), v),
            None => (0..BLOCK_CELLS).for_each(|i| f(join(b, i), v)),
        });
    }
}
