//! Partitioned octrees against the unpartitioned ones and a voxel-set model, on
//! seeded random data.

use std::collections::HashSet;
use std::path::Path;

use rand::{Rng, SeedableRng};

use super::*;
use crate::model::Frame;

pub(super) fn random_tree(rng: &mut rand_pcg::Pcg64, depth: u8) -> LinearOctree {
    let side = 1i64 << depth;
    let n = rng.random_range(0..400);
    let blob = rng.random_range(1..=side);
    let voxels: Vec<_> = (0..n)
        .map(|_| {
            [
                rng.random_range(0..blob),
                rng.random_range(0..blob),
                rng.random_range(0..side),
            ]
        })
        .collect();
    let mut t = LinearOctree::from_voxels(depth, [0, 0, 0], voxels).unwrap();
    if rng.random_bool(0.3) {
        // A big block, so that cuts split leaves.
        let full = LinearOctree::full(depth - 1, [0, 0, 0]).unwrap();
        t = t.union(&full).unwrap();
    }
    t
}

pub(super) fn random_ranges(rng: &mut rand_pcg::Pcg64, depth: u8) -> Vec<Partition> {
    let end = 1u64 << (3 * u32::from(depth));
    let k = rng.random_range(1..8);
    let mut cuts: Vec<u64> = (0..k).map(|_| rng.random_range(1..end)).collect();
    cuts.extend([0, end]);
    cuts.sort_unstable();
    cuts.dedup();
    cuts.windows(2)
        .map(|w| Partition { lo: w[0], hi: w[1] })
        .collect()
}

pub(super) fn voxels(t: &LinearOctree) -> HashSet<[i64; 3]> {
    t.voxels().collect()
}

#[test]
fn split_and_concat_give_the_tree_back() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(15);
    for _ in 0..100 {
        let depth = rng.random_range(1..=6);
        let tree = random_tree(&mut rng, depth);
        let ranges = random_ranges(&mut rng, depth);
        let p = PartitionedOctree::split(&tree, &ranges).unwrap();
        assert_eq!(p.ranges(), ranges);
        let mut total = 0;
        for (r, t) in p.parts() {
            t.assert_valid();
            assert!(t
                .leaves()
                .iter()
                .all(|l| l.code() >= r.lo && l.end() <= r.hi));
            total += t.voxel_count();
        }
        assert_eq!(total, tree.voxel_count());
        let back = p.concat();
        back.assert_valid();
        assert_eq!(back, tree);
        let again = p.resplit(&random_ranges(&mut rng, depth)).unwrap();
        assert_eq!(again.concat(), tree);
    }
}

#[test]
fn set_operations_part_by_part_equal_the_whole_and_the_voxel_model() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(16);
    for _ in 0..80 {
        let depth = rng.random_range(1..=5);
        let a = random_tree(&mut rng, depth);
        let b = random_tree(&mut rng, depth);
        let pa = PartitionedOctree::split(&a, &random_ranges(&mut rng, depth)).unwrap();
        let pb = PartitionedOctree::split(&b, &random_ranges(&mut rng, depth)).unwrap();
        let (va, vb) = (voxels(&a), voxels(&b));
        for (op, want) in [
            (SetOp::Union, va.union(&vb).copied().collect::<HashSet<_>>()),
            (SetOp::Intersection, va.intersection(&vb).copied().collect()),
            (SetOp::Difference, va.difference(&vb).copied().collect()),
            (
                SetOp::SymmetricDifference,
                va.symmetric_difference(&vb).copied().collect(),
            ),
        ] {
            let got = pa.set_op(&pb, op).unwrap();
            assert_eq!(got.ranges(), pa.ranges());
            for (_, t) in got.parts() {
                t.assert_valid();
            }
            let whole = got.concat();
            whole.assert_valid();
            assert_eq!(whole, a.set_op_same_space(&b, op), "{op:?}");
            assert_eq!(voxels(&whole), want, "{op:?}");
        }
    }
}

#[test]
fn bad_ranges_and_spaces_are_refused() {
    let t = LinearOctree::from_voxels(2, [0; 3], [[1, 1, 1]]).unwrap();
    for ranges in [
        vec![],
        vec![Partition { lo: 0, hi: 10 }],
        vec![Partition { lo: 0, hi: 10 }, Partition { lo: 11, hi: 64 }],
        vec![Partition { lo: 0, hi: 0 }, Partition { lo: 0, hi: 64 }],
    ] {
        assert!(PartitionedOctree::split(&t, &ranges).is_err(), "{ranges:?}");
    }
    let a = PartitionedOctree::split(&t, &[Partition { lo: 0, hi: 64 }]).unwrap();
    let u = LinearOctree::from_voxels(3, [0; 3], [[1, 1, 1]]).unwrap();
    let b = PartitionedOctree::split(&u, &[Partition { lo: 0, hi: 512 }]).unwrap();
    assert!(a.set_op(&b, SetOp::Union).is_err());
    let outside = PartitionedOctree::from_parts(
        2,
        [0; 3],
        vec![
            (Partition { lo: 0, hi: 1 }, t.clone()),
            (Partition { lo: 1, hi: 64 }, t),
        ],
    );
    assert!(outside
        .unwrap_err()
        .to_string()
        .contains("outside its range"));
}

