//! The tesseral side of `benches/occupancy/run.sh` (issue 13 §8): writes the synthetic
//! indoor and outdoor scans for the C++ peers (Bonxai, OctoMap) and times
//! `OccupancyMap::insert_scans` (the scans in order, each cast while the one before
//! it is applied) and random lookups on them.
//!
//! - `occupancy_peer gen DIR SCANS RAYS`: writes `DIR/indoor.scans` and
//!   `DIR/outdoor.scans` (per scan: origin as 3 × `f64`, point count as `u64`, points
//!   as 3 × `f64` each, little-endian).
//! - `occupancy_peer xyz CLOUD OUT COPIES`: writes a real scan given as text lines
//!   `x y z` (sensor at the origin, e.g. OctoMap's `share/data/scan.dat`) as `OUT`,
//!   `COPIES` scans of it from the same pose (a sensor standing still).
//! - `occupancy_peer run FILE MAX_RANGE`: builds the map at 5 cm, OctoMap's sensor
//!   model, then looks up 10⁶ cells drawn at random from the scans' end points (the
//!   same splitmix64 draws as the C++ drivers) and prints one `RESULT` line: scans,
//!   rays, insertion wall and CPU seconds, rays per second (wall), the map's bytes,
//!   occupied and free cells, lookup ns (a loop of `log_odds`, as the peers' loops
//!   of single lookups; wall, then `lookup_cpu_ns` in process CPU time), cells
//!   known, and `lookup_many_ns`, `lookup_many_cpu_ns`: the same cells through the
//!   batched `log_odds_many`, per cell; then `lookup_loops`, `lookup_min_cpu_ns` and
//!   `lookup_median_cpu_ns` over the first loop and `LOOKUP_LOOPS − 1` more (5 in all
//!   by default), and `lookup_turns_cpu_ns`, every loop's in order, as the C++ drivers
//!   report them. With `LOOKUP_GATE` it waits before the lookups (see `lookup_gate`),
//!   and with `LOOKUP_TURNS=1` too before each later loop (see `turn_gate`).
//!
//! The rayon pool size is `RAYON_NUM_THREADS` (one core: `RAYON_NUM_THREADS=1`).

#[path = "../benches/common/mod.rs"]
mod common;
#[path = "common/mod.rs"]
mod shared;

use std::io::{Read, Write};
use std::time::Instant;

use common::scans::{scans, Scan};
use common::SplitMix64;
use shared::process_cpu;
use tesseral::occupancy::{OccupancyMap, SensorModel};

fn write_scans(path: &str, scans: &[Scan]) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    for s in scans {
        for c in s.origin {
            f.write_all(&c.to_le_bytes())?;
        }
        f.write_all(&(s.points.len() as u64).to_le_bytes())?;
        for p in &s.points {
            for c in p {
                f.write_all(&c.to_le_bytes())?;
            }
        }
    }
    f.flush()
}

fn read_scans(path: &str) -> std::io::Result<Vec<Scan>> {
    let mut bytes = Vec::new();
    std::fs::File::open(path)?.read_to_end(&mut bytes)?;
    let mut words = bytes
        .chunks_exact(8)
        .map(|w| <[u8; 8]>::try_from(w).expect("8 bytes"));
    let mut out = Vec::new();
    while let Some(w) = words.next() {
        let mut f = || f64::from_le_bytes(words.next().expect("truncated scan file"));
        let origin = [f64::from_le_bytes(w), f(), f()];
        let n = u64::from_le_bytes(words.next().expect("truncated scan file"));
        let points = (0..n)
            .map(|_| {
                let mut f = || f64::from_le_bytes(words.next().expect("truncated scan file"));
                [f(), f(), f()]
            })
            .collect();
        out.push(Scan { origin, points });
    }
    Ok(out)
}

