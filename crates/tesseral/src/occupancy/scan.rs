//! Scan insertion: rays cast in parallel into per-thread hit/miss masks, sorted in
//! tesseral order of blocks, and applied block by block (a block's masks from several
//! threads merged there).

use rayon::prelude::*;

use std::sync::{Arc, Mutex, PoisonError};

use super::dda::RayOrigin;
use super::ray::{near_cube, Scratch};
use super::scan_order::{by_direction, tesseral_order, Place};
use super::sensor::Pose;
use super::store::{cube_index, BlockKey, BLOCK_LOG2};
use super::{prefetch, OccupancyMap, ScanStats};

/// Rays per rayon task.
const CHUNK: usize = 2048;

/// `floor(v)` as an integer, saturating as `v.floor() as i64` does (without a call
/// to the C library's `floor`, which the baseline x86-64 target makes).
#[inline]
fn floor(v: f64) -> i64 {
    let t = v as i64;
    if (t as f64) > v {
        t.saturating_sub(1)
    } else {
        t
    }
}

/// A scan cast but not applied yet: its threads' scratches, their blocks in tesseral
/// order, and its counts so far.
pub(super) struct Cast {
    scratches: Vec<Scratch>,
    order: Vec<Place>,
    stats: ScanStats,
}

impl Cast {
    /// The blocks the scan's rays marked (a block in several scratches once each).
    #[cfg(test)]
    pub fn blocks(&self) -> usize {
        self.order.len()
    }
}

/// The cell holding `p`, `inv` being 1 / resolution (as `OccupancyMap::cell_of`).
#[inline]
fn key_at(inv: f64, p: [f64; 3]) -> [i64; 3] {
    p.map(|c| floor(c * inv))
}

/// The farthest cell from 0 on an axis that a ray may reach, ±2^61: far past any
/// sensor (10^17 m at 5 cm), with room for the walk's differences of keys in `i64`.
const REACH: f64 = (1u64 << 61) as f64;

/// Whether `p`'s cell lies within [`REACH`] on every axis (`inv` = 1 / resolution);
/// false for a coordinate NaN or infinite.
#[inline]
pub(super) fn within_reach(inv: f64, p: [f64; 3]) -> bool {
    p.iter().all(|&c| (c * inv).abs() < REACH)
}

