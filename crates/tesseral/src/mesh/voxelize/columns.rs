//! Inside/outside by ray parity: each triangle's crossings of the voxel columns,
//! sorted per column, and the bounds on their number checked before the work.

use rayon::prelude::*;

use super::{Tri, HALF, ONE};

/// `orient2d(a, b, p)` in xy, with the symbolic-perturbation sign for exact zeros.
#[inline]
pub(super) fn edge_sign(a: [i64; 3], b: [i64; 3], px: i64, py: i64) -> (i128, bool) {
    let (bx, by) = (i128::from(b[0] - a[0]), i128::from(b[1] - a[1]));
    let w = bx * i128::from(py - a[1]) - by * i128::from(px - a[0]);
    let positive = if w != 0 {
        w > 0
    } else if by != 0 {
        by < 0
    } else {
        bx > 0
    };
    (w, positive)
}

/// Per-column sorted flip indices: voxel z of column (x, y) is inside when the number
/// of flips ≤ z is odd.
#[derive(Default)]
pub(super) struct Columns {
    /// Sorted ids of the columns with crossings (sparse form), or empty when
    /// `starts` is indexed by column id directly (dense form).
    cols: Vec<u32>,
    starts: Vec<u32>,
    flips: Vec<u32>,
    side: i64,
    dense: bool,
}

/// Columns up to this many are indexed densely (4 bytes each), beyond it by binary
/// search.
const DENSE_COLUMNS: i64 = 1 << 24;

impl Columns {
    pub(super) fn new(tris: &[Tri], depth: u8, max_crossings: usize) -> Result<Self, String> {
        let side = 1i64 << depth;
        let parts: Vec<Vec<u64>> = tris
            .par_chunks(4096)
            .map(|chunk| {
                let mut out = Vec::new();
                for t in chunk {
                    rasterize(t, side, &mut out);
                    if out.len() > max_crossings {
                        break;
                    }
                }
                out
            })
            .collect();
        let total: usize = parts.iter().map(Vec::len).sum();
        if total > max_crossings {
            return Err(format!(
                "more than {max_crossings} ray crossings at depth {depth}"
            ));
        }
        let mut entries: Vec<u64> = Vec::with_capacity(total);
        for p in parts {
            entries.extend(p);
        }
        entries.par_sort_unstable();
        let mut c = Columns {
            side,
            dense: side * side <= DENSE_COLUMNS,
            ..Columns::default()
        };
        if c.dense {
            let n = (side * side) as usize;
            c.starts = vec![0u32; n + 1];
            for e in &entries {
                c.starts[(e >> 32) as usize + 1] += 1;
            }
            for i in 0..n {
                c.starts[i + 1] += c.starts[i];
            }
            c.flips = entries.iter().map(|&e| e as u32).collect();
            return Ok(c);
        }
        for e in entries {
            let col = (e >> 32) as u32;
            if c.cols.last() != Some(&col) {
                c.cols.push(col);
                c.starts.push(c.flips.len() as u32);
            }
            c.flips.push(e as u32);
        }
        c.starts.push(c.flips.len() as u32);
        Ok(c)
    }

    #[inline]
    pub(super) fn column(&self, x: i64, y: i64) -> &[u32] {
        let col = (x + y * self.side) as u32;
        if self.dense {
            let i = col as usize;
            return &self.flips[self.starts[i] as usize..self.starts[i + 1] as usize];
        }
        match self.cols.binary_search(&col) {
            Ok(i) => &self.flips[self.starts[i] as usize..self.starts[i + 1] as usize],
            Err(_) => &[],
        }
    }

    pub(super) fn inside(&self, v: [i64; 3]) -> bool {
        let f = self.column(v[0], v[1]);
        f.partition_point(|&z| i64::from(z) <= v[2]) % 2 == 1
    }

    /// `Some(inside)` when the whole cell has one state, by scanning its columns.
    pub(super) fn uniform(&self, rel: [i64; 3], k: u8) -> Option<bool> {
        let s = 1i64 << k;
        let first = self.inside(rel);
        for y in rel[1]..rel[1] + s {
            for x in rel[0]..rel[0] + s {
                let f = self.column(x, y);
                let i = f.partition_point(|&z| i64::from(z) <= rel[2]);
                if (i % 2 == 1) != first {
                    return None;
                }
                if i < f.len() && i64::from(f[i]) < rel[2] + s {
                    return None;
                }
            }
        }
        Some(first)
    }
}

