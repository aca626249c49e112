//! Root growth and contraction, the directory, small blocks and implicit full
//! octants (Libes §3).

use std::collections::HashSet;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::*;

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
fn the_root_contracts_onto_a_small_block() {
    let mut t = DynamicOctree::new();
    t.insert([1, 2, 3]);
    t.insert([4, 2, 3]);
    t.insert([1 << 20, 0, 0]);
    t.assert_valid();
    assert!(t.small.live() >= 1);
    t.remove([1 << 20, 0, 0]);
    t.assert_valid();
    assert!(t.root_size_log2() <= 3);
    assert!(t.contains([1, 2, 3]) && t.contains([4, 2, 3]));
    assert!(!t.contains([2, 2, 3]));
    // The root block shifts inside itself when it grows and shrinks again.
    t.insert([-3, 2, 3]);
    t.remove([4, 2, 3]);
    t.assert_valid();
    assert_eq!(t.voxels(), vec![[-3, 2, 3], [1, 2, 3]]);
}

#[test]
fn the_directory_follows_a_large_tree_up_and_down() {
    let mut rng = Pcg64::seed_from_u64(77);
    let mut t = DynamicOctree::new();
    let mut m: HashSet<Voxel> = HashSet::new();
    let mut deepest = 0;
    let cells: Vec<Voxel> = (0..40_000)
        .map(|_| std::array::from_fn(|_| rng.random_range(-256..256)))
        .collect();
    for (i, &c) in cells.iter().enumerate() {
        assert_eq!(t.insert(c), m.insert(c));
        deepest = deepest.max(t.dir_levels);
        if i % 10_000 == 0 {
            t.assert_valid();
        }
    }
    t.assert_valid();
    assert!(deepest >= 5, "directory skipped only {deepest} levels");
    for _ in 0..20_000 {
        let q: Voxel = std::array::from_fn(|_| rng.random_range(-260..260));
        assert_eq!(t.contains(q), m.contains(&q), "{q:?}");
    }
    // Drain in random order: the directory shrinks with the tree.
    let mut order: Vec<Voxel> = m.iter().copied().collect();
    order.sort_unstable();
    for i in (1..order.len()).rev() {
        order.swap(i, rng.random_range(0..=i));
    }
    for (i, &c) in order.iter().enumerate() {
        assert!(t.remove(c));
        m.remove(&c);
        if i % 5_000 == 0 || m.len() < 50 {
            t.assert_valid();
            for &d in order.iter().skip(i).take(20) {
                assert_eq!(t.contains(d), m.contains(&d));
            }
        }
    }
    assert!(t.is_empty());
    assert_eq!(t.dir_levels, 0);
    assert_eq!(t.node_count(), 0);
}

#[test]
fn string_to_two_to_the_60_costs_sixty_expansions() {
    // Libes §5: "a surface that grows from a single voxel to a long string of 2^60
    // voxels will only cause octree expansion to occur sixty times".
    let mut t = DynamicOctree::new();
    t.insert([0, 0, 0]);
    assert_eq!((t.root_size_log2(), t.expansions()), (0, 0));
    for i in 0..60 {
        t.insert([1 << i, 0, 0]);
        t.insert([(1 << i) + (1 << i) / 2, 0, 0]);
        assert_eq!(t.expansions(), i + 1);
        t.assert_valid();
    }
    t.insert([(1 << 60) - 1, 0, 0]);
    assert_eq!(t.expansions(), 60);
    assert_eq!(t.root_size_log2(), 60);
    assert_eq!(t.root_min(), [0, 0, 0]);
    assert_eq!(t.contractions(), 0);
    t.insert([1 << 60, 0, 0]);
    assert_eq!(t.expansions(), 61);
    // And back: removing the far end shrinks the root again.
    t.remove([1 << 60, 0, 0]);
    assert_eq!(t.root_size_log2(), 60);
    assert_eq!(t.contractions(), 1);
    t.assert_valid();
}

#[test]
fn negative_growth_and_contraction_to_one_voxel() {
    let mut t = DynamicOctree::new();
    t.insert([0, 0, 0]);
    t.insert([-1, 0, 0]);
    assert_eq!((t.root_size_log2(), t.root_min()), (1, [-1, 0, 0]));
    t.insert([-3, -5, 9]);
    t.assert_valid();
    assert_eq!(t.root_size_log2(), 4);
    t.remove([0, 0, 0]);
    t.remove([-1, 0, 0]);
    t.assert_valid();
    assert_eq!((t.root_size_log2(), t.root_min()), (0, [-3, -5, 9]));
    assert_eq!(t.node_count(), 1);
    t.remove([-3, -5, 9]);
    assert!(t.is_empty());
    t.assert_valid();
}

#[test]
fn full_octants_are_implicit() {
    let mut t = DynamicOctree::with_faces();
    let mut m = Model::default();
    for x in -8..8 {
        for y in -8..8 {
            for z in -8..8 {
                t.insert([x, y, z]);
                m.insert([x, y, z]);
            }
        }
    }
    t.assert_valid();
    // A 16³ cube aligned to the root: the root itself is one full slot.
    assert_eq!(t.node_count(), 0);
    assert_eq!(t.root_size_log2(), 4);
    assert_eq!(t.face_count(), 6 * 16 * 16);
    let o = t.find([0, 0, 0]).unwrap();
    assert!(o.is_full());
    assert_eq!((o.min(), o.size_log2()), ([-8, -8, -8], 4));
    // Deleting one voxel instantiates the path down to its block only.
    t.remove([0, 0, 0]);
    m.remove([0, 0, 0]);
    t.assert_valid();
    assert_eq!(t.node_count(), 2);
    check_against(
        &t,
        &m,
        &[[0, 0, 0], [1, 0, 0], [-1, -1, -1], [7, 7, 7], [8, 0, 0]],
    );
    t.insert([0, 0, 0]);
    m.insert([0, 0, 0]);
    t.assert_valid();
    assert_eq!(t.node_count(), 0);
    check_against(&t, &m, &[[0, 0, 0], [8, 8, 8], [-9, 0, 0]]);
}
