//! Normals of a surface known only by its voxels (an octree file): estimated from the
//! occupancy of a small cube of voxels around the hit, gathered from the octree in one
//! descent ([`Brick::ball`]), so that the estimate follows the solid's surface and
//! not the staircase of its voxels. See `docs/shading.md` for the
//! estimators compared and the measured errors.

use super::index::Root;
use super::nodes::{Kid, NodeId, Nodes, Trace};

#[cfg(test)]
mod tests;

/// The largest half-side of a brick, in voxels.
pub(crate) const MAX_REACH: usize = 5;
const MAX_SIDE: usize = 2 * MAX_REACH + 1;

/// The occupancy of the cube of voxels `centre ± reach`: one row of bits per `(y, z)`,
/// bit `x` for the voxel at `x` from the cube's low corner.
#[derive(Debug, Clone)]
pub(crate) struct Brick {
    pub(super) reach: usize,
    rows: [u16; MAX_SIDE * MAX_SIDE],
}

impl Brick {
    /// The occupancy of the cube `centre ± reach` (`reach` at most [`MAX_REACH`]): one
    /// descent of the octree over the nodes that meet the cube; a black block fills
    /// its part of the cube row by row, whatever its size.
    ///
    /// # Runtime
    /// O(nodes meeting the cube), about the surface voxels inside it times a small
    /// factor, plus the depth.
    #[cfg(test)]
    pub(crate) fn around<T: Trace + ?Sized>(rt: &T, centre: [i64; 3], reach: usize) -> Brick {
        Self::gather(rt, centre, reach, i64::MAX)
    }

    /// As `Brick::around` (built for tests), but only the voxels within `reach + ½` of
    /// the centre are sure to be marked (the nodes that miss that ball are skipped):
    /// what [`Brick::ball_moment`] reads.
    pub(crate) fn ball<T: Trace + ?Sized>(rt: &T, centre: [i64; 3], reach: usize) -> Brick {
        let r = reach as i64;
        Self::gather(rt, centre, reach, r * r + r)
    }

    /// The voxels of the cube `centre ± reach` in the nodes with a voxel centre within
    /// `√room` of `centre` (`(r + ½)² = r² + r + ¼`: integers compare with `r² + r`).
    fn gather<T: Trace + ?Sized>(rt: &T, centre: [i64; 3], reach: usize, room: i64) -> Brick {
        assert!(reach <= MAX_REACH, "brick reach {reach} over {MAX_REACH}");
        let mut b = Brick {
            reach,
            rows: [0; MAX_SIDE * MAX_SIDE],
        };
        let r = reach as i64;
        let lo = centre.map(|c| c - r);
        let hi = centre.map(|c| c + r);
        let (depth, origin) = rt.space();
        match rt.root() {
            (Root::White, _) => {}
            (Root::Black, _) => b.paint(lo, hi, origin, 1i64 << depth),
            (Root::Gray, root) => {
                let at = Around {
                    lo,
                    hi,
                    centre,
                    room,
                };
                b.descend(&mut rt.cursor(), root, origin, depth, 0, &at);
            }
        }
        b
    }

    fn descend<N: Nodes>(
        &mut self,
        rt: &mut N,
        n: NodeId,
        min: [i64; 3],
        k: u8,
        path: u64,
        at: &Around,
    ) {
        let half = 1i64 << (k - 1);
        // Which halves of the node the cube meets, per axis: bit 0 low, bit 1 high.
        let mut halves = [0u8; 3];
        for a in 0..3 {
            let mid = min[a] + half;
            halves[a] = u8::from(at.lo[a] < mid) | (u8::from(at.hi[a] >= mid) << 1);
        }
        for label in 0..8u8 {
            if !rt.maybe(n, label) {
                continue;
            }
            let side = [label & 1, (label >> 1) & 1, (label >> 2) & 1];
            if (0..3).any(|a| halves[a] & (1 << side[a]) == 0) {
                continue;
            }
            let cmin = [0, 1, 2].map(|a| min[a] + half * i64::from(side[a]));
            // The squared distance from the centre to the child's nearest voxel.
            let far = (0..3)
                .map(|a| {
                    let d = (cmin[a] - at.centre[a])
                        .max(at.centre[a] - (cmin[a] + half - 1))
                        .max(0);
                    d * d
                })
                .sum::<i64>();
            if far > at.room {
                continue;
            }
            let cpath = (path << 3) | u64::from(label);
            match rt.kid(n, label, cpath, k - 1) {
                Kid::White => {}
                Kid::Black => self.paint(at.lo, at.hi, cmin, half),
                Kid::Gray(c) => self.descend(rt, c, cmin, k - 1, cpath, at),
            }
        }
    }

    /// Marks the voxels of the block `bmin + [0, size)³` that lie in the cube `lo..=hi`.
    fn paint(&mut self, lo: [i64; 3], hi: [i64; 3], bmin: [i64; 3], size: i64) {
        let a = [0, 1, 2].map(|i| bmin[i].max(lo[i]) - lo[i]);
        let b = [0, 1, 2].map(|i| (bmin[i] + size - 1).min(hi[i]) - lo[i]);
        if (0..3).any(|i| a[i] > b[i]) {
            return;
        }
        let side = 2 * self.reach + 1;
        let mask = ((1u32 << (b[0] - a[0] + 1)) - 1) << a[0];
        for z in a[2]..=b[2] {
            for y in a[1]..=b[1] {
                self.rows[y as usize + side * z as usize] |= mask as u16;
            }
        }
    }

    /// Whether the voxel at offset `u` from the centre is black.
    #[cfg(test)]
    pub(crate) fn get(&self, u: [i64; 3]) -> bool {
        let r = self.reach as i64;
        if u.iter().any(|c| c.abs() > r) {
            return false;
        }
        let side = 2 * self.reach + 1;
        let row = self.rows[(u[1] + r) as usize + side * (u[2] + r) as usize];
        (row >> (u[0] + r)) & 1 != 0
    }

