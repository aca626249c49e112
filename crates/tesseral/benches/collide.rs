//! Interference benchmarks on the same pairs of objects as the FCL harness in
//! `benches/fcl/` (Debian's libfcl-dev, `OcTree`-vs-`OcTree` `collide`):
//! - `spheres`: two balls of radius 32 (137 k voxels each), approaching diagonally;
//! - `room`: a hollow 128³ room with 4-voxel walls and a 16³ crate inside it;
//! - `terrain`: a 128 × 128 height field and a ball of radius 16 above it;
//! - `porous`: two 64³ blocks of random voxels (density 0.3), a worst case for
//!   octrees: hardly any block merges.
//!
//! Each pair is queried **touching** (the least overlap along the approach: a few
//! shared voxels), **near** (the first offset along the approach where the solids
//! do not even touch: a gap of about one voxel, the hardest case to prove; FCL counts
//! touching faces as a collision, so the offsets in between are left out) and
//! **apart** (3 steps further).
//!
//! First a plain timed summary prints `RESULT tesseral <pair> <state> ns <value>`
//! lines, with a `HashSet` baseline measured in the same run; with
//! `TESSERAL_FCL_PAIRS=DIR` it also writes the pairs as `.xyz` files and a manifest
//! for the C++ harness. `benches/fcl/run.sh` runs both and prints the ratios. Then
//! criterion runs (skip it with `TESSERAL_SUMMARY_ONLY=1`).

mod common;

use std::collections::HashSet;
use std::fmt::Write as _;
use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

use criterion::Criterion;
use tesseral::linear::LinearOctree;
use tesseral::motion::{
    clearance, clearance_squared, first_contact, interference, intersects, plan, BoxTree, Placed,
    Placement, PlanOptions,
};
use tesseral::Voxel;

use common::SplitMix64;

struct Pair {
    name: &'static str,
    a: Vec<Voxel>,
    b: Vec<Voxel>,
    /// Where the approach starts (B's offset) and its unit step.
    start: Voxel,
    dir: Voxel,
}

fn ball(r: i64) -> Vec<Voxel> {
    let mut v = Vec::new();
    let r2 = 4 * r * r;
    for x in 0..2 * r {
        for y in 0..2 * r {
            for z in 0..2 * r {
                let d = (2 * x + 1 - 2 * r).pow(2)
                    + (2 * y + 1 - 2 * r).pow(2)
                    + (2 * z + 1 - 2 * r).pow(2);
                if d < r2 {
                    v.push([x, y, z]);
                }
            }
        }
    }
    v
}

fn cube(side: i64) -> Vec<Voxel> {
    (0..side * side * side)
        .map(|i| [i % side, i / side % side, i / side / side])
        .collect()
}

fn room() -> Vec<Voxel> {
    let (n, t) = (128i64, 4i64);
    cube(n)
        .into_iter()
        .filter(|v| v.iter().any(|&c| c < t || c >= n - t))
        .collect()
}

fn terrain() -> Vec<Voxel> {
    let mut v = Vec::new();
    for x in 0..128i64 {
        for y in 0..128i64 {
            let h = 20.0
                + 8.0 * (x as f64 / 9.0).sin()
                + 6.0 * (y as f64 / 7.0).cos()
                + 3.0 * ((x + y) as f64 / 4.0).sin();
            for z in 0..h as i64 {
                v.push([x, y, z]);
            }
        }
    }
    v
}

fn porous(seed: u64) -> Vec<Voxel> {
    let mut r = SplitMix64(seed);
    cube(64).into_iter().filter(|_| r.next() % 10 < 3).collect()
}

fn pairs() -> Vec<Pair> {
    vec![
        Pair {
            name: "spheres",
            a: ball(32),
            b: ball(32),
            start: [0, 0, 0],
            dir: [1, 1, 0],
        },
        Pair {
            name: "room",
            a: room(),
            b: cube(16),
            start: [56, 56, 56],
            dir: [1, 0, 0],
        },
        Pair {
            name: "terrain",
            a: terrain(),
            b: ball(16),
            start: [48, 48, 0],
            dir: [0, 0, 1],
        },
        Pair {
            name: "porous",
            a: porous(1),
            b: porous(2),
            start: [0, 0, 0],
            dir: [1, 1, 1],
        },
    ]
}

