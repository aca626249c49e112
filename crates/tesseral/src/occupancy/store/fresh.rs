//! Updating an empty block (a scan reaching new space): the form and words that
//! [`update_sparse`](Store::update_sparse) would store, written straight from the
//! scan's masks. An empty block's cells after the scan take at most three values
//! (unknown, one miss, one hit), so the form is sparse, a palette of width 1 or 2, or
//! uniform; the masks are already the palette's bit planes (bit `i` of the 512 is
//! cell `i`).

use super::arena::UNIT;
use super::forms::{any_occupied, bits_words, choose, write_sparse, PALETTE, SPARSE};
use super::{Entry, Store, BLOCK_CELLS};
use crate::occupancy::sensor::{Fixed, UNKNOWN};

/// The bits of `x` spread to the even places of the result.
#[inline]
fn spread(x: u32) -> u64 {
    let x = u64::from(x);
    let x = (x | x << 16) & 0x0000_FFFF_0000_FFFF;
    let x = (x | x << 8) & 0x00FF_00FF_00FF_00FF;
    let x = (x | x << 4) & 0x0F0F_0F0F_0F0F_0F0F;
    let x = (x | x << 2) & 0x3333_3333_3333_3333;
    (x | x << 1) & 0x5555_5555_5555_5555
}

/// The first set bit of a 512-bit mask, or `BLOCK_CELLS` when none is.
fn first(mask: &[u64; 8]) -> usize {
    mask.iter()
        .position(|&w| w != 0)
        .map_or(BLOCK_CELLS, |w| w << 6 | mask[w].trailing_zeros() as usize)
}

impl Store {
    /// [`update`](Self::update) of an empty block `s`.
    pub(super) fn update_empty(&mut self, s: usize, miss: &[u64; 8], hit: &[u64; 8], fixed: Fixed) {
        let (vm, vh) = (fixed.apply_miss(UNKNOWN), fixed.apply_hit(UNKNOWN));
        let known: [u64; 8] = std::array::from_fn(|w| miss[w] | hit[w]);
        let n = known.iter().map(|w| w.count_ones() as usize).sum::<usize>();
        let (fm, fh) = (first(miss), first(hit));
        if n == 0 || vm == vh || miss.iter().zip(hit).any(|(m, h)| m & h != 0) {
            // Not a scan's update (the masks of a scan are disjoint and not empty).
            self.update_sparse(s, Entry::EMPTY, miss, hit, fixed);
            return;
        }
        // The values present, in order of first appearance (as a census numbers them).
        let unknown: [u64; 8] = std::array::from_fn(|w| !known[w]);
        let mut present: Vec<(usize, i16, &[u64; 8])> = Vec::with_capacity(3);
        for (at, v, mask) in [
            (first(&unknown), UNKNOWN, &unknown),
            (fm, vm, miss),
            (fh, vh, hit),
        ] {
            if at < BLOCK_CELLS {
                present.push((at, v, mask));
            }
        }
        present.sort_unstable_by_key(|p| p.0);
        let k = present.len() - usize::from(n < BLOCK_CELLS);
        let occupied = any_occupied(present.iter().map(|p| p.1), fixed);
        let (tag, units) = choose(n, present.len(), k, occupied, None);
        if tag == SPARSE && !(n == BLOCK_CELLS && k == 1) {
            let mut list = std::mem::take(&mut self.scratch);
            list.clear();
            for w in 0..8 {
                let mut bits = known[w];
                while bits != 0 {
                    let i = w << 6 | bits.trailing_zeros() as usize;
                    let v = if hit[w] & bits & bits.wrapping_neg() != 0 {
                        vh
                    } else {
                        vm
                    };
                    list.push((i as u32) << 16 | u32::from(v as u16));
                    bits &= bits - 1;
                }
            }
            if let Some(words) = self.place(s, SPARSE, units, occupied) {
                write_sparse(words, &list);
            }
            self.scratch = list;
            return;
        }
        if let [(_, v, _)] = present[..] {
            if v == fixed.min || v == fixed.max {
                self.set_uniform(s, v);
                return;
            }
        }
        // A palette of width 1 (two values or one) or 2 (three): the cells of value
        // number j set bit b of their number when bit b of j is set.
        debug_assert!(tag == PALETTE || tag == PALETTE + 1, "tag {tag}");
        let w = 1u32 << (tag - PALETTE);
        let plane = |b: usize| -> [u64; 8] {
            std::array::from_fn(|q| {
                present
                    .iter()
                    .enumerate()
                    .filter(|(j, _)| j >> b & 1 == 1)
                    .fold(0, |a, (_, p)| a | p.2[q])
            })
        };
        // A full arena refuses the block (the store remembers it: `overflowed`).
        let Some(words) = self.place(s, tag, units, occupied) else {
            return;
        };
        words.fill(0);
        let lo = plane(0);
        if w == 1 {
            for (q, &m) in lo.iter().enumerate() {
                for h in 0..4 {
                    words[q * 4 + h] = (m >> (16 * h)) as u16;
                }
            }
        } else {
            let hi = plane(1);
            for q in 0..8 {
                for half in 0..2 {
                    let sh = 32 * half;
                    let c = spread((lo[q] >> sh) as u32) | spread((hi[q] >> sh) as u32) << 1;
                    for h in 0..4 {
                        words[q * 8 + half * 4 + h] = (c >> (16 * h)) as u16;
                    }
                }
            }
        }
        let at = bits_words(w);
        words[at] = present.len() as u16;
        for (o, p) in words[at + 1..].iter_mut().zip(&present) {
            *o = p.1 as u16;
        }
        debug_assert!(at + 1 + present.len() <= units * UNIT);
    }
}

