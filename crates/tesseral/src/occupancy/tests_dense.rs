//! Scans dense enough that whole blocks fill with misses, so that rays jump across
//! them, against the naive model of `tests`.

use std::collections::HashMap;
use std::sync::atomic::Ordering;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::dda::JUMPS;
use super::tests::{check_same, Naive};
use super::*;

#[test]
fn dense_scans_match_the_naive_model() {
    let before = JUMPS.load(Ordering::Relaxed);
    for seed in 0..3u64 {
        let mut rng = Pcg64::seed_from_u64(100 + seed);
        let res = [0.25, 0.125, 0.1][seed as usize];
        let mut map = OccupancyMap::new(res, SensorModel::octomap()).unwrap();
        let mut naive = Naive {
            cells: HashMap::new(),
            f: map.fixed,
            res,
        };
        // Only a power-of-two resolution has faces that `floor(p / res)` and the
        // naive model's `k × res` agree on exactly: snap to faces only then.
        let dyadic = res.log2().fract() == 0.0;
        for scan in 0..3 {
            // An origin near the middle of its block (on a cell corner, a face or
            // anywhere); rays of 10 to 14 cells in every direction (so that the
            // blocks round the origin fill), some ending on faces, along axes, of zero
            // length.
            let origin = [0, 1, 2].map(|_| {
                let v: f64 = 4.0 * res + rng.random_range(-1.0..1.0) * res;
                match scan % 3 {
                    0 if dyadic => (v / res).round() * res,
                    1 if dyadic => (v / res * 2.0).round() * res / 2.0,
                    _ => v,
                }
            });
            let points: Vec<[f64; 3]> = (0..20_000)
                .map(|i| {
                    let d = loop {
                        let d = [0, 1, 2].map(|_| rng.random_range(-1.0..1.0f64));
                        let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                        if n > 0.1 && n <= 1.0 {
                            break d.map(|c| c / n);
                        }
                    };
                    let r = rng.random_range(10.0..14.0) * res;
                    let mut p = [0, 1, 2].map(|a| origin[a] + d[a] * r);
                    match i % 11 {
                        0 if dyadic => {
                            let a = rng.random_range(0..3);
                            p[a] = (p[a] / res).round() * res;
                        }
                        1 => {
                            let a = rng.random_range(0..3);
                            for b in 0..3 {
                                if b != a {
                                    p[b] = origin[b];
                                }
                            }
                        }
                        2 if i % 3 == 0 => p = origin,
                        _ => {}
                    }
                    p
                })
                .collect();
            let max_range = [None, Some(11.5 * res), None][scan];
            // One thread casts all the rays into one scratch (where blocks fill), or
            // several share them.
            let threads = if scan == 1 { 3 } else { 1 };
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let got = pool.install(|| map.insert_scan(origin, &points, max_range));
            let want = naive.scan(origin, &points, max_range);
            assert_eq!(got, want, "seed {seed} scan {scan}: stats");
            map.assert_valid();
            check_same(&map, &naive);
        }
    }
    assert!(
        JUMPS.load(Ordering::Relaxed) > before + 2_000,
        "rays jumped across full blocks ({} jumps)",
        JUMPS.load(Ordering::Relaxed) - before
    );
}
