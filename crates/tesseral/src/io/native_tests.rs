//! Tests of the `.tess` reader and writers, both versions.

use super::*;
use crate::io::leafstream::put_varint;
use crate::io::TessWriter;
use crate::model::{Frame, Layer};
use rand::{Rng, SeedableRng};

fn random_tree(seed: u64) -> LinearOctree {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let depth = rng.random_range(0..=6u8);
    let side = 1i64 << depth;
    let origin = [rng.random_range(-100..100), rng.random_range(-100..100), 7];
    let n = rng.random_range(0..300);
    let blob = rng.random_bool(0.5);
    let voxels: Vec<_> = (0..n)
        .map(|_| {
            let r = if blob { side / 2 + 1 } else { side };
            [
                origin[0] + rng.random_range(0..r),
                origin[1] + rng.random_range(0..r),
                origin[2] + rng.random_range(0..r),
            ]
        })
        .collect();
    LinearOctree::from_voxels(depth, origin, voxels).unwrap()
}

#[test]
fn round_trips_random_trees_with_frame_and_colours() {
    for seed in 0..200 {
        let tree = random_tree(seed);
        let pairs = tree
            .voxels()
            .step_by(3)
            .map(|v| (v, [v[0] as u8, v[1] as u8, 9, 255]));
        let colors = Layer::from_voxels(tree.depth(), tree.origin(), pairs).unwrap();
        // Free space: the voxels of the space's first octant that are not black.
        let octant = LinearOctree::full(tree.depth().saturating_sub(1), tree.origin()).unwrap();
        let free = octant.difference(&tree).unwrap();
        let known = tree.union(&free).unwrap();
        let odds = Layer::from_voxels(
            tree.depth(),
            tree.origin(),
            known
                .voxels()
                .map(|v| (v, if v[0] % 2 == 0 { 0.85f32 } else { -0.4 })),
        )
        .unwrap();
        let frame = if seed % 2 == 0 {
            Frame::new(0.05, [1.5, -2.0, 0.25])
        } else {
            Frame::default()
        };
        let model = Model::from_parts(
            tree.clone(),
            frame,
            (seed % 3 == 0).then_some(colors),
            (seed % 4 < 2).then_some(free),
            (seed % 4 == 0).then_some(odds),
        )
        .unwrap();
        model.assert_valid();
        let chunk = 1 + seed as usize % 7;
        for (version, bytes) in [
            (2, encode(&model)),
            (1, encode_v1(&model)),
            (2, encode_chunked(&model, chunk)),
        ] {
            let back = decode(&bytes).unwrap_or_else(|e| panic!("seed {seed} v{version}: {e}"));
            back.assert_valid();
            assert_eq!(back, model, "seed {seed} v{version}");
        }
    }
}

pub(crate) fn encode_v1(model: &Model) -> Vec<u8> {
    let mut out = Vec::new();
    write_v1(&mut out, model).unwrap();
    out
}

/// Version 2 with `chunk` leaves per chunk.
pub(crate) fn encode_chunked(model: &Model, chunk: usize) -> Vec<u8> {
    let t = &model.tree;
    let mut w = TessWriter::new(Vec::new(), t.depth(), t.origin())
        .unwrap()
        .with_chunk_leaves(chunk);
    for &l in t.leaves() {
        w.push(l).unwrap();
    }
    w.finish_sections(&Sections::of(model)).unwrap()
}

#[test]
fn every_truncation_and_bit_flip_of_a_chunked_file_is_an_error() {
    let tree = random_tree(11);
    assert!(tree.leaf_count() > 8);
    let model = Model::new(tree).with_frame(Frame::new(0.5, [1.0, 2.0, 3.0]));
    let bytes = encode_chunked(&model, 3);
    assert_eq!(decode(&bytes).unwrap(), model);
    for len in 0..bytes.len() {
        assert!(decode(&bytes[..len]).is_err(), "truncated to {len}");
    }
    for i in 0..bytes.len() {
        for bit in 0..8 {
            let mut b = bytes.clone();
            b[i] ^= 1 << bit;
            assert!(decode(&b).is_err(), "flip byte {i} bit {bit}");
        }
    }
}