#[cfg(test)]
mod tests {
    use super::super::forms::units_of;
    use super::*;
    use crate::occupancy::SensorModel;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    /// The fast path against the general one (`update_sparse` of an empty block):
    /// the same entry tag, the same words, the same cells, on masks of every density.
    #[test]
    fn an_empty_blocks_update_is_stored_as_the_general_path_stores_it() {
        let mut rng = Pcg64::seed_from_u64(8);
        // OctoMap's model, and one where a single hit or miss reaches a clamp (so
        // that full blocks of one value are uniform).
        let clamping = SensorModel::from_probabilities(0.99, 0.01, (0.3, 0.8), 0.5).unwrap();
        for model in [SensorModel::octomap(), clamping] {
            let fixed = Fixed::new(&model);
            for round in 0..3000 {
                // Densities from a few cells to all of them; some rounds only miss
                // or only hit.
                let p = [0.005, 0.03, 0.1, 0.5, 0.9, 0.99, 1.0][round % 7];
                let only = rng.random_range(0..4);
                let mut miss = [0u64; 8];
                let mut hit = [0u64; 8];
                for i in 0..BLOCK_CELLS {
                    if rng.random_bool(p) {
                        let h = match only {
                            0 => false,
                            1 => true,
                            _ => rng.random_bool(0.2),
                        };
                        let m = if h { &mut hit } else { &mut miss };
                        m[i >> 6] |= 1 << (i & 63);
                    }
                }
                if (0..8).all(|w| miss[w] | hit[w] == 0) {
                    continue;
                }
                let b = [rng.random_range(-20..20), 3, -4];
                let mut fast = Store::default();
                let mut general = Store::default();
                fast.update(b, &miss, &hit, fixed);
                let s = general.slot(b);
                general.update_sparse(s, Entry::EMPTY, &miss, &hit, fixed);
                fast.assert_valid(fixed);
                general.assert_valid(fixed);
                let (ef, eg) = (fast.entry(b), general.entry(b));
                assert_eq!(ef, eg, "round {round}");
                if let Some(e) = ef.filter(|e| e.in_arena()) {
                    let len = units_of(e.tag(), fast.words_of(e)) * UNIT;
                    assert_eq!(fast.words_of(e)[..len], general.words_of(e)[..len]);
                }
                let mut cells = [UNKNOWN; BLOCK_CELLS];
                super::super::forms::apply_masks(&mut cells, &miss, &hit, fixed);
                assert_eq!(fast.cells(b), cells, "round {round}");
            }
        }
    }
}