#[test]
fn balanced_ranges_tile_the_space() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(17);
    for _ in 0..50 {
        let depth = rng.random_range(1..=6);
        let tree = random_tree(&mut rng, depth);
        let k = rng.random_range(1..10);
        let ranges = balanced_ranges_of(&tree, k);
        assert!(!ranges.is_empty() && ranges.len() <= k);
        check_tiling(depth, &ranges).unwrap();
        let p = PartitionedOctree::split(&tree, &ranges).unwrap();
        if tree.leaf_count() >= 10 * k {
            // Cuts fall at leaf quantiles: no part holds much more than its share.
            let most = p.parts().iter().map(|(_, t)| t.leaf_count()).max().unwrap();
            assert!(most <= 2 * tree.leaf_count() / ranges.len() + 8, "{most}");
        }
    }
}

#[test]
fn datasets_round_trip_and_refuse_damage() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(18);
    let tree = random_tree(&mut rng, 6);
    let p = PartitionedOctree::split(&tree, &balanced_ranges_of(&tree, 4)).unwrap();
    let frame = Frame::new(0.25, [1.0, 2.0, 3.0]);
    let d = dir.path().join("ds");
    write_dataset(&d, &p, frame).unwrap();
    assert!(is_dataset(&d));
    let (back, f) = read_dataset(&d).unwrap();
    assert_eq!(back, p);
    assert_eq!(f, frame);
    let m = read_dataset_model(&d).unwrap();
    assert_eq!(m.tree, tree);
    // A damaged part: named, with its CRC.
    let part = d.join("part-00001.tess");
    let mut bytes = std::fs::read(&part).unwrap();
    let n = bytes.len();
    bytes[n / 2] ^= 1;
    std::fs::write(&part, &bytes).unwrap();
    let e = read_dataset(&d).unwrap_err().to_string();
    assert!(e.contains("part-00001.tess") && e.contains("CRC"), "{e}");
    // A bad manifest field: named with its line.
    let man = d.join(MANIFEST);
    let text = std::fs::read_to_string(&man).unwrap();
    std::fs::write(&man, text.replace("\"depth\"", "\"dpeth\"")).unwrap();
    let e = read_dataset(&d).unwrap_err().to_string();
    assert!(e.contains("manifest.json") && e.contains("line"), "{e}");
    std::fs::write(&man, text.replace("part-00000.tess", "../x.tess")).unwrap();
    let e = read_dataset(&d).unwrap_err().to_string();
    assert!(e.contains("parts[0].file"), "{e}");
}

#[test]
fn a_scene_builds_straight_into_a_dataset() {
    let dir = tempfile::tempdir().unwrap();
    let scene = crate::csg::Scene::parse(
        "depth 10\nbounds [0, 0, 0] [10, 10, 10]\nsphere(r = 4) at [5, 5, 5]\nbox(size = [9, 1, 1]) rotate [0, 30, 0] at [5, 5, 2]\n",
        Path::new("s.tss"),
    )
    .unwrap();
    let whole = scene.build().unwrap();
    let d = dir.path().join("ds");
    let mut calls = 0;
    let parts = build_scene_dataset(&scene, &d, 5, 4, &mut |_, _| calls += 1).unwrap();
    assert!(parts.len() > 1 && calls > 0);
    let (p, frame) = read_dataset(&d).unwrap();
    assert_eq!(frame, scene.frame());
    assert_eq!(p.concat(), whole);
    assert_eq!(
        parts.iter().map(|p| p.voxels).sum::<u64>(),
        whole.voxel_count()
    );
}

