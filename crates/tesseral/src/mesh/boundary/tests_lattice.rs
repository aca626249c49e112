//! The mesher's lattice (`lattice.rs`, `vertices.rs`) against the hash maps it
//! replaced (`reference.rs`): the same mesh, vertex for vertex and triangle for
//! triangle, on seeded random solids, blocky and smooth, at every depth up to the
//! deepest tree (whose points need 128-bit keys).

use rand::{Rng, SeedableRng};

use super::{reference, triangulate};
use crate::linear::{LinearOctree, MAX_DEPTH};
use crate::Voxel;

fn same_as_reference(tree: &LinearOctree, label: &str) {
    for merge in [true, false] {
        let (mesh, keys, rows) = triangulate::build(tree, merge);
        let (want, want_keys, want_rows) = reference::build(tree, merge);
        assert_eq!(keys, want_keys, "{label}, merge {merge}: vertex keys");
        assert_eq!(rows, want_rows, "{label}, merge {merge}: group rows");
        assert_eq!(mesh.positions, want.positions, "{label}, merge {merge}");
        assert_eq!(mesh.triangles, want.triangles, "{label}, merge {merge}");
        assert_eq!(mesh.edge_defects(), 0, "{label}, merge {merge}");
    }
}

/// Voxels of the box `[0, side)³` kept with probability `density`, moved to
/// `origin`; with `blocks`, in aligned 2³ blocks (larger rectangles).
fn random_solid(rng: &mut rand_pcg::Pcg64, depth: u8, origin: Voxel, blocks: bool) -> LinearOctree {
    let side = 1i64 << depth;
    let density = rng.random_range(0.05..0.95);
    let step = if blocks && depth > 1 { 2 } else { 1 };
    let mut voxels: Vec<Voxel> = Vec::new();
    for x in (0..side).step_by(step) {
        for y in (0..side).step_by(step) {
            for z in (0..side).step_by(step) {
                if rng.random_bool(density) {
                    for d in 0..step * step * step {
                        let d = d as i64;
                        let o = [d % 2, d / 2 % 2, d / 4].map(|c| c * (step as i64 - 1));
                        voxels.push([
                            x + o[0] + origin[0],
                            y + o[1] + origin[1],
                            z + o[2] + origin[2],
                        ]);
                    }
                }
            }
        }
    }
    LinearOctree::from_voxels(depth, origin, voxels).unwrap()
}

#[test]
fn random_solids_mesh_as_the_hash_maps_did() {
    for seed in 0..300u64 {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let depth = rng.random_range(1..=5u8);
        let origin = [0; 3].map(|_| rng.random_range(-40..40));
        let blocks = rng.random_bool(0.5);
        let tree = random_solid(&mut rng, depth, origin, blocks);
        tree.assert_valid();
        same_as_reference(&tree, &format!("seed {seed}"));
    }
}

#[test]
fn deep_trees_mesh_as_the_hash_maps_did() {
    // Depth 20 packs a point in 63 bits, depth 21 needs 128; voxels at both ends of
    // the space and in the middle, some touching along edges and at corners, and
    // origins far from zero.
    for (seed, depth) in [(1u64, 20u8), (2, MAX_DEPTH), (3, MAX_DEPTH)] {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let side = 1i64 << depth;
        let origin = [0; 3].map(|_| rng.random_range(-(1i64 << 40)..(1i64 << 40)));
        let mut voxels: Vec<Voxel> = Vec::new();
        for anchor in [[0, 0, 0], [side - 3, side - 3, side - 3], [side / 2; 3]] {
            for _ in 0..20 {
                let v = [0, 1, 2].map(|a| anchor[a] + rng.random_range(0..3) + origin[a]);
                voxels.push(v);
            }
        }
        let tree = LinearOctree::from_voxels(depth, origin, voxels).unwrap();
        tree.assert_valid();
        same_as_reference(&tree, &format!("depth {depth}"));
    }
}
