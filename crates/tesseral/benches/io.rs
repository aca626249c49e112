//! File-format throughput: native `.tess`, OctoMap `.bt`, binvox, and (with the mesh
//! module) voxelization and meshing.
//!
//! `bt_read` decodes a `.bt` with about one million leaves. By default the tree is
//! generated here (1,000,000 random voxels in a 512³ cube, seed 8); set
//! `TESSERAL_BT_FILE=path.bt` to time a given file instead, which is how
//! `benches/octomap/run_bt.sh` times the very file it hands to OctoMap's
//! `readBinary`.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rand::{Rng, SeedableRng};
use tesseral::io::{binvox, native, octomap, Model};
use tesseral::linear::LinearOctree;
use tesseral::mesh::{boundary_mesh, voxelize, Resolution, TriMesh, VoxelizeOptions};

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
        None => octomap::encode_bt(&Model::new(random_tree(1_000_000, 512, 8))).unwrap(),
    };
    let model = octomap::decode_bt(&bt_bytes).unwrap();
    let leaves = model.tree.leaf_count();
    let mut g = c.benchmark_group("io");
    g.sample_size(10);
    g.throughput(Throughput::Elements(leaves as u64));
    g.bench_function(format!("bt_read/{leaves}_leaves"), |b| {
        b.iter(|| octomap::decode_bt(black_box(&bt_bytes)).unwrap())
    });
    g.bench_function(format!("bt_write/{leaves}_leaves"), |b| {
        b.iter(|| octomap::encode_bt(black_box(&model)).unwrap())
    });
    let tess = native::encode(&model);
    g.bench_function(format!("tess_read/{leaves}_leaves"), |b| {
        b.iter(|| native::decode(black_box(&tess)).unwrap())
    });
    g.bench_function(format!("tess_write/{leaves}_leaves"), |b| {
        b.iter(|| native::encode(black_box(&model)))
    });
    let small = Model::new(random_tree(200_000, 256, 9));
    let bv = binvox::encode(&small).unwrap();
    g.throughput(Throughput::Elements(small.tree.voxel_count()));
    g.bench_function("binvox_read/200k_voxels_256", |b| {
        b.iter(|| binvox::decode(black_box(&bv)).unwrap())
    });
    g.finish();
    eprintln!(
        "io bench: .bt {} bytes, .tess {} bytes for {leaves} leaves ({:.2} bytes/leaf)",
        bt_bytes.len(),
        tess.len(),
        tess.len() as f64 / leaves as f64
    );
}

/// A closed UV sphere of radius 1 with bumps, `2·lon·(lat−1)` triangles.
fn bumpy_sphere(lat: usize, lon: usize) -> TriMesh {
    let mut positions = vec![[0.0, 0.0, -1.0]];
    for i in 1..lat {
        let th = std::f64::consts::PI * i as f64 / lat as f64;
        for j in 0..lon {
            let ph = 2.0 * std::f64::consts::PI * j as f64 / lon as f64;
            let r = 1.0 + 0.05 * (5.0 * th).sin() * (7.0 * ph).cos();
            positions.push([
                r * th.sin() * ph.cos(),
                r * th.sin() * ph.sin(),
                -r * th.cos(),
            ]);
        }
    }
    positions.push([0.0, 0.0, 1.0]);
    let top = (positions.len() - 1) as u32;
    let at = |i: usize, j: usize| (1 + (i - 1) * lon + j % lon) as u32;
    let mut triangles = Vec::new();
    for j in 0..lon {
        triangles.push([0, at(1, j + 1), at(1, j)]);
        triangles.push([top, at(lat - 1, j), at(lat - 1, j + 1)]);
    }
    for i in 1..lat - 1 {
        for j in 0..lon {
            triangles.push([at(i, j), at(i, j + 1), at(i + 1, j + 1)]);
            triangles.push([at(i, j), at(i + 1, j + 1), at(i + 1, j)]);
        }
    }
    TriMesh {
        positions,
        triangles,
        colors: Vec::new(),
    }
}

fn bench_mesh(c: &mut Criterion) {
    let sphere = bumpy_sphere(225, 224);
    let n = sphere.triangles.len();
    let mut g = c.benchmark_group("mesh");
    g.sample_size(10);
    for (depth, surface_only) in [(10u8, false), (10, true), (8, false)] {
        let opts = VoxelizeOptions {
            resolution: Resolution::Depth(depth),
            surface_only,
            ..Default::default()
        };
        let label = if surface_only { "surface" } else { "solid" };
        g.bench_function(
            format!("voxelize_{label}/{n}_triangles_depth_{depth}"),
            |b| b.iter(|| voxelize(black_box(&sphere), &opts).unwrap()),
        );
    }
    let solid = voxelize(
        &sphere,
        &VoxelizeOptions {
            resolution: Resolution::Depth(8),
            surface_only: false,
            ..Default::default()
        },
    )
    .unwrap();
    let mesh = boundary_mesh(&solid.tree);
    eprintln!(
        "mesh bench: depth-8 solid {} voxels, {} leaves -> {} triangles, {} vertices",
        solid.tree.voxel_count(),
        solid.tree.leaf_count(),
        mesh.triangles.len(),
        mesh.positions.len()
    );
    g.bench_function("boundary_mesh/sphere_depth_8", |b| {
        b.iter(|| boundary_mesh(black_box(&solid.tree)))
    });
    g.finish();
}

criterion_group!(benches, bench_io, bench_mesh);
criterion_main!(benches);
