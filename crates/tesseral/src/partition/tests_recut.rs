//! Streamed re-cuts into datasets and streamed `.xyz` lists, against the
//! in-memory paths (`balanced_ranges_of`, `split_model` + `write_model_part`,
//! `xyz::write`) and a voxel-set model, on seeded random coloured models read as
//! version-2 files (random chunk sizes), version-1 files and datasets.

use std::collections::HashSet;
use std::path::Path;

use rand::{Rng, SeedableRng};

use super::tests::{coloured, random_ranges};
use super::*;
use crate::io::{native, TessFile};
use crate::model::{Frame, Model};

/// A random tree of the depth-`depth` space at a random origin: scattered
/// voxels, sometimes a big block (so cuts split leaves), sometimes nothing.
fn random_tree(rng: &mut rand_pcg::Pcg64, depth: u8) -> LinearOctree {
    let origin = [0, 1, 2].map(|_| rng.random_range(-40i64..40));
    let side = 1i64 << depth;
    let n = if rng.random_bool(0.1) {
        0
    } else {
        rng.random_range(0..300)
    };
    let blob = rng.random_range(1..=side);
    let voxels: Vec<_> = (0..n)
        .map(|_| {
            [
                origin[0] + rng.random_range(0..blob),
                origin[1] + rng.random_range(0..side),
                origin[2] + rng.random_range(0..blob),
            ]
        })
        .collect();
    let mut t = LinearOctree::from_voxels(depth, origin, voxels).unwrap();
    if n > 0 && rng.random_bool(0.3) {
        let full = LinearOctree::full(depth - 1, origin).unwrap();
        t = t.union(&full).unwrap();
    }
    t.assert_valid();
    t
}

fn random_model(rng: &mut rand_pcg::Pcg64, i: usize) -> Model {
    let depth = rng.random_range(1..=5);
    let t = random_tree(rng, depth);
    let m = if i % 3 == 2 {
        Model::new(t)
    } else {
        coloured(
            rng,
            &t,
            &[[255, 0, 0, 255], [0, 255, 0, 255], [9, 9, 9, 128]],
        )
    };
    let mut m = m.with_frame(Frame::new(0.25, [1.0, -2.0, 3.5]));
    // No voxel coloured: no layer (as a file without colours reads).
    if m.colors.as_ref().is_some_and(|l| l.region_count() == 0) {
        m.colors = None;
    }
    m
}

/// How the input is given.
#[derive(Clone, Copy, Debug)]
enum Input {
    V2,
    /// Decoded whole when opened.
    V1,
    /// Opened by `TessFile::open_streaming`: its payload indexed in stretches.
    V1Streamed,
    Dataset,
}

const KINDS: [Input; 4] = [Input::V2, Input::V1, Input::V1Streamed, Input::Dataset];

