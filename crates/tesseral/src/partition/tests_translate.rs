//! The streamed translation of a `.tess` file against the in-memory
//! `Model::translate` and a voxel-set model, on seeded random coloured models.

use std::collections::HashSet;

use rand::{Rng, SeedableRng};

use super::tests::{coloured, random_tree, voxels};
use super::*;
use crate::io::{native, TessFile};
use crate::model::{Frame, Model};

/// Displacements of every kind for a depth-`depth` space: none, aligned to the
/// space, aligned to small blocks, unaligned, negative, and far enough to grow it.
fn offsets(rng: &mut rand_pcg::Pcg64, depth: u8) -> Vec<[i64; 3]> {
    let side = 1i64 << depth;
    let mut r = |lo: i64, hi: i64| rng.random_range(lo..=hi);
    vec![
        [0, 0, 0],
        [side, 0, -side],
        [4 * r(-2, 2), 2 * r(-3, 3), 0],
        [r(-3, 3), r(-3, 3), r(-3, 3)],
        [-1, -2, -3],
        [r(side, 3 * side), -r(side, 3 * side), r(0, 1)],
    ]
}

/// The streamed translation equals `Model::translate` (space, tree and colour
/// layer) and moves exactly the voxels of a hash-set model, with windows of a
/// few leaves so that the output is cut into many cells, down to single voxels.
#[test]
fn streamed_translation_equals_the_in_memory_one() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(31);
    let (red, green, blue) = ([255, 0, 0, 255], [0, 255, 0, 255], [0, 0, 255, 255]);
    for i in 0..30 {
        let depth = rng.random_range(1..=5);
        let t = random_tree(&mut rng, depth);
        let origin = [
            rng.random_range(-9..9),
            rng.random_range(-9..9),
            rng.random_range(-9..9),
        ];
        let t =
            LinearOctree::from_sorted_leaves(depth, origin, t.leaves().iter().copied()).unwrap();
        let frame = Frame::new(0.25, [1.0, -2.0, 0.5]);
        let model = if i % 5 == 4 {
            Model::new(t.clone())
        } else {
            coloured(&mut rng, &t, &[red, green, blue])
        }
        .with_frame(frame);
        let path = dir.path().join(format!("m{i}.tess"));
        std::fs::write(&path, native::tests::encode_chunked(&model, 1 + i % 5)).unwrap();
        let f = TessFile::open(&path).unwrap();
        for by in offsets(&mut rng, depth) {
            for run in [1, 3, 64, CELL_LEAVES] {
                let mut out = Vec::new();
                let s = stream_translate_in(&f, by, &mut out, dir.path(), run).unwrap();
                let got = native::decode(&out).unwrap();
                got.assert_valid();
                got.tree.assert_valid();
                let want = model.translate(by).unwrap();
                assert_eq!(
                    (got.tree.depth(), got.tree.origin()),
                    (want.tree.depth(), want.tree.origin()),
                    "space, {i} by {by:?}"
                );
                assert_eq!((s.depth, s.origin), (got.tree.depth(), got.tree.origin()));
                assert_eq!(s.bbox, got.tree.bbox());
                assert_eq!(got.tree, want.tree, "{i} by {by:?} run {run}");
                let moved: HashSet<[i64; 3]> = voxels(&t)
                    .into_iter()
                    .map(|v| [v[0] + by[0], v[1] + by[1], v[2] + by[2]])
                    .collect();
                assert_eq!(voxels(&got.tree), moved);
                let want_colors = want.colors.filter(|l| !l.is_empty());
                assert_eq!(got.colors, want_colors, "{i} by {by:?} run {run}");
                assert_eq!(got.frame, frame);
                assert_eq!(s.summary.voxels, t.voxel_count());
                assert_eq!(s.summary.leaves, got.tree.leaf_count() as u64);
            }
        }
    }
}

/// A translation past the deepest space is refused with an error, not a panic.
#[test]
fn streamed_translation_past_the_deepest_space_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let t = LinearOctree::from_voxels(3, [0, 0, 0], [[1, 2, 3]]).unwrap();
    let path = dir.path().join("a.tess");
    std::fs::write(&path, native::tests::encode_chunked(&Model::new(t), 1)).unwrap();
    let f = TessFile::open(&path).unwrap();
    let mut out = Vec::new();
    assert!(stream_translate(&f, [i64::MAX, 0, 0], &mut out, dir.path()).is_err());
    assert!(stream_translate(&f, [1 << 40, 0, 0], &mut out, dir.path()).is_err());
}
