//! The per-scan scratch of hit and miss masks per block, and the fast walk of a ray
//! through it (the DDA of [`dda`](super::dda), cell by cell inside a block, one jump
//! over a block all missed).

use std::sync::Arc;

use rustc_hash::FxHashMap;

use super::dda::{exit_block, face, steps_to_face, Dda};
#[cfg(test)]
use super::dda::{JUMPS, RUN_JUMPS};
use super::far::Far;
use super::store::{cube_index, BlockKey, BLOCK_LOG2};

/// The bits of one block's cells, one cache line: bit `x + 8y` of word `z`. A ray
/// crossing a block touches only its line of miss bits.
#[derive(Debug, Clone, Copy, Default)]
#[repr(C, align(64))]
pub(crate) struct Bits(pub [u64; 8]);

/// Blocks per side of the dense index around the origin (a power of two).
const NEAR_SIDE_LOG2: u32 = 6;
const NEAR_SIDE: i64 = 1 << NEAR_SIDE_LOG2;
/// An entry of the dense index with no slot (the index is zeroed memory, of which
/// only the pages a scan reaches are ever mapped); others hold the slot plus one.
const NO_SLOT: u32 = 0;
/// The flag of a slot in the dense index whose block is all missed (so that a ray
/// crossing it jumps to its exit without reading its bits).
const FULL: u32 = 1 << 31;
/// An entry of the dense index for a block that the map holds clamped free and no
/// ray ends in: it has no slot, and rays cross it as a full block.
const CLAMPED: u32 = u32::MAX;

/// Lines of miss bits per chunk (64 KiB): the chunks never move as a scratch grows
/// (a `Vec` of 64-byte-aligned lines would be copied at each doubling).
const CHUNK_LOG2: u32 = 10;
const CHUNK: usize = 1 << CHUNK_LOG2;

/// Blocks of the hash index packed in one `u64` when each axis lies within this
/// many blocks of the origin's (2^20 blocks: thousands of kilometres at any
/// resolution of interest); farther ones are keyed by their whole key.
const PACK: i64 = 1 << 20;

/// One thread's updates of a scan: blocks, each with its masks, found through a
/// dense index of the 64³ blocks around the origin (rays from one origin cross
/// these most often) and hash maps beyond. Each cell is a bit, so updates are
/// deduplicated as they are made, and the cells near the origin that every ray
/// crosses cost a bit set, not an update.
///
/// A block is a slot: its key, its line of miss bits (in chunks that never move),
/// and its hit bits only when a ray ends in it (few blocks do), so that a scan
/// crossing millions of blocks writes 92 bytes for each, not the 192 of a block
/// with both masks and its key in one aligned record.
#[derive(Debug)]
pub(crate) struct Scratch {
    /// The origin's block.
    centre: BlockKey,
    /// The lowest block of the dense index.
    near_lo: BlockKey,
    near: Vec<u32>,
    /// One bit per block of the dense index, in its order: set when rays cross the
    /// block in one jump (it is [`FULL`], or [`CLAMPED`]: the map's clamped blocks
    /// are set from the start), so that the walk tests 32 KiB rather than the
    /// index's 1 MiB before a jump.
    jump: Box<[u64]>,
    /// Blocks beyond the dense index, by their offset from `centre` (21 bits per
    /// axis), in bricks of 8³ blocks.
    far: Far,
    /// Blocks too far from `centre` to pack.
    wide: FxHashMap<BlockKey, u32>,
    /// The key of each slot.
    keys: Vec<BlockKey>,
    /// The miss bits of slot `s`: `miss[s >> CHUNK_LOG2][s % CHUNK]`.
    miss: Vec<Box<[Bits]>>,
    /// Per slot, 1 + its index in `hits`, or 0 when no ray ends in it.
    hit_at: Vec<u32>,
    hits: Vec<Bits>,
}

/// The dense index of a scratch centred on block `centre`: its lowest block and
/// the log2 of its side in blocks.
pub(crate) fn near_cube(centre: BlockKey) -> (BlockKey, u32) {
    (centre.map(|c| c - NEAR_SIDE / 2), NEAR_SIDE_LOG2)
}

/// No hits.
const NO_HITS: Bits = Bits([0; 8]);

