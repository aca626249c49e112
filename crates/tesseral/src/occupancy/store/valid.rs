//! The store's invariants.

use super::arena::UNIT;
use super::forms::{
    bits_words, list_at, lists_occupied, palette_index, sparse_units, units_of, DENSE, INLINE,
    PALETTE, PATCHED, SPARSE, SPARSE_VALUES,
};
use super::{block_of, stored, Store, BLOCK_CELLS, OCCUPIED, TABLE};
use super::{patched, Entry};
use crate::occupancy::sensor::{Fixed, UNKNOWN};

impl Store {
    /// Checks the invariants: the directory and the tables agree; every uniform
    /// block is clamped; every arena block lies inside its arena, overlapping no
    /// other block and no free chunk, and every unit is a block's or free; a block
    /// lies in the arena of blocks that list an occupied value if and only if it
    /// lists one (unless that arena was full when it should have moved); a sparse
    /// block lists 1 to 512 cells in order with at most six distinct values, a
    /// palette block's numbers lie in its value list of distinct values; every
    /// value is unknown (palette, dense) or within the clamps; no block is all
    /// unknown or uniformly clamped.
    ///
    /// # Panics
    /// When an invariant is broken.
    pub fn assert_valid(&self, fixed: Fixed) {
        self.dir.assert_valid(&self.keys);
        self.flat.assert_valid(stored(&self.keys, &self.tables));
        assert_eq!(self.tables.len(), self.keys.len() * TABLE, "tables' length");
        let (len, cap) = (self.tables.len(), self.tables.capacity());
        assert!(
            cap <= len + len / 4 + TABLE,
            "tables' capacity {cap} for {len} entries: grown by more than a quarter"
        );
        if let Some((k, t)) = self.last {
            assert_eq!(self.dir.get(k), Some(t), "the last superblock");
        }
        let mut owner = self.arenas.each_ref().map(|arena| {
            assert_eq!(arena.words.len() % UNIT, 0, "arena length");
            vec![false; arena.len_units()]
        });
        let mut claim = |a: usize, at: usize, units: usize, what: &str| {
            let owner = &mut owner[a];
            assert!(at + units <= owner.len(), "{what}: past the arena's end");
            for u in &mut owner[at..at + units] {
                assert!(!*u, "{what}: overlaps another chunk");
                *u = true;
            }
        };
        for (a, arena) in self.arenas.iter().enumerate() {
            let mut free_units = 0;
            for (units, list) in arena.free.iter().enumerate() {
                for &at in list {
                    claim(a, at as usize, units, "a free chunk");
                    free_units += units;
                }
            }
            assert_eq!(free_units, arena.free_units, "free units");
        }
        let in_clamps = |b: [i64; 3], v: i16| {
            assert!(
                (fixed.min..=fixed.max).contains(&v),
                "block {b:?}: value {v} outside the clamps"
            );
        };
        let mut blocks = 0;
        let mut cells = [UNKNOWN; BLOCK_CELLS];
        for (s, &e) in self.tables.iter().enumerate() {
            let b = block_of(&self.keys, s);
            if e.tag() == INLINE {
                let Some(v) = e.uniform_value() else {
                    assert_eq!(e, Entry::EMPTY, "block {b:?}: empty entry with bits");
                    continue;
                };
                assert!(
                    v == fixed.min || v == fixed.max,
                    "uniform block {b:?} holds {v}, not a clamp"
                );
                assert_eq!(e.0 & 0xFFF0, 0, "block {b:?}: uniform entry with bits");
                blocks += 1;
                continue;
            }
            blocks += 1;
            let at = e.offset() as usize;
            assert!(
                at < self.arenas[e.arena()].len_units(),
                "block {b:?}: offset past the arena"
            );
            let words = self.words_of(e);
            let units = units_of(e.tag(), words);
            claim(e.arena(), at, units, &format!("block {b:?}"));
            let words = &words[..units * UNIT];
            if !self.crowded {
                assert_eq!(
                    e.arena() == OCCUPIED,
                    lists_occupied(e.tag(), words, fixed),
                    "block {b:?}: in the wrong arena"
                );
            }
            match e.tag() {
                SPARSE => {
                    let (len, k) = (words[0] as usize, words[1] as usize);
                    assert!(
                        (1..=BLOCK_CELLS).contains(&len),
                        "sparse block {b:?}: {len} cells"
                    );
                    assert!(
                        (1..=SPARSE_VALUES).contains(&k),
                        "sparse block {b:?}: {k} values"
                    );
                    assert_eq!(units, sparse_units(len));
                    let values = &words[2..2 + k];
                    for (j, &v) in values.iter().enumerate() {
                        in_clamps(b, v as i16);
                        assert!(!values[..j].contains(&v), "sparse block {b:?}: value twice");
                    }
                    let list = &words[UNIT..UNIT + len];
                    assert!(
                        list.windows(2).all(|w| w[0] >> 3 < w[1] >> 3),
                        "sparse block {b:?} is not sorted"
                    );
                    assert!(
                        list.iter().all(|&c| usize::from(c & 7) < k),
                        "sparse block {b:?}: a value number past its list"
                    );
                    assert!(
                        words[UNIT + len..].iter().all(|&x| x == 0),
                        "sparse block {b:?}: bits past its cells"
                    );
                }
                PATCHED => patched::assert_valid(words, units, &format!("patched block {b:?}")),
                DENSE => {}
                t => {
                    let w = 1 << (t - PALETTE);
                    let k = words[bits_words(w)] as usize;
                    assert!(
                        (1..=1usize << w).contains(&k),
                        "palette block {b:?}: {k} values for width {w}"
                    );
                    let values = &words[list_at(w)..list_at(w) + k];
                    for (j, &v) in values.iter().enumerate() {
                        assert!(
                            !values[..j].contains(&v),
                            "palette block {b:?}: value twice"
                        );
                        if v as i16 != UNKNOWN {
                            in_clamps(b, v as i16);
                        }
                    }
                    for i in 0..BLOCK_CELLS {
                        assert!(
                            palette_index(words, w, i) < k,
                            "palette block {b:?}: cell {i} past the value list"
                        );
                    }
                }
            }
            super::forms::decode(e.tag(), words, &mut cells);
            let known: Vec<i16> = cells.iter().copied().filter(|&v| v != UNKNOWN).collect();
            assert!(
                !known.is_empty(),
                "block {b:?} is all unknown: it should be dropped"
            );
            known.iter().for_each(|&v| in_clamps(b, v));
            let first = cells[0];
            assert!(
                !(cells.iter().all(|&v| v == first) && (first == fixed.min || first == fixed.max)),
                "block {b:?} is uniformly clamped: it should be one entry"
            );
        }
        assert_eq!(blocks, self.blocks, "block count");
        assert!(
            owner.iter().flatten().all(|&u| u),
            "an arena unit is neither a block's nor free"
        );
    }
}
