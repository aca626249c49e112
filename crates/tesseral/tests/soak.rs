//! The long differential soak of issue 19: the dynamic octree against a set model
//! (a `HashMap` of present voxels with a `Vec` for uniform draws) over random
//! insertions, removals and queries, clustered and spread out to ±2^62. Ignored by
//! default; run it with
//!
//! ```text
//! TESSERAL_SOAK_OPS=100000000 cargo test --release -p tesseral --test soak -- --ignored --nocapture
//! ```
//!
//! (`TESSERAL_SOAK_OPS` per workload, default 10^8; `TESSERAL_SOAK_SEED` to repeat a
//! run). Every answer is compared, the counts after every operation, and
//! `assert_valid()` runs every 2^20 operations and at the end. The mapping issue's
//! scan insertion joins as one more entry of `WORKLOADS` (a workload draws the next
//! voxel to touch; a scan workload would draw the cells along a ray).

use std::collections::HashMap;
use std::time::Instant;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use tesseral::dynamic::DynamicOctree;
use tesseral::Voxel;

/// Keeps the model near this many voxels: above it removals win.
const TARGET: usize = 1 << 20;

/// A workload: how the next voxel to touch is drawn.
type Draw = fn(&mut Pcg64) -> Voxel;

const WORKLOADS: &[(&str, Draw)] = &[
    ("clustered", |r| {
        // A few hundred dense clusters: blocks fill, empty and merge.
        let c = i64::from(r.random_range(0..256u32)) * 1_000_003;
        [0; 3].map(|_| c + r.random_range(-40..40))
    }),
    ("spread to 2^62", |r| {
        [0; 3].map(|_| r.random_range(-(1i64 << 62)..(1i64 << 62)))
    }),
    ("both, near the ends of i64", |r| {
        if r.random_bool(0.5) {
            [0; 3].map(|_| r.random_range(-40..40))
        } else {
            let end = if r.random_bool(0.5) {
                i64::MIN
            } else {
                i64::MAX - 63
            };
            [0; 3].map(|_| end + r.random_range(0..64))
        }
    }),
];

/// The set model: presence with a uniform draw of a present voxel.
#[derive(Default)]
struct SetModel {
    at: HashMap<Voxel, usize>,
    list: Vec<Voxel>,
}

impl SetModel {
    fn insert(&mut self, v: Voxel) -> bool {
        if self.at.contains_key(&v) {
            return false;
        }
        self.at.insert(v, self.list.len());
        self.list.push(v);
        true
    }
    fn remove(&mut self, v: Voxel) -> bool {
        let Some(i) = self.at.remove(&v) else {
            return false;
        };
        self.list.swap_remove(i);
        if let Some(&moved) = self.list.get(i) {
            self.at.insert(moved, i);
        }
        true
    }
}

fn soak(name: &str, draw: Draw, ops: u64, seed: u64) {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut tree = DynamicOctree::new();
    let mut model = SetModel::default();
    let t0 = Instant::now();
    let mut peak = 0;
    for i in 0..ops {
        let roll = rng.random_range(0..100u32);
        let remove_bias = if model.list.len() > TARGET { 30 } else { 0 };
        if roll < 40 - remove_bias {
            let v = draw(&mut rng);
            assert_eq!(
                tree.insert(v),
                model.insert(v),
                "{name} seed {seed} op {i}: insert {v:?}"
            );
        } else if roll < 70 && !model.list.is_empty() {
            // Remove a present voxel (a drawn one is almost never present when spread).
            let v = model.list[rng.random_range(0..model.list.len())];
            assert!(tree.remove(v), "{name} seed {seed} op {i}: remove {v:?}");
            model.remove(v);
        } else if roll < 80 {
            let v = draw(&mut rng);
            assert_eq!(
                tree.remove(v),
                model.remove(v),
                "{name} seed {seed} op {i}: remove {v:?}"
            );
        } else {
            let v = draw(&mut rng);
            assert_eq!(
                tree.contains(v),
                model.at.contains_key(&v),
                "{name} seed {seed} op {i}: contains {v:?}"
            );
        }
        assert_eq!(
            tree.voxel_count(),
            model.list.len() as u64,
            "{name} seed {seed} op {i}"
        );
        peak = peak.max(model.list.len());
        if i & ((1 << 20) - 1) == 0 {
            tree.assert_valid();
        }
    }
    tree.assert_valid();
    for &v in &model.list {
        assert!(tree.contains(v), "{name} seed {seed}: {v:?} lost");
    }
    let secs = t0.elapsed().as_secs_f64();
    println!(
        "soak {name}: {ops} operations, seed {seed}, peak {peak} voxels, final {}, {secs:.1} s ({:.0} ns/op with the model), no mismatch",
        model.list.len(),
        secs * 1e9 / ops as f64
    );
}

#[test]
#[ignore = "long: 10^8 operations per workload; see the module docs"]
fn dynamic_octree_soak_against_a_set_model() {
    let ops = std::env::var("TESSERAL_SOAK_OPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(100_000_000u64);
    let seed = std::env::var("TESSERAL_SOAK_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0x50a6_u64);
    println!("seed {seed}");
    for (k, (name, draw)) in WORKLOADS.iter().enumerate() {
        soak(name, *draw, ops, seed + k as u64);
    }
}