impl Scratch {
    /// An empty scratch whose dense index is centred on block `centre`, with the
    /// blocks of that index that the map holds clamped free (a bit set over
    /// [`near_cube`]), if known: a miss changes nothing there, so rays cross
    /// those blocks without marking their cells (a hit still counts).
    pub fn new(centre: BlockKey, clamped: Option<Arc<[u64]>>) -> Self {
        let words = 1 << (3 * NEAR_SIDE_LOG2 - 6);
        let jump = match &clamped {
            Some(c) => c.to_vec().into_boxed_slice(),
            None => vec![0; words].into_boxed_slice(),
        };
        debug_assert_eq!(jump.len(), words);
        Self {
            jump,
            centre,
            near_lo: near_cube(centre).0,
            near: vec![NO_SLOT; 1 << (3 * NEAR_SIDE_LOG2)],
            far: Far::default(),
            wide: FxHashMap::default(),
            keys: Vec::new(),
            miss: Vec::new(),
            hit_at: Vec::new(),
            hits: Vec::new(),
        }
    }

    /// The keys of the slots (`0..keys().len()`).
    pub fn keys(&self) -> &[BlockKey] {
        &self.keys
    }

    /// The miss bits of slot `s`.
    #[inline(always)]
    pub fn miss(&self, s: usize) -> &[u64; 8] {
        &self.miss[s >> CHUNK_LOG2][s & (CHUNK - 1)].0
    }

    #[inline(always)]
    fn miss_mut(&mut self, s: usize) -> &mut [u64; 8] {
        &mut self.miss[s >> CHUNK_LOG2][s & (CHUNK - 1)].0
    }

