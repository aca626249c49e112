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
fn small_blocks_grow_into_bitmaps_and_go_away() {
    let mut t = DynamicOctree::new();
    let cells: Vec<Voxel> = (0..12).map(|i| [i % 8, i / 8, 3]).collect();
    // The first block is the root (a bitmap); its corner makes the blocks world-aligned.
    t.insert([-1024, -1024, -1024]);
    for (n, &c) in cells.iter().enumerate() {
        assert!(t.insert(c));
        assert!(!t.insert(c));
        t.assert_valid();
        let small = t.small.live();
        let bitmaps = t.leaves.live();
        // Up to eight voxels the new block is small; the ninth makes it a bitmap.
        if n < SMALL_CAP {
            assert_eq!((small, bitmaps), (1, 1), "after {} voxels", n + 1);
        } else {
            assert_eq!((small, bitmaps), (0, 2), "after {} voxels", n + 1);
        }
        for &d in &cells {
            assert_eq!(t.contains(d), cells[..=n].contains(&d));
        }
    }
    for (n, &c) in cells.iter().enumerate() {
        assert!(t.remove(c));
        assert!(!t.remove(c));
        t.assert_valid();
        // Down to four voxels the bitmap turns small again; the last one frees it.
        let left = cells.len() - n - 1;
        let forms = (t.small.live(), t.leaves.live());
        let want = match left {
            0 => (0, 1),
            1..=4 => (1, 1),
            _ => (0, 2),
        };
        assert_eq!(forms, want, "with {left} voxels left");
        for &d in &cells {
            assert_eq!(t.contains(d), cells[n + 1..].contains(&d));
        }
    }
    assert_eq!(t.voxel_count(), 1);
    assert_eq!(t.node_count(), 1); // the far voxel's block, the root again
    assert_eq!(t.small.live(), 0);
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
