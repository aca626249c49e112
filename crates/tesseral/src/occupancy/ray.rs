//! The 3-D DDA of Amanatides & Woo on cell keys, as OctoMap's `computeRayKeys`, and
//! the per-scan scratch of hit and miss masks per block.

use rustc_hash::FxHashMap;

use super::store::{BlockKey, BLOCK_LOG2};

/// The state of one ray's walk (Amanatides & Woo) after its first cell.
pub(crate) struct Dda {
    /// ±1 or 0 per axis.
    pub step: [i64; 3],
    /// The ray parameter at the next border along each axis.
    pub t_max: [f64; 3],
    /// The ray parameter between borders along each axis.
    pub t_delta: [f64; 3],
    /// Steps left along each axis before the end cell's plane.
    pub left_axis: [i64; 3],
    /// Steps left in all before the end cell.
    pub left: i64,
}

impl Dda {
    /// The walk from `origin` (in cell `key_origin`) to `end` (in `key_end`), or
    /// `None` when both lie in one cell: [`RayOrigin::dda`] for one ray.
    ///
    /// The steps left along an axis are never negative (the key of the end lies on
    /// the side `step` goes). The walk reaches the end cell when no step is left, and
    /// stops early when it would step past the end cell's plane along an axis, which
    /// only float rounding can cause. (OctoMap stops once the border distance exceeds
    /// the length, which can drop the last cell before an end point lying exactly on
    /// a face; the count on keys cannot.)
    #[cfg(test)]
    pub fn new(
        origin: [f64; 3],
        end: [f64; 3],
        key_origin: [i64; 3],
        key_end: [i64; 3],
        res: f64,
    ) -> Option<Self> {
        RayOrigin::new(origin, key_origin, res).dda_to(end, key_end)
    }
}

/// What the rays of a scan share: the origin, its cell, and the distance from the
/// origin to its cell's border on each side of each axis (OctoMap: centre ± res/2;
/// OctoMap adds the half cell rounded to `f32`, which moves the border by up to
/// 1e-9 of a cell; we keep it exact), so that a ray's set-up is its divisions alone.
#[derive(Debug, Clone, Copy)]
pub(crate) struct RayOrigin {
    origin: [f64; 3],
    key: [i64; 3],
    res: f64,
    /// Border minus origin per axis, stepping down (`[0]`) and up (`[1]`).
    to_border: [[f64; 2]; 3],
}

impl RayOrigin {
    /// The shared set-up of rays from `origin`, in cell `key`, at resolution `res`.
    pub fn new(origin: [f64; 3], key: [i64; 3], res: f64) -> Self {
        let to_border = [0, 1, 2].map(|i| {
            [-1.0, 1.0].map(|s: f64| (key[i] as f64 + 0.5) * res + s * res * 0.5 - origin[i])
        });
        Self {
            origin,
            key,
            res,
            to_border,
        }
    }

