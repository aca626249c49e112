//! RS/MC throughput and memory at areas 10^4 to 10^5, dense baseline against the
//! other lattice backends, measured in the same run.
//!
//! Areas of about 1e4, 3e4 and 1e5. Each surface is grown from one voxel with Libes's rule (seeded), then the chain
//! runs with the Hastings factor, β = 0 and `max_area` at the target, so the area
//! stays within a few percent below the target while the steps are timed. Memory is
//! the live heap of the lattice, counted by a wrapping global allocator.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicIsize, Ordering};

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use tesseral::dynamic::DynamicOctree;
use tesseral::rsmc::{Chain, DenseLattice, Lattice, Params};
use tesseral::Voxel;

struct Counting;
static LIVE: AtomicIsize = AtomicIsize::new(0);

// SAFETY: forwards to the system allocator and only counts sizes.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        LIVE.fetch_add(l.size() as isize, Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        LIVE.fetch_sub(l.size() as isize, Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, new: usize) -> *mut u8 {
        LIVE.fetch_add(new as isize - l.size() as isize, Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(p, l, new) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Grows a surface of at least `area` plaquettes with Libes's rule; its sorted
/// voxels and its area (the cap of the timed chain).
fn grow(area: u64) -> (Vec<Voxel>, u64) {
    let p = Params {
        hastings: false,
        ..Params::default()
    };
    let mut chain = Chain::new(DenseLattice::new(), p, 2024, &[[0, 0, 0]]).unwrap();
    while chain.area() < area {
        chain.run(10_000);
    }
    (chain.voxels(), chain.area())
}

/// A chain on lattice `L` holding `voxels`, and the live heap bytes of its lattice.
fn chain_on<L: Lattice>(voxels: &[Voxel], cap: u64) -> (Chain<L>, isize) {
    let before = LIVE.load(Ordering::Relaxed);
    let mut lattice = L::empty();
    for &v in voxels {
        lattice.insert(v);
    }
    let bytes = LIVE.load(Ordering::Relaxed) - before;
    drop(lattice);
    let p = Params {
        beta: 0.0,
        max_area: Some(cap),
        ..Params::default()
    };
    (Chain::new(L::empty(), p, 7, voxels).unwrap(), bytes)
}

fn bench_backend<L: Lattice>(c: &mut Criterion, name: &str, voxels: &[Voxel], cap: u64) -> f64 {
    let (mut chain, bytes) = chain_on::<L>(voxels, cap);
    let target = if cap < 20_000 {
        "1e4"
    } else if cap < 50_000 {
        "3e4"
    } else {
        "1e5"
    };
    eprintln!(
        "rsmc {name} area {}: {} heap bytes, {:.1} bytes per plaquette",
        chain.area(),
        bytes,
        bytes as f64 / chain.area() as f64
    );
    const N: u64 = 100_000;
    let mut group = c.benchmark_group(format!("rsmc_area_{target}"));
    group.throughput(Throughput::Elements(N));
    group.bench_function(name, |b| b.iter(|| chain.run(N)));
    group.finish();
    // A direct timing as well, for the ratio printed below.
    let before = chain.counters();
    let t = std::time::Instant::now();
    chain.run(5_000_000);
    let rate = 5e6 / t.elapsed().as_secs_f64();
    let after = chain.counters();
    let pct = |a: u64, b: u64| 100.0 * (a - b) as f64 / 5e6;
    eprintln!(
        "rsmc {name} area {}: {:.2} M steps/s (direct, 5M steps; {:.1}% accepted, {:.1}% illegal, {:.1}% capped)",
        chain.area(),
        rate / 1e6,
        pct(after.accepted, before.accepted),
        pct(after.illegal, before.illegal),
        pct(after.capped, before.capped),
    );
    rate
}

fn bench_rsmc(c: &mut Criterion) {
    for target in [10_000u64, 30_000, 100_000] {
        let (voxels, area) = grow(target);
        let dense = bench_backend::<DenseLattice>(c, "dense", &voxels, area);
        let octree = bench_backend::<DynamicOctree>(c, "octree", &voxels, area);
        eprintln!(
            "rsmc area {target}: octree/dense speed ratio {:.2}",
            octree / dense
        );
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = bench_rsmc
}
criterion_main!(benches);
