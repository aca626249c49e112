//! Updating a sparse (or empty) block: its sorted cells merged with a scan's masks.

use super::arena::UNIT;
use super::census::Census;
use super::forms::{any_occupied, choose, write_sparse, SPARSE, SPARSE_VALUES};
use super::patched::Patch;
use super::{Entry, Store, BLOCK_CELLS};
use crate::occupancy::sensor::{Fixed, UNKNOWN};

impl Store {
    /// [`update`](Self::update) of an empty or sparse block: the sorted old cells
    /// merged with the updated ones, in index order.
    pub(super) fn update_sparse(
        &mut self,
        s: usize,
        e: Entry,
        miss: &[u64; 8],
        hit: &[u64; 8],
        fixed: Fixed,
    ) {
        let mut out = std::mem::take(&mut self.scratch);
        out.clear();
        let empty = [0u16; UNIT];
        let words: &[u16] = if e.tag() == SPARSE {
            self.words_of(e)
        } else {
            &empty
        };
        let old = &words[UNIT..UNIT + words[0] as usize];
        let value = |c: u16| words[2 + (c & 7) as usize] as i16;
        let mut at = 0;
        for w in 0..8 {
            let mut bits = miss[w] | hit[w];
            while bits != 0 {
                let i = w << 6 | bits.trailing_zeros() as usize;
                let bit = bits & bits.wrapping_neg();
                bits ^= bit;
                while at < old.len() && usize::from(old[at] >> 3) < i {
                    out.push(u32::from(old[at] >> 3) << 16 | u32::from(value(old[at]) as u16));
                    at += 1;
                }
                let v = if at < old.len() && usize::from(old[at] >> 3) == i {
                    at += 1;
                    value(old[at - 1])
                } else {
                    UNKNOWN
                };
                let v = if hit[w] & bit != 0 {
                    fixed.apply_hit(v)
                } else {
                    fixed.apply_miss(v)
                };
                out.push((i as u32) << 16 | u32::from(v as u16));
            }
        }
        for &c in &old[at..] {
            out.push(u32::from(c >> 3) << 16 | u32::from(value(c) as u16));
        }
        // Distinct values, up to one more than a sparse block holds.
        let mut values = [0u16; SPARSE_VALUES + 1];
        let mut k = 0;
        for &c in &out {
            if !values[..k].contains(&(c as u16)) {
                values[k] = c as u16;
                k += 1;
                if k > SPARSE_VALUES {
                    break;
                }
            }
        }
        let n = out.len();
        let values_all = if n < BLOCK_CELLS { k + 1 } else { k };
        let occupied = any_occupied(values[..k].iter().map(|&v| v as i16), fixed);
        // Without the census a patched palette needs: when it might be smaller,
        // the census path below decides.
        let (tag, units) = choose(n, values_all, k, occupied, None);
        if tag == SPARSE
            && !(n == BLOCK_CELLS && k == 1)
            && !Patch::may_take_fewer(values_all, units)
        {
            if let Some(words) = self.place(s, SPARSE, units, occupied) {
                write_sparse(words, &out);
            }
            self.scratch = out;
        } else {
            let mut cells = [UNKNOWN; BLOCK_CELLS];
            for &c in &out {
                cells[(c >> 16) as usize] = c as u16 as i16;
            }
            let census = Census::of_list(&out);
            self.scratch = out;
            self.put_census(s, &cells, &census, fixed, false);
        }
    }
}
