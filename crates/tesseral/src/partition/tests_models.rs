//! The model-level steps of a distributed run (`models.rs`) and the reach of a
//! shuffle (`shuffle::reach`), against the whole model's operations and brute
//! force, on seeded random data.

use rand::{Rng, SeedableRng};

use super::tests::{coloured, random_ranges, random_tree};
use super::*;
use crate::model::{Frame, Model};

const RED: [u8; 4] = [255, 0, 0, 255];
const GREEN: [u8; 4] = [0, 255, 0, 255];
const BLUE: [u8; 4] = [0, 0, 255, 255];

/// Every coloured voxel with its colour's key (no layer and an empty one alike).
fn colour_voxels(m: &Model) -> Vec<([i64; 3], u64)> {
    m.colors.as_ref().map_or(Vec::new(), |l| {
        l.to_voxels().into_iter().map(|(v, k, _)| (v, k)).collect()
    })
}

fn same_model(got: &Model, want: &Model, what: &str) {
    got.assert_valid();
    assert_eq!(
        (got.tree.depth(), got.tree.origin()),
        (want.tree.depth(), want.tree.origin()),
        "{what}: space"
    );
    assert_eq!(got.tree, want.tree, "{what}: voxels");
    assert_eq!(got.frame, want.frame, "{what}: frame");
    assert_eq!(colour_voxels(got), colour_voxels(want), "{what}: colours");
}

/// The target ranges that the leaves of `moved` actually meet.
fn met(moved: &LinearOctree, ranges: &[Partition]) -> Vec<usize> {
    let mut out: Vec<usize> = Vec::new();
    for l in moved.leaves() {
        for (j, r) in ranges.iter().enumerate() {
            if l.code() < r.hi && r.lo < l.end() && !out.contains(&j) {
                out.push(j);
            }
        }
    }
    out.sort_unstable();
    out
}

#[test]
fn reach_holds_every_range_the_moved_leaves_meet() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(160);
    for _ in 0..200 {
        let depth = rng.random_range(1..=6);
        let tree = random_tree(&mut rng, depth);
        let src = random_ranges(&mut rng, depth);
        let side = 1i64 << depth;
        let by: [i64; 3] = std::array::from_fn(|_| rng.random_range(-2 * side..=2 * side));
        // The translated space, or any other space (voxels outside are dropped).
        let (d2, o2) = if rng.random_bool(0.5) {
            translated_space(depth, [0; 3], tree.bbox(), by).unwrap()
        } else {
            (
                rng.random_range(1..=7),
                std::array::from_fn(|_| rng.random_range(-70..=70)),
            )
        };
        let dst = random_ranges(&mut rng, d2);
        let reached = reach((depth, [0; 3]), &src, by, (d2, o2), &dst).unwrap();
        assert_eq!(reached.len(), src.len());
        let parts = PartitionedOctree::split(&tree, &src).unwrap();
        for ((_, part), r) in parts.parts().iter().zip(&reached) {
            assert!(r.windows(2).all(|w| w[0] < w[1]), "sorted, distinct: {r:?}");
            let (moved, _) = part.translate_into(by, d2, o2).unwrap();
            let need = met(&moved, &dst);
            assert!(
                need.iter().all(|j| r.contains(j)),
                "by {by:?} into depth {d2} at {o2:?}: met {need:?}, reached {r:?}"
            );
            // The pruned cut is the full cut without its empty pieces.
            let mine: Vec<Partition> = r.iter().map(|&j| dst[j]).collect();
            let m = Model::new(part.clone());
            let cut = move_and_split(&m, by, d2, o2, &mine, true).unwrap();
            let full = PartitionedOctree::split(&moved, &dst).unwrap();
            for (j, piece) in r.iter().zip(&cut) {
                piece.assert_valid();
                assert_eq!(piece.tree, full.parts()[*j].1);
            }
        }
    }
}

#[test]
fn in_one_space_without_a_move_reach_is_the_overlap() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(161);
    for _ in 0..100 {
        let depth = rng.random_range(1..=7);
        let (src, dst) = (
            random_ranges(&mut rng, depth),
            random_ranges(&mut rng, depth),
        );
        let o: [i64; 3] = std::array::from_fn(|_| rng.random_range(-9..=9));
        let got = reach((depth, o), &src, [0; 3], (depth, o), &dst).unwrap();
        for (p, r) in src.iter().zip(got) {
            let want: Vec<usize> = (0..dst.len())
                .filter(|&j| dst[j].lo < p.hi && p.lo < dst[j].hi)
                .collect();
            assert_eq!(r, want);
        }
    }
}

#[test]
fn a_64_part_shuffle_sends_each_part_to_few_ranges() {
    let depth = 10;
    let end = 1u64 << (3 * depth);
    let even = |k: u64| -> Vec<Partition> {
        (0..k)
            .map(|i| Partition {
                lo: i * end / k,
                hi: (i + 1) * end / k,
            })
            .collect()
    };
    let (src, dst) = (even(64), even(64));
    for by in [[3, -5, 7], [1001, -7, 333], [0, 0, 1], [-511, 257, 129]] {
        let got = reach((depth as u8, [0; 3]), &src, by, (depth as u8, [0; 3]), &dst).unwrap();
        let pieces: usize = got.iter().map(Vec::len).sum();
        // A full shuffle would make 64 × 64 = 4096 pieces.
        assert!(pieces <= 8 * 64, "by {by:?}: {pieces} pieces");
    }
    assert!(reach(
        (3, [0; 3]),
        &[Partition { lo: 0, hi: 513 }],
        [0; 3],
        (3, [0; 3]),
        &[]
    )
    .is_err());
}

