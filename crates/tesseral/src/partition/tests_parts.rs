//! Streamed set operations whose operands are lists of files (a dataset's parts
//! read in order as one stream) or version-1 files, against `Model::set_op` and a
//! voxel-set model, on seeded random coloured models.

use std::collections::HashSet;

use rand::{Rng, SeedableRng};

use super::tests::{coloured, random_ranges, random_tree, voxels};
use super::*;
use crate::io::{native, TessFile};
use crate::model::{Frame, Layer, Model};

/// `model` cut into `ranges`, each part with its share of the colours.
fn parts(model: &Model, ranges: &[Partition]) -> Vec<Model> {
    let t = &model.tree;
    let tree = PartitionedOctree::split(t, ranges).unwrap();
    let regions: Vec<_> = model
        .colors
        .iter()
        .flat_map(|l| l.regions().iter())
        .map(|(c, r)| (*c, PartitionedOctree::split(r, ranges).unwrap()))
        .collect();
    tree.parts()
        .iter()
        .enumerate()
        .map(|(i, (_, p))| {
            let m = Model::new(p.clone());
            if regions.is_empty() {
                return m;
            }
            let layer = Layer::from_regions(
                t.depth(),
                t.origin(),
                regions.iter().map(|(c, r)| (*c, r.parts()[i].1.clone())),
            )
            .unwrap();
            m.with_colors(layer).unwrap()
        })
        .collect()
}

/// A dataset's parts (random ranges, random chunk sizes) and a version-1 or
/// version-2 file, combined by every operation, give `Model::set_op`'s tree and
/// colour layer, and the voxels of the hash-set operation.
#[test]
fn streamed_set_operations_of_parts_and_version_1_files_equal_the_in_memory_ones() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(41);
    let (red, green, blue) = ([255, 0, 0, 255], [0, 255, 0, 255], [0, 0, 255, 255]);
    for i in 0..30 {
        let depth = rng.random_range(1..=5);
        let a = random_tree(&mut rng, depth);
        let b = random_tree(&mut rng, depth);
        let ma = coloured(&mut rng, &a, &[red, green]);
        let mb = if i % 4 == 3 {
            Model::new(b.clone())
        } else {
            coloured(&mut rng, &b, &[green, blue])
        };
        let ranges = random_ranges(&mut rng, depth);
        let mut fa = Vec::new();
        for (j, p) in parts(&ma, &ranges).iter().enumerate() {
            let path = dir.path().join(format!("a{i}-{j}.tess"));
            let chunk = rng.random_range(1..5);
            std::fs::write(&path, native::tests::encode_chunked(p, chunk)).unwrap();
            fa.push(TessFile::open(&path).unwrap());
        }
        let pb = dir.path().join(format!("b{i}.tess"));
        let v1 = i % 2 == 0;
        let bytes = if v1 {
            native::tests::encode_v1(&mb)
        } else {
            native::tests::encode_chunked(&mb, 3)
        };
        std::fs::write(&pb, bytes).unwrap();
        let fb = [TessFile::open(&pb).unwrap()];
        assert_eq!(fb[0].is_streamed(), !v1);
        let (va, vb) = (voxels(&a), voxels(&b));
        // The dataset as the in-memory reader joins it: a colour layer only when
        // a part has a colour region.
        let mut ma = ma;
        ma.colors = ma.colors.filter(|l| !l.is_empty());
        for op in [
            SetOp::Union,
            SetOp::Intersection,
            SetOp::Difference,
            SetOp::SymmetricDifference,
        ] {
            for (x, y, mx, my, vx, vy) in [
                (&fa[..], &fb[..], &ma, &mb, &va, &vb),
                (&fb[..], &fa[..], &mb, &ma, &vb, &va),
            ] {
                let mut out = Vec::new();
                let s =
                    stream_set_op_files(x, y, op, Frame::default(), &mut out, dir.path()).unwrap();
                let got = native::decode(&out).unwrap();
                got.assert_valid();
                got.tree.assert_valid();
                let want = mx.set_op(my, op).unwrap();
                assert_eq!(got.tree, want.tree, "{i} {op:?}");
                assert_eq!(got.colors, want.colors, "{i} {op:?}");
                let set: HashSet<[i64; 3]> = match op {
                    SetOp::Union => vx | vy,
                    SetOp::Intersection => vx & vy,
                    SetOp::Difference => vx - vy,
                    SetOp::SymmetricDifference => vx ^ vy,
                };
                assert_eq!(voxels(&got.tree), set, "{i} {op:?}");
                assert_eq!(s.leaves, got.tree.leaf_count() as u64);
                assert_eq!(s.voxels, got.tree.voxel_count());
            }
        }
    }
}

/// Parts given out of code order are an error, not a wrong result.
#[test]
fn parts_out_of_order_are_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let t = LinearOctree::from_voxels(3, [0, 0, 0], [[0, 0, 0], [7, 7, 7]]).unwrap();
    let p = PartitionedOctree::split(
        &t,
        &[Partition { lo: 0, hi: 8 }, Partition { lo: 8, hi: 512 }],
    )
    .unwrap();
    let mut files = Vec::new();
    for (i, (_, part)) in p.parts().iter().enumerate() {
        let path = dir.path().join(format!("p{i}.tess"));
        std::fs::write(
            &path,
            native::tests::encode_chunked(&Model::new(part.clone()), 1),
        )
        .unwrap();
        files.push(TessFile::open(&path).unwrap());
    }
    files.reverse();
    let mut out = Vec::new();
    let e = stream_set_op_files(
        &files,
        &files[..1],
        SetOp::Union,
        Frame::default(),
        &mut out,
        dir.path(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("out of code order"), "{e}");
}
