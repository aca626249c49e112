//! The forms of a stored block and their layouts in the arena (`u16` words):
//!
//! - *uniform*: all 512 cells clamped to one value, held in the entry itself;
//! - *sparse*: a header unit `[len, k, v0 … v5]` (its known cells and up to six
//!   distinct values), then `len` cells `index << 3 | value number`, sorted;
//! - *palette* of width `w` ∈ {1, 2, 4, 8}: 512 cells of `w` bits (cell `i` at bit
//!   `i·w`, never across a word), then `[k, v0 … v(k−1)]` (room for 2^w values when
//!   `w ≤ 4`, for `k` when `w = 8`); `UNKNOWN` may be one of the values;
//! - *patched*: a palette of width 2 whose fourth number sends a cell to a patch
//!   list (see [`super::patched`]);
//! - *dense*: 512 `i16`.

use super::arena::UNIT;
use super::census::Census;
use super::patched::{self, Patch};
use super::BLOCK_CELLS;
use crate::occupancy::sensor::{Fixed, UNKNOWN};

/// Entry tags (the low three bits of an entry). `INLINE`: no block in an arena,
/// the entry empty or uniform (see [`super::Entry`]).
pub(crate) const INLINE: u32 = 0;
pub(crate) const SPARSE: u32 = 1;
/// Palette of width `1 << (tag − PALETTE)`: tags 2 to 5.
pub(crate) const PALETTE: u32 = 2;
pub(crate) const PATCHED: u32 = 6;
pub(crate) const DENSE: u32 = 7;

/// Whether a block of this tag is a palette of 4 or 8 bits or dense: a form a
/// scan's update leaves for [`Store::repatch`](super::Store::repatch) to store
/// smaller (a patched palette, or a narrower palette).
#[inline]
pub(crate) fn wide(tag: u32) -> bool {
    tag == PALETTE + 2 || tag == PALETTE + 3 || tag == DENSE
}

/// The most distinct values a sparse block holds.
pub(crate) const SPARSE_VALUES: usize = 6;

/// Units of a sparse block of `len` cells.
#[inline]
pub(crate) fn sparse_units(len: usize) -> usize {
    1 + len.div_ceil(UNIT)
}

/// Words of a palette block's cells.
#[inline]
pub(crate) const fn bits_words(w: u32) -> usize {
    32 * w as usize
}

/// Where a palette block of width `w` lists its values: after its cells and the
/// list's length.
#[inline]
pub(crate) const fn list_at(w: u32) -> usize {
    bits_words(w) + 1
}

/// Words of a palette block's value list (its length first) holding `k` values.
#[inline]
fn list_words(w: u32, k: usize) -> usize {
    1 + if w <= 4 { 1 << w } else { k }
}

/// Units of a palette block of width `w` holding `k` values.
#[inline]
pub(crate) fn palette_units(w: u32, k: usize) -> usize {
    (bits_words(w) + list_words(w, k)).div_ceil(UNIT)
}

/// Units of a dense block.
pub(crate) const DENSE_UNITS: usize = BLOCK_CELLS / UNIT;

/// The narrowest palette width for `k` values.
#[inline]
pub(crate) fn width_for(k: usize) -> Option<u32> {
    match k {
        0..=2 => Some(1),
        3..=4 => Some(2),
        5..=16 => Some(4),
        17..=256 => Some(8),
        _ => None,
    }
}

/// The palette number of cell `i` in a palette block's words.
#[inline]
pub(crate) fn palette_index(words: &[u16], w: u32, i: usize) -> usize {
    let bit = i * w as usize;
    ((words[bit >> 4] >> (bit & 15)) & ((1u16 << w) - 1)) as usize
}

/// Sets the palette number of cell `i`.
#[inline]
pub(crate) fn set_palette_index(words: &mut [u16], w: u32, i: usize, j: usize) {
    let bit = i * w as usize;
    let m = ((1u16 << w) - 1) << (bit & 15);
    let x = &mut words[bit >> 4];
    *x = (*x & !m) | ((j as u16) << (bit & 15) & m);
}

/// A sparse block's value for cell `i` (`UNKNOWN` when it is not listed).
#[inline]
pub(crate) fn sparse_get(words: &[u16], i: usize) -> i16 {
    let len = words[0] as usize;
    let cells = &words[UNIT..UNIT + len];
    let key = (i as u16) << 3;
    let p = cells.partition_point(|&c| c < key);
    match cells.get(p) {
        Some(&c) if c >> 3 == i as u16 => words[2 + (c & 7) as usize] as i16,
        _ => UNKNOWN,
    }
}