#[test]
fn coloured_parts_combine_and_move_as_the_whole_model() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(162);
    let frame = Frame::new(0.5, [1.0, -2.0, 0.25]);
    for i in 0..60 {
        let depth = rng.random_range(1..=5);
        let (a, b) = (random_tree(&mut rng, depth), random_tree(&mut rng, depth));
        let ma = coloured(&mut rng, &a, &[RED, GREEN]).with_frame(frame);
        let mb = if i % 4 == 3 {
            Model::new(b).with_frame(frame)
        } else {
            coloured(&mut rng, &b, &[GREEN, BLUE]).with_frame(frame)
        };
        let ranges = random_ranges(&mut rng, depth);
        let pa = split_model(&ma, &ranges).unwrap();
        let pb = split_model(&mb, &ranges).unwrap();
        for p in pa.iter().chain(&pb) {
            p.assert_valid();
        }
        let whole = |parts: Vec<Model>| join_models(depth, [0; 3], frame, parts).unwrap();
        same_model(&whole(pa.clone()), &ma, "split and join");
        for op in [
            SetOp::Union,
            SetOp::Intersection,
            SetOp::Difference,
            SetOp::SymmetricDifference,
        ] {
            let got: Vec<Model> = pa
                .iter()
                .zip(&pb)
                .map(|(x, y)| set_op_models(x, y, op).unwrap())
                .collect();
            same_model(
                &whole(got),
                &ma.set_op(&mb, op).unwrap(),
                &format!("{op:?}"),
            );
        }
        // A translation as a shuffle: each part moved and cut by the target ranges
        // it reaches, the pieces of each range joined.
        let side = 1i64 << depth;
        let by: [i64; 3] = std::array::from_fn(|_| rng.random_range(-2 * side..=2 * side));
        let want = ma.translate(by).unwrap();
        let (d2, o2) = (want.tree.depth(), want.tree.origin());
        let dst = random_ranges(&mut rng, d2);
        let reached = reach((depth, [0; 3]), &ranges, by, (d2, o2), &dst).unwrap();
        let mut incoming: Vec<Vec<Model>> = vec![Vec::new(); dst.len()];
        for (part, r) in pa.iter().zip(&reached) {
            let mine: Vec<Partition> = r.iter().map(|&j| dst[j]).collect();
            for (j, piece) in r
                .iter()
                .zip(move_and_split(part, by, d2, o2, &mine, false).unwrap())
            {
                incoming[*j].push(piece);
            }
        }
        let moved: Vec<Model> = incoming
            .into_iter()
            .map(|p| join_models(d2, o2, frame, p).unwrap())
            .collect();
        for (m, r) in moved.iter().zip(&dst) {
            m.assert_valid();
            assert!(m
                .tree
                .leaves()
                .iter()
                .all(|l| l.code() >= r.lo && l.end() <= r.hi));
        }
        same_model(
            &join_models(d2, o2, frame, moved).unwrap(),
            &want,
            "translate",
        );
    }
}

#[test]
fn parts_move_into_a_grown_space_on_embedded_ranges() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(163);
    for _ in 0..60 {
        let depth = rng.random_range(1..=5);
        let tree = random_tree(&mut rng, depth);
        let m = coloured(&mut rng, &tree, &[RED, BLUE]);
        let ranges = random_ranges(&mut rng, depth);
        let far: [i64; 3] = std::array::from_fn(|_| rng.random_range(-100..=100));
        let (d2, o2) = crate::linear::grow::grown_space(depth, [0; 3], far, far).unwrap();
        let new = embedded_ranges(depth, [0; 3], &ranges, d2, o2).unwrap();
        let parts = split_model(&m, &ranges).unwrap();
        let moved: Vec<Model> = parts
            .iter()
            .zip(&new)
            .map(|(p, r)| {
                move_and_split(p, [0; 3], d2, o2, &[*r], false)
                    .unwrap()
                    .remove(0)
            })
            .collect();
        let back = join_models(d2, o2, m.frame, moved).unwrap();
        same_model(&back, &m.in_space(d2, o2).unwrap(), "embedded");
        if (d2, o2) != (depth, [0; 3]) {
            assert!(embedded_ranges(d2, o2, &new, depth, [0; 3]).is_err());
        }
    }
}

#[test]
fn a_scene_range_builds_with_the_scene_colours() {
    let text = "depth 6\nbounds [0, 0, 0] [32, 32, 32]\n\
        union { box(size = 20) at [12, 12, 12] colour \"red\" sphere(r = 9) at [18, 18, 18] } colour \"blue\"\n\
        sphere(r = 6) at [8, 8, 8]\ncylinder(r = 3, h = 20) at [24, 8, 20] colour \"green\"\n";
    let scene = crate::csg::Scene::parse(text, "t.tss".as_ref()).unwrap();
    let want = scene.build_model_limited(1 << 24).unwrap();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(164);
    for k in [1, 3, 7] {
        let ranges = if k == 7 {
            random_ranges(&mut rng, 6)
        } else {
            scene_ranges(&scene, k).unwrap()
        };
        let parts: Vec<Model> = ranges
            .iter()
            .map(|r| build_scene_range(&scene, *r, 1 + k).unwrap())
            .collect();
        for (p, r) in parts.iter().zip(&ranges) {
            p.assert_valid();
            assert!(p
                .tree
                .leaves()
                .iter()
                .all(|l| l.code() >= r.lo && l.end() <= r.hi));
        }
        let got = join_models(6, [0; 3], scene.frame(), parts).unwrap();
        same_model(&got, &want, &format!("{k} ranges"));
        assert!(colour_voxels(&got).len() > 100);
    }
}
