//! Surface cells: a uniform grid of triangle bins with a summed-volume table, and the
//! exact triangle/box overlap test.

use super::{Tri, MAX_BIN_ENTRIES, ONE};

/// A uniform grid of triangle references with a summed-volume table of counts.
pub(super) struct Bins {
    shift: u32,
    n: usize,
    starts: Vec<u32>,
    items: Vec<u32>,
    sum: Vec<u32>,
}

impl Bins {
    fn range(t: &Tri, side: i64, shift: u32) -> [[usize; 2]; 3] {
        [0, 1, 2].map(|a| {
            let lo = t.iter().map(|p| p[a]).min().unwrap_or(0) - 1;
            let hi = t.iter().map(|p| p[a]).max().unwrap_or(0) + 1;
            let v0 = lo.div_euclid(ONE).clamp(0, side - 1);
            let v1 = hi.div_euclid(ONE).clamp(0, side - 1);
            [(v0 >> shift) as usize, (v1 >> shift) as usize]
        })
    }

    pub(super) fn new(tris: &[Tri], depth: u8) -> Self {
        let side = 1i64 << depth;
        let mut shift = u32::from(depth.saturating_sub(7));
        loop {
            let total: u64 = tris
                .iter()
                .map(|t| {
                    let r = Self::range(t, side, shift);
                    r.iter().map(|[a, b]| (b - a + 1) as u64).product::<u64>()
                })
                .sum();
            if total <= MAX_BIN_ENTRIES || shift >= u32::from(depth) {
                break;
            }
            shift += 1;
        }
        let n = (side >> shift) as usize;
        let idx = |x: usize, y: usize, z: usize| (z * n + y) * n + x;
        let mut counts = vec![0u32; n * n * n + 1];
        for t in tris {
            let r = Self::range(t, side, shift);
            for z in r[2][0]..=r[2][1] {
                for y in r[1][0]..=r[1][1] {
                    for x in r[0][0]..=r[0][1] {
                        counts[idx(x, y, z)] += 1;
                    }
                }
            }
        }
        // Summed-volume table over (n+1)^3.
        let m = n + 1;
        let sidx = |x: usize, y: usize, z: usize| (z * m + y) * m + x;
        let mut sum = vec![0u32; m * m * m];
        for z in 0..n {
            for y in 0..n {
                for x in 0..n {
                    let c = counts[idx(x, y, z)].min(1);
                    sum[sidx(x + 1, y + 1, z + 1)] = c
                        .wrapping_add(sum[sidx(x, y + 1, z + 1)])
                        .wrapping_add(sum[sidx(x + 1, y, z + 1)])
                        .wrapping_add(sum[sidx(x + 1, y + 1, z)])
                        .wrapping_sub(sum[sidx(x, y, z + 1)])
                        .wrapping_sub(sum[sidx(x, y + 1, z)])
                        .wrapping_sub(sum[sidx(x + 1, y, z)])
                        .wrapping_add(sum[sidx(x, y, z)]);
                }
            }
        }
        let mut starts = vec![0u32; n * n * n + 1];
        let mut acc = 0u32;
        for (i, c) in counts.iter().enumerate().take(n * n * n) {
            starts[i] = acc;
            acc += c;
        }
        starts[n * n * n] = acc;
        let mut fill = starts.clone();
        let mut items = vec![0u32; acc as usize];
        for (ti, t) in tris.iter().enumerate() {
            let r = Self::range(t, side, shift);
            for z in r[2][0]..=r[2][1] {
                for y in r[1][0]..=r[1][1] {
                    for x in r[0][0]..=r[0][1] {
                        let b = idx(x, y, z);
                        items[fill[b] as usize] = ti as u32;
                        fill[b] += 1;
                    }
                }
            }
        }
        Bins {
            shift,
            n,
            starts,
            items,
            sum,
        }
    }