#[test]
fn streamed_set_operations_of_files_equal_the_in_memory_ones() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(19);
    for i in 0..40 {
        let depth = rng.random_range(1..=5);
        let a = random_tree(&mut rng, depth);
        let b = random_tree(&mut rng, depth);
        let (pa, pb) = (
            dir.path().join(format!("a{i}.tess")),
            dir.path().join(format!("b{i}.tess")),
        );
        for (p, t) in [(&pa, &a), (&pb, &b)] {
            let mut w = crate::io::TessWriter::new(Vec::new(), depth, [0; 3])
                .unwrap()
                .with_chunk_leaves(1 + i % 4);
            for &l in t.leaves() {
                w.push(l).unwrap();
            }
            std::fs::write(p, w.finish(Frame::default()).unwrap()).unwrap();
        }
        let (fa, fb) = (
            crate::io::TessFile::open(&pa).unwrap(),
            crate::io::TessFile::open(&pb).unwrap(),
        );
        for op in [
            SetOp::Union,
            SetOp::Intersection,
            SetOp::Difference,
            SetOp::SymmetricDifference,
        ] {
            let mut out = Vec::new();
            let s = stream_set_op(&fa, &fb, op, Frame::default(), &mut out).unwrap();
            let got = crate::io::native::decode(&out).unwrap().tree;
            got.assert_valid();
            let want = a.set_op_same_space(&b, op);
            assert_eq!(voxels(&got), voxels(&want), "{op:?}");
            assert_eq!(got.leaf_count(), want.leaf_count(), "{op:?}");
            assert_eq!(s.voxels, want.voxel_count());
        }
    }
}

/// Leaves of `t` in up to three colours (some left uncoloured), as a model.
pub(super) fn coloured(
    rng: &mut rand_pcg::Pcg64,
    t: &LinearOctree,
    palette: &[[u8; 4]],
) -> crate::model::Model {
    let mut regions: Vec<Vec<crate::linear::Leaf>> = vec![Vec::new(); palette.len()];
    for &l in t.leaves() {
        let i = rng.random_range(0..=palette.len());
        if i < palette.len() {
            regions[i].push(l);
        }
    }
    let layer = crate::model::Layer::from_regions(
        t.depth(),
        t.origin(),
        palette.iter().zip(regions).map(|(c, ls)| {
            (
                *c,
                LinearOctree::from_sorted_leaves(t.depth(), t.origin(), ls).unwrap(),
            )
        }),
    )
    .unwrap();
    crate::model::Model::new(t.clone())
        .with_colors(layer)
        .unwrap()
}

/// With colours: the streamed operation gives the in-memory `Model::set_op`'s
/// model (tree and colour layer), for operands with shared and distinct colours,
/// and for one operand without colours.
#[test]
fn streamed_set_operations_keep_colours_as_in_memory() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(23);
    let (red, green, blue) = ([255, 0, 0, 255], [0, 255, 0, 255], [0, 0, 255, 255]);
    for i in 0..40 {
        let depth = rng.random_range(1..=5);
        let a = random_tree(&mut rng, depth);
        let b = random_tree(&mut rng, depth);
        let ma = coloured(&mut rng, &a, &[red, green]);
        let mb = if i % 4 == 3 {
            crate::model::Model::new(b.clone())
        } else {
            coloured(&mut rng, &b, &[green, blue])
        };
        let (pa, pb) = (
            dir.path().join(format!("a{i}.tess")),
            dir.path().join(format!("b{i}.tess")),
        );
        std::fs::write(
            &pa,
            crate::io::native::tests::encode_chunked(&ma, 1 + i % 3),
        )
        .unwrap();
        std::fs::write(
            &pb,
            crate::io::native::tests::encode_chunked(&mb, 2 + i % 2),
        )
        .unwrap();
        let (fa, fb) = (
            crate::io::TessFile::open(&pa).unwrap(),
            crate::io::TessFile::open(&pb).unwrap(),
        );
        for op in [
            SetOp::Union,
            SetOp::Intersection,
            SetOp::Difference,
            SetOp::SymmetricDifference,
        ] {
            let mut out = Vec::new();
            stream_set_op_in(&fa, &fb, op, Frame::default(), &mut out, dir.path()).unwrap();
            let got = crate::io::native::decode(&out).unwrap();
            got.assert_valid();
            let want = ma.set_op(&mb, op).unwrap();
            assert_eq!(got.tree, want.tree, "{op:?}");
            // The layer itself too: kept, even empty, when an operand has one.
            assert_eq!(got.colors, want.colors, "{op:?} {i}");
        }
    }
}

/// More parts asked than there are weights to cut at: as many ranges as can be
/// cut, tiling the space, at once (a loop to `k` with `j · k` in 64 bits hung or
/// wrapped for a `k` near 2^64).
#[test]
fn balanced_ranges_cap_the_parts_at_the_weights() {
    let weights: Vec<std::ops::Range<u64>> = (0..10u64).map(|i| i * 100..i * 100 + 50).collect();
    for k in [1, 3, 10, 11, 1 << 40, usize::MAX] {
        let ranges = balanced_ranges(4, k, &weights);
        assert!(ranges.len() <= k.min(10), "k {k}: {} ranges", ranges.len());
        assert_eq!(ranges[0].lo, 0);
        assert_eq!(ranges.last().unwrap().hi, 1 << 12);
        assert!(ranges
            .windows(2)
            .all(|w| w[0].hi == w[1].lo && w[0].lo < w[0].hi));
    }
    assert_eq!(balanced_ranges(4, usize::MAX, &weights).len(), 10);
}