fn main() -> std::io::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let arg = |i: usize| -> &str {
        args.get(i).map_or_else(
            || {
                panic!(
                    "usage: occupancy_peer gen DIR SCANS RAYS | xyz CLOUD OUT COPIES | run FILE MAX_RANGE"
                )
            },
            String::as_str,
        )
    };
    match arg(1) {
        "gen" => {
            let (count, rays) = (
                arg(3).parse().expect("SCANS"),
                arg(4).parse().expect("RAYS"),
            );
            for (name, outdoor) in [("indoor", false), ("outdoor", true)] {
                write_scans(
                    &format!("{}/{name}.scans", arg(2)),
                    &scans(outdoor, count, rays),
                )?;
            }
        }
        "xyz" => {
            let text = std::fs::read_to_string(arg(2))?;
            let points: Vec<[f64; 3]> = text
                .lines()
                .filter(|l| !l.trim().is_empty())
                .map(|l| {
                    let v: Vec<f64> = l
                        .split_whitespace()
                        .map(|w| w.parse().expect("a number"))
                        .collect();
                    [v[0], v[1], v[2]]
                })
                .collect();
            let copies: usize = arg(4).parse().expect("COPIES");
            let scan = Scan {
                origin: [0.0; 3],
                points,
            };
            write_scans(arg(3), &vec![scan; copies])?;
        }
        "run" => {
            let sc = read_scans(arg(2))?;
            let max_range: f64 = arg(3).parse().expect("MAX_RANGE");
            let rays: usize = sc.iter().map(|s| s.points.len()).sum();
            let mut map = OccupancyMap::new(0.05, SensorModel::octomap()).expect("map");
            let (t, c) = (Instant::now(), process_cpu());
            // The library's call for a sequence of scans: each scan's rays are cast
            // while the one before it is applied (one core: the same work as a loop
            // of `insert_scan`).
            map.insert_scans(
                sc.iter().map(|s| (s.origin, s.points.as_slice())),
                Some(max_range),
            );
            let (wall, cpu) = (t.elapsed().as_secs_f64(), process_cpu() - c);
            let mut r = SplitMix64(7);
            let cells: Vec<[i64; 3]> = (0..1_000_000)
                .map(|_| {
                    let s = &sc[(r.next() % sc.len() as u64) as usize];
                    map.cell_of(s.points[(r.next() % s.points.len() as u64) as usize])
                })
                .collect();
            // The loop the C++ drivers run: one lookup per cell, the cells known
            // counted. (No `black_box` around each cell: the peers' loops have no
            // such barrier, and it cost our loop a store and a reload per cell, 12 %
            // of a lookup on the real scan.)
            let count_known = || cells.iter().filter(|&&c| map.log_odds(c).is_some()).count();
            lookup_gate()?;
            read_keys(&cells);
            let (t, c) = (Instant::now(), process_cpu());
            let known = count_known();
            let (lookup, lookup_cpu) = (t.elapsed().as_secs_f64(), process_cpu() - c);
            // More loops over the same cells, as the C++ drivers do (`repeat_lookups`).
            let loops = lookup_loops(
                lookup_cpu * 1e9 / cells.len() as f64,
                cells.len(),
                || read_keys(&cells),
                count_known,
            )?;
            // The same cells through the batched lookup (prefetching in passes).
            let mut out = vec![None; cells.len()];
            let (t, c) = (Instant::now(), process_cpu());
            map.log_odds_many(std::hint::black_box(&cells), &mut out);
            let known_many = out.iter().filter(|v| v.is_some()).count();
            let (many, many_cpu) = (t.elapsed().as_secs_f64(), process_cpu() - c);
            assert_eq!(known_many, known, "batched and single lookups agree");
            let counts = map.counts();
            println!(
                "RESULT tesseral scans {} rays {rays} insert_s {wall:.3} cpu_s {cpu:.3} rays_per_s {:.4e} bytes {} occupied {} free {} lookup_ns {:.1} known {known} lookup_cpu_ns {:.1} lookup_many_ns {:.1} lookup_many_cpu_ns {:.1} {loops}",
                sc.len(),
                rays as f64 / wall,
                map.bytes(),
                counts.occupied,
                counts.free,
                lookup * 1e3,
                lookup_cpu * 1e3,
                many * 1e3,
                many_cpu * 1e3,
            );
        }
        other => panic!("unknown command {other}: gen, xyz or run"),
    }
    Ok(())
}

