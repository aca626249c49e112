//! Scan insertion: rays cast in parallel into per-thread hit/miss masks, merged,
//! sorted in tesseral order of blocks, and applied block by block.

use rayon::prelude::*;

use super::ray::{Masks, Scratch};
use super::sensor::Pose;
use super::store::BLOCK_LOG2;
use super::{OccupancyMap, ScanStats};
use crate::code::encode_wide;

/// Rays per rayon task.
const CHUNK: usize = 2048;

/// The tesseral code of a block key (its low 42 bits per axis, offset so that
/// negative keys sort below positive ones).
fn block_code(b: [i64; 3]) -> u128 {
    let m = (1u64 << 42) - 1;
    let u = b.map(|c| (c as u64 ^ (1 << 41)) & m);
    encode_wide(u[0], u[1], u[2])
}

impl OccupancyMap {
    /// Inserts a scan taken from `origin`: see the [module docs](super) for the
    /// semantics (OctoMap's `insertPointCloud`). `max_range` of `None`, negative or
    /// NaN means no limit.
    ///
    /// # Runtime
    /// O(c) for c cells crossed, cast in parallel; O(b log b) to sort the b blocks
    /// touched; each block touched is applied once, with whole 512-cell blocks skipped
    /// when they are clamped free and only missed.
    pub fn insert_scan(
        &mut self,
        origin: [f64; 3],
        points: &[[f64; 3]],
        max_range: Option<f64>,
    ) -> ScanStats {
        let mut stats = ScanStats {
            points: points.len() as u64,
            ..ScanStats::default()
        };
        if !origin.iter().all(|c| c.is_finite()) {
            stats.skipped = stats.points;
            return stats;
        }
        let max_range = max_range.filter(|r| *r >= 0.0);
        let res = self.resolution;
        let inv = 1.0 / res;
        let key = move |p: [f64; 3]| p.map(|c| (c * inv).floor() as i64);
        let key_origin = key(origin);
        let block_of_origin = key_origin.map(|c| c >> BLOCK_LOG2);
        let cast = |s: &mut Scratch, p: &[f64; 3]| {
            let d = [p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]];
            let norm = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            match max_range {
                Some(r) if norm > r => {
                    let end = [0, 1, 2].map(|i| origin[i] + d[i] / norm * r);
                    s.miss_ray(origin, end, key_origin, key(end), res);
                }
                _ => {
                    s.miss_ray(origin, *p, key_origin, key(*p), res);
                    s.hit(key(*p));
                }
            }
        };
        // Few chunks (one per thread alone, four per thread with more, for
        // balance): each has its own scratch, merged at the end.
        let threads = rayon::current_num_threads();
        let pieces = if threads == 1 { 1 } else { 4 * threads };
        let chunk = points.len().div_ceil(pieces).max(CHUNK);
        let (scratch, skipped) = points
            .par_chunks(chunk)
            .with_min_len(1)
            .fold(
                || (Scratch::new(block_of_origin), 0u64),
                |(mut s, mut skipped), chunk| {
                    for p in chunk {
                        if p.iter().all(|c| c.is_finite()) {
                            cast(&mut s, p);
                        } else {
                            skipped += 1;
                        }
                    }
                    (s, skipped)
                },
            )
            .reduce(
                || (Scratch::new(block_of_origin), 0),
                |(a, n), (b, m)| (a.merge(b), n + m),
            );
        stats.skipped = skipped;
        stats.rays = stats.points - skipped;
        // The blocks in tesseral order: their codes sorted beside their places.
        let mut order: Vec<(u128, u32)> = scratch
            .blocks
            .par_iter()
            .enumerate()
            .map(|(i, m)| (block_code(m.key), i as u32))
            .collect();
        order.par_sort_unstable();
        let (hits, misses) = self.apply(&scratch.blocks, &order);
        stats.hits = hits;
        stats.misses = misses;
        stats
    }

    /// [`insert_scan`](Self::insert_scan) with points in the sensor frame, moved by
    /// `pose`; the sensor sits at the pose's translation.
    pub fn insert_scan_posed(
        &mut self,
        pose: &Pose,
        points_in_sensor_frame: &[[f64; 3]],
        max_range: Option<f64>,
    ) -> ScanStats {
        let world: Vec<[f64; 3]> = points_in_sensor_frame
            .par_iter()
            .map(|p| pose.apply(*p))
            .collect();
        self.insert_scan(pose.translation, &world, max_range)
    }

    /// Applies the masks of a scan, block by block in the order given; returns the
    /// numbers of cells hit and missed.
    fn apply(&mut self, blocks: &[Masks], order: &[(u128, u32)]) -> (u64, u64) {
        let fixed = self.fixed;
        let (mut hits, mut misses) = (0u64, 0u64);
        self.store.reserve(blocks.len() / 4);
        for &(_, i) in order {
            let m = &blocks[i as usize];
            let miss: [u64; 8] = std::array::from_fn(|w| m.miss[w] & !m.hit[w]);
            hits += u64::from(m.hit.iter().map(|w| w.count_ones()).sum::<u32>());
            misses += u64::from(miss.iter().map(|w| w.count_ones()).sum::<u32>());
            self.store.update(m.key, &miss, &m.hit, fixed);
        }
        (hits, misses)
    }
}
