//! Rays cross the blocks that the map holds clamped free without marking them
//! (`OccupancyMap::clamped_near`): the maps and counts stay those of the naive
//! model, and `insert_scans`, which casts a scan before the one before it is
//! applied, gives the map and counts of a loop of `insert_scan`.

use std::collections::HashMap;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::scan::cast_scan;
use super::tests::{check_same, Cell, Naive};
use super::*;

/// `n` points at random directions from `origin`, `r` away.
fn sphere(rng: &mut Pcg64, origin: [f64; 3], n: usize, r: f64) -> Vec<[f64; 3]> {
    (0..n)
        .map(|_| loop {
            let d: [f64; 3] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
            let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            if len > 0.1 && len <= 1.0 {
                break [0, 1, 2].map(|a| origin[a] + d[a] / len * r);
            }
        })
        .collect()
}

fn cells(map: &OccupancyMap) -> HashMap<Cell, i16> {
    let mut m = HashMap::new();
    map.store.for_each(|c, v| {
        m.insert(c, v);
    });
    m
}

/// A cell in a block the map holds uniform at the lower clamp, other than the
/// origin's block.
fn cell_in_clamped_block(map: &OccupancyMap, origin_block: [i64; 3]) -> [f64; 3] {
    let res = map.resolution();
    let c = cells(map)
        .keys()
        .copied()
        .filter(|c| c.map(|k| k >> 3) != origin_block)
        .find(|c| {
            let b = c.map(|k| k >> 3);
            map.store.entry(b).map(|e| e.kind()) == Some(store::Kind::Uniform(map.fixed.min))
        })
        .expect("a block clamped free");
    c.map(|k| (k as f64 + 0.5) * res)
}

/// A scan's origin and points.
type Scan = ([f64; 3], Vec<[f64; 3]>);

/// Scans from two origins with a sensor whose lower clamp is one miss, so that
/// blocks clamp after one scan; then hits inside a clamped block, crossed again by
/// the next scans (whose misses must reach the hit cell). Each scan is inserted and
/// checked against the naive model as it is made; gives the map and the scans.
fn scans() -> (OccupancyMap, Vec<Scan>) {
    let mut map_for_hits = OccupancyMap::new(0.5, model()).unwrap();
    let mut naive = Naive {
        cells: HashMap::new(),
        f: map_for_hits.fixed,
        res: 0.5,
    };
    let map_for_hits = &mut map_for_hits;
    let mut rng = Pcg64::seed_from_u64(5);
    let origins = [[0.3, 0.3, 0.3], [1.3, 0.8, 0.2]];
    let mut out = Vec::new();
    for scan in 0..7 {
        let origin = origins[usize::from(scan >= 5)];
        let mut points = sphere(&mut rng, origin, 6000, 7.0);
        if scan == 3 || scan == 5 {
            points.push(cell_in_clamped_block(map_for_hits, [0, 0, 0]));
        }
        let got = map_for_hits.insert_scan(origin, &points, None);
        assert_eq!(got, naive.scan(origin, &points, None), "scan {scan}");
        check_same(map_for_hits, &naive);
        map_for_hits.assert_valid();
        out.push((origin, points));
    }
    (map_for_hits.clone(), out)
}

fn model() -> SensorModel {
    SensorModel::from_probabilities(0.7, 0.4, (0.4, 0.971), 0.5).unwrap()
}

#[test]
fn rays_cross_clamped_free_blocks_and_keep_the_naive_map() {
    let (map, scans) = scans();
    // The skip happened: with the clamped blocks known, the last scan marks fewer
    // blocks, and applying either cast gives the same map.
    let (origin, points) = &scans[6];
    let mut replay = OccupancyMap::new(0.5, model()).unwrap();
    replay.insert_scans(scans[..6].iter().map(|(o, p)| (*o, p.as_slice())), None);
    assert_eq!(cells(&replay), cells(&map_before_last(&scans)));
    let clamped = replay.clamped_near(*origin, None);
    assert!(clamped.is_some(), "blocks clamped free round the origin");
    let with = cast_scan(0.5, *origin, points, None, clamped, true);
    let without = cast_scan(0.5, *origin, points, None, None, true);
    assert!(
        with.blocks() < without.blocks(),
        "{} blocks marked with the clamped blocks known, {} without",
        with.blocks(),
        without.blocks()
    );
    let mut other = replay.clone();
    let a = replay.apply_cast(with);
    let b = other.apply_cast(without);
    assert_eq!(a, b, "the same counts");
    assert_eq!(cells(&replay), cells(&other));
    assert_eq!(cells(&replay), cells(&map));
    replay.assert_valid();
}

