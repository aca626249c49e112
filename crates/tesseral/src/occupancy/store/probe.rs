//! Finding a cell in a sparse block's sorted list without branching on the data.
//!
//! A binary search over a sparse block's cells (up to 136 of them) takes as many
//! steps as the list's length has bits: its loop exit is mispredicted on most
//! lookups of a map whose sparse blocks vary in length, and each misprediction
//! holds up the lookups after it until the block's words have come from memory.
//! [`sparse_value`] instead compares the cell with the first [`LANES`] listed cells
//! at once (eight SSE2 compares whose loads overlap; one for a list of up to eight
//! cells) and picks the match with bit arithmetic. Longer lists, blocks of more
//! than eight cells fewer than `UNIT + LANES` words (the compares' reach) from the
//! arena's end, and CPUs other than x86_64 use the binary search
//! ([`sparse_get`]), which gives the same answers (tested against each other and
//! against a model of cells).

use super::arena::UNIT;
use super::forms::sparse_get;
use crate::occupancy::sensor::UNKNOWN;

/// Listed cells compared at once.
pub(crate) const LANES: usize = 64;

/// The value of cell `i` of the sparse block whose words start at `at`
/// (`UNKNOWN` when it is not listed). O(1) for lists of up to [`LANES`] cells,
/// O(log len) beyond.
#[inline(always)]
pub(crate) fn sparse_value(words: &[u16], at: usize, i: usize) -> i16 {
    sparse_value_short(words, at, i).unwrap_or_else(|| sparse_get(&words[at..], i))
}

/// [`sparse_value`] by compares alone: `None` when the list is longer than
/// [`LANES`], when a list longer than [`UNIT`] has fewer than `UNIT + LANES` words
/// left from `at`, or off x86_64.
///
/// A list of up to [`UNIT`] cells (most sparse surfaces outdoors: 93 % of the
/// street's sparse lookups) is compared in one load of its own unit of cells.
/// Longer lists read the words past their end (another block's, or free) and mask
/// their lanes off; for a short list those were one or two more cache lines that
/// the lookup waited for (the street's random lookups 3-5 % faster without them).
#[inline(always)]
fn sparse_value_short(words: &[u16], at: usize, i: usize) -> Option<i16> {
    #[cfg(target_arch = "x86_64")]
    {
        let head = words.get(at..at + 2 * UNIT)?;
        let len = usize::from(head[0]);
        if len <= UNIT {
            let cells = head[UNIT..].try_into().expect("UNIT words");
            return Some(pick(head, matches::<UNIT>(cells, i) & below(len), UNIT));
        }
        if len > LANES {
            return None;
        }
        let w = words.get(at..at + UNIT + LANES)?;
        let cells = w[UNIT..].try_into().expect("LANES words");
        Some(pick(w, matches::<LANES>(cells, i) & below(len), LANES))
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = (words, at, i);
        None
    }
}

/// The value of the listed cell whose lane is set in `hits` (of `lanes`, a power
/// of two), `UNKNOWN` when none is: with no hit the first cell is read and its
/// value dropped, no branch.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn pick(w: &[u16], hits: u64, lanes: usize) -> i16 {
    let c = w[UNIT + (hits.trailing_zeros() as usize & (lanes - 1))];
    let v = w[2 + usize::from(c & 7)] as i16;
    if hits != 0 {
        v
    } else {
        UNKNOWN
    }
}

/// A mask of the lanes below `len` (`len` ≤ 64), without a branch.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn below(len: usize) -> u64 {
    (1u64 << (len & 63)).wrapping_sub(1) | ((len >> 6) as u64).wrapping_neg()
}

/// Bit `k` set where listed cell `k` is cell `i` (a listed cell is
/// `index << 3 | value number`), over `N` cells: [`UNIT`] (one compare) or [`LANES`].
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn matches<const N: usize>(cells: &[u16; N], i: usize) -> u64 {
    use std::arch::x86_64::{
        __m128i, _mm_and_si128, _mm_cmpeq_epi16, _mm_loadu_si128, _mm_movemask_epi8,
        _mm_packs_epi16, _mm_set1_epi16, _mm_setzero_si128,
    };
    const { assert!(N == UNIT || N == LANES) };
    let p = cells.as_ptr().cast::<__m128i>();
    // SAFETY: SSE2 is part of every x86_64 CPU. Load `k` (k < N / 8) reads the
    // eight words `cells[8k..8k + 8]`, inside the array; `loadu` needs no alignment.
    unsafe {
        let key = _mm_set1_epi16((i << 3) as i16);
        let index = _mm_set1_epi16(!7);
        let eq = |k: usize| _mm_cmpeq_epi16(_mm_and_si128(_mm_loadu_si128(p.add(k)), index), key);
        let mut bits = 0u64;
        let mut k = 0;
        while k < N / 8 {
            // Two compares' 16 lanes of 0 or −1 packed to bytes: one bit a lane
            // (with one compare, its eight lanes and eight of zeros).
            let hi = if k + 1 < N / 8 {
                eq(k + 1)
            } else {
                _mm_setzero_si128()
            };
            let m = _mm_movemask_epi8(_mm_packs_epi16(eq(k), hi));
            bits |= u64::from(m as u16) << (8 * k);
            k += 2;
        }
        bits
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::occupancy::store::forms::{sparse_units, write_sparse};
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    /// Every list length from 0 to past [`LANES`], blocks in the middle and at the
    /// very end of the words, every cell: the same as the binary search and as the
    /// cells written.
    #[test]
    fn the_compares_agree_with_the_binary_search_and_the_cells() {
        let mut rng = Pcg64::seed_from_u64(3);
        for len in 0..=140usize {
            for round in 0..6 {
                let mut idx: Vec<usize> = (0..512).collect();
                for k in 0..len {
                    let j = rng.random_range(k..512);
                    idx.swap(k, j);
                }
                let mut idx = idx[..len].to_vec();
                idx.sort_unstable();
                let values: Vec<i16> = (0..6).map(|_| rng.random_range(-2000..2000)).collect();
                let cells: Vec<u32> = idx
                    .iter()
                    .map(|&i| (i as u32) << 16 | u32::from(values[rng.random_range(0..6)] as u16))
                    .collect();
                let units = sparse_units(len);
                // Garbage before and, in odd rounds, after the block.
                let before = rng.random_range(0..3) * UNIT;
                let after = if round % 2 == 0 {
                    0
                } else {
                    rng.random_range(1..100)
                };
                let mut words: Vec<u16> = (0..before + units * UNIT + after)
                    .map(|_| rng.random())
                    .collect();
                write_sparse(&mut words[before..before + units * UNIT], &cells);
                let mut want = [UNKNOWN; 512];
                for &c in &cells {
                    want[(c >> 16) as usize] = c as u16 as i16;
                }
                let short = if len <= UNIT {
                    words.len() >= before + 2 * UNIT
                } else {
                    words.len() >= before + UNIT + LANES && len <= LANES
                };
                for (i, &w) in want.iter().enumerate() {
                    assert_eq!(sparse_value(&words, before, i), w, "len {len} cell {i}");
                    assert_eq!(sparse_get(&words[before..], i), w, "len {len} cell {i}");
                    let s = sparse_value_short(&words, before, i);
                    if cfg!(target_arch = "x86_64") && short {
                        assert_eq!(s, Some(w), "len {len} cell {i}: the compares");
                    } else {
                        assert_eq!(s, None, "len {len}: not short");
                    }
                }
            }
        }
    }
}
