//! Brute-force checks of the motion module on seeded random voxel sets.
//!
//! The shared generators and models are here; the tests are in one file per topic:
//! `interfere.rs` (rotations, interference, clearance), `sweep.rs` (first contact),
//! `world.rs` (worlds in motion), `plan.rs` (Minkowski sums and planning).

use std::collections::HashSet;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::*;
use crate::linear::LinearOctree;
use crate::Voxel;

/// A random solid: a few boxes (so the octree has large blocks) plus loose voxels.
pub(crate) fn random_solid(
    rng: &mut Pcg64,
    depth: u8,
    origin: Voxel,
) -> (LinearOctree, Vec<Voxel>) {
    let side = 1i64 << depth;
    let mut set = HashSet::new();
    for _ in 0..rng.random_range(0..=4) {
        let lo: Vec<i64> = (0..3).map(|_| rng.random_range(0..side)).collect();
        let ext: Vec<i64> = (0..3).map(|a| rng.random_range(1..=side - lo[a])).collect();
        for x in 0..ext[0] {
            for y in 0..ext[1] {
                for z in 0..ext[2] {
                    set.insert([
                        origin[0] + lo[0] + x,
                        origin[1] + lo[1] + y,
                        origin[2] + lo[2] + z,
                    ]);
                }
            }
        }
    }
    for _ in 0..rng.random_range(0..12) {
        set.insert([
            origin[0] + rng.random_range(0..side),
            origin[1] + rng.random_range(0..side),
            origin[2] + rng.random_range(0..side),
        ]);
    }
    let voxels: Vec<Voxel> = set.into_iter().collect();
    let tree = LinearOctree::from_voxels(depth, origin, voxels.iter().copied()).unwrap();
    tree.assert_valid();
    (tree, voxels)
}

fn unit_gap2(p: Voxel, q: Voxel) -> u128 {
    (0..3)
        .map(|a| {
            let g = ((p[a] - q[a]).abs() - 1).max(0) as u128;
            g * g
        })
        .sum()
}

/// An offset that puts the rotated `b` near `a` (within `jitter` voxels of centring).
fn offset_near(
    rng: &mut Pcg64,
    va: &[Voxel],
    vb: &[Voxel],
    rotation: Rotation,
    jitter: i64,
) -> Voxel {
    let centre = |vs: &mut dyn Iterator<Item = Voxel>| {
        let (mut sum, mut n) = ([0i64; 3], 0i64);
        for v in vs {
            for a in 0..3 {
                sum[a] += v[a];
            }
            n += 1;
        }
        let n = n.max(1);
        [sum[0] / n, sum[1] / n, sum[2] / n]
    };
    let ca = centre(&mut va.iter().copied());
    let cb = centre(&mut vb.iter().map(|&v| rotation.apply_voxel(v)));
    [0, 1, 2].map(|a| ca[a] - cb[a] + rng.random_range(-jitter..=jitter))
}

/// A wall one voxel thick at `x`, 16 × 16 voxels in y and z, in a depth-6 space.
fn thin_wall(x: i64) -> LinearOctree {
    LinearOctree::from_voxels(
        6,
        [0, 0, 0],
        (0..16).flat_map(|y| (0..16).map(move |z| [x, y, z])),
    )
    .unwrap()
}

fn seeded(test: &str, seed: u64) -> Pcg64 {
    eprintln!("{test}: seed {seed}");
    Pcg64::seed_from_u64(seed)
}

mod interfere;
mod plan;
mod sweep;
mod world;