/// The map of every scan but the last, inserted one by one.
fn map_before_last(scans: &[Scan]) -> OccupancyMap {
    let mut map = OccupancyMap::new(0.5, model()).unwrap();
    for (o, p) in &scans[..scans.len() - 1] {
        map.insert_scan(*o, p, None);
    }
    map
}

#[test]
fn insert_scans_keeps_the_misses_of_blocks_the_scan_before_hits() {
    let (map, scans) = scans();
    let mut looped = OccupancyMap::new(0.5, model()).unwrap();
    let want: Vec<ScanStats> = scans
        .iter()
        .map(|(o, p)| looped.insert_scan(*o, p, None))
        .collect();
    assert_eq!(
        cells(&looped),
        cells(&map),
        "the loop gives the checked map"
    );
    // The batch ends packed, as the loop's map once shrunk.
    looped.shrink_to_fit();
    looped.assert_valid();
    assert_eq!(cells(&looped), cells(&map), "shrink_to_fit keeps the cells");
    for threads in [1, 2, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut piped = OccupancyMap::new(0.5, model()).unwrap();
        let got = pool
            .install(|| piped.insert_scans(scans.iter().map(|(o, p)| (*o, p.as_slice())), None));
        piped.assert_valid();
        assert_eq!(got, want, "{threads} threads: counts");
        assert_eq!(cells(&piped), cells(&looped), "{threads} threads: cells");
        // The batch ends packed, as the loop's map once shrunk.
        assert_eq!(piped.bytes(), looped.bytes(), "{threads} threads: bytes");
    }
}

/// `Store::uniform_in` gives the blocks of a cube whose 512 cells all hold the value
/// asked for (from a model of cells), for the lower clamp and for the upper one.
#[test]
fn uniform_in_finds_the_blocks_clamped_to_a_value_and_no_others() {
    let mut rng = Pcg64::seed_from_u64(8);
    let mut map = OccupancyMap::new(0.5, model()).unwrap();
    let origin = [0.3, 0.3, 0.3];
    // Every cell of block [3, 0, 0] hit (five times: clamped occupied).
    let block: Vec<[f64; 3]> = (0..512)
        .map(|i: i64| [24 + (i & 7), i >> 3 & 7, i >> 6].map(|k| (k as f64 + 0.5) * 0.5))
        .collect();
    for _ in 0..5 {
        let mut points = sphere(&mut rng, origin, 3000, 7.0);
        points.extend(&block);
        map.insert_scan(origin, &points, None);
    }
    assert_eq!(
        map.store.entry([3, 0, 0]).map(|e| e.kind()),
        Some(store::Kind::Uniform(map.fixed.max))
    );
    let known = cells(&map);
    let lo = [-40, -30, -33];
    for value in [map.fixed.min, map.fixed.max] {
        let bits = map.store.uniform_in(lo, 6, value);
        let mut found = 0;
        for at in 0..1usize << 18 {
            let b = [at & 63, at >> 6 & 63, at >> 12].map(|d| d as i64);
            let b = [0, 1, 2].map(|a| lo[a] + b[a]);
            let want = (0..512).all(|i: i64| {
                let c = [
                    b[0] << 3 | i & 7,
                    b[1] << 3 | i >> 3 & 7,
                    b[2] << 3 | i >> 6,
                ];
                known.get(&c) == Some(&value)
            });
            assert_eq!(bits[at / 64] >> (at % 64) & 1 == 1, want, "block {b:?}");
            found += usize::from(want);
        }
        assert!(found > 0, "some block holds {value} in all its cells");
    }
}