    /// The bin ranges covering voxels `[lo, hi]` (inclusive), and whether any holds a
    /// triangle.
    pub(super) fn query(&self, lo: [i64; 3], hi: [i64; 3]) -> Option<[[usize; 2]; 3]> {
        let r = [0, 1, 2].map(|a| {
            [
                (lo[a] >> self.shift) as usize,
                (hi[a] >> self.shift) as usize,
            ]
        });
        let m = self.n + 1;
        let s = |x: usize, y: usize, z: usize| self.sum[(z * m + y) * m + x];
        let (x0, x1, y0, y1, z0, z1) = (
            r[0][0],
            r[0][1] + 1,
            r[1][0],
            r[1][1] + 1,
            r[2][0],
            r[2][1] + 1,
        );
        let total = s(x1, y1, z1)
            .wrapping_sub(s(x0, y1, z1))
            .wrapping_sub(s(x1, y0, z1))
            .wrapping_sub(s(x1, y1, z0))
            .wrapping_add(s(x0, y0, z1))
            .wrapping_add(s(x0, y1, z0))
            .wrapping_add(s(x1, y0, z0))
            .wrapping_sub(s(x0, y0, z0));
        (total > 0).then_some(r)
    }

    pub(super) fn any(&self, r: [[usize; 2]; 3], mut hit: impl FnMut(u32) -> bool) -> bool {
        let n = self.n;
        for z in r[2][0]..=r[2][1] {
            for y in r[1][0]..=r[1][1] {
                for x in r[0][0]..=r[0][1] {
                    let b = (z * n + y) * n + x;
                    let items = &self.items[self.starts[b] as usize..self.starts[b + 1] as usize];
                    if items.iter().any(|&t| hit(t)) {
                        return true;
                    }
                }
            }
        }
        false
    }
}

/// Exact triangle/box overlap (closed box `[lo, hi]`), by the separating-axis theorem
/// (Akenine-Möller 2001), on integers doubled so the box centre is integral.
pub(super) fn tri_box_overlap(lo: [i64; 3], hi: [i64; 3], t: &Tri) -> bool {
    // Cheap rejection on the bounding boxes first, in i64.
    for a in 0..3 {
        if t[0][a].min(t[1][a]).min(t[2][a]) > hi[a] || t[0][a].max(t[1][a]).max(t[2][a]) < lo[a] {
            return false;
        }
    }
    let c: [i128; 3] = [0, 1, 2].map(|a| i128::from(lo[a]) + i128::from(hi[a]));
    let e: [i128; 3] = [0, 1, 2].map(|a| i128::from(hi[a]) - i128::from(lo[a]));
    let v: [[i128; 3]; 3] = t.map(|p| [0, 1, 2].map(|a| 2 * i128::from(p[a]) - c[a]));
    for a in 0..3 {
        let mn = v[0][a].min(v[1][a]).min(v[2][a]);
        let mx = v[0][a].max(v[1][a]).max(v[2][a]);
        if mn > e[a] || mx < -e[a] {
            return false;
        }
    }
    let sub = |p: [i128; 3], q: [i128; 3]| [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
    let dot = |p: [i128; 3], q: [i128; 3]| p[0] * q[0] + p[1] * q[1] + p[2] * q[2];
    let f = [sub(v[1], v[0]), sub(v[2], v[1]), sub(v[0], v[2])];
    let radius = |ax: [i128; 3]| e[0] * ax[0].abs() + e[1] * ax[1].abs() + e[2] * ax[2].abs();
    for fj in f {
        for ax in [[0, -fj[2], fj[1]], [fj[2], 0, -fj[0]], [-fj[1], fj[0], 0]] {
            let p = v.map(|vi| dot(ax, vi));
            let r = radius(ax);
            if p[0].min(p[1]).min(p[2]) > r || p[0].max(p[1]).max(p[2]) < -r {
                return false;
            }
        }
    }
    let n = [
        f[0][1] * f[1][2] - f[0][2] * f[1][1],
        f[0][2] * f[1][0] - f[0][0] * f[1][2],
        f[0][0] * f[1][1] - f[0][1] * f[1][0],
    ];
    dot(n, v[0]).abs() <= radius(n)
}