struct Prepared {
    name: &'static str,
    a: LinearOctree,
    b: LinearOctree,
    va: Vec<Voxel>,
    vb: Vec<Voxel>,
    touching: Voxel,
    near: Voxel,
    apart: Voxel,
}

impl Prepared {
    fn states(&self) -> [(&'static str, Voxel, bool); 3] {
        [
            ("touching", self.touching, true),
            ("near", self.near, false),
            ("apart", self.apart, false),
        ]
    }
}

fn prepare(p: Pair) -> Prepared {
    let a = LinearOctree::from_voxels_fitted(&p.a).unwrap();
    let b = LinearOctree::from_voxels_fitted(&p.b).unwrap();
    let at = |k: i64| [0, 1, 2].map(|i| p.start[i] + k * p.dir[i]);
    // Walk along the approach until the state flips; touching is the overlapping
    // offset next to the flip, separated is 3 steps on the free side.
    let first = intersects(&a, &b, Placement::at(at(0)));
    let mut k = 0;
    while intersects(&a, &b, Placement::at(at(k + 1))) == first {
        k += 1;
        assert!(k < 10_000, "{}: no flip along the approach", p.name);
    }
    // Step further away until the closed voxel cubes do not even touch.
    let away: i64 = if first { 1 } else { -1 };
    let touching = if first { k } else { k + 1 };
    let mut free = touching + away;
    let (pa, pb) = (BoxTree::new(&a), BoxTree::new(&b));
    while clearance_squared(
        Placed::fixed(&pa),
        Placed::new(&pb, Placement::at(at(free))),
    ) == Some(0)
    {
        free += away;
    }
    let (touching, near, apart) = (at(touching), at(free), at(free + 3 * away));
    assert!(intersects(&a, &b, Placement::at(touching)));
    assert!(!intersects(&a, &b, Placement::at(near)));
    assert!(!intersects(&a, &b, Placement::at(apart)));
    Prepared {
        name: p.name,
        a,
        b,
        va: p.a,
        vb: p.b,
        touching,
        near,
        apart,
    }
}

/// Mean nanoseconds per call, best of 5 batches of at least 0.2 s.
fn time_ns(mut f: impl FnMut() -> bool) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let t = Instant::now();
        let mut n = 0u64;
        while t.elapsed().as_secs_f64() < 0.2 {
            for _ in 0..16 {
                black_box(f());
            }
            n += 16;
        }
        best = best.min(t.elapsed().as_secs_f64() * 1e9 / n as f64);
    }
    best
}

fn write_pairs(dir: &Path, prepared: &[Prepared]) {
    std::fs::create_dir_all(dir).unwrap();
    let mut manifest = String::new();
    for p in prepared {
        for (side, vs) in [("a", &p.va), ("b", &p.vb)] {
            let mut s = String::with_capacity(vs.len() * 12);
            for v in vs {
                writeln!(s, "{} {} {}", v[0], v[1], v[2]).unwrap();
            }
            std::fs::write(dir.join(format!("{}_{side}.xyz", p.name)), s).unwrap();
        }
        for (state, o, hit) in p.states() {
            writeln!(
                manifest,
                "{} {state} {} {} {} {}",
                p.name,
                o[0],
                o[1],
                o[2],
                u8::from(hit)
            )
            .unwrap();
        }
    }
    std::fs::write(dir.join("pairs.txt"), manifest).unwrap();
}