    /// The blocks in which a ray ends.
    pub fn hit_blocks(&self) -> impl Iterator<Item = BlockKey> + '_ {
        self.keys
            .iter()
            .zip(&self.hit_at)
            .filter(|(_, &h)| h != 0)
            .map(|(k, _)| *k)
    }

    /// The hit bits of slot `s`.
    #[inline]
    pub fn hits(&self, s: usize) -> &[u64; 8] {
        match self.hit_at[s] {
            0 => &NO_HITS.0,
            h => &self.hits[h as usize - 1].0,
        }
    }

    /// The slot of block `b`, made (empty) when the scratch has none, also for a
    /// block the map holds clamped free (still crossed as full).
    #[inline]
    fn slot(&mut self, b: BlockKey) -> usize {
        let (v, at) = self.enter(b);
        if v == CLAMPED - 1 {
            let n = self.keys.len() as u32;
            self.near[at] = FULL | (n + 1);
            self.push(b);
            return n as usize;
        }
        (v & !FULL) as usize
    }

    /// The slot of block `b` (made when the scratch has none), with [`FULL`] set when
    /// the block is known to be all missed, and its place in the dense index
    /// (`usize::MAX` when beyond).
    #[inline(always)]
    fn enter(&mut self, b: BlockKey) -> (u32, usize) {
        self.enter_at(b, cube_index(self.near_lo, NEAR_SIDE_LOG2, b))
    }

    /// Block `b`'s place in the dense index, if any, and whether rays cross it in one
    /// jump (its bit in `jump`).
    #[inline(always)]
    fn near_jump(&self, b: BlockKey) -> (Option<usize>, bool) {
        let near = cube_index(self.near_lo, NEAR_SIDE_LOG2, b);
        (near, near.is_some_and(|at| self.jumps(at)))
    }

    /// Whether rays cross the block at `at` in the dense index in one jump.
    #[inline(always)]
    fn jumps(&self, at: usize) -> bool {
        self.jump[at >> 6] >> (at & 63) & 1 != 0
    }

    /// Marks the block at `at` in the dense index all missed.
    #[inline(always)]
    fn set_full(&mut self, at: usize) {
        self.near[at] |= FULL;
        self.jump[at >> 6] |= 1 << (at & 63);
    }

    /// [`enter`](Self::enter) with `b`'s place in the dense index, if any.
    #[inline(always)]
    fn enter_at(&mut self, b: BlockKey, near: Option<usize>) -> (u32, usize) {
        let n = self.keys.len() as u32;
        debug_assert!(n < FULL - 2, "a scratch holds fewer than 2^31 - 2 blocks");
        let (i, at) = if let Some(at) = near {
            let mut i = self.near[at];
            if i == NO_SLOT {
                // A block with no slot is in `jump` only as clamped by the map (a
                // block full of misses has a slot).
                let clamped = self.jumps(at);
                i = if clamped { CLAMPED } else { n + 1 };
                self.near[at] = i;
            }
            (i - 1, at)
        } else {
            (self.far_slot(b, n), usize::MAX)
        };
        if i == n {
            self.push(b);
        }
        (i, at)
    }

    /// The slot of block `b` outside the dense index, or `n` (entered as `b`'s).
    #[inline]
    fn far_slot(&mut self, b: BlockKey, n: u32) -> u32 {
        let d = [0, 1, 2].map(|i| b[i].checked_sub(self.centre[i]));
        if let [Some(x), Some(y), Some(z)] = d {
            if [x, y, z].iter().all(|c| (-PACK..PACK).contains(c)) {
                let p = |c: i64| (c + PACK) as u64;
                return self.far.slot([p(x), p(y), p(z)], n);
            }
        }
        *self.wide.entry(b).or_insert(n)
    }

    /// Appends an empty slot for block `b`.
    fn push(&mut self, b: BlockKey) {
        if self.keys.len() & (CHUNK - 1) == 0 {
            self.miss
                .push(vec![Bits::default(); CHUNK].into_boxed_slice());
        }
        self.keys.push(b);
        self.hit_at.push(0);
    }

    /// Marks missed the cells of a ray, as [`walk`] visits them: the walk is kept in
    /// registers, in the cell's block-local coordinates, with one probe per block
    /// crossed. A block whose 512 cells are all missed already is crossed in one
    /// jump to its exit ([`exit_block`]): near the origin most blocks fill after a
    /// few hundred rays.
    #[cfg(test)]
    pub fn miss_ray(
        &mut self,
        origin: [f64; 3],
        end: [f64; 3],
        key_origin: [i64; 3],
        key_end: [i64; 3],
        res: f64,
    ) {
        if let Some(w) = Dda::new(origin, end, key_origin, key_end, res) {
            self.miss_walk(&w, key_origin);
        }
    }

    /// `miss_ray` (built for tests) for the walk `w` from cell `key_origin`.
    #[inline]
    pub fn miss_walk(&mut self, w: &Dda, key_origin: [i64; 3]) {
        let mask = (1i64 << BLOCK_LOG2) - 1;
        let mut block = key_origin.map(|c| c >> BLOCK_LOG2);
        let [mut x, mut y, mut z] = key_origin.map(|c| c & mask);
        let [sx, sy, sz] = w.step;
        let [mut tx, mut ty, mut tz] = w.t_max;
        let [dx, dy, dz] = w.t_delta;
        let [mut lx, mut ly, mut lz] = w.left_axis;
        let mut left = w.left;
        let all = |m: &[u64; 8]| m.iter().fold(u64::MAX, |a, &w| a & w) == u64::MAX;
        // The block of the end cell, and whether `b` is two blocks or more from it
        // along some axis (then the walk cannot end in `b` or on its exit step).
        let end_block: BlockKey =
            [0, 1, 2].map(|i| (key_origin[i] + w.step[i] * w.left_axis[i]) >> BLOCK_LOG2);
        let far = |b: BlockKey| (0..3).any(|i| (b[i] - end_block[i]).abs() >= 2);
        loop {
            // (x, y, z) is the walk's cell, in `block`, not marked yet. A block of the
            // dense index is known full by its bit in `jump`, set as a ray leaves it
            // full (its line is in cache then); one beyond is checked as it is
            // entered.
            let (mut near, mut jump) = self.near_jump(block);
            if jump && far(block) {
                // A run of full blocks far from the end: only the faces matter. Each
                // axis keeps the parameter of its next face (`e*`, summed as the walk
                // sums), and its cell state (`t*`, the coordinate, steps left) as of
                // the last face it crossed; the others' state is caught up once, on
                // leaving the run.
                let (mut ex, mut ey, mut ez) = (
                    face(tx, dx, x, sx),
                    face(ty, dy, y, sy),
                    face(tz, dz, z, sz),
                );
                // The axis and parameter of the last face crossed.
                let mut entry = None;
                macro_rules! cross {
                    ($e:ident, $t:ident, $d:ident, $c:ident, $s:ident, $l:ident, $axis:expr) => {{
                        let steps = steps_to_face($c, $s);
                        if $l < steps {
                            // (Not expected far from the end.) The exact path takes it.
                            break;
                        }
                        $l -= steps;
                        entry = Some(($axis, $e));
                        $t = $e + $d;
                        $c = if $s > 0 { 0 } else { mask };
                        $e = face($t, $d, $c, $s);
                        block[$axis] += $s;
                    }};
                }
                loop {
                    // Ties: as `walk` (z first, then y, then x).
                    if ex < ey {
                        if ex < ez {
                            cross!(ex, tx, dx, x, sx, lx, 0);
                        } else {
                            cross!(ez, tz, dz, z, sz, lz, 2);
                        }
                    } else if ey < ez {
                        cross!(ey, ty, dy, y, sy, ly, 1);
                    } else {
                        cross!(ez, tz, dz, z, sz, lz, 2);
                    }
                    #[cfg(test)]
                    RUN_JUMPS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    (near, jump) = self.near_jump(block);
                    if !(jump && far(block)) {
                        break;
                    }
                }
                if let Some((a, p)) = entry {
                    // The other axes' borders before the last face crossed, as the walk
                    // would have stepped them (a border at the face's parameter comes
                    // first when its axis is higher); none is past its own next face.
                    // Where the walk would have stopped on one (no step left along its
                    // axis: float rounding at the end), it stopped in a full block of
                    // the run: nothing is left to mark.
                    macro_rules! catch_up {
                        ($t:ident, $d:ident, $c:ident, $s:ident, $l:ident, $axis:expr) => {
                            if $axis != a && $s != 0 {
                                while $t < p || ($t == p && $axis > a) {
                                    if $l == 0 {
                                        return;
                                    }
                                    $t += $d;
                                    $c += $s;
                                    $l -= 1;
                                }
                                debug_assert!($c & !mask == 0);
                            }
                        };
                    }
                    catch_up!(tx, dx, x, sx, lx, 0);
                    catch_up!(ty, dy, y, sy, ly, 1);
                    catch_up!(tz, dz, z, sz, lz, 2);
                    left = lx + ly + lz;
                }
            }
            let (v, at) = if jump {
                (FULL, 0)
            } else {
                self.enter_at(block, near)
            };
            let s = (v & !FULL) as usize;
            let full = v & FULL != 0 || {
                let m = self.miss_mut(s);
                m[z as usize] |= 1 << (x | y << 3);
                at == usize::MAX && all(m)
            };
            if full {
                // Every cell of the block is missed: only the exit matters.
                #[cfg(test)]
                JUMPS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let (axis, n, t) = exit_block([tx, ty, tz], [dx, dy, dz], w.step, [x, y, z]);
                let steps = n[0] + n[1] + n[2];
                if n[0] > lx || n[1] > ly || n[2] > lz || steps >= left {
                    // The walk ends in the block or on its exit step.
                    return;
                }
                (lx, ly, lz) = (lx - n[0], ly - n[1], lz - n[2]);
                left -= steps;
                [tx, ty, tz] = t;
                x = (x + sx * n[0]) & mask;
                y = (y + sy * n[1]) & mask;
                z = (z + sz * n[2]) & mask;
                block[axis] += w.step[axis];
                continue;
            }
            let m = self.miss_mut(s);
            // The bits of the cells walked in word `z` since it was last written: kept
            // in a register and written when the walk leaves the word, so that steps
            // along x and y do not wait on their own store to the same word.
            let mut acc = 0u64;
            macro_rules! flush {
                () => {
                    m[z as usize] |= acc;
                };
            }
            // One step along an axis: stop before passing the end cell's plane or on
            // reaching the end cell; leave the loop when the local coordinate wraps.
            macro_rules! step {
                ($l:ident, $t:ident, $d:ident, $c:ident, $s:ident, $axis:expr) => {{
                    if $l == 0 {
                        flush!();
                        return;
                    }
                    $l -= 1;
                    left -= 1;
                    if left == 0 {
                        flush!();
                        return;
                    }
                    $t += $d;
                    $c += $s;
                    if $c & !mask != 0 {
                        $c &= mask;
                        block[$axis] += $s;
                        break;
                    }
                }};
            }
            loop {
                // Ties: as `walk` (z first, then y, then x).
                if tx < ty {
                    if tx < tz {
                        step!(lx, tx, dx, x, sx, 0);
                    } else {
                        flush!();
                        acc = 0;
                        step!(lz, tz, dz, z, sz, 2);
                    }
                } else if ty < tz {
                    step!(ly, ty, dy, y, sy, 1);
                } else {
                    flush!();
                    acc = 0;
                    step!(lz, tz, dz, z, sz, 2);
                }
                acc |= 1 << (x | y << 3);
            }
            // After a step out along z, `acc` is empty (written before the step).
            flush!();
            // (One word first: stores to the line are still in flight, and a wider
            // load of them would wait for them all.)
            if at != usize::MAX && m[0] == u64::MAX && all(m) {
                self.set_full(at);
            }
        }
    }

    /// Marks every cell of block `b` missed.
    #[cfg(test)]
    pub fn fill(&mut self, b: BlockKey) {
        let (v, at) = self.enter(b);
        *self.miss_mut((v & !FULL) as usize) = [u64::MAX; 8];
        if at != usize::MAX {
            self.set_full(at);
        }
    }

    /// Marks a cell hit.
    #[inline]
    pub fn hit(&mut self, c: [i64; 3]) {
        let s = self.slot(c.map(|x| x >> BLOCK_LOG2));
        if self.hit_at[s] == 0 {
            self.hits.push(NO_HITS);
            self.hit_at[s] = self.hits.len() as u32;
        }
        let h = &mut self.hits[self.hit_at[s] as usize - 1].0;
        h[(c[2] & 7) as usize] |= 1 << ((c[0] & 7) | (c[1] & 7) << 3);
    }
}
