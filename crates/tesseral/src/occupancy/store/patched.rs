//! The *patched palette*, the form of a surface seen from many viewpoints.
//!
//! After many scans, most of such a block's cells hold one of a few values
//! (unknown, clamped free, clamped occupied) and a few dozen hold log-odds short
//! of the clamps, a dozen distinct among them. A palette tells them apart with 4
//! or 8 bits in every cell. The patched palette gives every cell 2 bits, as a
//! palette of width 2 does: numbers 0 to 2 for the block's three most common
//! values, and 3 ([`ESCAPE`]) for a cell whose value is in the *patch*. The patch
//! lists the other values, and the escaped cells' numbers in that list in cell
//! order, 1, 2, 4 or 8 bits each. An escaped cell's rank (the escaped cells
//! before it) comes from a count per 32 cells and one popcount.
//!
//! Layout (`u16` words):
//! - `0..64`: the cells' numbers, 2 bits each (cell `i` at bit `2i`);
//! - `64`: the escaped cells' count;
//! - `65..68`: the three common values (where a palette of width 2 lists its
//!   values, so that a lookup reads a cell the same way in both, and only an
//!   escaped cell goes further);
//! - `68`: the width of the escaped cells' numbers in the patch;
//! - `69..85`: the escaped cells before cell `32·g`, for `g` in `0..16`;
//! - `85`: the patch's value count `k` (2 to 256);
//! - `86..86 + k`: the patch's values;
//! - then the escaped cells' numbers in the patch, [`width_for`]`(k)` bits each.

use super::arena::UNIT;
use super::census::Census;
use super::forms::{pack, palette_index, palette_numbers, width_for};
use super::BLOCK_CELLS;

/// The number of the escaped cells.
pub(crate) const ESCAPE: usize = 3;

/// Where the escaped cells' count lies.
const ESCAPED: usize = 64;
/// Where the three common values lie.
pub(crate) const COMMON: usize = 65;
/// Where the width of the patch's numbers lies.
const WIDTH: usize = 68;
/// Where the counts of escaped cells before each [`GROUP`] cells lie.
const RANKS: usize = 69;
/// Cells per count of escaped cells: their numbers fill a `u64`.
const GROUP: usize = 32;
/// Where the patch's value count lies, then its values, then the numbers.
const PATCH: usize = RANKS + BLOCK_CELLS / GROUP;

/// The most values a patched palette holds: three common and 256 in the patch.
const MOST: usize = 3 + 256;

/// What a block's patched palette holds, from its census.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Patch {
    /// The numbers in the census of the three most common values, most common
    /// first.
    common: [u16; 3],
    /// Cells of none of them.
    escaped: usize,
    /// The values in the patch (those of the escaped cells).
    listed: usize,
}

impl Patch {
    /// The patch of a block with this census: `None` for four values or fewer
    /// (a palette of width 2 holds them) or more than the patch holds.
    pub fn of(census: &Census) -> Option<Self> {
        let k = census.values.len();
        if !(5..=MOST).contains(&k) {
            return None;
        }
        let mut count = [0u16; MOST];
        for &j in &census.index {
            count[usize::from(j)] += 1;
        }
        let mut common = [0u16; 3];
        let mut held = 0;
        for c in 0..3 {
            let j = (0..k)
                .filter(|j| !common[..c].contains(&(*j as u16)))
                .max_by_key(|&j| (count[j], std::cmp::Reverse(j)))
                .expect("five values or more");
            common[c] = j as u16;
            held += usize::from(count[j]);
        }
        Some(Self {
            common,
            escaped: BLOCK_CELLS - held,
            listed: k - 3,
        })
    }

    /// Units of the block.
    pub fn units(&self) -> usize {
        units(self.listed, self.escaped)
    }

    /// Whether a block of `values` distinct values (`UNKNOWN` counted) may take
    /// fewer than `than` units as a patched palette (it does for some census).
    pub fn may_take_fewer(values: usize, than: usize) -> bool {
        (5..=MOST).contains(&values) && units(values - 3, 0) < than
    }
}

