//! The tesseral side of `benches/openvdb-transform/run.sh`: a solid sphere of radius
//! R (voxel centres inside) rotated by DEGREES about z through the origin with
//! point sampling, on one thread; best of 5, in wall-clock time and in the process's
//! CPU time (the latter is steadier on a loaded machine).
//!
//! `cargo run --release -p tesseral --example rotate_sphere -- [R] [DEGREES]`

use std::time::Instant;

use tesseral::linear::rotation_matrix;

mod common;
use common::{process_cpu, sphere};

fn main() {
    let mut args = std::env::args().skip(1);
    let r: i64 = args.next().map_or(100, |a| a.parse().expect("radius"));
    let degrees: f64 = args.next().map_or(30.0, |a| a.parse().expect("degrees"));
    let tree = sphere(r);
    let m = rotation_matrix([0.0, 0.0, 1.0], degrees);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("one thread");
    let (mut best, mut best_cpu) = (f64::MAX, f64::MAX);
    let mut out = None;
    for _ in 0..5 {
        let (start, cpu) = (Instant::now(), process_cpu());
        let o = pool.install(|| tree.affine(m, [0.0; 3]).expect("rotate"));
        best = best.min(start.elapsed().as_secs_f64());
        best_cpu = best_cpu.min(process_cpu() - cpu);
        out = Some(o);
    }
    let out = out.expect("five runs");
    println!(
        "tesseral: sphere r={r} ({} voxels, {} leaves) rotated {degrees} deg about z, one core: {:.1} ms (cpu {:.1} ms), {} voxels, {} leaves",
        tree.voxel_count(),
        tree.leaf_count(),
        best * 1e3,
        best_cpu * 1e3,
        out.voxel_count(),
        out.leaf_count()
    );
}