/// `|d|`, without overflow for offsets past 10^154 (where the squares would).
#[inline]
pub(super) fn length(d: [f64; 3]) -> f64 {
    let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    if n.is_finite() {
        return n;
    }
    let m = d.iter().fold(0f64, |m, c| m.max(c.abs()));
    let u = d.map(|c| c / m);
    m * (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt()
}

/// Whether the ray from `origin` (within reach) to `p` is cast: `p`'s coordinates
/// finite, and the ray's end (`p`, or where `max_range` cuts the ray) within
/// [`REACH`]. Other points are skipped and counted.
#[inline]
pub(super) fn castable(inv: f64, origin: [f64; 3], p: &[f64; 3], max_range: Option<f64>) -> bool {
    if !p.iter().all(|c| c.is_finite()) {
        return false;
    }
    if within_reach(inv, *p) {
        return true;
    }
    let Some(r) = max_range else {
        return false;
    };
    let d = [0, 1, 2].map(|i| p[i] - origin[i]);
    let n = length(d);
    n > r && within_reach(inv, [0, 1, 2].map(|i| origin[i] + d[i] / n * r))
}

/// Casts a scan's rays at resolution `res` into per-thread scratches and puts their
/// blocks in tesseral order. Reads nothing of the map, so that the next scan can be
/// cast while this one is applied ([`OccupancyMap::insert_scans`]); given the blocks
/// round the origin that the map holds clamped free
/// ([`OccupancyMap::clamped_near`]), rays cross those without marking their cells.
/// `alone`: no scan is applied while this one is cast (the threads are all its own).
pub(super) fn cast_scan(
    res: f64,
    origin: [f64; 3],
    points: &[[f64; 3]],
    max_range: Option<f64>,
    clamped: Option<Arc<[u64]>>,
    alone: bool,
) -> Cast {
    let mut stats = ScanStats {
        points: points.len() as u64,
        ..ScanStats::default()
    };
    let inv = 1.0 / res;
    if !within_reach(inv, origin) {
        stats.skipped = stats.points;
        return Cast {
            scratches: Vec::new(),
            order: Vec::new(),
            stats,
        };
    }
    let max_range = max_range.filter(|r| *r >= 0.0);
    let key = move |p: [f64; 3]| key_at(inv, p);
    let key_origin = key(origin);
    let block_of_origin = key_origin.map(|c| c >> BLOCK_LOG2);
    let rays = RayOrigin::new(origin, key_origin, res);
    let cast = |s: &mut Scratch, p: &[f64; 3]| {
        let d = [p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]];
        let norm = length(d);
        match max_range {
            Some(r) if norm > r => {
                let end = [0, 1, 2].map(|i| origin[i] + d[i] / norm * r);
                if let Some(w) = rays.dda_to(end, key(end)) {
                    s.miss_walk(&w, key_origin);
                }
            }
            _ => {
                // The walk's offset and length are those just computed.
                let k = key(*p);
                if let Some(w) = rays.dda(d, norm, k) {
                    s.miss_walk(&w, key_origin);
                }
                s.hit(k);
            }
        }
    };
    let (order, skipped) = by_direction(origin, points, |p| castable(inv, origin, p, max_range));
    // Chunks of the rays in direction order, each with its own scratch: one for a
    // thread alone. With more threads, several per thread for balance (a chunk of
    // rays to far surfaces costs more than one to near ones): 16 per thread for a
    // scan cast `alone`, 4 beside the apply of the scan before it (each scratch
    // adds merging to the apply, which is serial). On one scan of 88,206 rays
    // (OctoMap's `scan.dat`) on two cores, 16 rather than 4 took the insertion from
    // a median of 35 ms to 32.5 (six runs each); beside an apply (ten street
    // scans), 16 took 1.10 s against 1.05-1.09 (docs/mapping-history.md,
    // "Nineteenth pass").
    let threads = rayon::current_num_threads();
    let pieces = match (threads, alone) {
        (1, _) => 1,
        (_, true) => 16 * threads,
        (_, false) => 4 * threads,
    };
    let chunk = order.len().div_ceil(pieces).max(CHUNK);
    let new = || Scratch::new(block_of_origin, clamped.clone());
    // A scan cast alone: one scratch a thread, whichever chunks it takes. `fold`
    // makes one for each piece of work a thread steals (16 or 17 on two threads),
    // and each fills the blocks near the sensor again and adds to the merge. On
    // OctoMap's one scan on two cores: 34-35 ms against 38-43 (eight runs each,
    // the binaries before and after alternated, on an Intel Xeon VM). Beside an
    // apply a chunk's scratch keeps to one cone of directions, which the street's
    // scans needed: one scratch a thread for every scan took the street's ten
    // 1.22-1.24 s against 1.15-1.21.
    let scratches: Vec<Scratch> = if alone && threads > 1 {
        cast_per_thread(&order, chunk, threads, new, cast)
    } else {
        order
            .par_chunks(chunk)
            .with_min_len(1)
            .fold(new, |mut s, chunk| {
                for p in chunk {
                    cast(&mut s, p);
                }
                s
            })
            .collect()
    };
    stats.skipped = skipped;
    stats.rays = stats.points - skipped;
    // The blocks of all scratches in tesseral order (a block in several scratches
    // comes once per scratch, side by side: merged as it is applied).
    let keys: Vec<&[BlockKey]> = scratches.iter().map(Scratch::keys).collect();
    let order = tesseral_order(&keys);
    Cast {
        scratches,
        order,
        stats,
    }
}

