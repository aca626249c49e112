//! Random create/delete sequences against the models, near 0 and at the ends of
//! `i64`, in both block forms.

use std::collections::HashSet;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::*;

#[test]
fn random_sequences_small_dense_box_with_faces() {
    for seed in 0..6 {
        random_ops(seed, [-5, -3, -8], 12, 1500, 0.7, true);
    }
}

#[test]
fn random_sequences_sparse_box_with_faces() {
    for seed in 10..13 {
        random_ops(seed, [-300, -40, 7], 400, 800, 0.6, true);
    }
}

#[test]
fn random_sequences_without_faces() {
    for seed in 20..24 {
        random_ops(seed, [-20, -20, -20], 40, 1500, 0.65, false);
    }
}

#[test]
fn random_sequences_with_the_other_block_form() {
    // Faces over small blocks, and bitmap blocks without faces.
    for seed in 30..33 {
        random_ops_in(seed, [-6, -6, -6], 14, 1200, 0.7, true, true);
        random_ops_in(seed, [-20, -20, -20], 40, 1200, 0.65, false, false);
    }
    // Sparse: most blocks stay small, some are promoted, all are released again.
    random_ops_in(34, [-100, -100, -100], 200, 2000, 0.55, true, true);
}

#[test]
fn random_sequences_near_two_to_the_62() {
    let e = 1i64 << 62;
    for (seed, lo) in [
        (30, [e - 6, -e - 6, 0]),
        (31, [-e - 3, e - 3, e - 3]),
        (32, [i64::MAX - 10, i64::MIN, 0]),
    ] {
        random_ops(seed, lo, 12, 600, 0.6, true);
    }
}

#[test]
fn far_apart_voxels_near_two_to_the_62() {
    let e = 1i64 << 62;
    let pts = [
        [e, -e, 0],
        [-e, e, 5],
        [e + 1, -e, 0],
        [0, 0, 0],
        [-e, -e, -e],
        [i64::MAX, i64::MIN, 1],
        [i64::MIN, i64::MAX, -1],
    ];
    let mut t = DynamicOctree::with_faces();
    let mut m = Model::default();
    for p in pts {
        assert!(t.insert(p));
        m.insert(p);
        t.assert_valid();
        check_against(&t, &m, &pts);
    }
    assert_eq!(t.root_size_log2(), 64);
    assert_eq!(t.face_count(), 6 * 7 - 2);
    for p in pts {
        assert!(t.remove(p));
        m.remove(p);
        t.assert_valid();
        check_against(&t, &m, &pts);
    }
    assert!(t.is_empty());
    assert_eq!(t.node_count(), 0);
}

#[test]
fn clusters_at_the_ends_of_the_i64_range_with_the_directory() {
    // A 2^64 root with thousands of blocks: the directory skips six levels, and the
    // clusters sit where offsets wrap.
    let mut rng = Pcg64::seed_from_u64(62);
    let centres = [
        [i64::MIN, i64::MIN, i64::MIN],
        [i64::MAX, 0, i64::MAX],
        [0, 0, 0],
    ];
    let mut t = DynamicOctree::new();
    let mut m: HashSet<Voxel> = HashSet::new();
    let mut cells = Vec::new();
    for (k, c) in centres.iter().cycle().take(6000).enumerate() {
        let v: Voxel = std::array::from_fn(|a| c[a].wrapping_add(rng.random_range(-200..200)));
        cells.push(v);
        assert_eq!(t.insert(v), m.insert(v));
        if k % 1000 == 999 {
            t.assert_valid();
        }
    }
    assert_eq!(t.root_size_log2(), 64);
    assert!(t.dir_levels >= 4, "directory skips {} levels", t.dir_levels);
    for _ in 0..5000 {
        let c = centres[rng.random_range(0..3)];
        let q: Voxel = std::array::from_fn(|a| c[a].wrapping_add(rng.random_range(-210..210)));
        assert_eq!(t.contains(q), m.contains(&q), "{q:?}");
    }
    for (k, v) in cells.iter().enumerate() {
        assert_eq!(t.remove(*v), m.remove(v));
        if k % 1000 == 999 {
            t.assert_valid();
        }
    }
    assert!(t.is_empty());
    t.assert_valid();
}