/// Four consecutive words as one `u64`, the first in the low bits (one 8-byte load on a
/// little-endian machine).
#[inline(always)]
pub(crate) fn join4(q: [u16; 4]) -> u64 {
    u64::from(q[0]) | u64::from(q[1]) << 16 | u64::from(q[2]) << 32 | u64::from(q[3]) << 48
}

/// The cells of a palette block of width `w` per number, into `n[..1 << w]`
/// (widths 1 and 2 by popcounts of the bit planes, 64 cells at a time).
pub(crate) fn palette_numbers(words: &[u16], w: u32, n: &mut [u64; 256]) {
    let u64s = || {
        words[..bits_words(w)]
            .chunks_exact(4)
            .map(|q| join4([q[0], q[1], q[2], q[3]]))
    };
    let all = BLOCK_CELLS as u64;
    match w {
        1 => {
            let ones: u64 = u64s().map(|x| u64::from(x.count_ones())).sum();
            n[..2].copy_from_slice(&[all - ones, ones]);
        }
        2 => {
            const EVEN: u64 = 0x5555_5555_5555_5555;
            let mut c = [0u64; 4];
            for x in u64s() {
                let (lo, hi) = (x & EVEN, x >> 1 & EVEN);
                c[1] += u64::from((lo & !hi).count_ones());
                c[2] += u64::from((hi & !lo).count_ones());
                c[3] += u64::from((lo & hi).count_ones());
            }
            c[0] = all - c[1] - c[2] - c[3];
            n[..4].copy_from_slice(&c);
        }
        _ => {
            n[..1 << w].fill(0);
            for i in 0..BLOCK_CELLS {
                n[palette_index(words, w, i)] += 1;
            }
        }
    }
}

/// The units a block of this tag takes, from its words (which start at its offset).
pub(crate) fn units_of(tag: u32, words: &[u16]) -> usize {
    match tag {
        SPARSE => sparse_units(words[0] as usize),
        PATCHED => patched::units_of(words),
        DENSE => DENSE_UNITS,
        _ => {
            let w = 1 << (tag - PALETTE);
            palette_units(w, words[bits_words(w)] as usize)
        }
    }
}

/// Whether one of `values` is occupied (known and at least the threshold).
#[inline]
pub(crate) fn any_occupied(values: impl IntoIterator<Item = i16>, fixed: Fixed) -> bool {
    values
        .into_iter()
        .any(|v| v != UNKNOWN && v >= fixed.threshold)
}

/// Whether an arena block (tag and words from its offset) lists an occupied value:
/// in the values of a sparse block's header or of a palette block's list (a value
/// listed may no longer be any cell's), in the cells of a dense block.
pub(crate) fn lists_occupied(tag: u32, words: &[u16], fixed: Fixed) -> bool {
    let listed = match tag {
        SPARSE => &words[2..2 + usize::from(words[1])],
        PATCHED => {
            let (common, patch) = patched::values(words);
            return any_occupied(common.iter().chain(patch).map(|&v| v as i16), fixed);
        }
        DENSE => &words[..BLOCK_CELLS],
        _ => {
            let at = bits_words(1 << (tag - PALETTE));
            &words[at + 1..at + 1 + usize::from(words[at])]
        }
    };
    any_occupied(listed.iter().map(|&v| v as i16), fixed)
}

/// The 512 values of a block in the arena (tag and words from its offset).
pub(crate) fn decode(tag: u32, words: &[u16], out: &mut [i16; BLOCK_CELLS]) {
    match tag {
        SPARSE => {
            out.fill(UNKNOWN);
            let len = words[0] as usize;
            for &c in &words[UNIT..UNIT + len] {
                out[(c >> 3) as usize] = words[2 + (c & 7) as usize] as i16;
            }
        }
        PATCHED => patched::decode(words, out),
        DENSE => {
            for (o, &v) in out.iter_mut().zip(words) {
                *o = v as i16;
            }
        }
        _ => {
            let w = 1 << (tag - PALETTE);
            let list = &words[list_at(w)..];
            for (i, o) in out.iter_mut().enumerate() {
                *o = list[palette_index(words, w, i)] as i16;
            }
        }
    }
}

/// Units a surface's palette (of width 2) may take beyond the sparse form's and
/// still be chosen (see [`choose`]).
pub(crate) const SURFACE_SLACK: usize = 6;

