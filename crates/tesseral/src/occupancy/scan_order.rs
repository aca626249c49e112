//! The orders a scan is cast and applied in: its rays by direction (so that a
//! thread's rays cross the same blocks) and its blocks in tesseral order (so that
//! the map is walked in order, not one random path per block).

use rayon::prelude::*;

use super::store::BlockKey;
use crate::code::encode_wide;
use crate::linear::sort::sort_by_u64;

/// Direction cells per face side of the cube round the origin (a power of two).
const FACE_SIDE: u32 = 32;

/// The bits of a 5-bit number spread to the even places.
fn spread(x: u32) -> u32 {
    let x = (x | x << 4) & 0x0F0F;
    let x = (x | x << 2) & 0x3333;
    (x | x << 1) & 0x5555
}

/// The points `keep` takes (finite, within reach: `scan::castable`), copied in the
/// order of the direction of their ray (a cube map of 6 × 32 × 32 cells, each face in
/// Morton order), and the number of points it leaves out. Rays in one direction cell cross the same blocks, so their masks stay
/// in cache, and a thread's share of the rays is a few cones, not the whole scene.
/// The order changes no result: each ray only sets bits.
pub(super) fn by_direction(
    origin: [f64; 3],
    points: &[[f64; 3]],
    keep: impl Fn(&[f64; 3]) -> bool + Sync,
) -> (Vec<[f64; 3]>, u64) {
    const CELLS: usize = 6 * (FACE_SIDE * FACE_SIDE) as usize;
    const SKIP: u16 = CELLS as u16;
    let cell: Vec<u16> = points
        .par_iter()
        .with_min_len(4096)
        .map(|p| {
            if !keep(p) {
                return SKIP;
            }
            let d = [p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]];
            let m = d.map(f64::abs);
            let a = if m[0] >= m[1] && m[0] >= m[2] {
                0
            } else if m[1] >= m[2] {
                1
            } else {
                2
            };
            if m[a] == 0.0 {
                return 0;
            }
            let inv = 1.0 / m[a];
            let side = f64::from(FACE_SIDE);
            let q = |c: f64| ((c * inv + 1.0) * 0.5 * side).clamp(0.0, side - 1.0) as u32;
            let (u, v) = (q(d[(a + 1) % 3]), q(d[(a + 2) % 3]));
            let face = 2 * a as u32 + u32::from(d[a] < 0.0);
            (face * FACE_SIDE * FACE_SIDE + (spread(u) | spread(v) << 1)) as u16
        })
        .collect();
    let mut start = vec![0usize; CELLS + 3];
    for &c in &cell {
        start[c as usize + 2] += 1;
    }
    let skipped = start[CELLS + 2];
    for i in 2..start.len() {
        start[i] += start[i - 1];
    }
    let mut order = vec![[0.0; 3]; points.len() - skipped];
    for (i, &c) in cell.iter().enumerate() {
        if c != SKIP {
            let at = &mut start[c as usize + 1];
            order[*at] = points[i];
            *at += 1;
        }
    }
    (order, skipped as u64)
}

/// The tesseral code of a block key (its low 42 bits per axis, offset so that
/// negative keys sort below positive ones).
fn block_code(b: [i64; 3]) -> u128 {
    let m = (1u64 << 42) - 1;
    let u = b.map(|c| (c as u64 ^ (1 << 41)) & m);
    encode_wide(u[0], u[1], u[2])
}

/// A block of a scan: its scratch and its index there.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(super) struct Place {
    pub scratch: u32,
    pub index: u32,
}

/// Each block of the scratches with its tesseral code, in scratch order.
fn coded(blocks: &[&[BlockKey]]) -> Vec<(u128, Place)> {
    blocks
        .par_iter()
        .enumerate()
        .flat_map_iter(|(s, b)| {
            b.iter().enumerate().map(move |(i, k)| {
                let p = Place {
                    scratch: s as u32,
                    index: i as u32,
                };
                (block_code(*k), p)
            })
        })
        .collect()
}

/// The blocks of the scratches in tesseral order of their keys (a key in several
/// scratches: side by side, in scratch order).
///
/// The codes' high 64 bits take few values (a scene spans far fewer than 2^21
/// blocks per axis, and the sign offset splits it in at most eight parts): the blocks
/// are put in buckets by those bits and each bucket sorted on the low 64 bits, which
/// moves half the bytes of sorting the whole codes. Many high values (a scan over
/// thousands of kilometres): one sort of whole codes.
pub(super) fn tesseral_order(blocks: &[&[BlockKey]]) -> Vec<Place> {
    let codes = coded(blocks);
    let mut highs: Vec<u64> = Vec::new();
    let mut last = None;
    for &(c, _) in &codes {
        let h = (c >> 64) as u64;
        if last != Some(h) && !highs.contains(&h) {
            highs.push(h);
            if highs.len() > 64 {
                let mut codes = codes;
                codes.par_sort_unstable();
                return codes.into_iter().map(|(_, p)| p).collect();
            }
        }
        last = Some(h);
    }
    highs.sort_unstable();
    let mut buckets: Vec<Vec<(u64, Place)>> = vec![Vec::new(); highs.len()];
    let mut last = (u64::MAX, 0);
    for &(c, p) in &codes {
        let h = (c >> 64) as u64;
        if h != last.0 {
            last = (
                h,
                highs.binary_search(&h).unwrap_or_else(|_| unreachable!()),
            );
        }
        buckets[last.1].push((c as u64, p));
    }
    drop(codes);
    let mut out = Vec::new();
    for mut b in buckets {
        // Stable: a block in several scratches keeps their order. A bucket's codes
        // differ in their low bytes only (a scene a few hundred blocks wide: three or
        // four passes), so this moves each pair a few times where a comparison sort
        // moves it log₂ n times.
        sort_by_u64(&mut b, |p| p.0);
        out.extend(b.into_iter().map(|(_, p)| p));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    /// The bucketed order against one sort of whole codes: keys near the origin
    /// (both signs, few high parts) and keys over the whole range (the fallback), a
    /// key in several scratches among them.
    #[test]
    fn blocks_come_in_tesseral_order_duplicates_side_by_side() {
        let mut rng = Pcg64::seed_from_u64(5);
        for (round, span) in [40i64, 1 << 20, 1 << 41, 3, 12].into_iter().enumerate() {
            let scratches: Vec<Vec<BlockKey>> = (0..3)
                .map(|_| {
                    let mut seen = std::collections::HashSet::new();
                    (0..2000)
                        .map(|_| [0, 1, 2].map(|_| rng.random_range(-span..span)))
                        .filter(|k| seen.insert(*k))
                        .collect()
                })
                .collect();
            let blocks: Vec<&[BlockKey]> = scratches.iter().map(|s| &s[..]).collect();
            let got = tesseral_order(&blocks);
            let mut want = coded(&blocks);
            want.sort_unstable();
            let want: Vec<Place> = want.into_iter().map(|(_, p)| p).collect();
            assert_eq!(got, want, "round {round}");
        }
    }
}