    /// Minus the first moment of the black voxels within the ball of radius
    /// `reach + ½` around the centre: each row of the ball is masked to the ball's
    /// chord, and its count and sum of offsets read from [`ROW_SUMS`].
    pub(crate) fn ball_moment(&self) -> [i64; 3] {
        let r = self.reach as i64;
        let side = 2 * self.reach + 1;
        let chords = &CHORDS[self.reach];
        let mut g = [0i64; 3];
        for z in -r..=r {
            for y in -r..=r {
                let m = chords[y.unsigned_abs() as usize][z.unsigned_abs() as usize];
                if m < 0 {
                    continue;
                }
                let row = self.rows[(y + r) as usize + side * (z + r) as usize];
                // Bits r − m ..= r + m: the chord of the ball on this row.
                let mask = ((1u32 << (2 * m + 1)) - 1) << (r - i64::from(m));
                let (count, sum) = ROW_SUMS[(u32::from(row) & mask) as usize];
                let count = i64::from(count);
                g[0] += i64::from(sum) - r * count;
                g[1] += y * count;
                g[2] += z * count;
            }
        }
        g.map(|c| -c)
    }
}

/// The region a brick gathers: the cube `lo..=hi` around `centre`, and the squared
/// distance from the centre within which nodes are visited.
struct Around {
    lo: [i64; 3],
    hi: [i64; 3],
    centre: [i64; 3],
    room: i64,
}

/// For each row pattern of [`MAX_SIDE`] bits: how many bits are set, and the sum of
/// their indices.
const ROW_SUMS: [(u8, u8); 1 << MAX_SIDE] = {
    let mut t = [(0u8, 0u8); 1 << MAX_SIDE];
    let mut row = 0;
    while row < t.len() {
        let (mut count, mut sum, mut i) = (0u8, 0u8, 0);
        while i < MAX_SIDE {
            if (row >> i) & 1 != 0 {
                count += 1;
                sum += i as u8;
            }
            i += 1;
        }
        t[row] = (count, sum);
        row += 1;
    }
    t
};

/// For each reach and `|y|`, `|z|` up to it: the largest `|x|` with
/// `x² + y² + z² ≤ (reach + ½)²`, or −1 when the row misses the ball.
const CHORDS: [[[i8; MAX_REACH + 1]; MAX_REACH + 1]; MAX_REACH + 1] = {
    let mut t = [[[-1i8; MAX_REACH + 1]; MAX_REACH + 1]; MAX_REACH + 1];
    let mut r = 0;
    while r <= MAX_REACH {
        let mut y = 0;
        while y <= r {
            let mut z = 0;
            while z <= r {
                // (r + ½)² = r² + r + ¼, and squares of integers are integers.
                let room = (r * r + r) as i64 - (y * y + z * z) as i64;
                let mut x = -1i64;
                while x < r as i64 && (x + 1) * (x + 1) <= room {
                    x += 1;
                }
                t[r][y][z] = x as i8;
                z += 1;
            }
            y += 1;
        }
        r += 1;
    }
    t
};

/// The half-side of the cube of voxels the renderer's normals look at: a ball of
/// radius 4.5 voxels (see the module documentation for the choice).
pub(crate) const REACH: usize = 4;

/// The outward unit normal of the surface at the black voxel `v`, seen through the
/// face with outward normal `face`: minus the first moment of the black voxels within
/// [`REACH`] + ½ of `v`. Where that moment vanishes (a lone voxel, a thin sheet) or
/// points behind the face seen, the face's own normal.
#[must_use]
pub(crate) fn surface_normal<T: Trace + ?Sized>(rt: &T, v: [i64; 3], face: [f64; 3]) -> [f64; 3] {
    let g = Brick::ball(rt, v, REACH).ball_moment().map(|c| c as f64);
    let len = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
    let facing = g[0] * face[0] + g[1] * face[1] + g[2] * face[2];
    if len == 0.0 || facing <= 0.0 {
        return face;
    }
    g.map(|c| c / len)
}

/// Normals already estimated, by voxel and face: neighbouring pixels mostly see the
/// same voxel. Direct-mapped; one per tile of the image.
pub(crate) struct NormalCache {
    keys: Vec<([i64; 3], u8)>,
    normals: Vec<[f64; 3]>,
}

const CACHE_SLOTS: usize = 256;

impl NormalCache {
    pub(crate) fn new() -> Self {
        Self {
            keys: vec![([i64::MIN; 3], 0); CACHE_SLOTS],
            normals: vec![[0.0; 3]; CACHE_SLOTS],
        }
    }

    /// [`surface_normal`], looked up first.
    pub(crate) fn normal<T: Trace + ?Sized>(
        &mut self,
        rt: &T,
        v: [i64; 3],
        face: [f64; 3],
    ) -> [f64; 3] {
        let f = face
            .iter()
            .enumerate()
            .map(|(a, &c)| {
                if c > 0.0 {
                    2 * a as u8 + 1
                } else if c < 0.0 {
                    2 * a as u8 + 2
                } else {
                    0
                }
            })
            .sum::<u8>();
        let h = (v[0].wrapping_mul(0x9E37_79B9)
            ^ v[1].wrapping_mul(0x85EB_CA6B)
            ^ v[2].wrapping_mul(0xC2B2_AE35)) as usize;
        let slot = (h ^ h >> 11) % CACHE_SLOTS;
        if self.keys[slot] != (v, f) {
            self.keys[slot] = (v, f);
            self.normals[slot] = surface_normal(rt, v, face);
        }
        self.normals[slot]
    }
}