/// Writes `model` as the input `kind` under `dir` (named by `tag`) and opens its
/// files in code order.
fn input_files(
    rng: &mut rand_pcg::Pcg64,
    model: &Model,
    kind: Input,
    dir: &Path,
    tag: &str,
) -> Vec<TessFile> {
    match kind {
        Input::V2 | Input::V1 | Input::V1Streamed => {
            let path = dir.join(format!("{tag}.tess"));
            let bytes = match kind {
                Input::V2 => native::tests::encode_chunked(model, rng.random_range(1..6)),
                _ => native::tests::encode_v1(model),
            };
            std::fs::write(&path, bytes).unwrap();
            let f = match kind {
                Input::V1Streamed => TessFile::open_streaming(&path).unwrap(),
                _ => TessFile::open(&path).unwrap(),
            };
            assert_eq!(f.is_streamed(), !matches!(kind, Input::V1));
            vec![f]
        }
        Input::Dataset => {
            let ranges = random_ranges(rng, model.tree.depth());
            let ds = dir.join(format!("{tag}-in"));
            std::fs::create_dir_all(&ds).unwrap();
            let parts: Vec<_> = ranges
                .iter()
                .zip(split_model(model, &ranges).unwrap())
                .enumerate()
                .map(|(i, (p, m))| write_model_part(&ds, i, *p, &m).unwrap())
                .collect();
            let t = &model.tree;
            write_manifest(&ds, t.depth(), t.origin(), model.frame, &parts).unwrap();
            let m = read_manifest(&ds).unwrap();
            (0..m.parts.len())
                .map(|i| open_part(&ds, &m, i).unwrap())
                .collect()
        }
    }
}

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// The streamed re-cut of a file or dataset into K parts writes, part for part,
/// the bytes of the in-memory cut (`split_model` + `write_model_part`) and the
/// same manifest; its ranges are `balanced_ranges_of` the tree for one file; the
/// dataset reads back as the model (tree, colours, frame, the voxel set), and
/// joined by `stream_concat` it is the bytes of the model's own `.tess`.
#[test]
fn streamed_datasets_equal_the_in_memory_cut() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(15);
    for i in 0..48 {
        let model = random_model(&mut rng, i);
        let kind = KINDS[i % 4];
        let files = input_files(&mut rng, &model, kind, d, &format!("in{i}"));
        let k = rng.random_range(1..7);
        let ranges = leaf_ranges(&files, k).unwrap();
        assert!(ranges.len() <= k);
        if !matches!(kind, Input::Dataset) {
            assert_eq!(ranges, balanced_ranges_of(&model.tree, k), "{i} {kind:?}");
        }
        // Every fourth model is cut at random codes instead, which split leaves
        // (of the shape and of the colours) across the cuts.
        let ranges = if i % 4 == 3 {
            random_ranges(&mut rng, model.tree.depth())
        } else {
            ranges
        };
        let out = d.join(format!("out{i}"));
        let mem = d.join(format!("mem{i}"));
        std::fs::create_dir_all(&out).unwrap();
        std::fs::create_dir_all(&mem).unwrap();
        let parts = stream_dataset(&files, model.frame, &ranges, &out).unwrap();
        let cut = split_model(&model, &ranges).unwrap();
        let mut expected = Vec::new();
        for (j, (p, m)) in ranges.iter().zip(&cut).enumerate() {
            expected.push(write_model_part(&mem, j, *p, m).unwrap());
            let name = dataset::part_name(j);
            assert_eq!(
                std::fs::read(out.join(&name)).unwrap(),
                std::fs::read(mem.join(&name)).unwrap(),
                "{i} {kind:?} part {j}"
            );
        }
        assert_eq!(parts, expected, "{i} {kind:?}");
        let t = &model.tree;
        write_manifest(&mem, t.depth(), t.origin(), model.frame, &expected).unwrap();
        assert_eq!(
            std::fs::read(out.join(MANIFEST)).unwrap(),
            std::fs::read(mem.join(MANIFEST)).unwrap()
        );
        // Only the parts and the manifest: no spool or temporary is left.
        assert_eq!(names(&out).len(), ranges.len() + 1);
        let back = read_dataset_model(&out).unwrap();
        back.tree.assert_valid();
        assert_eq!(back.tree, model.tree, "{i} {kind:?}");
        assert_eq!(back.colors, model.colors, "{i} {kind:?}");
        assert_eq!(back.frame, model.frame);
        let vs: HashSet<_> = back.tree.voxels().collect();
        assert_eq!(vs, model.tree.voxels().collect::<HashSet<_>>());
        // Joined again: the bytes of the model's own file.
        let m = read_manifest(&out).unwrap();
        let parts: Vec<_> = (0..m.parts.len())
            .map(|j| open_part(&out, &m, j).unwrap())
            .collect();
        let mut joined = Vec::new();
        stream_concat(&parts, model.frame, &mut joined, d).unwrap();
        assert_eq!(joined, native::encode(&model), "{i} {kind:?}");
    }
}

