//! Building octrees from solids and scenes (issue 4 targets: sphere r = 100 at depth 8
//! ≤ 3 ms; sphere r = 1000 at depth 11 ≤ 300 ms; the depth-10 showcase ≤ 1 s).
//! The baseline in the same run is the generic top-down builder
//! (`LinearOctree::from_classifier`) over the same classifier, without pruning.

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use tesseral::csg::{Scene, Shape, Solid};
use tesseral::linear::LinearOctree;

fn sphere(r: f64, depth: u8) -> tesseral::csg::Csg {
    let c = f64::from(1u32 << depth) / 2.0;
    Solid::shape(Shape::sphere(r))
        .at([c, c, c])
        .compile()
        .unwrap()
}

fn bench_spheres(c: &mut Criterion) {
    let mut g = c.benchmark_group("scene");
    g.sample_size(10);
    let s8 = sphere(100.0, 8);
    g.bench_function("sphere_r100_d8", |b| {
        b.iter(|| black_box(s8.build(8, [0, 0, 0]).unwrap()))
    });
    g.bench_function("sphere_r100_d8_generic_baseline", |b| {
        b.iter(|| black_box(LinearOctree::from_classifier(8, [0, 0, 0], &s8).unwrap()))
    });
    let s11 = sphere(1000.0, 11);
    g.bench_function("sphere_r1000_d11", |b| {
        b.iter(|| black_box(s11.build(11, [0, 0, 0]).unwrap()))
    });
    let src = include_str!("../../../scenes/showcase.tss");
    let scene = Scene::parse(src, "showcase.tss".as_ref()).unwrap();
    let csg = scene.csg().unwrap();
    g.bench_function("showcase_d10", |b| {
        b.iter(|| black_box(csg.build(scene.depth, [0, 0, 0]).unwrap()))
    });
    g.bench_function("showcase_d10_generic_baseline", |b| {
        b.iter(|| black_box(LinearOctree::from_classifier(scene.depth, [0, 0, 0], &csg).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, bench_spheres);
criterion_main!(benches);
