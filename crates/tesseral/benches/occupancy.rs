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
use common::scans::{scans, Scan};
use common::SplitMix64;

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
