//! The steps a distributed engine runs one by one (`shuffle.rs`), against the whole
//! tree's operations and a voxel-set model, on seeded random data.

use std::collections::HashSet;
use std::path::Path;

use rand::{Rng, SeedableRng};

use super::tests::{random_ranges, random_tree, voxels};
use super::*;

#[test]
fn a_partitioned_translation_equals_the_whole_one_and_the_voxel_model() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(150);
    for _ in 0..120 {
        let depth = rng.random_range(1..=6);
        let tree = random_tree(&mut rng, depth);
        let p = PartitionedOctree::split(&tree, &random_ranges(&mut rng, depth)).unwrap();
        let side = 1i64 << depth;
        // Small moves (the space is kept), large and negative ones (it grows).
        let by: [i64; 3] = std::array::from_fn(|_| rng.random_range(-2 * side..=2 * side));
        let k = rng.random_range(1..9);
        let got = p.translate(by, k).unwrap();
        let want = tree.translate(by).unwrap();
        assert_eq!((got.depth(), got.origin()), (want.depth(), want.origin()));
        let end = 1u64 << (3 * u32::from(got.depth()));
        assert!(got.parts().len() == k || (got.parts().len() as u64) == end);
        for (r, t) in got.parts() {
            t.assert_valid();
            assert!(t
                .leaves()
                .iter()
                .all(|l| l.code() >= r.lo && l.end() <= r.hi));
        }
        let whole = got.concat();
        whole.assert_valid();
        assert_eq!(whole, want, "by {by:?}");
        let model: HashSet<[i64; 3]> = voxels(&tree)
            .into_iter()
            .map(|v| std::array::from_fn(|a| v[a] + by[a]))
            .collect();
        assert_eq!(voxels(&whole), model, "by {by:?}");
    }
}

#[test]
fn translate_into_moves_into_any_space() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(151);
    for _ in 0..100 {
        let depth = rng.random_range(1..=5);
        let tree = random_tree(&mut rng, depth);
        let by: [i64; 3] = std::array::from_fn(|_| rng.random_range(-40..=40));
        let d2 = rng.random_range(1..=6);
        let o2: [i64; 3] = std::array::from_fn(|_| rng.random_range(-20..=20));
        let (got, dropped) = tree.translate_into(by, d2, o2).unwrap();
        got.assert_valid();
        assert_eq!((got.depth(), got.origin()), (d2, o2));
        let side = 1i64 << d2;
        let moved: Vec<[i64; 3]> = voxels(&tree)
            .into_iter()
            .map(|v| std::array::from_fn(|a| v[a] + by[a]))
            .collect();
        let inside: HashSet<[i64; 3]> = moved
            .iter()
            .copied()
            .filter(|v| (0..3).all(|a| v[a] >= o2[a] && v[a] < o2[a] + side))
            .collect();
        assert_eq!(voxels(&got), inside);
        assert_eq!(dropped, (moved.len() - inside.len()) as u64);
    }
}

#[test]
fn pieces_join_into_their_union() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(152);
    for _ in 0..60 {
        let depth = rng.random_range(1..=5);
        let n = rng.random_range(0..6);
        let pieces: Vec<LinearOctree> = (0..n).map(|_| random_tree(&mut rng, depth)).collect();
        let want: HashSet<[i64; 3]> = pieces.iter().flat_map(voxels).collect();
        let got = join_pieces(depth, [0; 3], pieces).unwrap();
        got.assert_valid();
        assert_eq!(voxels(&got), want);
    }
    // Disjoint pieces (a tree cut into ranges, shuffled): the one-pass join.
    for _ in 0..60 {
        let depth = rng.random_range(1..=6);
        let tree = random_tree(&mut rng, depth);
        let p = PartitionedOctree::split(&tree, &random_ranges(&mut rng, depth)).unwrap();
        let mut pieces: Vec<LinearOctree> = p.parts().iter().map(|(_, t)| t.clone()).collect();
        pieces.reverse();
        let got = join_pieces(depth, [0; 3], pieces).unwrap();
        got.assert_valid();
        assert_eq!(got, tree);
    }
    let a = LinearOctree::from_voxels(2, [0; 3], [[1, 1, 1]]).unwrap();
    let b = LinearOctree::from_voxels(3, [0; 3], [[1, 1, 1]]).unwrap();
    assert!(join_pieces(2, [0; 3], vec![a.clone(), b.clone()]).is_err());
    assert!(set_op_part(&a, &b, SetOp::Union)
        .unwrap_err()
        .to_string()
        .contains("different spaces"));
}

