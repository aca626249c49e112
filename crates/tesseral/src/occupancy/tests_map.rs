//! The occupancy map's other behaviour: pruning, the fixed point against OctoMap's
//! floats, scan counts, far keys, posed scans, models, and the scan soak (against
//! the naive model of `tests`).

use std::collections::{HashMap, HashSet};

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::sensor::{Fixed, UNKNOWN};
use super::tests::{check_same, Cell, Naive};
use super::*;
#[test]
fn pruning_keeps_clamped_blocks_as_one_entry() {
    let mut map = OccupancyMap::new(1.0, SensorModel::octomap()).unwrap();
    // Rays along x through a 16-cell line of blocks, many times: free, clamped.
    let points: Vec<[f64; 3]> = (0..8)
        .flat_map(|y| (0..8).map(move |z| [40.5, f64::from(y) + 0.5, f64::from(z) + 0.5]))
        .collect();
    for _ in 0..10 {
        for y in 0..8 {
            for z in 0..8 {
                map.insert_scan(
                    [0.5, f64::from(y) + 0.5, f64::from(z) + 0.5],
                    &points[..0],
                    None,
                );
            }
        }
        let origins: Vec<[f64; 3]> = points.iter().map(|p| [0.5, p[1], p[2]]).collect();
        for (o, p) in origins.iter().zip(&points) {
            map.insert_scan(*o, &[*p], None);
        }
        map.assert_valid();
    }
    // Blocks 0..=4 along x are all free and clamped: uniform; block 5 holds the hits.
    for bx in 0..5 {
        assert!(
            matches!(
                map.store.entry([bx, 0, 0]).map(|e| e.kind()),
                Some(store::Kind::Uniform(_))
            ),
            "block {bx}"
        );
    }
    assert_eq!(map.state([3, 3, 3]), CellState::Free);
    assert_eq!(
        map.log_odds([3, 3, 3]),
        Some(map.fixed.to_f32(map.fixed.min))
    );
    assert_eq!(map.state([40, 3, 3]), CellState::Occupied);
    assert_eq!(map.occupied_count(), 64);
    assert_eq!(map.free_count(), 40 * 64);
    assert_eq!(map.leaf_count(), 5 + 64);
}

#[test]
fn fixed_point_agrees_with_octomap_floats_on_occupancy() {
    // Every state reachable in up to 40 updates from unknown, as (OctoMap's f32
    // log-odds, our fixed point): the occupancy decision is the same in each.
    let m = SensorModel::octomap();
    let f = Fixed::new(&m);
    let mut frontier: HashSet<(u32, i16)> = HashSet::from([(0f32.to_bits(), 0i16)]);
    let mut seen = frontier.clone();
    let mut worst = 0f32;
    for _ in 0..40 {
        let mut next = HashSet::new();
        for &(b, q) in &frontier {
            let x = f32::from_bits(b);
            for (inc, hit) in [(m.hit(), true), (m.miss(), false)] {
                let y = (x + inc).clamp(m.clamp_min(), m.clamp_max());
                let r = if hit { f.apply_hit(q) } else { f.apply_miss(q) };
                assert_eq!(
                    y >= m.threshold(),
                    r >= f.threshold,
                    "{y} vs {}",
                    f.to_f32(r)
                );
                worst = worst.max((y - f.to_f32(r)).abs());
                if seen.insert((y.to_bits(), r)) {
                    next.insert((y.to_bits(), r));
                }
            }
        }
        frontier = next;
    }
    assert!(worst < 2e-3, "fixed point drifts by {worst}");
}

/// `to_f32` multiplies by 2^-scale rather than dividing by 2^scale: the same float,
/// for every stored value and every scale a model can get.
#[test]
fn to_f32_is_the_exact_quotient_at_every_scale() {
    let m = SensorModel::octomap();
    for scale_log2 in 0..=14 {
        let f = Fixed {
            scale_log2,
            ..Fixed::new(&m)
        };
        for v in i16::MIN..=i16::MAX {
            let want = f32::from(v) / (1u32 << scale_log2) as f32;
            assert_eq!(
                f.to_f32(v).to_bits(),
                want.to_bits(),
                "{v} at 2^{scale_log2}"
            );
        }
    }
}