fn summary(prepared: &[Prepared]) {
    for p in prepared {
        println!(
            "INFO tesseral {} leaves {} {} voxels {} {}",
            p.name,
            p.a.leaf_count(),
            p.b.leaf_count(),
            p.va.len(),
            p.vb.len()
        );
        let set: HashSet<Voxel> = p.va.iter().copied().collect();
        let (pa, pb) = (BoxTree::new(&p.a), BoxTree::new(&p.b));
        for (state, o, _) in p.states() {
            let place = Placement::at(o);
            // Prepared trees (built once per object, as FCL's OcTree is).
            let ns = time_ns(|| intersects(&pa, &pb, place));
            println!("RESULT tesseral {} {state} ns {ns:.1}", p.name);
            let ns = time_ns(|| interference(&pa, &pb, place, false).intersects);
            println!("RESULT tesseral-volume {} {state} ns {ns:.1}", p.name);
            // The linear octrees as they are, with no preparation.
            let ns = time_ns(|| intersects(&p.a, &p.b, place));
            println!("RESULT tesseral-linear {} {state} ns {ns:.1}", p.name);
            // Baseline: look every voxel of B up in a hash set of A's voxels.
            let base = time_ns(|| {
                p.vb.iter()
                    .any(|v| set.contains(&[v[0] + o[0], v[1] + o[1], v[2] + o[2]]))
            });
            println!("RESULT hashset {} {state} ns {base:.1}", p.name);
        }
    }
}

fn main() {
    let prepared: Vec<Prepared> = pairs().into_iter().map(prepare).collect();
    if let Ok(dir) = std::env::var("TESSERAL_FCL_PAIRS") {
        write_pairs(Path::new(&dir), &prepared);
    }
    summary(&prepared);
    if std::env::var_os("TESSERAL_SUMMARY_ONLY").is_some() {
        return;
    }
    let mut c = Criterion::default().configure_from_args();
    for p in &prepared {
        let mut g = c.benchmark_group(format!("collide/{}", p.name));
        let (pa, pb) = (BoxTree::new(&p.a), BoxTree::new(&p.b));
        g.bench_function("prepare", |b| b.iter(|| BoxTree::new(black_box(&p.a))));
        for (state, o, _) in p.states() {
            let place = Placement::at(o);
            g.bench_function(format!("intersects/{state}"), |b| {
                b.iter(|| intersects(black_box(&pa), black_box(&pb), place))
            });
            g.bench_function(format!("intersects_linear/{state}"), |b| {
                b.iter(|| intersects(black_box(&p.a), black_box(&p.b), place))
            });
            g.bench_function(format!("volume/{state}"), |b| {
                b.iter(|| interference(black_box(&pa), black_box(&pb), place, false))
            });
            g.bench_function(format!("clearance/{state}"), |b| {
                b.iter(|| clearance(black_box(&pa), black_box(&pb), place))
            });
        }
        // The swept test over the whole approach, from 20 steps back to the contact.
        let back = [0, 1, 2].map(|i| p.apart[i] + 8 * (p.apart[i] - p.touching[i]));
        let mv = [0, 1, 2].map(|i| p.touching[i] - back[i]);
        g.bench_function("first_contact", |b| {
            b.iter(|| {
                first_contact(
                    Placed::fixed(black_box(&pa)),
                    [0; 3],
                    Placed::new(black_box(&pb), Placement::at(back)),
                    mv,
                )
            })
        });
        g.finish();
    }
    // Planning: the crate across the room, through a wall with a door.
    let mut room_voxels = room();
    room_voxels.extend(
        (4..124i64)
            .flat_map(|y| (4..124i64).map(move |z| [64, y, z]))
            .filter(|v| !((40..70).contains(&v[1]) && (4..40).contains(&v[2]))),
    );
    let env = LinearOctree::from_voxels_fitted(&room_voxels).unwrap();
    let crate16 = LinearOctree::from_voxels_fitted(&cube(16)).unwrap();
    c.bench_function("plan/room_door", |b| {
        b.iter(|| {
            plan(
                &env,
                &crate16,
                [8, 8, 8],
                [100, 100, 8],
                &PlanOptions::default(),
            )
            .unwrap()
        })
    });
    c.final_summary();
}