#[test]
fn exact_ranges_are_k_ranges_tiling_the_space() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(153);
    for _ in 0..100 {
        let depth = rng.random_range(1..=6);
        let end = 1u64 << (3 * depth);
        let n = rng.random_range(0..50);
        let mut codes: Vec<u64> = (0..n).map(|_| rng.random_range(0..end)).collect();
        codes.sort_unstable();
        let k = rng.random_range(1..70);
        let r = balanced_ranges_exact(depth, k, &codes);
        assert_eq!(r.len() as u64, (k as u64).min(end));
        check_tiling(depth, &r).unwrap();
    }
    // The cuts follow the sample: two clusters, two parts.
    let r = balanced_ranges_exact(4, 2, &[5, 6, 7, 1000, 1001, 1002]);
    assert_eq!(r[0].hi, 1000);
}

#[test]
fn samples_land_where_the_moved_leaves_do() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(154);
    for _ in 0..50 {
        let depth = rng.random_range(1..=5);
        let tree = random_tree(&mut rng, depth);
        let by: [i64; 3] = std::array::from_fn(|_| rng.random_range(-10..=10));
        let bbox = union_bbox([tree.bbox()]);
        let (d, o) = translated_space(depth, [0; 3], bbox, by).unwrap();
        let moved = tree.translate(by).unwrap();
        assert_eq!((d, o), (moved.depth(), moved.origin()));
        let s = translated_sample(&tree, by, d, o, 16);
        assert!(s.len() <= 16 && s.len() <= tree.leaf_count());
        assert!(s.windows(2).all(|w| w[0] <= w[1]));
        for c in s {
            assert!(moved.contains(moved.voxel_of(c)));
        }
    }
    assert_eq!(union_bbox([None, None]), None);
}

#[test]
fn parts_written_one_by_one_read_back_as_the_dataset() {
    let dir = tempfile::tempdir().unwrap();
    let scene = crate::csg::Scene::parse(
        "depth 9\nbounds [0, 0, 0] [10, 10, 10]\nsphere(r = 4) at [5, 5, 5]\n",
        Path::new("s.tss"),
    )
    .unwrap();
    let csg = scene.csg().unwrap();
    let ranges = scene_ranges(&scene, 4).unwrap();
    assert!(ranges.len() > 1);
    check_tiling(9, &ranges).unwrap();
    let d = dir.path().join("ds");
    std::fs::create_dir_all(&d).unwrap();
    let frame = scene.frame();
    let mut entries = Vec::new();
    for (i, r) in ranges.iter().enumerate() {
        let t = csg.build_range(9, [0; 3], r.range()).unwrap();
        entries.push(write_part(&d, i, *r, &t, frame).unwrap());
    }
    write_manifest(&d, 9, [0; 3], frame, &entries).unwrap();
    // The same parts as the streaming dataset build (which also writes the scene's
    // colours, which parts written one by one do not carry).
    let d2 = dir.path().join("ds2");
    build_scene_dataset(&scene, &d2, 4, 2, &mut |_, _| {}).unwrap();
    let (m, m2) = (read_manifest(&d).unwrap(), read_manifest(&d2).unwrap());
    assert_eq!((m.depth, m.origin), (m2.depth, m2.origin));
    assert_eq!(m.parts.len(), m2.parts.len());
    for (i, (p, q)) in m.parts.iter().zip(&m2.parts).enumerate() {
        assert_eq!(
            (p.lo, p.hi, p.leaves, p.voxels, &p.file),
            (q.lo, q.hi, q.leaves, q.voxels, &q.file),
            "part {i}"
        );
        assert_eq!(
            read_part(&d, &m, i).unwrap().tree,
            read_part(&d2, &m2, i).unwrap().tree,
            "part {i}"
        );
    }
    let mut joined = Vec::new();
    for i in 0..m.parts.len() {
        let part = read_part(&d, &m, i).unwrap();
        assert_eq!(part.frame, frame);
        joined.push(part.tree);
    }
    assert!(read_part(&d, &m, m.parts.len()).is_err());
    let whole = join_pieces(9, [0; 3], joined).unwrap();
    assert_eq!(whole, scene.build().unwrap());
    // A part whose leaves leave its range is refused before writing.
    let t = csg.build_range(9, [0; 3], 0..u64::MAX).unwrap();
    let e = write_part(&d, 0, ranges[0], &t, frame)
        .unwrap_err()
        .to_string();
    assert!(e.contains("outside its range"), "{e}");
}