/// Words of the escaped cells' numbers.
#[inline]
fn number_words(listed: usize, escaped: usize) -> usize {
    let w = width_for(listed).expect("at most 256 values in a patch") as usize;
    (escaped * w).div_ceil(16)
}

/// Units of a patched palette with `listed` values in its patch and `escaped`
/// cells.
fn units(listed: usize, escaped: usize) -> usize {
    (PATCH + 1 + listed + number_words(listed, escaped)).div_ceil(UNIT)
}

/// Units of the patched palette whose words start `words`.
pub(crate) fn units_of(words: &[u16]) -> usize {
    units(usize::from(words[PATCH]), usize::from(words[ESCAPED]))
}

/// The three common values and the patch's values.
pub(crate) fn values(words: &[u16]) -> (&[u16], &[u16]) {
    let k = usize::from(words[PATCH]);
    (&words[COMMON..COMMON + 3], &words[PATCH + 1..PATCH + 1 + k])
}

/// Writes the patched palette of a block with this census and patch over
/// `words` (its whole chunk).
pub(crate) fn write(words: &mut [u16], census: &Census, patch: &Patch) {
    words.fill(0);
    // Each census number's number here (0 to 2, or 3: escaped), and its number in
    // the patch.
    let mut code = [ESCAPE as u16; MOST];
    let mut in_patch = [0u16; MOST];
    for (c, &j) in patch.common.iter().enumerate() {
        code[usize::from(j)] = c as u16;
        words[COMMON + c] = census.values[usize::from(j)] as u16;
    }
    let mut listed = 0;
    for (j, &v) in census.values.iter().enumerate() {
        if code[j] == ESCAPE as u16 {
            in_patch[j] = listed as u16;
            words[PATCH + 1 + listed] = v as u16;
            listed += 1;
        }
    }
    debug_assert_eq!(listed, patch.listed);
    words[PATCH] = listed as u16;
    words[ESCAPED] = patch.escaped as u16;
    let codes: [u16; BLOCK_CELLS] = std::array::from_fn(|i| code[usize::from(census.index[i])]);
    pack::<2>(&mut words[..ESCAPED], &codes);
    let w = width_for(listed).expect("at most 256 values in a patch");
    words[WIDTH] = w as u16;
    let (head, numbers) = words.split_at_mut(PATCH + 1 + listed);
    let mut rank = 0;
    for (i, &j) in census.index.iter().enumerate() {
        if i % GROUP == 0 {
            head[RANKS + i / GROUP] = rank as u16;
        }
        if code[usize::from(j)] == ESCAPE as u16 {
            let bit = rank * w as usize;
            numbers[bit >> 4] |= in_patch[usize::from(j)] << (bit & 15);
            rank += 1;
        }
    }
    debug_assert_eq!(rank, patch.escaped);
}

/// The 512 values of a patched palette.
pub(crate) fn decode(words: &[u16], out: &mut [i16; BLOCK_CELLS]) {
    let k = usize::from(words[PATCH]);
    let w = width_for(k).expect("at most 256 values in a patch");
    let numbers = &words[PATCH + 1 + k..];
    let mut rank = 0;
    for (i, o) in out.iter_mut().enumerate() {
        let c = palette_index(words, 2, i);
        *o = if c != ESCAPE {
            words[COMMON + c] as i16
        } else {
            rank += 1;
            words[PATCH + 1 + palette_index(numbers, w, rank - 1)] as i16
        };
    }
}

/// The escaped cells of a patched palette per number in its patch, into
/// `n[..k]` for its `k` values, and per common number into `common`.
pub(crate) fn numbers(words: &[u16], n: &mut [u64; 256], common: &mut [u64; 3]) {
    let k = usize::from(words[PATCH]);
    let w = width_for(k).expect("at most 256 values in a patch");
    let numbers = &words[PATCH + 1 + k..];
    n[..k].fill(0);
    for r in 0..usize::from(words[ESCAPED]) {
        n[palette_index(numbers, w, r)] += 1;
    }
    // The cells' numbers as a 2-bit palette's, counted by popcounts (the escaped
    // cells' number 3 among them).
    let mut four = [0u64; 256];
    palette_numbers(words, 2, &mut four);
    common.copy_from_slice(&four[..3]);
}

