//! The tesseral side of `benches/openvdb-setops/run.sh` (issue 17 §1): builds the
//! operand pairs, writes each operand's leaves for the OpenVDB side (four
//! little-endian `i32` per leaf: x, y, z of its lowest voxel, log2 of its side), and
//! times union, intersection and difference on `THREADS` rayon threads (best of
//! `REPS`; on one thread the process's CPU time, on more the wall time).
//!
//! The timed call is `LinearOctree::set_op` on two trees in one space whose bricked
//! forms were made outside the clock (as the OpenVDB side builds its grids outside
//! it): it returns a new tree in canonical form, in bricked form, its allocation
//! included. Also timed: making the two bricked forms from the leaf lists, making
//! the result's leaf list (`leaves()`, its first call), and the same operation on
//! the leaf lists (neither operand bricked), whose result is checked to be equal.
//!
//! `cargo run --release -p tesseral --example setops_peer -- DIR REPS THREADS SCENES [ONLY]`
//! (ONLY: time the workloads whose name contains it).
//!
//! Prints per workload
//! `INPUT <workload> <voxels a> <voxels b> <leaves a> <leaves b> <ms to brick both> <bricked bytes of both>`
//! and per operation
//! `RESULT <workload> <op> <ms> <voxels> <bytes/voxel> <leaves> <ms leaf path> <ms leaves()> <bytes/voxel leaf path>`,
//! where bytes/voxel is the result's heap size (bricked form only; for the leaf
//! path its leaf list) over its voxel count.

use std::io::Write;
use std::path::Path;
use std::time::Instant;

mod common;
use common::process_cpu;

use tesseral::csg::Scene;
use tesseral::linear::{CellClass, LinearOctree, SetOp};

/// A solid ball of radius `r` centred on the lattice point `c`: a voxel is inside
/// when its centre is (`|2x + 1 - 2c|^2 <= 4 r^2` in integers, as OpenVDB gets it
/// through the exported leaves).
fn ball(c: [i64; 3], r: i64) -> impl Fn([i64; 3], u8) -> CellClass + Sync {
    move |min: [i64; 3], k: u8| {
        let s = 1i64 << k;
        let (mut near, mut far) = (0i64, 0i64);
        for a in 0..3 {
            let (lo, hi) = (2 * (min[a] - c[a]) + 1, 2 * (min[a] + s - c[a]) - 1);
            let n = if lo > 0 {
                lo
            } else if hi < 0 {
                hi
            } else {
                0
            };
            near += n * n;
            far += lo.abs().max(hi.abs()).pow(2);
        }
        if far <= 4 * r * r {
            CellClass::Inside
        } else if near > 4 * r * r {
            CellClass::Outside
        } else {
            CellClass::Partial
        }
    }
}

fn spheres(depth: u8, c: i64, r: i64, offset: i64) -> (LinearOctree, LinearOctree) {
    let a = LinearOctree::from_classifier(depth, [0; 3], &ball([c; 3], r)).expect("sphere");
    let b =
        LinearOctree::from_classifier(depth, [0; 3], &ball([c + offset, c, c], r)).expect("sphere");
    // Both wholly inside the space: nothing is clipped.
    let side = 1i64 << depth;
    assert!(
        c - r >= 0 && c + offset + r < side,
        "a sphere leaves the space"
    );
    (a, b)
}

/// splitmix64, as in the benches' `common/`.
fn splitmix(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A block of `n^3` cells from `min`, each black with probability 0.3.
fn porous(depth: u8, min: [i64; 3], n: i64, seed: u64) -> LinearOctree {
    let mut s = seed;
    let threshold = (0.3 * u64::MAX as f64) as u64;
    let mut voxels = Vec::new();
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                if splitmix(&mut s) < threshold {
                    voxels.push([min[0] + x, min[1] + y, min[2] + z]);
                }
            }
        }
    }
    LinearOctree::from_voxels(depth, [0; 3], voxels).expect("porous block")
}

fn scene(dir: &Path, name: &str) -> LinearOctree {
    Scene::read(&dir.join(name))
        .and_then(|s| s.build())
        .expect("scene")
}