#[test]
fn forged_chunked_counts_with_valid_checksums_are_refused() {
    let tree = random_tree(5);
    let bytes = encode_chunked(&Model::new(tree), 4);
    let n = bytes.len();
    let t = n - super::super::chunked::TRAILER_LEN;
    let reseal = |b: &mut Vec<u8>| {
        let sections = u64::from_le_bytes(b[t..t + 8].try_into().unwrap()) as usize;
        let mut crc = crc32fast::Hasher::new();
        crc.update(&b[..40]);
        crc.update(&b[sections..n - 12]);
        let c = crc.finalize();
        b[t + 36..t + 40].copy_from_slice(&c.to_le_bytes());
    };
    // The leaf count, the chunk count and the index offset, each forged.
    for (at, value) in [(t + 24, 1u64 << 60), (t + 16, 1u64 << 59), (t + 8, 3)] {
        let mut b = bytes.clone();
        b[at..at + 8].copy_from_slice(&value.to_le_bytes());
        reseal(&mut b);
        assert!(decode(&b).is_err(), "field at {at}");
    }
    // The first index entry's count.
    let index = u64::from_le_bytes(bytes[t + 8..t + 16].try_into().unwrap()) as usize;
    let mut b = bytes.clone();
    b[index + 24..index + 32].copy_from_slice(&1_000_000u64.to_le_bytes());
    reseal(&mut b);
    let err = decode(&b).unwrap_err().to_string();
    assert!(err.contains("chunk 0"), "{err}");
}

#[test]
fn the_writer_merges_voxels_pushed_one_by_one() {
    for seed in 0..60 {
        let tree = random_tree(seed);
        for chunk in [1, 2, 5, 1000] {
            let mut w = TessWriter::new(Vec::new(), tree.depth(), tree.origin())
                .unwrap()
                .with_chunk_leaves(chunk);
            for l in tree.leaves() {
                for code in l.code()..l.end() {
                    w.push(crate::linear::Leaf::new(code, 0)).unwrap();
                }
            }
            let back = decode(&w.finish(Frame::default()).unwrap()).unwrap();
            back.tree.assert_valid();
            assert_eq!(
                back.tree.leaves(),
                tree.leaves(),
                "seed {seed} chunk {chunk}"
            );
        }
    }
}

#[test]
fn the_writer_refuses_leaves_out_of_order_or_outside() {
    use crate::linear::Leaf;
    let mut w = TessWriter::new(Vec::new(), 2, [0; 3]).unwrap();
    w.push(Leaf::new(8, 1)).unwrap();
    let e = w.push(Leaf::new(9, 0)).unwrap_err().to_string();
    assert!(e.contains("tesseral order"), "{e}");
    let e = w.push(Leaf::new(64, 0)).unwrap_err().to_string();
    assert!(e.contains("outside"), "{e}");
    assert!(TessWriter::new(Vec::new(), 30, [0; 3]).is_err());
}

#[test]
fn a_file_written_by_version_1_still_reads() {
    // Written by `tesseral build` before the chunked format (commit f759ede), from
    // this scene; the test builds the scene again and compares.
    let text = "depth 5\nbounds [0, 0, 0] [3.2, 3.2, 3.2]\n\
        sphere(r = 1.0) at [1.6, 1.6, 1.6] colour \"red\"\n\
        box(size = [0.8, 0.8, 0.8]) at [0.5, 0.5, 2.6] colour \"blue\"\n";
    let scene = crate::csg::Scene::parse(text, std::path::Path::new("v1.tss")).unwrap();
    let expected = scene.build_model_limited(usize::MAX).unwrap();
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/v1-colours.tess");
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(u16::from_le_bytes([bytes[8], bytes[9]]), VERSION_1);
    let model = read(&path).unwrap();
    model.assert_valid();
    assert_eq!(model.tree.voxel_count(), 4736);
    assert_eq!(model, expected);
    let f = crate::io::TessFile::open(&path).unwrap();
    assert!(!f.is_streamed());
    assert_eq!(f.to_model().unwrap(), expected);
    // Written again, it is version 2 and the same model.
    let again = encode(&model);
    assert_eq!(u16::from_le_bytes([again[8], again[9]]), VERSION);
    assert_eq!(decode(&again).unwrap(), expected);
}