/// An upper bound on the ray crossings of a solid voxelization: per triangle, the
/// column centres its projection can hold, at most those of its bounding box and at
/// most `A + P/2 + 1` (Nosarzewska's bound on the lattice points of a convex region
/// of area A and perimeter P). O(triangles).
#[must_use]
pub(super) fn crossing_bound(tris: &[Tri]) -> u64 {
    let one = ONE as f64;
    tris.iter()
        .map(|t| {
            let p = t.map(|v| [v[0] as f64 / one, v[1] as f64 / one]);
            let area = ((p[1][0] - p[0][0]) * (p[2][1] - p[0][1])
                - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]))
                .abs()
                / 2.0;
            if area == 0.0 {
                return 0;
            }
            let len = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
            let perimeter = len(p[0], p[1]) + len(p[1], p[2]) + len(p[2], p[0]);
            let span = |a: usize| {
                let lo = p.iter().map(|q| q[a]).fold(f64::INFINITY, f64::min);
                let hi = p.iter().map(|q| q[a]).fold(f64::NEG_INFINITY, f64::max);
                (hi - lo).floor() + 2.0
            };
            let convex = area + perimeter / 2.0 + 1.0;
            (span(0) * span(1)).min(convex).ceil() as u64
        })
        .sum()
}

/// The total area of the triangles in voxel units. O(triangles).
pub(super) fn surface_area(tris: &[Tri]) -> f64 {
    let one = ONE as f64;
    tris.iter()
        .map(|t| {
            let p = t.map(|v| v.map(|c| c as f64 / one));
            let u = [0, 1, 2].map(|a| p[1][a] - p[0][a]);
            let w = [0, 1, 2].map(|a| p[2][a] - p[0][a]);
            let c = [
                u[1] * w[2] - u[2] * w[1],
                u[2] * w[0] - u[0] * w[2],
                u[0] * w[1] - u[1] * w[0],
            ];
            (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt() / 2.0
        })
        .sum()
}

/// Appends `(column << 32) | flip` for every column centre that `t`'s xy-projection
/// covers.
pub(super) fn rasterize(t: &Tri, side: i64, out: &mut Vec<u64>) {
    let [a, mut b, mut c] = *t;
    let (w, _) = edge_sign(a, b, c[0], c[1]);
    if w == 0 {
        return; // vertical in projection: no column crosses it
    }
    if w < 0 {
        std::mem::swap(&mut b, &mut c);
    }
    let minx = a[0].min(b[0]).min(c[0]);
    let maxx = a[0].max(b[0]).max(c[0]);
    let miny = a[1].min(b[1]).min(c[1]);
    let maxy = a[1].max(b[1]).max(c[1]);
    // Columns whose centre i·ONE + HALF lies in [min, max].
    let i0 = ((minx - HALF).div_euclid(ONE) + 1).max(0);
    let i1 = (maxx - HALF).div_euclid(ONE).min(side - 1);
    let j0 = ((miny - HALF).div_euclid(ONE) + 1).max(0);
    let j1 = (maxy - HALF).div_euclid(ONE).min(side - 1);
    // Include centres exactly on the bounding box (the perturbation decides).
    let i0 = if (i0 - 1) * ONE + HALF == minx && i0 > 0 {
        i0 - 1
    } else {
        i0
    };
    let j0 = if (j0 - 1) * ONE + HALF == miny && j0 > 0 {
        j0 - 1
    } else {
        j0
    };
    for j in j0..=j1 {
        let py = j * ONE + HALF;
        for i in i0..=i1 {
            let px = i * ONE + HALF;
            let (wa, ia) = edge_sign(b, c, px, py);
            if !ia {
                continue;
            }
            let (wb, ib) = edge_sign(c, a, px, py);
            if !ib {
                continue;
            }
            let (wc, ic) = edge_sign(a, b, px, py);
            if !ic {
                continue;
            }
            let den = wa + wb + wc;
            let num = wa * i128::from(a[2]) + wb * i128::from(b[2]) + wc * i128::from(c[2]);
            let flip = (num - i128::from(HALF) * den).div_euclid(i128::from(ONE) * den) + 1;
            let flip = flip.clamp(0, i128::from(side)) as u64;
            out.push(((i + j * side) as u64) << 32 | flip);
        }
    }
}
