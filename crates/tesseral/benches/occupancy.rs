//! Scan insertion, memory and random lookup of the occupancy map, on synthetic scans
//! with fixed seeds:
//! - indoor: a 12 × 9 × 3 m room with boxes, sensor inside, ranges to 10 m;
//! - outdoor: ground, buildings and poles over 200 m, ranges to 50 m (longer rays
//!   are cut at 50 m and clear space only).
//!
//! `OCC_SCANS` (default 10) scans of `OCC_RAYS` (default 100 000) rays each, 5 cm.
//! With `OCC_DUMP=dir`, the scans are written to `dir/indoor.scans` and
//! `dir/outdoor.scans` (per scan: origin as 3 × f64, point count as u64, points as
//! 3 × f64 each, little-endian) for the C++ peers, and the figures are printed.
//!
//! Run: `cargo bench -p tesseral --bench occupancy`; one core:
//! `RAYON_NUM_THREADS=1 taskset -c 0 cargo bench -p tesseral --bench occupancy`.

use std::hint::black_box;
use std::io::Write;
use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use tesseral::occupancy::{OccupancyMap, SensorModel};

mod common;
use common::SplitMix64;

struct Scan {
    origin: [f64; 3],
    points: Vec<[f64; 3]>,
}

fn unit(r: &mut SplitMix64) -> f64 {
    (r.next() >> 11) as f64 / (1u64 << 53) as f64
}

/// Distance along `o + t·d` to an axis-aligned box, if hit from outside.
fn hit_box(o: [f64; 3], d: [f64; 3], lo: [f64; 3], hi: [f64; 3]) -> Option<f64> {
    let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
    for a in 0..3 {
        let inv = 1.0 / d[a];
        let (mut u, mut v) = ((lo[a] - o[a]) * inv, (hi[a] - o[a]) * inv);
        if u > v {
            std::mem::swap(&mut u, &mut v);
        }
        t0 = t0.max(u);
        t1 = t1.min(v);
    }
    (t0 <= t1 && t0 > 0.0).then_some(t0)
}

/// Distance to leave the inside of a box.
fn exit_box(o: [f64; 3], d: [f64; 3], lo: [f64; 3], hi: [f64; 3]) -> f64 {
    (0..3)
        .map(|a| {
            if d[a] > 0.0 {
                (hi[a] - o[a]) / d[a]
            } else if d[a] < 0.0 {
                (lo[a] - o[a]) / d[a]
            } else {
                f64::INFINITY
            }
        })
        .fold(f64::INFINITY, f64::min)
}

fn direction(r: &mut SplitMix64) -> [f64; 3] {
    loop {
        let d = [0, 1, 2].map(|_| 2.0 * unit(r) - 1.0);
        let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if n > 0.1 && n <= 1.0 {
            return d.map(|c| c / n);
        }
    }
}

fn scans(outdoor: bool, count: usize, rays: usize) -> Vec<Scan> {
    let mut r = SplitMix64(if outdoor { 0x0D00 } else { 0x1D00 });
    let (lo, hi) = if outdoor {
        ([-100.0, -100.0, 0.0], [100.0, 100.0, 1000.0])
    } else {
        ([0.0, 0.0, 0.0], [12.0, 9.0, 3.0])
    };
    let boxes: Vec<([f64; 3], [f64; 3])> = (0..if outdoor { 60 } else { 12 })
        .map(|_| {
            let c = [0, 1].map(|a| lo[a] + unit(&mut r) * (hi[a] - lo[a]));
            let s = if outdoor {
                [
                    2.0 + 15.0 * unit(&mut r),
                    2.0 + 15.0 * unit(&mut r),
                    3.0 + 25.0 * unit(&mut r),
                ]
            } else {
                [
                    0.3 + unit(&mut r),
                    0.3 + unit(&mut r),
                    0.4 + 1.2 * unit(&mut r),
                ]
            };
            ([c[0], c[1], 0.0], [c[0] + s[0], c[1] + s[1], s[2]])
        })
        .collect();
    (0..count)
        .map(|i| {
            let t = i as f64 / count.max(1) as f64;
            let origin = if outdoor {
                [-60.0 + 120.0 * t, 20.0 * (6.0 * t).sin(), 1.8]
            } else {
                [1.0 + 10.0 * t, 4.5 + 3.0 * (6.0 * t).sin(), 1.2]
            };
            let points = (0..rays)
                .map(|_| {
                    let d = direction(&mut r);
                    let mut t = exit_box(origin, d, lo, hi);
                    for (a, b) in &boxes {
                        if let Some(u) = hit_box(origin, d, *a, *b) {
                            t = t.min(u);
                        }
                    }
                    // Outdoors the sky returns nothing: cap at 80 m (cut at 50 m).
                    let t = t.min(if outdoor { 80.0 } else { 10.0 });
                    [0, 1, 2].map(|a| origin[a] + d[a] * t)
                })
                .collect();
            Scan { origin, points }
        })
        .collect()
}