#[test]
fn tess_file_reads_code_ranges_chunk_by_chunk() {
    let dir = tempfile::tempdir().unwrap();
    for seed in 0..40 {
        let tree = random_tree(seed);
        let path = dir.path().join(format!("{seed}.tess"));
        std::fs::write(
            &path,
            encode_chunked(&Model::new(tree.clone()), 1 + seed as usize % 5),
        )
        .unwrap();
        let f = crate::io::TessFile::open(&path).unwrap();
        assert!(f.is_streamed());
        assert_eq!(f.leaf_count(), tree.leaf_count() as u64);
        let all: Vec<_> = f.leaves().collect::<Result<_, _>>().unwrap();
        assert_eq!(all, tree.leaves());
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let end = 1u64 << (3 * u32::from(tree.depth()));
        for _ in 0..20 {
            let a = rng.random_range(0..=end);
            let b = rng.random_range(a..=end);
            let got: Vec<_> = f.leaves_in(a, b).collect::<Result<_, _>>().unwrap();
            let want: Vec<_> = tree
                .leaves()
                .iter()
                .copied()
                .filter(|l| l.end() > a && l.code() < b)
                .collect();
            assert_eq!(got, want, "seed {seed} [{a}, {b})");
        }
        assert_eq!(f.to_model().unwrap().tree, tree);
    }
}

#[test]
fn every_truncation_and_bit_flip_is_an_error() {
    let tree = random_tree(7);
    let bytes = encode(&Model::new(tree));
    for len in 0..bytes.len() {
        assert!(decode(&bytes[..len]).is_err(), "truncated to {len}");
    }
    for i in 0..bytes.len() {
        for bit in 0..8 {
            let mut b = bytes.clone();
            b[i] ^= 1 << bit;
            assert!(decode(&b).is_err(), "flip byte {i} bit {bit}");
        }
    }
}

#[test]
fn hostile_counts_with_valid_checksums_are_refused() {
    // A forged header claiming 2^60 leaves, with a correct checksum.
    let tree = LinearOctree::from_voxels(3, [0, 0, 0], [[1, 1, 1]]).unwrap();
    let mut bytes = encode_v1(&Model::new(tree));
    bytes[40..48].copy_from_slice(&(1u64 << 60).to_le_bytes());
    let n = bytes.len();
    let crc = crc32fast::hash(&bytes[..n - 4]);
    bytes[n - 4..].copy_from_slice(&crc.to_le_bytes());
    let err = decode(&bytes).unwrap_err().to_string();
    assert!(err.contains("leaf count"), "{err}");
    // Depth beyond the limit.
    let mut bytes = encode_v1(&Model::new(LinearOctree::empty(2, [0; 3]).unwrap()));
    bytes[12] = 40;
    let crc = crc32fast::hash(&bytes[..bytes.len() - 4]);
    let n = bytes.len();
    bytes[n - 4..].copy_from_slice(&crc.to_le_bytes());
    let err = decode(&bytes).unwrap_err().to_string();
    assert!(err.contains("depth 40"), "{err}");
}

#[test]
fn varint_round_trip_and_overflow() {
    for v in [0, 1, 127, 128, 300, u64::MAX >> 1, u64::MAX] {
        let mut out = Vec::new();
        put_varint(&mut out, v);
        assert_eq!(
            Reader {
                bytes: &out,
                pos: 0
            }
            .varint(),
            Ok(v)
        );
    }
    let over = [0xffu8; 10];
    assert!(Reader {
        bytes: &over,
        pos: 0
    }
    .varint()
    .is_err());
}

#[test]
fn mapped_and_unmapped_reads_agree() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.tess");
    let model = Model::new(random_tree(3));
    crate::io::write_model(&path, &model).unwrap();
    assert_eq!(read(&path).unwrap(), model);
    assert_eq!(read_unmapped(&path).unwrap(), model);
    assert_eq!(crate::io::read_octree(&path).unwrap(), model.tree);
}

/// Found by `fuzz/fuzz_targets/tess_chunked.rs`: a trailer whose sections offset is
/// near `u64::MAX` overflowed the layout check. With the index CRC fixed up as the
/// fuzz target does, it must be an error, not a panic.
#[test]
fn a_sections_offset_near_u64_max_is_an_error() {
    let mut bytes = include_bytes!("../../tests/fixtures/v2-sections-offset-overflow.bin").to_vec();
    let n = bytes.len();
    let t = n - 48;
    let s = usize::try_from(u64::from_le_bytes(bytes[t..t + 8].try_into().unwrap()))
        .ok()
        .filter(|&s| s <= n - 12);
    if let Some(s) = s {
        let mut crc = crc32fast::Hasher::new();
        crc.update(&bytes[..40]);
        crc.update(&bytes[s..n - 12]);
        let c = crc.finalize();
        bytes[t + 36..t + 40].copy_from_slice(&c.to_le_bytes());
    }
    assert!(decode(&bytes).is_err());
    assert!(crate::io::TessFile::from_bytes(bytes, std::path::Path::new("x.tess")).is_err());
}