/// Casts `rays` in chunks of `chunk` over the pool's `threads`, each thread into one
/// scratch of its own, made by `new` when it takes its first chunk. The map made
/// from the scratches does not depend on which thread cast which chunk: a block's
/// masks in several scratches are merged as they are applied.
fn cast_per_thread(
    rays: &[[f64; 3]],
    chunk: usize,
    threads: usize,
    new: impl Fn() -> Scratch + Sync,
    cast: impl Fn(&mut Scratch, &[f64; 3]) + Sync,
) -> Vec<Scratch> {
    let slots: Vec<Mutex<Option<Scratch>>> = (0..threads).map(|_| Mutex::new(None)).collect();
    rays.par_chunks(chunk).with_min_len(1).for_each(|rays| {
        // Each thread locks only its own slot, so the lock is never contended (a
        // thread outside the pool, which has no index, shares slot 0).
        let t = rayon::current_thread_index().unwrap_or(0) % threads;
        let mut slot = slots[t].lock().unwrap_or_else(PoisonError::into_inner);
        let s = slot.get_or_insert_with(&new);
        for p in rays {
            cast(s, p);
        }
    });
    slots
        .into_iter()
        .filter_map(|m| m.into_inner().unwrap_or_else(PoisonError::into_inner))
        .collect()
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
        let clamped = self.clamped_near(origin, None);
        let cast = cast_scan(self.resolution, origin, points, max_range, clamped, true);
        let stats = self.apply_cast(cast);
        self.store.settle();
        stats
    }

    /// Inserts scans in the order given, each from its origin, and gives each one's
    /// counts: the map's cells and the counts are those of a loop of
    /// [`insert_scan`](Self::insert_scan). Faster with several threads: a scan's
    /// rays are cast while the scan before it is applied to the map (applying is
    /// serial; casting reads nothing of the map), so that no thread waits while
    /// one writes blocks. After the last scan the map's storage is tidied, once
    /// for the whole call: the blocks the scans left as wide palettes are made
    /// patched palettes where that is smaller, and an arena in which more than an
    /// eighth of the bytes hold no block is compacted, so that the map may hold
    /// fewer bytes than after the loop ([`shrink_to_fit`](Self::shrink_to_fit)
    /// does the same after a loop).
    ///
    /// The points of a scan are a slice or anything that holds one (a `Vec` made as
    /// the iterator is read: each is dropped once its scan is cast). The iterator is
    /// read one scan ahead of the map, and two scans' masks are held at once. A
    /// block refused for lack of room is recorded as by `insert_scan`: check
    /// [`check_capacity`](Self::check_capacity) after the call, or after each scan
    /// with [`insert_scans_each`](Self::insert_scans_each).
    ///
    /// # Runtime
    /// As the loop of `insert_scan` in CPU time; in wall time each scan's apply
    /// phase overlaps the next scan's casting.
    pub fn insert_scans<P: AsRef<[[f64; 3]]> + Sync>(
        &mut self,
        scans: impl IntoIterator<Item = ([f64; 3], P)>,
        max_range: Option<f64>,
    ) -> Vec<ScanStats> {
        let mut done = Vec::new();
        let all: Result<(), std::convert::Infallible> =
            self.insert_scans_each(scans, max_range, |_, stats| {
                done.push(stats);
                Ok(())
            });
        let Ok(()) = all;
        done
    }

    /// [`insert_scans`](Self::insert_scans), calling `each` with the map and the
    /// counts of each scan as soon as it is applied, in order. An error from `each`
    /// stops the insertion there (the next scan, cast already, is not applied) and
    /// is returned.
    pub fn insert_scans_each<P: AsRef<[[f64; 3]]> + Sync, E>(
        &mut self,
        scans: impl IntoIterator<Item = ([f64; 3], P)>,
        max_range: Option<f64>,
        mut each: impl FnMut(&Self, ScanStats) -> Result<(), E>,
    ) -> Result<(), E> {
        let res = self.resolution;
        let mut pending: Option<Cast> = None;
        for (origin, points) in scans {
            let points = points.as_ref();
            // What the map holds clamped free once the pending scan is applied.
            let clamped = self.clamped_near(origin, pending.as_ref());
            let next = match pending.take() {
                None => cast_scan(res, origin, points, max_range, clamped, true),
                Some(cast) => {
                    let (stats, next) = rayon::join(
                        || self.apply_cast(cast),
                        || cast_scan(res, origin, points, max_range, clamped, false),
                    );
                    each(self, stats)?;
                    next
                }
            };
            pending = Some(next);
        }
        if let Some(cast) = pending {
            let stats = self.apply_cast(cast);
            self.store.pack(self.fixed);
            each(self, stats)?;
        }
        Ok(())
    }

    /// The blocks of the dense index of a scan from `origin` ([`near_cube`]) that
    /// the map holds clamped free, less those in which a ray of `pending` (a scan
    /// cast, not applied yet) ends: once `pending` is applied, a miss changes
    /// nothing in these blocks (its misses keep them clamped free; a miss only
    /// lowers a value). `None` for an origin not finite or when no block is.
    pub(super) fn clamped_near(
        &self,
        origin: [f64; 3],
        pending: Option<&Cast>,
    ) -> Option<Arc<[u64]>> {
        if !within_reach(1.0 / self.resolution, origin) {
            return None;
        }
        debug_assert!(self.fixed.miss < 0, "a miss lowers a cell's value");
        let centre = key_at(1.0 / self.resolution, origin).map(|c| c >> BLOCK_LOG2);
        let (lo, side_log2) = near_cube(centre);
        let mut bits = self.store.uniform_in(lo, side_log2, self.fixed.min);
        for b in pending
            .iter()
            .flat_map(|c| &c.scratches)
            .flat_map(Scratch::hit_blocks)
        {
            if let Some(at) = cube_index(lo, side_log2, b) {
                bits[at / 64] &= !(1 << (at % 64));
            }
        }
        bits.iter().any(|&w| w != 0).then(|| bits.into())
    }

    /// Applies a cast scan to the map; gives its counts.
    pub(super) fn apply_cast(&mut self, cast: Cast) -> ScanStats {
        let (hits, misses) = self.apply(&cast.scratches, &cast.order);
        self.store.worked(hits + misses);
        ScanStats {
            hits,
            misses,
            ..cast.stats
        }
    }

    /// [`insert_scan`](Self::insert_scan) with points in the sensor frame, moved by
    /// `pose`; the sensor sits at the pose's translation.
    pub fn insert_scan_posed(
        &mut self,
        pose: &Pose,
        points_in_sensor_frame: &[[f64; 3]],
        max_range: Option<f64>,
    ) -> ScanStats {
        let world = pose.apply_all(points_in_sensor_frame);
        self.insert_scan(pose.translation, &world, max_range)
    }

    /// Applies the masks of a scan, block by block in the order given (the masks of
    /// one block, in several scratches, side by side); returns the numbers of cells
    /// hit and missed. The scratches are read out of order: the block `AHEAD` places
    /// on is prefetched, so that its cache misses overlap this block's writing.
    fn apply(&mut self, scratches: &[Scratch], order: &[Place]) -> (u64, u64) {
        const AHEAD: usize = 8;
        let fixed = self.fixed;
        let (mut hits, mut misses) = (0u64, 0u64);
        self.store.reserve(order.len() / 4);
        let key = |p: &Place| scratches[p.scratch as usize].keys()[p.index as usize];
        let mut i = 0;
        while i < order.len() {
            if let Some(p) = order.get(i + AHEAD) {
                let s = &scratches[p.scratch as usize];
                prefetch(s.miss(p.index as usize));
                prefetch(&s.keys()[p.index as usize]);
            }
            let p = order[i];
            let s = &scratches[p.scratch as usize];
            let k = key(&p);
            let (mut miss, mut hit) = (*s.miss(p.index as usize), *s.hits(p.index as usize));
            i += 1;
            while i < order.len() && key(&order[i]) == k {
                let o = &scratches[order[i].scratch as usize];
                let (om, oh) = (
                    o.miss(order[i].index as usize),
                    o.hits(order[i].index as usize),
                );
                for w in 0..8 {
                    miss[w] |= om[w];
                    hit[w] |= oh[w];
                }
                i += 1;
            }
            for w in 0..8 {
                miss[w] &= !hit[w];
            }
            hits += u64::from(hit.iter().map(|w| w.count_ones()).sum::<u32>());
            // Misses in a block clamped free change nothing and are not counted
            // (rays may cross such a block without marking it).
            if !self.store.update(k, &miss, &hit, fixed) {
                misses += u64::from(miss.iter().map(|w| w.count_ones()).sum::<u32>());
            }
        }
        (hits, misses)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::occupancy::SensorModel;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;
    use std::collections::HashMap;

    /// The map's known cells.
    fn cells(map: &OccupancyMap) -> HashMap<[i64; 3], i16> {
        let mut m = HashMap::new();
        map.store.for_each(|c, v| {
            m.insert(c, v);
        });
        m
    }

    /// Scans cast by several threads, each piece of the rays into its own scratch,
    /// give the map (cells, stats, bytes) that one thread gives: the one-thread map
    /// is checked against the naive model in `tests`.
    #[test]
    fn threads_with_their_own_scratches_give_the_map_of_one_thread() {
        let mut rng = Pcg64::seed_from_u64(21);
        let res = 0.1;
        // Origin, points and maximum range of each scan.
        type Scan = ([f64; 3], Vec<[f64; 3]>, Option<f64>);
        let scans: Vec<Scan> = (0..4)
            .map(|scan| {
                let origin = [0, 1, 2].map(|_| rng.random_range(-2.0..2.0));
                let n = [3000, 5000, 700, 4000][scan];
                let points = (0..n)
                    .map(|i| {
                        if i % 97 == 0 {
                            return [f64::NAN, 0.0, 0.0];
                        }
                        [0, 1, 2].map(|a| origin[a] + rng.random_range(-6.0..6.0))
                    })
                    .collect();
                (origin, points, [None, Some(4.0), None, Some(2.5)][scan])
            })
            .collect();
        let build = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut map = OccupancyMap::new(res, SensorModel::octomap()).unwrap();
            let stats: Vec<ScanStats> = scans
                .iter()
                .map(|(o, p, r)| {
                    let s = pool.install(|| map.insert_scan(*o, p, *r));
                    map.assert_valid();
                    s
                })
                .collect();
            (cells(&map), stats, map.bytes())
        };
        let one = build(1);
        assert!(one.0.len() > 10_000, "{} cells", one.0.len());
        for threads in [2, 3, 7] {
            let got = build(threads);
            assert_eq!(got.1, one.1, "{threads} threads: stats");
            assert!(got.0 == one.0, "{threads} threads: cells differ");
            assert_eq!(got.2, one.2, "{threads} threads: bytes");
        }
    }
}