fn env(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

fn build(scans: &[Scan], max_range: f64) -> OccupancyMap {
    let mut map = OccupancyMap::new(0.05, SensorModel::octomap()).unwrap();
    for s in scans {
        map.insert_scan(s.origin, &s.points, Some(max_range));
    }
    map
}

fn dump(dir: &str, name: &str, scans: &[Scan]) {
    let mut f =
        std::io::BufWriter::new(std::fs::File::create(format!("{dir}/{name}.scans")).unwrap());
    for s in scans {
        for c in s.origin {
            f.write_all(&c.to_le_bytes()).unwrap();
        }
        f.write_all(&(s.points.len() as u64).to_le_bytes()).unwrap();
        for p in &s.points {
            for c in p {
                f.write_all(&c.to_le_bytes()).unwrap();
            }
        }
    }
}

fn bench(c: &mut Criterion) {
    let (count, rays) = (env("OCC_SCANS", 10), env("OCC_RAYS", 100_000));
    for (name, outdoor, max_range) in [("indoor", false, 10.0), ("outdoor", true, 50.0)] {
        let sc = scans(outdoor, count, rays);
        if let Ok(dir) = std::env::var("OCC_DUMP") {
            dump(&dir, name, &sc);
            let t = Instant::now();
            let map = build(&sc, max_range);
            let s = t.elapsed().as_secs_f64();
            let mut r = SplitMix64(7);
            let cells: Vec<[i64; 3]> = (0..1_000_000)
                .map(|_| {
                    let s = &sc[(r.next() % sc.len() as u64) as usize];
                    let p = s.points[(r.next() % s.points.len() as u64) as usize];
                    map.cell_of(p)
                })
                .collect();
            let t = Instant::now();
            let known = cells.iter().filter(|&&c| map.log_odds(c).is_some()).count();
            let l = t.elapsed().as_secs_f64();
            println!(
                "{name}: {} scans x {rays} rays: {s:.3} s, {:.3e} rays/s, {} bytes ({:.1} MB), {} occupied, {} free, {} blocks; lookup {:.1} ns ({known} known of 1e6)",
                sc.len(),
                (sc.len() * rays) as f64 / s,
                map.bytes(),
                map.bytes() as f64 / 1e6,
                map.occupied_count(),
                map.free_count(),
                map.block_count(),
                l * 1e3,
            );
        }
        let mut g = c.benchmark_group(format!("occupancy_{name}"));
        g.sample_size(10);
        g.throughput(Throughput::Elements((sc.len() * rays) as u64));
        g.bench_function("insert_scans", |b| {
            b.iter(|| black_box(build(&sc, max_range)))
        });
        let map = build(&sc, max_range);
        let mut r = SplitMix64(9);
        let cells: Vec<[i64; 3]> = (0..100_000)
            .map(|_| {
                let s = &sc[(r.next() % sc.len() as u64) as usize];
                map.cell_of(s.points[(r.next() % s.points.len() as u64) as usize])
            })
            .collect();
        g.throughput(Throughput::Elements(cells.len() as u64));
        g.bench_function("lookup_random", |b| {
            b.iter(|| {
                cells
                    .iter()
                    .filter(|&&c| map.log_odds(black_box(c)).is_some())
                    .count()
            })
        });
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