/// With `LOOKUP_GATE=PATH` (`run.sh`'s paired runs): creates `PATH.ready` once the
/// map is built and the cells drawn, then waits, idle, until `PATH.go` exists, as
/// `scans.hpp`'s `lookup_gate` does for the C++ peers, so that the tools' lookups
/// are timed one right after another rather than minutes apart.
fn lookup_gate() -> std::io::Result<()> {
    let Some(base) = std::env::var_os("LOOKUP_GATE").filter(|g| !g.is_empty()) else {
        return Ok(());
    };
    let with = |ext: &str| {
        let mut p = base.clone();
        p.push(ext);
        std::path::PathBuf::from(p)
    };
    std::fs::File::create(with(".ready"))?;
    let go = with(".go");
    while !go.exists() {
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    Ok(())
}

/// Reads the cells to be looked up, so that the timed loop finds them in the cache,
/// as `scans.hpp`'s `read_keys` does for the C++ peers: in the paired runs the other
/// tools' work evicts them while this one waits at its gate, and a loop streaming its
/// 24-byte keys from memory was up to 70 % slower in the room (OctoMap's keys are 6
/// bytes, and its loop twenty times longer). The map is not touched.
fn read_keys(cells: &[[i64; 3]]) {
    std::hint::black_box(cells.iter().fold(0, |a, c| a ^ c[0]));
}

/// With `LOOKUP_GATE=PATH` and `LOOKUP_TURNS=1` (`run.sh`'s paired runs): the gate
/// files of lookup loop `k` (from 0, the first timed one), which waits for
/// `PATH.go` (k = 0, in [`lookup_gate`]) or `PATH.go<k>` and creates `PATH.done<k>`
/// once timed, as `scans.hpp`'s `turn_wait` and `turn_done`: the tools' loops take
/// turns, each tool's loop k right after the others' loop k.
fn turn_gate(k: usize, what: &str) -> Option<std::path::PathBuf> {
    let base = std::env::var_os("LOOKUP_GATE").filter(|g| !g.is_empty())?;
    (std::env::var_os("LOOKUP_TURNS")? == "1").then(|| {
        let mut p = base;
        p.push(format!(".{what}{k}"));
        std::path::PathBuf::from(p)
    })
}

/// Waits for lookup loop `k`'s turn (k ≥ 1: loop 0 waits in [`lookup_gate`]).
fn turn_wait(k: usize) {
    if let Some(go) = turn_gate(k, "go") {
        while !go.exists() {
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
    }
}

/// Ends lookup loop `k`'s turn.
fn turn_done(k: usize) -> std::io::Result<()> {
    match turn_gate(k, "done") {
        Some(done) => std::fs::File::create(done).map(drop),
        None => Ok(()),
    }
}

/// Ends the first timed loop's turn, then gives `lookup_loops N lookup_min_cpu_ns X
/// lookup_median_cpu_ns Y lookup_turns_cpu_ns A,B,...` over the first loop
/// (`first_ns`, process CPU ns per lookup) and `LOOKUP_LOOPS − 1` more runs of `run`
/// (`LOOKUP_LOOPS` defaults to 5), which looks up `cells` cells, each run in its turn
/// ([`turn_wait`]; then the turn numbered `LOOKUP_LOOPS` for the rest of the run)
/// after `before` (the keys read again): the fastest and the median loop, and every
/// loop in order, as `scans.hpp`'s `repeat_lookups` and `print_loops` give them for
/// the C++ peers, so that a loop slowed by another process can be told from the
/// tool's own time.
fn lookup_loops(
    first_ns: f64,
    cells: usize,
    before: impl Fn(),
    run: impl Fn() -> usize,
) -> std::io::Result<String> {
    let loops = std::env::var("LOOKUP_LOOPS")
        .ok()
        .and_then(|v| v.parse::<usize>().ok())
        .unwrap_or(5)
        .max(1);
    let mut ns = vec![first_ns];
    turn_done(0)?;
    for k in 1..loops {
        turn_wait(k);
        before();
        let c = process_cpu();
        std::hint::black_box(run());
        ns.push((process_cpu() - c) * 1e9 / cells as f64);
        turn_done(k)?;
    }
    // The rest of the run (the batched lookups, exiting) in a turn of its own, after
    // every tool's loops, so that no other tool's exit shares the core with it.
    turn_wait(loops);
    let turns: Vec<String> = ns.iter().map(|x| format!("{x:.1}")).collect();
    ns.sort_by(f64::total_cmp);
    Ok(format!(
        "lookup_loops {} lookup_min_cpu_ns {:.1} lookup_median_cpu_ns {:.1} lookup_turns_cpu_ns {}",
        ns.len(),
        ns[0],
        ns[ns.len() / 2],
        turns.join(",")
    ))
}