    /// The walk to `end`, in cell `key_end` ([`dda`](Self::dda) with the offset
    /// and length computed here).
    #[inline(always)]
    pub fn dda_to(&self, end: [f64; 3], key_end: [i64; 3]) -> Option<Dda> {
        let o = self.origin;
        let d = [end[0] - o[0], end[1] - o[1], end[2] - o[2]];
        self.dda(d, (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt(), key_end)
    }

    /// The walk along `d` (end minus origin) of length `length` (`|d|`, summed
    /// x, y, z), ending in cell `key_end`, or `None` when that is the origin's
    /// cell. The divisions do not depend on each other or on a branch, so that
    /// they overlap.
    #[inline(always)]
    pub fn dda(&self, d: [f64; 3], length: f64, key_end: [i64; 3]) -> Option<Dda> {
        if key_end == self.key {
            return None;
        }
        let dir = d.map(|c| c / length);
        // +1, −1, or 0 (also for NaN, from a length that underflowed).
        let step = dir.map(|c| i64::from(c > 0.0) - i64::from(c < 0.0));
        let t = [0, 1, 2].map(|i| self.to_border[i][usize::from(dir[i] > 0.0)] / dir[i]);
        let td = dir.map(|c| self.res / c.abs());
        let t_max = [0, 1, 2].map(|i| if step[i] != 0 { t[i] } else { f64::MAX });
        let t_delta = [0, 1, 2].map(|i| if step[i] != 0 { td[i] } else { f64::MAX });
        let left_axis = [0, 1, 2].map(|i| (key_end[i] - self.key[i]) * step[i]);
        Some(Dda {
            step,
            t_max,
            t_delta,
            left_axis,
            left: left_axis[0] + left_axis[1] + left_axis[2],
        })
    }
}

/// One ray's walk: the cells OctoMap's `computeRayKeys(origin, end)` returns.
///
/// Nothing when both ends lie in one cell; otherwise the origin's cell, then each
/// cell entered, stopping before the end's cell (or once the walk has passed it
/// along an axis, which only float rounding can cause). Ties between axes go as
/// in OctoMap (x before z, y before z, y before x only when strictly smaller).
/// This is the reference form; [`Scratch::miss_ray`] is the fast one.
#[cfg(test)]
pub(crate) fn walk(
    origin: [f64; 3],
    end: [f64; 3],
    key_origin: [i64; 3],
    key_end: [i64; 3],
    res: f64,
    mut visit: impl FnMut([i64; 3]),
) {
    let Some(mut w) = Dda::new(origin, end, key_origin, key_end, res) else {
        return;
    };
    visit(key_origin);
    let mut key = key_origin;
    loop {
        let dim = if w.t_max[0] < w.t_max[1] {
            if w.t_max[0] < w.t_max[2] {
                0
            } else {
                2
            }
        } else if w.t_max[1] < w.t_max[2] {
            1
        } else {
            2
        };
        if w.left_axis[dim] == 0 {
            return;
        }
        w.left_axis[dim] -= 1;
        w.left -= 1;
        if w.left == 0 {
            return;
        }
        key[dim] += w.step[dim];
        w.t_max[dim] += w.t_delta[dim];
        visit(key);
    }
}

/// Where a walk leaves its block: the axis it leaves along, the steps it takes along
/// each axis up to and including the step out, and the ray parameters then, exactly
/// as [`walk`]'s steps would leave them.
///
/// The walk is a merge of three sequences of border parameters, one per axis, each
/// summed step by step as the walk sums them (`t`, `t + d`, `t + d + d`, ...), in the
/// order (parameter, then z before y before x on ties). The step out of the block
/// along axis `i` comes `w_i` borders on (8 − x or x + 1); the first of these in the
/// merge order is the exit, and the steps along another axis are its borders that
/// precede the exit. At most 8 sums per axis, whatever the path inside.
#[inline]
pub(crate) fn exit_block(
    t: [f64; 3],
    d: [f64; 3],
    step: [i64; 3],
    c: [i64; 3],
) -> (usize, [i64; 3], [f64; 3]) {
    let mut w = [0i64; 3];
    let mut e = [f64::MAX; 3];
    for i in 0..3 {
        if step[i] != 0 {
            w[i] = if step[i] > 0 { 8 - c[i] } else { c[i] + 1 };
            let mut v = t[i];
            for _ in 1..w[i] {
                v += d[i];
            }
            e[i] = v;
        }
    }
    let a = if e[0] < e[1] {
        if e[0] < e[2] {
            0
        } else {
            2
        }
    } else if e[1] < e[2] {
        1
    } else {
        2
    };
    let mut n = [0i64; 3];
    let mut out = t;
    for j in 0..3 {
        if j == a {
            n[j] = w[j];
            out[j] = e[j] + d[j];
        } else if step[j] != 0 {
            while n[j] + 1 < w[j] && (out[j] < e[a] || (out[j] == e[a] && j > a)) {
                out[j] += d[j];
                n[j] += 1;
            }
        }
    }
    (a, n, out)
}

/// Blocks crossed by [`exit_block`] so far (tests check that the jump is taken).
#[cfg(test)]
pub(crate) static JUMPS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

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
    /// Blocks beyond the dense index, by their offset from `centre` packed in 21
    /// bits per axis.
    far: FxHashMap<u64, u32>,
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

/// No hits.
const NO_HITS: Bits = Bits([0; 8]);

impl Scratch {
    /// An empty scratch whose dense index is centred on block `centre`.
    pub fn new(centre: BlockKey) -> Self {
        Self {
            centre,
            near_lo: centre.map(|c| c - NEAR_SIDE / 2),
            near: vec![NO_SLOT; 1 << (3 * NEAR_SIDE_LOG2)],
            far: FxHashMap::default(),
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

    /// The hit bits of slot `s`.
    #[inline]
    pub fn hits(&self, s: usize) -> &[u64; 8] {
        match self.hit_at[s] {
            0 => &NO_HITS.0,
            h => &self.hits[h as usize - 1].0,
        }
    }

    /// The slot of block `b`, made (empty) when the scratch has none.
    #[inline]
    fn slot(&mut self, b: BlockKey) -> usize {
        (self.enter(b).0 & !FULL) as usize
    }

    /// The slot of block `b` (made when the scratch has none), with [`FULL`] set when
    /// the block is known to be all missed, and its place in the dense index
    /// (`usize::MAX` when beyond).
    #[inline(always)]
    fn enter(&mut self, b: BlockKey) -> (u32, usize) {
        let d = [0, 1, 2].map(|i| b[i].wrapping_sub(self.near_lo[i]));
        let n = self.keys.len() as u32;
        debug_assert!(n < FULL - 1, "a scratch holds fewer than 2^31 - 1 blocks");
        let (i, at) = if (d[0] | d[1] | d[2]) & !(NEAR_SIDE - 1) == 0 {
            let at = (d[0] | d[1] << NEAR_SIDE_LOG2 | d[2] << (2 * NEAR_SIDE_LOG2)) as usize;
            let i = &mut self.near[at];
            if *i == NO_SLOT {
                *i = n + 1;
            }
            (*i - 1, at)
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
                return *self.far.entry(p(x) | p(y) << 21 | p(z) << 42).or_insert(n);
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

    /// [`miss_ray`](Self::miss_ray) for the walk `w` from cell `key_origin`.
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
        loop {
            // (x, y, z) is the walk's cell, in `block`, not marked yet. A block of the
            // dense index is known full by its flag, set as a ray leaves it full (its
            // line is in cache then); one beyond is checked as it is entered.
            let (v, at) = self.enter(block);
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
                self.near[at] |= FULL;
            }
        }
    }

    /// Marks every cell of block `b` missed.
    #[cfg(test)]
    pub fn fill(&mut self, b: BlockKey) {
        let (v, at) = self.enter(b);
        *self.miss_mut((v & !FULL) as usize) = [u64::MAX; 8];
        if at != usize::MAX {
            self.near[at] |= FULL;
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
