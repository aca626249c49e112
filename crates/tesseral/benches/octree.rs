//! Issue 3 benchmarks: a solid sphere of radius 100 at depth 8, centred at
//! (128, 128, 128) (about 4.19 M voxels), built with `from_classifier`.
//!
//! Run: `cargo bench -p tesseral --bench octree -- --warm-up-time 1 --measurement-time 3`

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use tesseral::linear::{CellClass, LinearOctree, SetOp};
use tesseral::pointer::PointerOctree;
use tesseral::Voxel;

/// A ball of radius `r` centred at `c`: a voxel is inside when its centre is.
fn ball(c: [f64; 3], r: f64) -> impl Fn(Voxel, u8) -> CellClass + Sync {
    move |min: Voxel, k: u8| {
        let s = (1i64 << k) as f64;
        let (mut near, mut far) = (0.0, 0.0);
        for a in 0..3 {
            let lo = min[a] as f64 + 0.5 - c[a];
            let hi = min[a] as f64 + s - 0.5 - c[a];
            let n = if lo > 0.0 {
                lo
            } else if hi < 0.0 {
                -hi
            } else {
                0.0
            };
            near += n * n;
            far += lo.abs().max(hi.abs()).powi(2);
        }
        if far <= r * r {
            CellClass::Inside
        } else if near > r * r {
            CellClass::Outside
        } else {
            CellClass::Partial
        }
    }
}

fn sphere(cx: f64) -> LinearOctree {
    LinearOctree::from_classifier(8, [0, 0, 0], &ball([cx, 128.0, 128.0], 100.0)).unwrap()
}

fn set_operations(c: &mut Criterion) {
    let a = sphere(128.0);
    // The second sphere is offset by 50 voxels in x in the same space (it is cut by
    // the space's face at x = 256).
    let b = sphere(178.0);
    let p = PointerOctree::from_linear(&a);
    eprintln!(
        "sphere: {} voxels, {} leaves, linear {:.3} bytes/voxel, pointer {} nodes \
         ({:.3} bytes/voxel at 36 bytes a node); offset sphere: {} leaves",
        a.voxel_count(),
        a.leaf_count(),
        (a.leaf_count() * 8) as f64 / a.voxel_count() as f64,
        p.node_count(),
        (p.node_count() * 36) as f64 / a.voxel_count() as f64,
        b.leaf_count()
    );
    let mut g = c.benchmark_group("set_op");
    for (name, op) in [
        ("union", SetOp::Union),
        ("intersection", SetOp::Intersection),
        ("difference", SetOp::Difference),
        ("xor", SetOp::SymmetricDifference),
    ] {
        g.bench_function(name, |bch| {
            bch.iter(|| black_box(a.set_op(&b, op).unwrap()))
        });
    }
    g.bench_function("complement", |bch| bch.iter(|| black_box(a.complement())));
    // The same union with the second operand in its own space, 50 voxels east: it is
    // aligned (resampled) into the first one's lattice first.
    let b_own =
        LinearOctree::from_classifier(8, [50, 0, 0], &ball([178.0, 128.0, 128.0], 100.0)).unwrap();
    g.bench_function("union_unaligned_spaces", |bch| {
        bch.iter(|| black_box(a.union(&b_own).unwrap()))
    });
    // Issue 17: the same spheres in a depth-9 space, where neither is clipped (the
    // peer figures come from benches/openvdb-setops/run.sh).
    let a9 = LinearOctree::from_classifier(9, [0, 0, 0], &ball([128.0; 3], 100.0)).unwrap();
    let b9 =
        LinearOctree::from_classifier(9, [0, 0, 0], &ball([178.0, 128.0, 128.0], 100.0)).unwrap();
    for (name, op) in [
        ("union_unclipped", SetOp::Union),
        ("intersection_unclipped", SetOp::Intersection),
        ("difference_unclipped", SetOp::Difference),
    ] {
        g.bench_function(name, |bch| {
            bch.iter(|| black_box(a9.set_op(&b9, op).unwrap()))
        });
    }
    // The same on the bricked forms (made once, outside the loop), what the
    // OpenVDB harness times; then making the bricked forms, and the leaf list of a
    // bricked result.
    let (a9b, b9b) = (a9.clone(), b9.clone());
    a9b.build_bricks();
    b9b.build_bricks();
    for (name, op) in [
        ("union_unclipped_bricked", SetOp::Union),
        ("intersection_unclipped_bricked", SetOp::Intersection),
        ("difference_unclipped_bricked", SetOp::Difference),
    ] {
        g.bench_function(name, |bch| {
            bch.iter(|| black_box(a9b.set_op(&b9b, op).unwrap()))
        });
    }
    g.bench_function("bricking_unclipped", |bch| {
        bch.iter_batched(
            || a9.clone(),
            |t| {
                t.build_bricks();
                t
            },
            BatchSize::LargeInput,
        )
    });
    g.bench_function("leaves_of_bricked_union_unclipped", |bch| {
        bch.iter_batched(
            || a9b.set_op(&b9b, SetOp::Union).unwrap(),
            |t| {
                black_box(t.leaves().len());
                t
            },
            BatchSize::LargeInput,
        )
    });
    g.finish();
}

fn translation(c: &mut Criterion) {
    let a = sphere(128.0);
    let mut g = c.benchmark_group("translate");
    // Unaligned displacements (the targets), then aligned ones: (64, 0, 0)
    // and (32, -32, 0) are multiples of every leaf's side, so leaves move whole.
    for by in [
        [50, 0, 0],
        [37, -11, 5],
        [1, 0, 0],
        [64, 0, 0],
        [32, -32, 0],
    ] {
        g.bench_function(format!("linear {by:?}"), |bch| {
            bch.iter(|| black_box(a.translate(by).unwrap()))
        });
    }
    // Baseline: rebuild from the moved voxels (radix-sorted codes, then merged).
    let voxels: Vec<Voxel> = a.voxels().collect();
    g.sample_size(10);
    for by in [[50, 0, 0], [37, -11, 5]] {
        g.bench_function(format!("rebuild_from_voxels {by:?}"), |bch| {
            bch.iter(|| {
                let moved = voxels
                    .iter()
                    .map(|v| [v[0] + by[0], v[1] + by[1], v[2] + by[2]]);
                black_box(LinearOctree::from_voxels(10, [-256, -256, -256], moved).unwrap())
            })
        });
    }
    // Ahuja & Nash §3.2 on the pointer octree; the clone is outside the timing.
    let p = PointerOctree::from_linear(&a);
    for by in [[64, 0, 0], [50, 0, 0], [37, -11, 5]] {
        g.bench_function(format!("pointer {by:?}"), |bch| {
            bch.iter_batched(
                || p.clone(),
                |mut t| black_box(t.translate(by).unwrap()),
                BatchSize::LargeInput,
            )
        });
    }
    g.finish();
}

criterion_group!(benches, set_operations, translation);
criterion_main!(benches);