#[test]
fn stats_count_skipped_points_and_bad_origins() {
    let mut map = OccupancyMap::new(0.1, SensorModel::octomap()).unwrap();
    let s = map.insert_scan([0.0; 3], &[[f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0]], None);
    assert_eq!((s.points, s.rays, s.skipped, s.hits), (2, 1, 1, 1));
    let s = map.insert_scan([f64::INFINITY, 0.0, 0.0], &[[1.0, 0.0, 0.0]], None);
    assert_eq!((s.points, s.rays, s.skipped), (1, 0, 1));
    assert!(OccupancyMap::new(0.0, SensorModel::octomap()).is_err());
    assert!(SensorModel::from_probabilities(0.4, 0.4, (0.1, 0.9), 0.5).is_err());
    assert!(SensorModel::from_probabilities(0.7, 0.4, (0.6, 0.9), 0.5).is_err());
    map.assert_valid();
}

#[test]
fn unbounded_keys_far_from_the_origin() {
    let mut map = OccupancyMap::new(1.0, SensorModel::octomap()).unwrap();
    let far = 4.0e15;
    let s = map.insert_scan(
        [far + 0.5, -far + 0.5, 0.5],
        &[[far + 10.5, -far + 0.5, 0.5]],
        None,
    );
    assert_eq!((s.hits, s.misses), (1, 10));
    assert_eq!(
        map.state([4_000_000_000_000_010, -4_000_000_000_000_000, 0]),
        CellState::Occupied
    );
    map.assert_valid();
}

#[test]
fn posed_scans_rotate_then_translate() {
    let pose = Pose {
        translation: [1.0, 2.0, 3.0],
        roll: 0.0,
        pitch: 0.0,
        yaw: std::f64::consts::FRAC_PI_2,
    };
    let p = pose.apply([1.0, 0.0, 0.0]);
    assert!((p[0] - 1.0).abs() < 1e-12 && (p[1] - 3.0).abs() < 1e-12 && (p[2] - 3.0).abs() < 1e-12);
    let mut a = OccupancyMap::new(0.1, SensorModel::octomap()).unwrap();
    let mut b = a.clone();
    let pts = [[1.0, 0.3, 0.2], [0.5, -0.4, 0.1]];
    a.insert_scan_posed(&pose, &pts, None);
    let world: Vec<[f64; 3]> = pts.iter().map(|q| pose.apply(*q)).collect();
    b.insert_scan(pose.translation, &world, None);
    assert_eq!(a.cells(), b.cells());
}

#[test]
fn models_round_trip() {
    let mut rng = Pcg64::seed_from_u64(3);
    let mut map = OccupancyMap::new(0.1, SensorModel::octomap()).unwrap();
    for _ in 0..5 {
        let pts: Vec<[f64; 3]> = (0..200)
            .map(|_| [0, 1, 2].map(|_| rng.random_range(-2.0..2.0)))
            .collect();
        map.insert_scan([0.0, 0.0, 0.0], &pts, Some(1.5));
    }
    let m = map.to_model().unwrap();
    m.assert_valid();
    assert_eq!(m.tree.voxel_count(), map.occupied_count());
    assert_eq!(m.free.as_ref().unwrap().voxel_count(), map.free_count());
    let back = OccupancyMap::from_model(&m).unwrap();
    back.assert_valid();
    assert_eq!(back.cells(), map.cells());
    let _ = UNKNOWN;
}

