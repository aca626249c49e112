//! The work a scan asks for, known before it is cast: a budget check for rays that
//! run far (a corrupt point a million kilometres away, a scan without a maximum range).

use super::scan::{castable, length, within_reach};
use super::OccupancyMap;

/// An upper bound on what casting a scan costs, from its points alone.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ScanWork {
    /// Rays that would be cast (points with finite coordinates whose rays end
    /// within ±2^61 cells).
    pub rays: u64,
    /// At most this many cells are crossed, summed over the rays (saturating).
    pub cells: u64,
    /// The longest ray, in world units, after the maximum range.
    pub longest: f64,
}

/// Cells a segment of `length` crosses at `resolution`, at most: a 3-D DDA takes one
/// step per cell face crossed, at most √3·length/resolution faces, plus the first cell
/// and one more per axis for the partial cells at both ends.
fn cells_along(length: f64, resolution: f64) -> f64 {
    (3f64.sqrt() * length / resolution).ceil() + 4.0
}

impl OccupancyMap {
    /// The work of [`insert_scan`](Self::insert_scan) for these arguments, in O(n) and
    /// without touching the map; [`insert_scan_posed`](Self::insert_scan_posed) costs
    /// the same as `insert_scan` from the origin `[0, 0, 0]` of the sensor frame.
    #[must_use]
    pub fn scan_work(
        &self,
        origin: [f64; 3],
        points: &[[f64; 3]],
        max_range: Option<f64>,
    ) -> ScanWork {
        let mut w = ScanWork::default();
        let inv = 1.0 / self.resolution;
        if !within_reach(inv, origin) {
            return w;
        }
        let max_range = max_range.filter(|r| *r >= 0.0);
        let mut cells = 0f64;
        for p in points
            .iter()
            .filter(|p| castable(inv, origin, p, max_range))
        {
            let d = [0, 1, 2].map(|i| p[i] - origin[i]);
            let length = length(d).min(max_range.unwrap_or(f64::INFINITY));
            w.rays += 1;
            w.longest = w.longest.max(length);
            cells += cells_along(length, self.resolution);
        }
        // `as` saturates: a sum past u64::MAX (or an infinite one) reads u64::MAX.
        w.cells = cells as u64;
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::occupancy::SensorModel;
    use rand::{Rng, SeedableRng};

    #[test]
    fn the_bound_holds_for_every_ray_and_catches_far_points() {
        let mut map = OccupancyMap::new(0.05, SensorModel::octomap()).unwrap();
        let mut rng = rand::rngs::StdRng::seed_from_u64(13);
        for _ in 0..200 {
            let origin = [0, 1, 2].map(|_| rng.random_range(-3.0..3.0));
            // Rays along the axes, on cell faces, and anywhere; some cut by max range.
            let points: Vec<[f64; 3]> = (0..20)
                .map(|i| match i % 3 {
                    0 => [
                        origin[0] + rng.random_range(-5.0..5.0),
                        origin[1],
                        origin[2],
                    ],
                    1 => [0, 1, 2].map(|_| f64::from(rng.random_range(-100i32..100)) * 0.05),
                    _ => [0, 1, 2].map(|_| rng.random_range(-8.0..8.0)),
                })
                .collect();
            let max_range = rng.random_bool(0.5).then(|| rng.random_range(0.5..6.0));
            let work = map.scan_work(origin, &points, max_range);
            let stats = map.insert_scan(origin, &points, max_range);
            assert_eq!(work.rays, stats.rays);
            // Each cell updated was crossed by some ray: the bound covers them all.
            assert!(stats.hits + stats.misses <= work.cells);
            map.assert_valid();
        }
        // One ray: the bound is within a few cells of what the walk crosses.
        let mut one = OccupancyMap::new(0.1, SensorModel::octomap()).unwrap();
        let s = one.insert_scan([0.05, 0.05, 0.05], &[[1.05, 0.05, 0.05]], None);
        let w = one.scan_work([0.05, 0.05, 0.05], &[[1.05, 0.05, 0.05]], None);
        assert_eq!(s.hits + s.misses, 11);
        assert!((11..=22).contains(&w.cells), "{w:?}");
        // A point a million kilometres away, NaN skipped, and a cut at 10 m.
        let far = [[1e9, 0.0, 0.0], [f64::NAN, 0.0, 0.0]];
        let w = one.scan_work([0.0; 3], &far, None);
        assert_eq!((w.rays, w.longest), (1, 1e9));
        assert!(w.cells > 10_000_000_000, "{w:?}");
        let w = one.scan_work([0.0; 3], &far, Some(10.0));
        assert_eq!(w.longest, 10.0);
        assert!(w.cells < 200, "{w:?}");
        // Past 2^61 cells a point is skipped, unless the range cuts its ray nearer.
        let huge = [[1e300, 1e300, 0.0]];
        assert_eq!(one.scan_work([0.0; 3], &huge, None), ScanWork::default());
        let w = one.scan_work([0.0; 3], &huge, Some(1.0));
        assert_eq!((w.rays, w.longest), (1, 1.0));
        let w = one.scan_work([0.0; 3], &[[1e16, 1e16, 0.0]], None);
        assert_eq!(w.rays, 1);
        assert!(w.cells > 200_000_000_000_000_000, "{w:?}");
        assert_eq!(
            one.scan_work([f64::NAN; 3], &far, None),
            ScanWork::default()
        );
    }
}