/// The form a block takes: its tag and its units (0 for none and uniform). The
/// smallest (a palette over a patched palette on a tie: its lookups read one
/// word less), except that a *surface* (a block that lists an occupied value) whose
/// values fit a palette of width 2 (never 1) takes that palette unless the sparse form
/// is more than [`SURFACE_SLACK`] units (96 bytes) smaller. Lookups land mostly on
/// surfaces, and a palette is read without the sparse form's compares and without
/// a mispredicted branch between the two forms. A surface's palette has width 2 at
/// least: lookups read cells of two bits (width-2 and patched palettes) with
/// constant shifts, and a surface of width 1 would send 5 % of the real scan's
/// lookups down the general path, a branch mispredicted after the entry's miss.
/// The slack keeps the few-cell
/// surfaces of a thinly seen map sparse, so that the surfaces' arena still fits
/// the caches (ARCHITECTURE.md, "Surfaces in palettes").
pub(crate) fn choose(
    known: usize,
    values: usize,
    known_values: usize,
    surface: bool,
    patch: Option<&Patch>,
) -> (u32, usize) {
    let mut best = (DENSE, DENSE_UNITS);
    if let Some(u) = patch.map(Patch::units) {
        if u < DENSE_UNITS {
            best = (PATCHED, u);
        }
    }
    let mut slack = 0;
    if let Some(w) = width_for(values).map(|w| if surface { w.max(2) } else { w }) {
        let u = palette_units(w, values);
        if u <= best.1 {
            best = (PALETTE + w.trailing_zeros(), u);
            if surface && w <= 2 {
                slack = SURFACE_SLACK;
            }
        }
    }
    if known_values <= SPARSE_VALUES {
        let u = sparse_units(known);
        if u + slack < best.1 {
            best = (SPARSE, u);
        }
    }
    best
}

/// Writes a sparse block over `words` (its whole chunk): `cells` are
/// `index << 16 | value as u16`, sorted by index, with at most [`SPARSE_VALUES`]
/// distinct values.
pub(crate) fn write_sparse(words: &mut [u16], cells: &[u32]) {
    let (head, body) = words.split_at_mut(UNIT);
    head.fill(0);
    head[0] = cells.len() as u16;
    let mut k = 0;
    for (o, &c) in body.iter_mut().zip(cells) {
        let v = c as u16;
        let j = match head[2..2 + k].iter().position(|&x| x == v) {
            Some(j) => j,
            None => {
                head[2 + k] = v;
                k += 1;
                k - 1
            }
        };
        *o = ((c >> 16) as u16) << 3 | j as u16;
    }
    debug_assert!(k <= SPARSE_VALUES);
    head[1] = k as u16;
    body[cells.len()..].fill(0);
}

/// Writes a palette block of width `w` over `words` (its whole chunk).
pub(crate) fn write_palette(words: &mut [u16], w: u32, census: &Census) {
    let at = bits_words(w);
    match w {
        1 => pack::<1>(&mut words[..at], &census.index),
        2 => pack::<2>(&mut words[..at], &census.index),
        4 => pack::<4>(&mut words[..at], &census.index),
        _ => pack::<8>(&mut words[..at], &census.index),
    }
    words[at..].fill(0);
    words[at] = census.values.len() as u16;
    for (o, &v) in words[at + 1..].iter_mut().zip(&census.values) {
        *o = v as u16;
    }
}

/// Packs 512 value numbers of `W` bits into `words`, one word at a time (each
/// word built in a register: no store waits on the one before it to the same word).
#[inline]
pub(crate) fn pack<const W: usize>(words: &mut [u16], index: &[u16; BLOCK_CELLS]) {
    for (o, cells) in words.iter_mut().zip(index.chunks_exact(16 / W)) {
        *o = cells
            .iter()
            .enumerate()
            .fold(0, |a, (c, &j)| a | j << (c * W));
    }
}

/// Writes a dense block.
pub(crate) fn write_dense(words: &mut [u16], cells: &[i16; BLOCK_CELLS]) {
    for (o, &v) in words.iter_mut().zip(cells) {
        *o = v as u16;
    }
}

/// Applies disjoint miss and hit masks to a block's 512 values.
pub(crate) fn apply_masks(
    cells: &mut [i16; BLOCK_CELLS],
    miss: &[u64; 8],
    hit: &[u64; 8],
    fixed: Fixed,
) {
    for w in 0..8 {
        let mut bits = miss[w];
        while bits != 0 {
            let i = w << 6 | bits.trailing_zeros() as usize;
            cells[i] = fixed.apply_miss(cells[i]);
            bits &= bits - 1;
        }
        let mut bits = hit[w];
        while bits != 0 {
            let i = w << 6 | bits.trailing_zeros() as usize;
            cells[i] = fixed.apply_hit(cells[i]);
            bits &= bits - 1;
        }
    }
}