/// `to_model` against the map cell by cell (state and log-odds), in each kind of
/// space it picks: an aligned cube inside OctoMap's keys, OctoMap's root for a map
/// across 0, and a cube from the lowest block beyond OctoMap's keys; with blocks
/// clamped whole (stored uniform, emitted as one leaf) and blocks of single cells;
/// and the map's own `.bt` and `.ot` writer against the model's.
#[test]
fn models_hold_every_cell_in_every_space() {
    let mut rng = Pcg64::seed_from_u64(31);
    for (centre, aligned) in [
        ([0.4, 0.4, 0.4], true),
        ([13.2, 7.6, 2.0], true),
        ([-25.2, 4.4, -8.4], true),
        ([3300.4, 3.6, -1.2], false),
    ] {
        let mut map = OccupancyMap::new(0.1, SensorModel::octomap()).unwrap();
        for _ in 0..12 {
            // Dense rays to a shell clamp the blocks round the sensor free, whole;
            // a few to random points add cells of other values.
            let pts: Vec<[f64; 3]> = (0..6000)
                .map(|i| {
                    let d = [0, 1, 2].map(|_| rng.random_range(-1.0..1.0f64));
                    let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt().max(1e-3);
                    let r = if i < 5940 {
                        1.6
                    } else {
                        rng.random_range(1.0..2.5)
                    };
                    [0, 1, 2].map(|a| centre[a] + d[a] / len * r)
                })
                .collect();
            map.insert_scan(centre, &pts, None);
        }
        let m = map.to_model().unwrap();
        m.assert_valid();
        let (depth, origin) = (m.tree.depth(), m.tree.origin());
        let root = depth == 16 && origin == [-32768; 3];
        let cube = origin.iter().all(|&o| o.rem_euclid(1 << depth) == 0);
        assert_eq!(
            root || cube,
            aligned,
            "{centre:?}: depth {depth} from {origin:?}"
        );
        let cells = map.cells();
        let free = m.free.as_ref().unwrap();
        let layer = m.log_odds.as_ref().unwrap();
        let t = map.fixed.to_f32(map.fixed.threshold);
        for &(c, v) in &cells {
            assert_eq!(m.tree.contains(c), v >= t, "{c:?} {v}");
            assert_eq!(free.contains(c), v < t, "{c:?} {v}");
            assert_eq!(layer.get(c), Some(v), "{c:?}");
        }
        let n = cells.len() as u64;
        assert_eq!(m.tree.voxel_count() + free.voxel_count(), n);
        assert_eq!(layer.voxel_count(), n);
        let blocks: HashSet<[i64; 3]> = cells.iter().map(|(c, _)| c.map(|x| x >> 3)).collect();
        let uniform = blocks
            .iter()
            .filter(|&&b| {
                matches!(
                    map.store.entry(b).map(|e| e.kind()),
                    Some(store::Kind::Uniform(_))
                )
            })
            .count();
        assert!(
            uniform > 0 && uniform < blocks.len(),
            "{centre:?}: {uniform} of {} blocks uniform",
            blocks.len()
        );
        assert_eq!(OccupancyMap::from_model(&m).unwrap().cells(), cells);
        // Written straight from the blocks, the OctoMap files are the model's.
        use crate::io::octomap;
        if aligned {
            assert_eq!(map.encode_bt().unwrap(), octomap::encode_bt(&m).unwrap());
            assert_eq!(map.encode_ot().unwrap(), octomap::encode_ot(&m).unwrap());
        } else {
            assert!(octomap::encode_bt(&m).is_err());
            for e in [map.encode_bt().unwrap_err(), map.encode_ot().unwrap_err()] {
                assert!(matches!(e, OccupancyError::KeyRange { hi, .. } if hi[0] > 32767));
            }
        }
    }
}

/// The scan half of the 10^8-operation soak (issue 19 §4): scans from wandering
/// origins until 10^8 cell updates are made, `assert_valid` after each, and every
/// 25th scan checked against the naive model on a sample of its rays.
#[test]
#[ignore = "soak: minutes; run with --ignored"]
fn soak_scan_insertion() {
    let mut rng = Pcg64::seed_from_u64(19);
    let res = 0.05;
    let mut map = OccupancyMap::new(res, SensorModel::octomap()).unwrap();
    let mut updates = 0u64;
    let mut scan = 0;
    while updates < 100_000_000 {
        let origin = [0, 1, 2].map(|_| rng.random_range(-20.0..20.0));
        let points: Vec<[f64; 3]> = (0..20_000)
            .map(|_| [0, 1, 2].map(|a| origin[a] + rng.random_range(-6.0..6.0)))
            .collect();
        let max_range = if scan % 2 == 0 { Some(5.0) } else { None };
        if scan % 25 == 0 {
            // A small scan through both: the map must change as the naive model says.
            let few = &points[..50];
            let mut naive = Naive {
                cells: HashMap::new(),
                f: map.fixed,
                res,
            };
            let before: HashMap<Cell, i32> = {
                let mut m = HashMap::new();
                map.store.for_each(|c, v| {
                    m.insert(c, i32::from(v));
                });
                m
            };
            naive.cells = before;
            let got = map.insert_scan(origin, few, max_range);
            assert_eq!(got, naive.scan(origin, few, max_range));
            check_same(&map, &naive);
        }
        let s = map.insert_scan(origin, &points, max_range);
        updates += s.hits + s.misses;
        map.assert_valid();
        scan += 1;
    }
}

