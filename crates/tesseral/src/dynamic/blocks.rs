//! The lowest level: 8×8×8 bit blocks and small blocks, and the bit arithmetic on them (local indices, shifts, 27-neighbourhood extraction).

#[allow(unused_imports)]
use super::*;

/// A sparse 8×8×8 block: up to eight voxels as local indices `x + 8y + 64z` (the
/// bit numbers of a [`Leaf`]) in the first lanes, in any order, then vacant lanes
/// ([`VACANT`]). 16 bytes, a
/// quarter of a bitmap block: sparse content (scattered points, thin structures)
/// takes a quarter of the memory, and more of it stays in the cache.
#[derive(Clone, Copy)]
#[repr(C, align(16))]
pub(super) struct Small(pub(super) [u16; SMALL_CAP]);

impl Small {
    /// A block holding the one voxel `key`.
    pub(super) fn one(key: u16) -> Self {
        let mut lanes = [VACANT; SMALL_CAP];
        lanes[0] = key;
        Small(lanes)
    }
    /// The voxels of `words` (at most [`SMALL_CAP`]) as a small block.
    pub(super) fn from_words(words: &[u64; 8]) -> Self {
        let mut lanes = [VACANT; SMALL_CAP];
        let mut k = 0;
        for (z, &word) in words.iter().enumerate() {
            let mut rest = word;
            while rest != 0 {
                lanes[k] = (z as u16) << 6 | rest.trailing_zeros() as u16;
                k += 1;
                rest &= rest - 1;
            }
        }
        Small(lanes)
    }
    /// Whether lane value `key` is present. Branch-free (all eight lanes are
    /// compared), so a hit does not mispredict a loop exit.
    #[inline(always)]
    pub(super) fn has(&self, key: u16) -> bool {
        self.0.iter().fold(false, |found, &e| found | (e == key))
    }
    /// Occupied lanes (they come first). Branch-free.
    #[inline(always)]
    pub(super) fn count(&self) -> usize {
        self.0.iter().map(|&e| usize::from(e != VACANT)).sum()
    }
    /// Adds `key`: `Some(true)` when it is new, `Some(false)` when it was there, `None`
    /// when the block is full (it must become a bitmap block first).
    #[inline]
    pub(super) fn insert(&mut self, key: u16) -> Option<bool> {
        if self.has(key) {
            return Some(false);
        }
        let n = self.count();
        if n == SMALL_CAP {
            return None;
        }
        self.0[n] = key;
        Some(true)
    }
    /// Removes `key` (the last occupied lane fills its place); false when absent.
    #[inline]
    pub(super) fn remove(&mut self, key: u16) -> bool {
        let Some(lane) = self.0.iter().position(|&e| e == key) else {
            return false;
        };
        let last = self.count() - 1;
        self.0[lane] = self.0[last];
        self.0[last] = VACANT;
        true
    }
    pub(super) fn words(&self) -> [u64; 8] {
        let mut l = [0u64; 8];
        for &e in &self.0 {
            if e != VACANT {
                l[usize::from(e >> 6)] |= 1 << (e & 63);
            }
        }
        l
    }
}

#[inline]
pub(super) fn within(u: [u64; 3], log2: u32) -> bool {
    log2 >= 64 || (u[0] | u[1] | u[2]) >> log2 == 0
}

#[inline]
pub(super) fn child_index(u: [u64; 3], level: u32) -> usize {
    let s = level - 1;
    ((u[0] >> s) & 1 | ((u[1] >> s) & 1) << 1 | ((u[2] >> s) & 1) << 2) as usize
}

#[inline]
pub(super) fn leaf_bit(u: [u64; 3]) -> (usize, u64) {
    ((u[2] & 7) as usize, 1u64 << ((u[0] & 7) + 8 * (u[1] & 7)))
}

#[inline]
pub(super) fn is_index(slot: u32) -> bool {
    slot != EMPTY && slot != FULL
}

/// Whether a block-level slot holds a small block.
#[inline(always)]
pub(super) fn is_small(slot: u32) -> bool {
    slot & SMALL != 0
}

/// The lane value of offsets `u` in a small block: `x + 8y + 64z` of the local cell.
#[inline(always)]
pub(super) fn local_index(u: [u64; 3]) -> u16 {
    ((u[0] & 7) | (u[1] & 7) << 3 | (u[2] & 7) << 6) as u16
}

/// Moves the content of a block by `s` cells along `axis`, up or down. The caller
/// guarantees that no set bit leaves the block (or wraps into the next row).
pub(super) fn shift_leaf(l: &mut [u64; 8], axis: usize, s: u64, up: bool) {
    match axis {
        0 | 1 => {
            let sh = if axis == 0 { s } else { 8 * s };
            for w in l.iter_mut() {
                *w = if up { *w << sh } else { *w >> sh };
            }
        }
        _ => {
            let s = s as usize;
            if up {
                for z in (0..8).rev() {
                    l[z] = if z >= s { l[z - s] } else { 0 };
                }
            } else {
                for z in 0..8 {
                    l[z] = if z + s < 8 { l[z + s] } else { 0 };
                }
            }
        }
    }
}

