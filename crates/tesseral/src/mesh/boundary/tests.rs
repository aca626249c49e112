use super::*;
use rand::{Rng, SeedableRng};

use crate::Voxel;

fn check(tree: &LinearOctree, label: &str) -> TriMesh {
    let m = boundary_mesh(tree);
    assert_eq!(m.edge_defects(), 0, "{label}: open or non-manifold edges");
    assert!(
        (m.volume() - tree.voxel_count() as f64).abs() < 1e-6,
        "{label}: volume {} != voxels {}",
        m.volume(),
        tree.voxel_count()
    );
    let s = smooth_mesh(tree);
    assert_eq!(s.edge_defects(), 0, "{label}: smooth mesh has bad edges");
    m
}

#[test]
fn edge_and_corner_contacts_split_vertices() {
    // Two voxels touching along an edge, and two touching at a corner.
    let edge = LinearOctree::from_voxels(2, [0; 3], [[0, 0, 0], [1, 1, 0]]).unwrap();
    let m = check(&edge, "edge");
    assert_eq!(m.positions.len(), 16, "two separate cubes: 8 + 8 vertices");
    let corner = LinearOctree::from_voxels(2, [0; 3], [[0, 0, 0], [1, 1, 1]]).unwrap();
    let m = check(&corner, "corner");
    assert_eq!(m.positions.len(), 16);
    // The complement case: a block with one voxel missing at a corner and an
    // edge-diagonal pair missing.
    let mut vox: Vec<Voxel> = Vec::new();
    for x in 0..4 {
        for y in 0..4 {
            for z in 0..4 {
                let hole = z < 2 && ((x, y) == (1, 1) || (x, y) == (2, 2));
                if !hole {
                    vox.push([x, y, z]);
                }
            }
        }
    }
    check(&LinearOctree::from_voxels(2, [0; 3], vox).unwrap(), "holes");
}

#[test]
fn random_solids_are_watertight_with_exact_volume() {
    for seed in 0..120u64 {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let depth = rng.random_range(1..=4u8);
        let side = 1i64 << depth;
        let origin = [
            rng.random_range(-3..3),
            rng.random_range(-3..3),
            rng.random_range(-3..3),
        ];
        let density = rng.random_range(0.05..0.95);
        let voxels: Vec<Voxel> = (0..side)
            .flat_map(|x| (0..side).flat_map(move |y| (0..side).map(move |z| [x, y, z])))
            .filter(|_| rng.random_bool(density))
            .map(|v| [v[0] + origin[0], v[1] + origin[1], v[2] + origin[2]])
            .collect();
        let tree = LinearOctree::from_voxels(depth, origin, voxels).unwrap();
        check(&tree, &format!("seed {seed}"));
    }
}

#[test]
fn big_blocks_cost_few_triangles() {
    // A 16³ block beside a single voxel: the block's shared side is cut where
    // the voxel's square sits, everything else stays one rectangle.
    let mut vox: Vec<Voxel> = Vec::new();
    for x in 0..16 {
        for y in 0..16 {
            for z in 0..16 {
                vox.push([x, y, z]);
            }
        }
    }
    vox.push([16, 3, 5]);
    let tree = LinearOctree::from_voxels(5, [0; 3], vox).unwrap();
    let m = check(&tree, "block and voxel");
    assert!(m.triangles.len() < 60, "{} triangles", m.triangles.len());
}

#[test]
fn dense_random_blocks_of_4_cubed_are_manifold() {
    // Every pinch (two voxels, or two holes, meeting along an edge) in dense
    // random 4×4×4 solids, blocky and smooth.
    for seed in 0..1500u64 {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let d = rng.random_range(0.3..0.95);
        let mut voxels: Vec<Voxel> = Vec::new();
        for x in 0..4 {
            for y in 0..4 {
                for z in 0..4 {
                    if rng.random_bool(d) {
                        voxels.push([x, y, z]);
                    }
                }
            }
        }
        let tree = LinearOctree::from_voxels(2, [0; 3], voxels).unwrap();
        check(&tree, &format!("dense seed {seed}"));
    }
}
