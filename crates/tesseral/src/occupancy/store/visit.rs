//! Reading the whole store: every block's known cells, counts of them.

use super::forms::{decode, EMPTY, UNIFORM};
use super::{join, BlockKey, Store, BLOCK_CELLS, TABLE};
use crate::occupancy::sensor::UNKNOWN;

impl Store {
    /// Calls `f` on every block's known cells: `(index in block, value)`, or once
    /// with `None` and the value of a uniform block.
    fn visit(&self, mut f: impl FnMut(BlockKey, Option<usize>, i16)) {
        let mut cells = [UNKNOWN; BLOCK_CELLS];
        for (t, &key) in self.keys.iter().enumerate() {
            for (l, &e) in self.tables[t * TABLE..(t + 1) * TABLE].iter().enumerate() {
                let b = join(key, l);
                match e.tag() {
                    EMPTY => {}
                    UNIFORM => f(b, None, (e.0 >> 16) as u16 as i16),
                    tag => {
                        decode(tag, self.words_of(e), &mut cells);
                        for (i, &v) in cells.iter().enumerate() {
                            if v != UNKNOWN {
                                f(b, Some(i), v);
                            }
                        }
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
        self.blocks
    }

    /// Calls `f` on every known cell, in no order.
    pub fn for_each(&self, mut f: impl FnMut([i64; 3], i16)) {
        self.visit(|b, i, v| match i {
            Some(i) => f(join(b, i), v),
            None => (0..BLOCK_CELLS).for_each(|i| f(join(b, i), v)),
        });
    }
}