/// The value of cell `i` of the patched palette at `at` in `words`, an escaped
/// cell: its rank from the count before its 32 cells and a popcount of the
/// escaped cells among those before it, then its number in the patch.
///
/// `read(k)` gives word `k` of `words` (the lookups' unchecked read).
#[inline(always)]
pub(crate) fn escaped_value(read: impl Fn(usize) -> u16, at: usize, i: usize) -> i16 {
    let (g, r) = (i / GROUP, i % GROUP);
    // The group's numbers, cell c at bit 2c.
    let run = (0..4).fold(0u64, |x, q| x | u64::from(read(at + 4 * g + q)) << (16 * q));
    const EVEN: u64 = 0x5555_5555_5555_5555;
    let escaped = run & run >> 1 & EVEN & ((1u64 << (2 * r)) - 1);
    let rank = usize::from(read(at + RANKS + g)) + even_ones(escaped);
    let k = usize::from(read(at + PATCH));
    let w = usize::from(read(at + WIDTH));
    let bit = rank * w;
    let number = usize::from(read(at + PATCH + 1 + k + (bit >> 4)) >> (bit & 15)) & ((1 << w) - 1);
    read(at + PATCH + 1 + number) as i16
}

/// The set bits of `x`, all at even positions: a popcount by shifts and one
/// multiply, shorter than the general one that x86-64's baseline (no `popcnt`)
/// compiles `count_ones` to.
#[inline(always)]
fn even_ones(x: u64) -> usize {
    const NIBBLES: u64 = 0x1111_1111_1111_1111;
    // Each nibble: its bits 0 and 2, 0 to 2; then each byte, 0 to 4.
    let x = (x & NIBBLES) + (x >> 2 & NIBBLES);
    let x = (x + (x >> 4)) & 0x0F0F_0F0F_0F0F_0F0F;
    (x.wrapping_mul(0x0101_0101_0101_0101) >> 56) as usize
}

/// Checks a patched palette's invariants (its `units` units from `words`): the
/// common values and the patch's are distinct; the width fits the patch; the
/// counts and ranks match the cells; every number lies in the patch; no bits
/// past the numbers. `what` names the block.
pub(crate) fn assert_valid(words: &[u16], units: usize, what: &str) {
    let k = usize::from(words[PATCH]);
    assert!((2..=256).contains(&k), "{what}: a patch of {k} values");
    let w = width_for(k).expect("checked");
    assert_eq!(u32::from(words[WIDTH]), w, "{what}: numbers' width");
    let (common, patch) = values(words);
    let all: Vec<u16> = common.iter().chain(patch).copied().collect();
    for (j, &v) in all.iter().enumerate() {
        assert!(!all[..j].contains(&v), "{what}: value {} twice", v as i16);
    }
    let mut rank = 0;
    for i in 0..BLOCK_CELLS {
        if i % GROUP == 0 {
            assert_eq!(
                usize::from(words[RANKS + i / GROUP]),
                rank,
                "{what}: rank at cell {i}"
            );
        }
        rank += usize::from(palette_index(words, 2, i) == ESCAPE);
    }
    assert_eq!(usize::from(words[ESCAPED]), rank, "{what}: escaped cells");
    let w = w as usize;
    let numbers = &words[PATCH + 1 + k..units * UNIT];
    for r in 0..rank {
        assert!(
            palette_index(numbers, w as u32, r) < k,
            "{what}: escaped cell {r} past the patch"
        );
    }
    let used = rank * w;
    assert!(
        numbers.iter().enumerate().all(|(q, &x)| {
            let from = used.saturating_sub(16 * q).min(16);
            from == 16 || x >> from == 0
        }),
        "{what}: bits past the numbers"
    );
}