/// Per-axis occupancy masks of a block: bit `i` of mask `a` is set when some voxel
/// has coordinate `i` along axis `a`.
pub(super) fn leaf_axis_masks(l: &[u64; 8]) -> [u8; 3] {
    let mut rows = 0u64;
    let mut zm = 0u8;
    for (z, &w) in l.iter().enumerate() {
        rows |= w;
        if w != 0 {
            zm |= 1 << z;
        }
    }
    let mut xm = 0u8;
    let mut ym = 0u8;
    for y in 0..8 {
        let b = (rows >> (8 * y)) as u8;
        xm |= b;
        if b != 0 {
            ym |= 1 << y;
        }
    }
    [xm, ym, zm]
}

/// The 27-bit neighbourhood of local voxel `u & 7` inside one block; needs every local
/// coordinate in 1..=6.
#[inline]
pub(super) fn extract27(l: &[u64; 8], u: [u64; 3]) -> u32 {
    let (lx, ly, lz) = (
        (u[0] & 7) as usize,
        (u[1] & 7) as usize,
        (u[2] & 7) as usize,
    );
    let sh = lx - 1 + 8 * (ly - 1);
    let mut r = 0u32;
    for dz in 0..3 {
        let w = l[lz - 1 + dz] >> sh;
        let plane = (w & 7) | ((w >> 8) & 7) << 3 | ((w >> 16) & 7) << 6;
        r |= (plane as u32) << (9 * dz);
    }
    r
}

/// The 27-bit neighbourhood of offsets `u` from the up to eight blocks around it:
/// `word(b, z)` is word `z` of block `b` (bit `i` of `b` selects the upper block along
/// axis `i`; `lo`/`hi` are the block coordinates of `u − 1` and `u + 1`). Row by row:
/// the three cells (x−1, x, x+1) of a row come from one block word, or from two when
/// the row crosses a block boundary in x.
#[inline(always)]
pub(super) fn rows27(
    u: [u64; 3],
    lo: [u64; 3],
    hi: [u64; 3],
    word: impl Fn(usize, usize) -> u64,
) -> u32 {
    let lx = u[0] & 7;
    let mut r = 0u32;
    for dz in 0..3u64 {
        let cz = u[2].wrapping_add(dz).wrapping_sub(1);
        let bz = usize::from(cz >> 3 != lo[2]) << 2;
        let lz = (cz & 7) as usize;
        for dy in 0..3u64 {
            let cy = u[1].wrapping_add(dy).wrapping_sub(1);
            let b = usize::from(cy >> 3 != lo[1]) << 1 | bz;
            let sh = 8 * (cy & 7);
            let row = if lo[0] == hi[0] {
                (word(b, lz) >> (sh + lx - 1)) & 7
            } else {
                let wl = word(b, lz) >> sh;
                let wh = word(b | 1, lz) >> sh;
                if lx == 0 {
                    (wl >> 7 & 1) | (wh & 3) << 1
                } else {
                    (wl >> 6 & 3) | (wh & 1) << 2
                }
            };
            r |= (row as u32) << (3 * dy + 9 * dz);
        }
    }
    r
}

impl DynamicOctree {
    /// Turns the small block in `slot` (child `ci` of `parent`, containing offsets
    /// `u`) into a bitmap block; returns the new block.
    pub(super) fn promote(&mut self, slot: u32, parent: u32, ci: usize, u: [u64; 3]) -> u32 {
        let words = self.small[(slot & !SMALL) as usize].words();
        self.free_small(slot);
        let big = self.alloc_leaf(parent, 0);
        self.leaves[big as usize].0 = words;
        self.set_slot(parent, ci, big, LEAF_LOG2, u);
        big
    }

    /// Whether the block in `slot` (block level, sentinels included) holds the voxel
    /// at offsets `u`.
    #[inline(always)]
    pub(super) fn block_has(&self, slot: u32, u: [u64; 3]) -> bool {
        if is_small(slot) {
            self.small[(slot & !SMALL) as usize].has(local_index(u))
        } else {
            let (w, b) = leaf_bit(u);
            self.leaves[slot as usize].0[w] & b != 0
        }
    }

    /// The 512 bits of the block in `slot` (block level, sentinels included).
    #[inline]
    pub(super) fn block_words(&self, slot: u32) -> [u64; 8] {
        if is_small(slot) {
            self.small[(slot & !SMALL) as usize].words()
        } else {
            self.leaves[slot as usize].0
        }
    }
}
