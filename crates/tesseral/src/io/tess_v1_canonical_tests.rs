//! Version-1 files whose payload is not canonical (eight sibling leaves in a row,
//! which no writer leaves but the whole-file decoder merges): streamed, they read
//! as the decoder reads them, stretch by stretch and by code range.

use std::collections::BTreeSet;
use std::path::Path;

use rand::{Rng, SeedableRng};

use crate::io::leafstream::put_leaves;
use crate::io::native::{self, MAGIC, VERSION_1};
use crate::io::TessFile;
use crate::linear::{Leaf, LinearOctree};
use crate::model::Rgba;

/// A version-1 file written by hand: the payload holds `leaves` as given (sorted
/// and disjoint, not necessarily canonical), the colour layer `regions` as given.
fn raw_v1(depth: u8, leaves: &[Leaf], regions: &[(Rgba, Vec<Leaf>)]) -> Vec<u8> {
    let mut payload = Vec::new();
    put_leaves(&mut payload, leaves);
    let mut out = Vec::new();
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&VERSION_1.to_le_bytes());
    let flags: u16 = if regions.is_empty() { 0 } else { 4 };
    out.extend_from_slice(&flags.to_le_bytes());
    out.extend_from_slice(&[depth, 0, 0, 0]);
    for o in [-3i64, 0, 5] {
        out.extend_from_slice(&o.to_le_bytes());
    }
    out.extend_from_slice(&(leaves.len() as u64).to_le_bytes());
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&payload);
    if !regions.is_empty() {
        out.extend_from_slice(&(regions.len() as u64).to_le_bytes());
        for (c, ls) in regions {
            out.extend_from_slice(c);
            out.extend_from_slice(&(ls.len() as u64).to_le_bytes());
            put_leaves(&mut out, ls);
        }
    }
    let crc = crc32fast::hash(&out);
    out.extend_from_slice(&crc.to_le_bytes());
    out
}

/// Reads `bytes` streamed and whole, checks that every reader gives `want` (each
/// stretch's range and count its leaves', code ranges as filters of `want`), and
/// gives the streamed file.
fn check_reads(bytes: Vec<u8>, want: &[Leaf]) -> TessFile {
    let path = Path::new("n.tess");
    let model = native::decode(&bytes).unwrap();
    model.tree.assert_valid();
    assert_eq!(model.tree.leaves(), want, "the whole-file decoder");
    let whole = TessFile::from_bytes(bytes.clone(), path).unwrap();
    let f = TessFile::from_bytes_streaming(bytes, path).unwrap();
    assert!(f.is_streamed());
    assert_eq!(f.leaf_count(), want.len() as u64);
    for g in [&whole, &f] {
        let mut all = Vec::new();
        for (i, c) in g.chunks().iter().enumerate() {
            let ls = g.chunk(i).unwrap();
            assert_eq!(ls.len() as u64, c.count);
            assert_eq!((ls[0].code(), ls[ls.len() - 1].end()), (c.lo, c.hi));
            all.extend(ls);
        }
        assert_eq!(all, want, "chunk by chunk");
    }
    let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
    let end = want.last().map_or(1, |l| l.end() + 1);
    for _ in 0..30 {
        let lo = rng.random_range(0..end);
        let hi = rng.random_range(lo..=end);
        let got: Vec<Leaf> = f.leaves_in(lo, hi).map(Result::unwrap).collect();
        let filtered: Vec<Leaf> = want
            .iter()
            .filter(|l| l.end() > lo && l.code() < hi)
            .copied()
            .collect();
        assert_eq!(got, filtered, "[{lo}, {hi})");
    }
    assert_eq!(f.to_model().unwrap(), model);
    f
}

/// The fuzz finding: a complete octet of voxels (codes 264..=271, packed 528 to
/// 542) between two other voxels reads as their parent, `Leaf(535)`, streamed
/// as whole; a colour region with such an octet is not streamed (the decoded
/// layer merges it), one without is.
#[test]
fn a_complete_sibling_octet_streams_as_its_parent() {
    let octet: Vec<Leaf> = (264..272).map(|c| Leaf::new(c, 0)).collect();
    let mut stored = vec![Leaf::new(7, 0)];
    stored.extend(&octet);
    stored.push(Leaf::new(300, 0));
    let want = [Leaf::new(7, 0), Leaf::new(264, 1), Leaf::new(300, 0)];
    assert_eq!(want[1].packed(), 535);
    check_reads(raw_v1(3, &stored, &[]), &want);
    let f = check_reads(raw_v1(3, &stored, &[([9, 8, 7, 6], octet)]), &want);
    assert!(f.colour_streams().unwrap().is_none());
    assert!(f.colour_leaves().unwrap().is_none());
    let layer = f.to_model().unwrap().colors.unwrap();
    assert_eq!(layer.regions()[0].1.leaves(), [Leaf::new(264, 1)]);
    let f = check_reads(raw_v1(3, &stored, &[([9, 8, 7, 6], vec![want[2]])]), &want);
    let streams = f.colour_streams().unwrap().unwrap();
    assert_eq!(streams.len(), 1);
    let leaves: Vec<Leaf> = streams[0].1.clone().map(Result::unwrap).collect();
    assert_eq!(leaves, [want[2]]);
}

/// Merges across the stretches of 65,536 leaves: 65,535 leaves that do not
/// merge, then a block of 16³ stored as 4,096 voxels (the first stretch's last
/// leaf, read past the stretch), then more; and a space stored voxel by voxel is
/// one leaf. Then seeded random payloads (aligned blocks stored whole, as their
/// eight children, voxel by voxel, or in part) against a set of voxels.
#[test]
fn merged_stretches_match_a_voxel_model() {
    let mut stored: Vec<Leaf> = (0..65_535).map(|i| Leaf::new(2 * i, 0)).collect();
    stored.extend((131_072..135_168).map(|c| Leaf::new(c, 0)));
    stored.extend((135_168..200_000).step_by(2).map(|c| Leaf::new(c, 0)));
    let want = LinearOctree::from_sorted_leaves(6, [-3, 0, 5], stored.clone()).unwrap();
    assert_eq!(want.leaves()[65_535], Leaf::new(131_072, 4));
    let f = check_reads(raw_v1(6, &stored, &[]), want.leaves());
    assert_eq!(f.chunks().len(), 2);
    assert_eq!(f.chunks()[0].hi, 135_168);
    let all: Vec<Leaf> = (0..1 << 12).map(|c| Leaf::new(c, 0)).collect();
    check_reads(raw_v1(4, &all, &[]), &[Leaf::new(0, 4)]);

    let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
    for _ in 0..40 {
        let depth = 4;
        let mut stored = Vec::new();
        let mut voxels = BTreeSet::new();
        for b in 0..64u64 {
            let base = b * 64;
            match rng.random_range(0..5) {
                0 => stored.push(Leaf::new(base, 2)),
                1 => stored.extend((0..8).map(|k| Leaf::new(base + 8 * k, 1))),
                2 => stored.extend((0..64).map(|k| Leaf::new(base + k, 0))),
                3 => stored.extend(
                    (0..64)
                        .filter(|_| rng.random_bool(0.9))
                        .map(|k| Leaf::new(base + k, 0)),
                ),
                _ => continue,
            }
        }
        for l in &stored {
            voxels.extend(l.code()..l.end());
        }
        let model = LinearOctree::from_sorted_leaves(
            depth,
            [-3, 0, 5],
            voxels.iter().map(|&c| Leaf::new(c, 0)),
        )
        .unwrap();
        check_reads(raw_v1(depth, &stored, &[]), model.leaves());
    }
}
