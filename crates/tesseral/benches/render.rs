//! Rendering (issue 4 target: 1024 × 1024 primary rays of the depth-10 showcase at
//! ≥ 10 M rays/s per core). Criterion's throughput gives rays per second for the whole
//! machine (rayon over all cores); divide by the cores used for per core. The baseline
//! in the same run is one thread (a rayon pool of size 1).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;
use tesseral::csg::Scene;
use tesseral::render::{primary_hits, render, Camera, RayTree, RenderOptions, View};

fn bench_render(c: &mut Criterion) {
    let src = include_str!("../../../scenes/showcase.tss");
    let scene = Scene::parse(src, "showcase.tss".as_ref()).unwrap();
    let tree = scene.build().unwrap();
    let mut g = c.benchmark_group("render");
    g.sample_size(10);
    g.bench_function("ray_index_build_showcase", |b| {
        b.iter(|| black_box(RayTree::new(&tree)))
    });
    let rt = RayTree::new(&tree);
    let opts = RenderOptions {
        width: 1024,
        height: 1024,
        camera: Camera::view(View::Iso),
        ..Default::default()
    };
    g.throughput(Throughput::Elements(1024 * 1024));
    g.bench_function("primary_rays_1024x1024_showcase", |b| {
        b.iter(|| black_box(primary_hits(&rt, &opts)))
    });
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    g.bench_function("primary_rays_1024x1024_showcase_1_thread", |b| {
        b.iter(|| one.install(|| black_box(primary_hits(&rt, &opts))))
    });
    g.bench_function("shaded_1024x1024_showcase", |b| {
        b.iter(|| black_box(render(&tree, Default::default(), &opts)))
    });
    g.finish();
}

criterion_group!(benches, bench_render);
criterion_main!(benches);