/// Calls `f` on the index of every set bit of a block mask.
#[inline(always)]
pub(crate) fn for_bits(mask: &[u64; 8], mut f: impl FnMut(usize)) {
    for (w, &m) in mask.iter().enumerate() {
        let mut bits = m;
        while bits != 0 {
            f(w << 6 | bits.trailing_zeros() as usize);
            bits &= bits - 1;
        }
    }
}

/// Updates a palette block in place when its value list has room: each cell of
/// `miss` gets a miss and each of `hit` a hit, through a per-value map from old to
/// new value numbers. Returns `false`, leaving the block as it was, when the new
/// values do not fit in the width (then the caller re-encodes the block).
///
/// One pass over the updated cells reads their value numbers; a second writes the
/// new ones, skipped for misses when every missed value maps to itself (cells
/// clamped free, the common case of a block seen scan after scan). O(cells updated
/// + values); the width is a constant in each of its four forms.
pub(crate) fn palette_update(
    words: &mut [u16],
    w: u32,
    miss: &[u64; 8],
    hit: &[u64; 8],
    fixed: Fixed,
) -> bool {
    match w {
        1 => palette_update_w::<1>(words, miss, hit, fixed),
        2 => palette_update_w::<2>(words, miss, hit, fixed),
        4 => palette_update_w::<4>(words, miss, hit, fixed),
        _ => palette_update_w::<8>(words, miss, hit, fixed),
    }
}

/// [`palette_update`] for width `W`.
fn palette_update_w<const W: u32>(
    words: &mut [u16],
    miss: &[u64; 8],
    hit: &[u64; 8],
    fixed: Fixed,
) -> bool {
    let w = W;
    let at = bits_words(w);
    let k = words[at] as usize;
    let room = if w <= 4 {
        1 << w
    } else {
        (palette_units(w, k) * UNIT - at - 1).min(256)
    };
    // Which value numbers are missed and hit.
    let mut missed = [0u64; 4];
    let mut hits = [0u64; 4];
    for_bits(miss, |i| {
        let j = palette_index(words, w, i);
        missed[j >> 6] |= 1 << (j & 63);
    });
    for_bits(hit, |i| {
        let j = palette_index(words, w, i);
        hits[j >> 6] |= 1 << (j & 63);
    });
    let mut values = [0i16; 256];
    for (v, &x) in values.iter_mut().zip(&words[at + 1..at + 1 + k]) {
        *v = x as i16;
    }
    let mut n = k;
    let mut to_miss = [0u8; 256];
    let mut to_hit = [0u8; 256];
    // Whether some missed value number maps to another.
    let mut misses_move = false;
    for (set, to, hit) in [(&missed, &mut to_miss, false), (&hits, &mut to_hit, true)] {
        for (q, &m) in set.iter().enumerate() {
            let mut bits = m;
            while bits != 0 {
                let j = q << 6 | bits.trailing_zeros() as usize;
                bits &= bits - 1;
                let v = if hit {
                    fixed.apply_hit(values[j])
                } else {
                    fixed.apply_miss(values[j])
                };
                to[j] = match values[..n].iter().position(|&x| x == v) {
                    Some(t) => t as u8,
                    None if n < room => {
                        values[n] = v;
                        n += 1;
                        (n - 1) as u8
                    }
                    None => return false,
                };
                misses_move |= !hit && to[j] as usize != j;
            }
        }
    }
    if misses_move {
        for_bits(miss, |i| {
            let j = palette_index(words, w, i);
            set_palette_index(words, w, i, to_miss[j] as usize);
        });
    }
    for_bits(hit, |i| {
        let j = palette_index(words, w, i);
        set_palette_index(words, w, i, to_hit[j] as usize);
    });
    words[at] = n as u16;
    for (o, &v) in words[at + 1 + k..at + 1 + n].iter_mut().zip(&values[k..n]) {
        *o = v as u16;
    }
    true
}

/// The value of every cell of a palette block when all cells hold the same
/// value number.
pub(crate) fn palette_single(words: &[u16], w: u32) -> Option<i16> {
    let first = palette_index(words, w, 0);
    // The first word repeated holds that number in every cell.
    let mut pattern = 0u16;
    for c in 0..16 / w as usize {
        pattern |= (first as u16) << (c * w as usize);
    }
    words[..bits_words(w)]
        .iter()
        .all(|&x| x == pattern)
        .then(|| words[list_at(w) + first] as i16)
}