/// The streamed `.xyz` of a file or dataset is the in-memory `xyz::write` of the
/// model, byte for byte, and `leaf_facts` gives the joined tree's leaf and voxel
/// counts and bounding box.
#[test]
fn streamed_xyz_equals_the_in_memory_list() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(16);
    for i in 0..36 {
        let model = random_model(&mut rng, i);
        let kind = KINDS[i % 4];
        let files = input_files(&mut rng, &model, kind, d, &format!("x{i}"));
        let facts = leaf_facts(&files).unwrap();
        let t = &model.tree;
        assert_eq!(
            facts,
            LeafFacts {
                leaves: t.leaf_count() as u64,
                voxels: t.voxel_count(),
                bbox: t.bbox(),
            },
            "{i} {kind:?}"
        );
        let mut streamed = Vec::new();
        write_xyz(&files, facts.voxels, &mut streamed).unwrap();
        let mut mem = Vec::new();
        crate::io::xyz::write(&mut mem, t).unwrap();
        assert_eq!(streamed, mem, "{i} {kind:?}");
        assert_eq!(
            crate::io::estimate_xyz_bytes(facts.voxels, facts.bbox),
            crate::io::estimate_output_bytes(t, "xyz").unwrap()
        );
    }
}

/// Long runs of mergeable leaves split across many parts: the merged leaf count
/// of `leaf_facts` past its window is the joined tree's.
#[test]
fn leaf_facts_merge_across_many_parts() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let t = LinearOctree::full(6, [-3, 0, 5]).unwrap();
    let model = Model::new(t.clone());
    let end = 1u64 << 18;
    let ranges: Vec<Partition> = (0..97u64)
        .map(|j| Partition {
            lo: j * end / 97,
            hi: (j + 1) * end / 97,
        })
        .collect();
    for (i, (p, m)) in ranges
        .iter()
        .zip(split_model(&model, &ranges).unwrap())
        .enumerate()
    {
        write_model_part(d, i, *p, &m).unwrap();
    }
    let files: Vec<_> = (0..ranges.len())
        .map(|i| TessFile::open(&d.join(dataset::part_name(i))).unwrap())
        .collect();
    let split: u64 = files.iter().map(TessFile::leaf_count).sum();
    assert!(split > 1000, "{split}");
    let facts = leaf_facts(&files).unwrap();
    assert_eq!(facts.leaves, 1);
    assert_eq!(facts.voxels, t.voxel_count());
    assert_eq!(facts.bbox, t.bbox());
}

/// Files out of code order, of different spaces, and ranges that do not tile the
/// space are errors; a failed part leaves no file of it.
#[test]
fn bad_streams_and_ranges_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let a = LinearOctree::from_voxels(3, [0, 0, 0], [[0, 0, 0], [7, 7, 7]]).unwrap();
    let b = LinearOctree::from_voxels(3, [0, 0, 0], [[1, 0, 0]]).unwrap();
    let c = LinearOctree::from_voxels(2, [0, 0, 0], [[1, 0, 0]]).unwrap();
    for (name, t) in [("a", &a), ("b", &b), ("c", &c)] {
        crate::io::write_model(&d.join(format!("{name}.tess")), &Model::new(t.clone())).unwrap();
    }
    let open = |n: &str| TessFile::open(&d.join(format!("{n}.tess"))).unwrap();
    let whole = [Partition { lo: 0, hi: 512 }];
    let out = d.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let files = [open("a"), open("b")];
    let e = stream_dataset(&files, Frame::default(), &whole, &out).unwrap_err();
    assert!(e.to_string().contains("out of code order"), "{e}");
    assert!(names(&out).is_empty(), "{:?}", names(&out));
    assert!(leaf_facts(&files).is_err());
    assert!(write_xyz(&files, 3, &mut Vec::new()).is_err());
    let mixed = [open("a"), open("c")];
    assert!(leaf_ranges(&mixed, 2).is_err());
    assert!(leaf_facts(&mixed).is_err());
    let gap = [Partition { lo: 0, hi: 100 }];
    assert!(stream_dataset(&[open("a")], Frame::default(), &gap, &out).is_err());
    assert!(leaf_ranges(&[], 2).is_err());
}
