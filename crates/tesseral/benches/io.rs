//! File-format throughput: native `.tess`, OctoMap `.bt`, binvox, and (with the mesh
//! module) voxelization and meshing.
//!
//! `bt_read` decodes a `.bt` with about one million leaves. By default the tree is
//! generated here (1,000,000 random voxels in a 512³ cube, seed 8); set
//! `TESSERAL_BT_FILE=path.bt` to time a given file instead, which is how
//! `benches/octomap/run_bt.sh` times the very file it hands to OctoMap's
//! `readBinary`.

use std::hint::black_box;
use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rand::{Rng, SeedableRng};
use tesseral::io::{binvox, native, octomap, VoxelModel};
use tesseral::linear::LinearOctree;

fn random_tree(n: usize, side: i64, seed: u64) -> LinearOctree {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let voxels: Vec<_> = (0..n)
        .map(|_| {
            [
                rng.random_range(-side / 2..side / 2),
                rng.random_range(-side / 2..side / 2),
                rng.random_range(-side / 2..side / 2),
            ]
        })
        .collect();
    LinearOctree::from_voxels(side.trailing_zeros() as u8, [-side / 2; 3], voxels).unwrap()
}

fn bench_io(c: &mut Criterion) {
    let bt_bytes = match std::env::var_os("TESSERAL_BT_FILE") {
        Some(p) => std::fs::read(&p).expect("TESSERAL_BT_FILE must be readable"),
        None => octomap::encode_bt(&VoxelModel::new(random_tree(1_000_000, 512, 8))).unwrap(),
    };
    let model = octomap::decode_bt(&bt_bytes, Path::new("b.bt")).unwrap();
    let leaves = model.tree.leaf_count();
    let mut g = c.benchmark_group("io");
    g.sample_size(10);
    g.throughput(Throughput::Elements(leaves as u64));
    g.bench_function(format!("bt_read/{leaves}_leaves"), |b| {
        b.iter(|| octomap::decode_bt(black_box(&bt_bytes), Path::new("b.bt")).unwrap())
    });
    g.bench_function(format!("bt_write/{leaves}_leaves"), |b| {
        b.iter(|| octomap::encode_bt(black_box(&model)).unwrap())
    });
    let tess = native::encode(&model);
    g.bench_function(format!("tess_read/{leaves}_leaves"), |b| {
        b.iter(|| native::decode(black_box(&tess), Path::new("b.tess")).unwrap())
    });
    g.bench_function(format!("tess_write/{leaves}_leaves"), |b| {
        b.iter(|| native::encode(black_box(&model)))
    });
    let small = VoxelModel::new(random_tree(200_000, 256, 9));
    let bv = binvox::encode(&small).unwrap();
    g.throughput(Throughput::Elements(small.tree.voxel_count()));
    g.bench_function("binvox_read/200k_voxels_256", |b| {
        b.iter(|| binvox::decode(black_box(&bv), Path::new("b.binvox")).unwrap())
    });
    g.finish();
    eprintln!(
        "io bench: .bt {} bytes, .tess {} bytes for {leaves} leaves ({:.2} bytes/leaf)",
        bt_bytes.len(),
        tess.len(),
        tess.len() as f64 / leaves as f64
    );
}

criterion_group!(benches, bench_io);
criterion_main!(benches);
