//! The streamed translation of a `.tess` file against the in-memory
//! `Model::translate` and a voxel-set model, on seeded random coloured models.

use std::collections::HashSet;

use rand::{Rng, SeedableRng};

use super::tests::{coloured, random_tree, voxels};
use super::*;
use crate::io::{native, TessFile};
use crate::model::{Frame, Model};

/// Displacements of every kind for `t`: none, aligned to the space, aligned to
/// small blocks, unaligned, negative, far enough to grow the space, and moving the
/// leaves up to each edge of the space (kept) and one voxel past it (grown).
fn offsets(rng: &mut rand_pcg::Pcg64, t: &LinearOctree) -> Vec<[i64; 3]> {
    let side = 1i64 << t.depth();
    let mut r = |lo: i64, hi: i64| rng.random_range(lo..=hi);
    let mut out = vec![
        [0, 0, 0],
        [side, 0, -side],
        [4 * r(-2, 2), 2 * r(-3, 3), 0],
        [r(-3, 3), r(-3, 3), r(-3, 3)],
        [-1, -2, -3],
        [r(side, 3 * side), -r(side, 3 * side), r(0, 1)],
    ];
    if let Some((lo, hi)) = t.bbox() {
        let o = t.origin();
        let to_low: [i64; 3] = std::array::from_fn(|a| o[a] - lo[a]);
        let to_high: [i64; 3] = std::array::from_fn(|a| o[a] + side - 1 - hi[a]);
        out.push(to_low);
        out.push(to_high);
        out.push([to_low[0] - 1, to_low[1], to_low[2]]);
        out.push([to_high[0], to_high[1], to_high[2] + 1]);
    }
    out
}

/// The streamed translation writes the bytes the in-memory path writes for
/// `Model::translate` (space, tree and colour layer, an empty layer included) and
/// moves exactly the voxels of a hash-set model, with windows of a few leaves so
/// that the output is cut into many cells, down to single voxels.
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
        for by in offsets(&mut rng, &t) {
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
                assert_eq!(got.colors, want.colors, "{i} by {by:?} run {run}");
                assert!(
                    out == native::encode(&want),
                    "bytes, {i} by {by:?} run {run}"
                );
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

/// An empty model, with an empty colour layer or none, translates to the bytes
/// the in-memory path writes: the layer is kept (empty) or stays absent.
#[test]
fn an_empty_result_keeps_the_colour_layer_as_in_memory() {
    let dir = tempfile::tempdir().unwrap();
    let frame = Frame::new(0.5, [1.0, 2.0, 3.0]);
    for (i, origin) in [[0, 0, 0], [-5, 3, 9]].into_iter().enumerate() {
        let t = LinearOctree::empty(4, origin).unwrap();
        let layer = crate::model::Layer::from_regions(4, origin, []).unwrap();
        for (j, colors) in [None, Some(layer)].into_iter().enumerate() {
            let model = Model {
                colors,
                ..Model::new(t.clone()).with_frame(frame)
            };
            let path = dir.path().join(format!("e{i}{j}.tess"));
            std::fs::write(&path, native::encode(&model)).unwrap();
            let f = TessFile::open(&path).unwrap();
            for by in [[0, 0, 0], [3, -7, 16], [1 << 20, 0, 0]] {
                let mut out = Vec::new();
                let s = stream_translate(&f, by, &mut out, dir.path()).unwrap();
                let want = model.translate(by).unwrap();
                let got = native::decode(&out).unwrap();
                got.assert_valid();
                assert_eq!(got, want, "{i} {j} by {by:?}");
                assert_eq!(got.colors.is_some(), j == 1);
                assert!(out == native::encode(&want), "bytes, {i} {j} by {by:?}");
                assert_eq!((s.bbox, s.summary.leaves, s.summary.colours), (None, 0, 0));
            }
        }
    }
}

/// Colour regions as a layer is built from.
type Regions = Vec<([u8; 4], LinearOctree)>;

/// Colours on voxels that are not black (outside the shape's bounding box, or
/// inside it in a hole) and colour regions that overlap are refused with the
/// in-memory reader's error, naming the file, and nothing is written; the same
/// colours on black voxels translate.
#[test]
fn colours_off_the_shape_are_refused_as_in_memory() {
    let dir = tempfile::tempdir().unwrap();
    let (red, blue) = ([255, 0, 0, 255], [0, 0, 255, 255]);
    let t = LinearOctree::from_voxels(4, [0, 0, 0], [[1, 1, 1], [5, 1, 1], [2, 2, 2]]).unwrap();
    let region =
        |vs: &[[i64; 3]]| LinearOctree::from_voxels(4, [0, 0, 0], vs.iter().copied()).unwrap();
    let cases: [(&str, Regions); 4] = [
        (
            "ok",
            vec![
                (red, region(&[[1, 1, 1], [2, 2, 2]])),
                (blue, region(&[[5, 1, 1]])),
            ],
        ),
        // Outside the bounding box [1, 5] × [1, 2] × [1, 2].
        ("not black", vec![(red, region(&[[1, 1, 1], [14, 0, 9]]))]),
        // Inside it, on a hole.
        ("not black", vec![(red, region(&[[3, 1, 1]]))]),
        (
            "overlap",
            vec![
                (red, region(&[[1, 1, 1]])),
                (blue, region(&[[1, 1, 1], [5, 1, 1]])),
            ],
        ),
    ];
    for (i, (want, regions)) in cases.into_iter().enumerate() {
        // Unchecked, so that the overlapping case reaches the file (`from_regions`
        // refuses it); written as is: `Model::with_colors` would restrict the layer
        // to the shape.
        let layer = crate::model::Layer::from_regions_unchecked(4, [0, 0, 0], regions);
        let model = Model {
            colors: Some(layer),
            ..Model::new(t.clone())
        };
        let path = dir.path().join(format!("c{i}.tess"));
        std::fs::write(&path, native::encode(&model)).unwrap();
        let f = TessFile::open(&path).unwrap();
        for by in [[0, 0, 0], [3, -1, 2], [16, 0, 0]] {
            let mut out = Vec::new();
            let got = stream_translate(&f, by, &mut out, dir.path());
            if want == "ok" {
                let got = native::decode(&out).unwrap();
                assert_eq!(got, model.translate(by).unwrap());
                continue;
            }
            let e = got.unwrap_err().to_string();
            assert!(e.contains(want) && e.contains(&format!("c{i}.tess")), "{e}");
            assert!(
                out.is_empty(),
                "case {i}: nothing is written before the check"
            );
            let in_memory = f.to_model().unwrap_err().to_string();
            assert!(in_memory.contains(want), "{in_memory}");
        }
    }
}
