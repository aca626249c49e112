//! Dynamic octree benchmarks, on the same workloads as the OctoMap harness in
//! `benches/octomap/` (same generator, same cells, same order):
//! - `random`: 1,000,000 random cells in [−256, 256)³ (splitmix64, seed 1);
//! - `shell`: every cell whose centre lies at distance [200, 230) from the origin,
//!   in z, y, x scan order (17,454,936 cells).
//!
//! Lookups: 1,000,000 random cells of the box (seed 2), and up to 1,000,000 of the
//! workload's own cells shuffled (seed 3).
//!
//! First a plain timed summary (best of 3) prints `RESULT tesseral <workload>
//! <measure> <value>` lines, with a `HashSet<[i64; 3]>` baseline measured in the same
//! run; `benches/octomap/run.sh` puts them side by side with OctoMap's. Then criterion
//! runs (skip them with `TESSERAL_SUMMARY_ONLY=1`).

mod common;

use std::collections::HashSet;
use std::hint::black_box;
use std::time::Instant;

use criterion::{BatchSize, Criterion};
use tesseral::dynamic::DynamicOctree;
use tesseral::Voxel;

use common::SplitMix64;

/// A random cell of the box [−256, 256)³.
fn cell(r: &mut SplitMix64) -> Voxel {
    let x = (r.next() >> 55) as i64 - 256;
    let y = (r.next() >> 55) as i64 - 256;
    let z = (r.next() >> 55) as i64 - 256;
    [x, y, z]
}

fn random_cells(seed: u64, n: usize) -> Vec<Voxel> {
    let mut r = SplitMix64(seed);
    (0..n).map(|_| cell(&mut r)).collect()
}

fn shell_cells() -> Vec<Voxel> {
    let (lo, hi) = (4 * 200 * 200, 4 * 230 * 230);
    let mut v = Vec::new();
    for z in -256i64..256 {
        for y in -256i64..256 {
            for x in -256i64..256 {
                let d = (2 * x + 1).pow(2) + (2 * y + 1).pow(2) + (2 * z + 1).pow(2);
                if d >= lo && d < hi {
                    v.push([x, y, z]);
                }
            }
        }
    }
    v
}

fn occupied_queries(mut v: Vec<Voxel>) -> Vec<Voxel> {
    let mut r = SplitMix64(3);
    for i in (1..v.len()).rev() {
        let j = (r.next() % (i as u64 + 1)) as usize;
        v.swap(i, j);
    }
    v.truncate(1_000_000);
    v
}

fn best_of<F: FnMut() -> f64>(n: usize, mut f: F) -> f64 {
    (0..n).map(|_| f()).fold(f64::INFINITY, f64::min)
}

fn build(cells: &[Voxel], faces: bool) -> DynamicOctree {
    let mut t = if faces {
        DynamicOctree::with_faces()
    } else {
        DynamicOctree::new()
    };
    for &c in cells {
        t.insert(c);
    }
    t
}

fn rss_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/statm").ok()?;
    let res: u64 = s.split_whitespace().nth(1)?.parse().ok()?;
    Some(res * 4096)
}

fn summary(name: &str, cells: &[Voxel]) {
    let rq = random_cells(2, 1_000_000);
    let oq = occupied_queries(cells.to_vec());
    let n = cells.len() as f64;
    let r = |m: &str, v: f64| println!("RESULT tesseral {name} {m} {v:.2}");

    let insert = best_of(3, || {
        let t0 = Instant::now();
        let t = build(cells, false);
        let dt = t0.elapsed().as_nanos() as f64 / n;
        black_box(t.voxel_count());
        dt
    });
    let rss0 = rss_bytes();
    let t = build(cells, false);
    let rss1 = rss_bytes();
    let stored = t.voxel_count() as f64;
    r("cells", n);
    r("stored", stored);
    r("insert_ns", insert);
    let lookup = |qs: &[Voxel]| {
        best_of(3, || {
            let t0 = Instant::now();
            let hits = qs.iter().filter(|&&q| t.contains(q)).count();
            black_box(hits);
            t0.elapsed().as_nanos() as f64 / qs.len() as f64
        })
    };
    r("lookup_random_ns", lookup(&rq));
    r(
        "lookup_random_hits",
        rq.iter().filter(|&&q| t.contains(q)).count() as f64,
    );
    r("lookup_occupied_ns", lookup(&oq));
    r(
        "lookup_occupied_hits",
        oq.iter().filter(|&&q| t.contains(q)).count() as f64,
    );
    let nb = best_of(3, || {
        let t0 = Instant::now();
        let s = oq.iter().fold(0u32, |a, &q| a ^ t.neighbourhood(q).bits());
        black_box(s);
        t0.elapsed().as_nanos() as f64 / oq.len() as f64
    });
    r("neighbourhood_ns", nb);
    r("nodes", t.node_count() as f64);
    r("bytes", t.bytes() as f64);
    r("bytes_per_voxel", t.bytes() as f64 / stored);
    if let (Some(a), Some(b)) = (rss0, rss1) {
        r("rss_bytes_per_voxel", b.saturating_sub(a) as f64 / stored);
    }
    let mut s = t.clone();
    s.shrink_to_fit();
    r("bytes_per_voxel_shrunk", s.bytes() as f64 / stored);
    drop((t, s));

    // With face bookkeeping (the RS/MC configuration).
    let t0 = Instant::now();
    let f = build(cells, true);
    r("faces_insert_ns", t0.elapsed().as_nanos() as f64 / n);
    r("faces", f.face_count() as f64);
    r("faces_bytes_per_voxel", f.bytes() as f64 / stored);
    drop(f);

    // Baseline in the same run: a std HashSet of voxels.
    let hs_insert = best_of(3, || {
        let t0 = Instant::now();
        let mut h = HashSet::new();
        for &c in cells {
            h.insert(c);
        }
        let dt = t0.elapsed().as_nanos() as f64 / n;
        black_box(h.len());
        dt
    });
    let h: HashSet<Voxel> = cells.iter().copied().collect();
    r("hashset_insert_ns", hs_insert);
    let hs_lookup = best_of(3, || {
        let t0 = Instant::now();
        let hits = rq.iter().filter(|q| h.contains(*q)).count();
        black_box(hits);
        t0.elapsed().as_nanos() as f64 / rq.len() as f64
    });
    r("hashset_lookup_random_ns", hs_lookup);
    let hs_bytes = h.capacity().next_power_of_two() as f64 * 25.0;
    r("hashset_bytes_per_voxel", hs_bytes / stored);
}

