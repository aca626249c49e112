//! A block's census: its distinct values in order of first appearance and each
//! cell's number among them, from which [`choose`](super::forms::choose) picks a
//! form and [`write_palette`](super::forms::write_palette) packs a palette.

use super::BLOCK_CELLS;
use crate::occupancy::sensor::UNKNOWN;

/// What a block's values are, and the form that stores them in the fewest units.
#[derive(Debug, PartialEq, Eq)]
pub(crate) struct Census {
    /// Distinct values, in order of first appearance (`UNKNOWN` included).
    pub values: Vec<i16>,
    /// Each cell's number in `values`.
    pub index: [u16; BLOCK_CELLS],
    /// Known cells.
    pub known: usize,
}

impl Census {
    /// The census of a block's 512 cells: one probe of a small hash table a cell.
    pub fn of(cells: &[i16; BLOCK_CELLS]) -> Self {
        // A small open-addressed table from value to number.
        let mut slots = [u16::MAX; 1024];
        let mut values = Vec::new();
        let mut index = [0u16; BLOCK_CELLS];
        let mut known = 0;
        for (i, &v) in cells.iter().enumerate() {
            known += usize::from(v != UNKNOWN);
            let mut h = (u32::from(v as u16).wrapping_mul(0x9E37_79B1) >> 22) as usize;
            loop {
                let s = slots[h];
                if s == u16::MAX {
                    slots[h] = values.len() as u16;
                    index[i] = values.len() as u16;
                    values.push(v);
                    break;
                }
                if values[s as usize] == v {
                    index[i] = s;
                    break;
                }
                h = (h + 1) & 1023;
            }
        }
        Self {
            values,
            index,
            known,
        }
    }

    /// The census of a block whose known cells are `list` (`index << 16 | value as
    /// u16`, sorted by index, no value `UNKNOWN`), the same as [`Census::of`] its
    /// cells, without a pass over all 512: O(512 + n·k) for n cells listed and k
    /// distinct values, a fill and a few compares a cell instead of a hash probe.
    pub fn of_list(list: &[u32]) -> Self {
        let mut values = Vec::new();
        let mut number = |v: i16| match values.iter().position(|&x| x == v) {
            Some(j) => j as u16,
            None => {
                values.push(v);
                values.len() as u16 - 1
            }
        };
        // The unknown cells' number, given when the first of them comes.
        let mut unknown = None;
        let mut index = [0u16; BLOCK_CELLS];
        let mut next = 0;
        for &c in list {
            let i = (c >> 16) as usize;
            if i > next && unknown.is_none() {
                unknown = Some(number(UNKNOWN));
            }
            index[i] = number(c as u16 as i16);
            next = i + 1;
        }
        if next < BLOCK_CELLS && unknown.is_none() {
            unknown = Some(number(UNKNOWN));
        }
        if let Some(u @ 1..) = unknown {
            // The runs of cells between those listed.
            let mut from = 0;
            for &c in list {
                let i = (c >> 16) as usize;
                index[from..i].fill(u);
                from = i + 1;
            }
            index[from..].fill(u);
        }
        Self {
            values,
            index,
            known: list.len(),
        }
    }

    /// Distinct known values.
    pub fn known_values(&self) -> usize {
        self.values.len() - usize::from(self.values.contains(&UNKNOWN))
    }
}
