//! The 3-D DDA of Amanatides & Woo on cell keys, as OctoMap's `computeRayKeys`, and
//! the per-scan scratch of hit and miss masks per block.

use rustc_hash::FxHashMap;

use super::store::{BlockKey, BLOCK_LOG2};

/// One ray's walk: the cells OctoMap's `computeRayKeys(origin, end)` returns.
///
/// Nothing when both ends lie in one cell; otherwise the origin's cell, then each
/// cell entered, stopping before the end's cell (or once the walk has passed it
/// along an axis, which only float rounding can cause). Ties between axes go as
/// in OctoMap (x before z, y before z, y before x only when strictly smaller).
#[inline]
pub(crate) fn walk(
    origin: [f64; 3],
    end: [f64; 3],
    key_origin: [i64; 3],
    key_end: [i64; 3],
    res: f64,
    mut visit: impl FnMut([i64; 3]),
) {
    if key_origin == key_end {
        return;
    }
    visit(key_origin);
    let d = [end[0] - origin[0], end[1] - origin[1], end[2] - origin[2]];
    let length = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let dir = d.map(|c| c / length);
    let mut step = [0i64; 3];
    let mut t_max = [f64::MAX; 3];
    let mut t_delta = [f64::MAX; 3];
    for i in 0..3 {
        if dir[i] > 0.0 {
            step[i] = 1;
        } else if dir[i] < 0.0 {
            step[i] = -1;
        }
        if step[i] != 0 {
            // The cell's border in the ray's direction (OctoMap: centre ± res/2).
            // (OctoMap adds the half cell rounded to `f32`, which moves the border by
            // up to 1e-9 of a cell; we keep it exact.)
            let border = (key_origin[i] as f64 + 0.5) * res + step[i] as f64 * res * 0.5;
            t_max[i] = (border - origin[i]) / dir[i];
            t_delta[i] = res / dir[i].abs();
        }
    }
    let mut key = key_origin;
    loop {
        let dim = if t_max[0] < t_max[1] {
            if t_max[0] < t_max[2] {
                0
            } else {
                2
            }
        } else if t_max[1] < t_max[2] {
            1
        } else {
            2
        };
        key[dim] += step[dim];
        t_max[dim] += t_delta[dim];
        if key == key_end {
            return;
        }
        // Past the end cell along this axis: rounding led the walk beside it.
        // (OctoMap stops once the border distance exceeds the length, which can
        // drop the last cell before an end point lying exactly on a face; the
        // test on keys cannot.)
        if (key[dim] - key_end[dim]) * step[dim] > 0 {
            return;
        }
        visit(key);
    }
}

/// Hit and miss bits of one block: bit `x + 8y` of word `z`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Masks {
    pub key: BlockKey,
    pub miss: [u64; 8],
    pub hit: [u64; 8],
}

/// One thread's updates of a scan: blocks in a hash map, each with its masks. Each
/// cell is a bit, so updates are deduplicated as they are made, and the cells near
/// the origin that every ray crosses cost a bit set, not an update.
#[derive(Debug, Default)]
pub(crate) struct Scratch {
    index: FxHashMap<BlockKey, u32>,
    pub blocks: Vec<Masks>,
    last: Option<(BlockKey, u32)>,
}

impl Scratch {
    #[inline]
    fn slot(&mut self, b: BlockKey) -> usize {
        if let Some((k, i)) = self.last {
            if k == b {
                return i as usize;
            }
        }
        let n = self.blocks.len() as u32;
        let i = *self.index.entry(b).or_insert(n);
        if i == n {
            self.blocks.push(Masks {
                key: b,
                miss: [0; 8],
                hit: [0; 8],
            });
        }
        self.last = Some((b, i));
        i as usize
    }

    /// Marks a cell missed.
    #[inline]
    pub fn miss(&mut self, c: [i64; 3]) {
        let s = self.slot(c.map(|x| x >> BLOCK_LOG2));
        self.blocks[s].miss[(c[2] & 7) as usize] |= 1 << ((c[0] & 7) | (c[1] & 7) << 3);
    }

    /// Marks a cell hit.
    #[inline]
    pub fn hit(&mut self, c: [i64; 3]) {
        let s = self.slot(c.map(|x| x >> BLOCK_LOG2));
        self.blocks[s].hit[(c[2] & 7) as usize] |= 1 << ((c[0] & 7) | (c[1] & 7) << 3);
    }

    /// Adds another thread's updates.
    pub fn merge(mut self, other: Self) -> Self {
        if self.blocks.len() < other.blocks.len() {
            return other.merge(self);
        }
        for m in other.blocks {
            let s = self.slot(m.key);
            let t = &mut self.blocks[s];
            for w in 0..8 {
                t.miss[w] |= m.miss[w];
                t.hit[w] |= m.hit[w];
            }
        }
        self
    }
}