/// A random-surface-like walk with face bookkeeping: start from a 24³ cube; each step
/// draws a random face (splitmix64), reads the 27-neighbourhood of the voxel behind it,
/// then creates the white voxel in front of the face or deletes the black one behind
/// it, alternately. Prints ns per step.
fn surface_walk_summary() {
    let mut t = DynamicOctree::with_faces();
    for x in 0..24 {
        for y in 0..24 {
            for z in 0..24 {
                t.insert([x, y, z]);
            }
        }
    }
    let mut r = SplitMix64(9);
    let steps = 2_000_000;
    let t0 = Instant::now();
    let mut acc = 0u32;
    for i in 0..steps {
        let f = t.face((r.next() % t.face_count() as u64) as usize);
        acc ^= t.neighbourhood(f.voxel).bits();
        if i % 2 == 0 {
            t.insert(f.outside());
        } else if t.voxel_count() > 1 {
            t.remove(f.voxel);
        }
    }
    let dt = t0.elapsed().as_nanos() as f64 / steps as f64;
    black_box(acc);
    println!("RESULT tesseral walk step_ns {dt:.2}");
    // The read-only part of a step on the same surface: draw a face, read the
    // 27-neighbourhoods of the voxels on both sides of it.
    let picks: Vec<usize> = (0..steps)
        .map(|_| (r.next() % t.face_count() as u64) as usize)
        .collect();
    let nb = best_of(3, || {
        let t0 = Instant::now();
        let mut acc = 0u32;
        for &i in &picks {
            let f = t.face(i);
            acc ^= t.neighbourhood(f.voxel).bits() ^ t.neighbourhood(f.outside()).bits();
        }
        black_box(acc);
        t0.elapsed().as_nanos() as f64 / (2 * steps) as f64
    });
    println!("RESULT tesseral walk neighbourhood_ns {nb:.2}");
    println!("RESULT tesseral walk voxels {}", t.voxel_count());
    println!("RESULT tesseral walk faces {}", t.face_count());
    println!(
        "RESULT tesseral walk bytes_per_face {:.2}",
        t.bytes() as f64 / t.face_count() as f64
    );
}

fn criterion_benches(c: &mut Criterion, name: &str, cells: &[Voxel]) {
    let rq = random_cells(2, 1_000_000);
    let oq = occupied_queries(cells.to_vec());
    let mut g = c.benchmark_group(format!("dynamic_{name}"));
    g.sample_size(10);
    g.bench_function("insert_all", |b| {
        b.iter_batched(|| (), |()| build(cells, false), BatchSize::PerIteration)
    });
    let t = build(cells, false);
    g.bench_function("lookup_random_1M", |b| {
        b.iter(|| rq.iter().filter(|&&q| t.contains(q)).count())
    });
    g.bench_function("lookup_occupied_1M", |b| {
        b.iter(|| oq.iter().filter(|&&q| t.contains(q)).count())
    });
    g.bench_function("neighbourhood_occupied_1M", |b| {
        b.iter(|| oq.iter().fold(0u32, |a, &q| a ^ t.neighbourhood(q).bits()))
    });
    let h: HashSet<Voxel> = cells.iter().copied().collect();
    g.bench_function("baseline_hashset_lookup_random_1M", |b| {
        b.iter(|| rq.iter().filter(|q| h.contains(*q)).count())
    });
    g.finish();
}

fn main() {
    let random = random_cells(1, 1_000_000);
    let shell = shell_cells();
    summary("random", &random);
    summary("shell", &shell);
    surface_walk_summary();
    if std::env::var_os("TESSERAL_SUMMARY_ONLY").is_some() {
        return;
    }
    let mut c = Criterion::default().configure_from_args();
    criterion_benches(&mut c, "random", &random);
    criterion_benches(&mut c, "shell", &shell);
    c.final_summary();
}