fn export(tree: &LinearOctree, path: &Path) {
    let mut out = Vec::with_capacity(tree.leaf_count() * 16);
    for b in tree.blocks() {
        for v in [b.min[0], b.min[1], b.min[2], i64::from(b.size_log2)] {
            let v = i32::try_from(v).expect("fits i32");
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    std::fs::File::create(path)
        .and_then(|mut f| f.write_all(&out))
        .expect("write leaves");
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (dir, reps, threads, scenes, only) = match &args[..] {
        [d, r, t, s] => (d, r, t, s, ""),
        [d, r, t, s, o] => (d, r, t, s, o.as_str()),
        _ => panic!("usage: setops_peer DIR REPS THREADS SCENES [WORKLOAD-SUBSTRING]"),
    };
    let dir = Path::new(dir);
    let reps: usize = reps.parse().expect("REPS");
    let threads: usize = threads.parse().expect("THREADS");
    let scenes = Path::new(scenes);
    // rayon's global pool gets THREADS threads; the operations are called from this
    // thread, as OpenVDB's are from its own (on one thread nothing is handed to the
    // pool: the merge runs on the calling thread).
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build_global()
        .expect("thread pool");

    let mut work: Vec<(&str, LinearOctree, LinearOctree)> = Vec::new();
    let (a, b) = spheres(9, 128, 100, 50);
    work.push(("spheres-r100-d9", a, b));
    let (a, b) = spheres(11, 512, 400, 200);
    work.push(("spheres-r400-d11", a, b));
    work.push((
        "porous-128-d8",
        porous(8, [32, 32, 32], 128, 1),
        porous(8, [96, 32, 32], 128, 2),
    ));
    work.push((
        "scenes-tank-truck-d7",
        scene(scenes, "tank.tss"),
        scene(scenes, "truck.tss"),
    ));
    // The aircraft (depth 8) placed over the showcase's dome (depth 10).
    let showcase = scene(scenes, "showcase.tss");
    let (aircraft, _) = scene(scenes, "aircraft.tss")
        .resample(10, [-384, -384, -160])
        .expect("resample");
    let aircraft = LinearOctree::from_sorted_leaves(10, [0; 3], aircraft.leaves().iter().copied())
        .expect("rebase");
    work.push(("scenes-showcase-aircraft-d10", showcase, aircraft));

    for (name, built_a, built_b) in work.iter().filter(|w| w.0.contains(only)) {
        // The constructors return trees holding both forms; leaf-only copies time
        // the bricking and the leaf path.
        let (a, b) = (&leaf_only(built_a), &leaf_only(built_b));
        export(a, &dir.join(format!("{name}.a.leaves")));
        export(b, &dir.join(format!("{name}.b.leaves")));
        // The bricked forms: the time to make both from the leaf lists (best of
        // REPS, each on fresh leaf-only copies made outside the clock).
        let mut brick_ms = f64::MAX;
        for _ in 0..reps {
            let (x, y) = (a.clone(), b.clone());
            let t0 = process_cpu();
            x.build_bricks();
            y.build_bricks();
            brick_ms = brick_ms.min(process_cpu() - t0);
        }
        // The operands as built (bricked by their constructors).
        let (ab, bb) = (built_a.clone(), built_b.clone());
        ab.build_bricks();
        bb.build_bricks();
        println!(
            "INPUT {name} {} {} {} {} {:.4} {}",
            a.voxel_count(),
            b.voxel_count(),
            a.leaf_count(),
            b.leaf_count(),
            brick_ms * 1e3,
            // The clones hold their leaf lists at capacity = length.
            ab.heap_bytes() + bb.heap_bytes() - 8 * (a.leaf_count() + b.leaf_count()),
        );
        for (op_name, op) in [
            ("union", SetOp::Union),
            ("intersection", SetOp::Intersection),
            ("difference", SetOp::Difference),
        ] {
            // The operation on the bricked forms (what the ratio is of).
            let (best, out) = best_of(reps, threads, || ab.set_op(&bb, op).expect("same space"));
            let voxels = out.voxel_count();
            let bytes = out.heap_bytes() as f64 / (voxels.max(1)) as f64;
            // The leaf list of a bricked result, made on first use.
            let mut leaves_ms = f64::MAX;
            for _ in 0..reps {
                let r = ab.set_op(&bb, op).expect("same space");
                let t0 = process_cpu();
                std::hint::black_box(r.leaves());
                leaves_ms = leaves_ms.min(process_cpu() - t0);
            }
            // The same operation on the leaf lists (neither operand bricked).
            let (leaf_best, leaf_out) =
                best_of(reps, threads, || a.set_op(b, op).expect("same space"));
            assert!(leaf_out == out, "the two paths disagree");
            let leaf_bytes = leaf_out.heap_bytes() as f64 / (voxels.max(1)) as f64;
            println!(
                "RESULT {name} {op_name} {:.4} {voxels} {bytes:.4} {} {:.4} {:.4} {leaf_bytes:.4}",
                best * 1e3,
                out.leaf_count(),
                leaf_best * 1e3,
                leaves_ms * 1e3,
            );
        }
    }
}

/// The best time of `reps` calls of `f` (one thread: the process's CPU time; more:
/// wall time) and the last result; each result is dropped before the next call.
fn best_of(reps: usize, threads: usize, f: impl Fn() -> LinearOctree) -> (f64, LinearOctree) {
    let mut best = f64::MAX;
    let mut out = None;
    for _ in 0..reps {
        drop(out.take());
        let (start, t0) = (Instant::now(), process_cpu());
        let o = f();
        let (wall, cpu) = (start.elapsed().as_secs_f64(), process_cpu() - t0);
        best = best.min(if threads == 1 { cpu } else { wall });
        out = Some(o);
    }
    (best, out.expect("reps > 0"))
}

/// A copy of `t` holding its leaf list only.
fn leaf_only(t: &LinearOctree) -> LinearOctree {
    LinearOctree::from_sorted_leaves(t.depth(), t.origin(), t.leaves().iter().copied())
        .expect("a canonical tree's leaves")
}