/// `insert_scans` (a scan cast while the one before it is applied) gives the map
/// (cells, `bytes`) and the counts of a loop of `insert_scan` on one thread (which
/// `tests` holds against the naive model), with one thread and with several; a scan
/// from a non-finite origin among them counts its points skipped and changes nothing.
#[test]
fn insert_scans_gives_the_map_and_counts_of_a_loop_of_insert_scan() {
    let mut rng = Pcg64::seed_from_u64(31);
    let res = 0.25;
    let scans: Vec<([f64; 3], Vec<[f64; 3]>)> = (0..7)
        .map(|scan| {
            let origin = if scan == 3 {
                [f64::NAN, 0.0, 0.0]
            } else {
                [0, 1, 2].map(|_| rng.random_range(-3.0..3.0))
            };
            let n = [400, 900, 50, 300, 0, 1200, 700][scan];
            let points = (0..n)
                .map(|i| {
                    if i % 53 == 0 {
                        return [0.0, f64::INFINITY, 0.0];
                    }
                    [0, 1, 2].map(|_| rng.random_range(-8.0..8.0))
                })
                .collect();
            (origin, points)
        })
        .collect();
    let cells = |map: &OccupancyMap| {
        let mut m = HashMap::new();
        map.store.for_each(|c, v| {
            m.insert(c, v);
        });
        m
    };
    for max_range in [None, Some(4.0)] {
        let mut want_map = OccupancyMap::new(res, SensorModel::octomap()).unwrap();
        let want: Vec<ScanStats> = scans
            .iter()
            .map(|(o, p)| want_map.insert_scan(*o, p, max_range))
            .collect();
        assert_eq!(
            want[3].skipped, 300,
            "a non-finite origin skips every point"
        );
        assert!(cells(&want_map).len() > 10_000);
        // The batch ends packed, as the loop's map once shrunk.
        let before = cells(&want_map);
        want_map.shrink_to_fit();
        want_map.assert_valid();
        assert!(cells(&want_map) == before, "shrink_to_fit keeps the cells");
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut map = OccupancyMap::new(res, SensorModel::octomap()).unwrap();
            let got = pool.install(|| {
                map.insert_scans(scans.iter().map(|(o, p)| (*o, p.as_slice())), max_range)
            });
            map.assert_valid();
            assert_eq!(got, want, "{threads} threads, {max_range:?}: counts");
            assert!(cells(&map) == cells(&want_map), "{threads} threads: cells");
            assert_eq!(map.bytes(), want_map.bytes(), "{threads} threads: bytes");
        }
    }
}

#[test]
fn points_past_reach_are_skipped_and_huge_offsets_cut_at_the_range() {
    // Past ±2^61 cells a point is skipped, not merged into the edge cell; a point
    // 10^200 away (its squared length overflows) still clears its ray to the range.
    let mut map = OccupancyMap::new(1.0, SensorModel::octomap()).unwrap();
    let s = map.insert_scan([0.5; 3], &[[1e19, 0.5, 0.5], [5e30, 0.5, 0.5]], None);
    assert_eq!((s.points, s.rays, s.skipped, s.hits), (2, 0, 2, 0));
    let s = map.insert_scan([0.5; 3], &[[1e200, 0.5, 0.5]], Some(10.0));
    assert_eq!((s.rays, s.skipped, s.hits), (1, 0, 0));
    // Cells 0..=9 free, the cut end's cell not (as OctoMap's computeRayKeys).
    assert_eq!(map.free_count(), 10);
    assert_eq!(map.state([9, 0, 0]), CellState::Free);
    assert_eq!(map.state([10, 0, 0]), CellState::Unknown);
    // A sensor past reach: every point skipped, the map unchanged.
    let s = map.insert_scan([1e19, 0.5, 0.5], &[[1e19 + 4.0, 0.5, 0.5]], None);
    assert_eq!((s.rays, s.skipped), (0, 1));
    assert_eq!(map.counts().leaves, 10);
    // Just inside reach, a point far off is a ray like any other.
    let edge = ((1u64 << 61) - 4096) as f64;
    let s = map.insert_scan([edge - 3.5, 0.5, 0.5], &[[edge, 0.5, 0.5]], None);
    assert_eq!((s.rays, s.hits), (1, 1));
    assert_eq!(map.state([edge as i64, 0, 0]), CellState::Occupied);
    map.assert_valid();
}
