//! The dynamic octree's own `.tess` (`tess_dyn.rs`): round trips against a
//! `HashSet` of voxels near the origin, far apart (2^40) and at the edges of `i64`;
//! every damaged or hostile file refused with its block and offset, never a panic;
//! the memory budget; model files for octrees that fit one.

use super::*;
use crate::io::FormatError;

/// Writes and reads back `t`, checking every voxel, the validity and that a second
/// write gives the same bytes.
fn round_trip(t: &DynamicOctree, set: &HashSet<Voxel>) -> Vec<u8> {
    let bytes = t.encode_tess_dyn();
    let back = DynamicOctree::decode_tess_dyn(&bytes).unwrap();
    back.assert_valid();
    assert_eq!(back.voxel_count(), set.len() as u64);
    let got: HashSet<Voxel> = back.voxels().into_iter().collect();
    assert_eq!(&got, set);
    assert_eq!(
        back.encode_tess_dyn(),
        bytes,
        "a second write gives the same bytes"
    );
    assert_eq!(back.world_block_count(), t.world_block_count());
    assert_eq!(back.bounds(), t.bounds());
    bytes
}

/// Random voxels around each centre (within ±`r`), inserted and some removed.
fn random_set(seed: u64, centres: &[Voxel], r: i64, n: usize) -> (DynamicOctree, HashSet<Voxel>) {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut t = DynamicOctree::new();
    let mut set = HashSet::new();
    for _ in 0..n {
        let c = centres[rng.random_range(0..centres.len())];
        let v = c.map(|k| k.wrapping_add(rng.random_range(-r..=r)));
        if rng.random_bool(0.8) {
            t.insert(v);
            set.insert(v);
        } else {
            t.remove(v);
            set.remove(&v);
        }
    }
    (t, set)
}

#[test]
fn random_sets_round_trip_near_far_and_at_the_edges() {
    let far = 1i64 << 40;
    let (lo, hi) = (i64::MIN, i64::MAX);
    for (seed, centres, r) in [
        (1, vec![[0, 0, 0]], 6),
        (2, vec![[0, 0, 0]], 40),
        (3, vec![[0, 0, 0], [far, -far, 3]], 20),
        (4, vec![[-far, 5, far], [far, far, -far], [0, 0, 0]], 12),
        (
            5,
            vec![[lo + 20, lo + 20, lo + 20], [hi - 20, hi - 20, hi - 20]],
            20,
        ),
        (
            6,
            vec![[lo + 9, 0, hi - 9], [0, hi - 3, lo + 3], [5, 5, 5]],
            9,
        ),
    ] {
        for small in [true, false] {
            let (mut t, set) = random_set(seed, &centres, r, 3000);
            t.set_small_blocks(small);
            t.assert_valid();
            round_trip(&t, &set);
        }
    }
}

#[test]
fn solids_on_any_alignment_round_trip_as_full_blocks() {
    for off in [0i64, 3, -5, 1 << 40] {
        let mut set = HashSet::new();
        let mut t = DynamicOctree::new();
        t.insert([off + 1000, 7, 7]); // a root corner not on the 8³ grid
        set.insert([off + 1000, 7, 7]);
        for x in 0..32 {
            for y in 0..16 {
                for z in 0..24 {
                    let v = [off + x, y - 4, z + 2];
                    t.insert(v);
                    set.insert(v);
                }
            }
        }
        let bytes = round_trip(&t, &set);
        // 32×16×24 voxels on an unaligned grid: 5×3×4 blocks, some full.
        assert!(bytes.len() < 60 * 70, "{}", bytes.len());
    }
    let lin = crate::linear::LinearOctree::from_voxels(
        6,
        [-32, -32, -32],
        (0..32).flat_map(|x| (0..32).flat_map(move |y| (0..32).map(move |z| [x, y, z]))),
    )
    .unwrap();
    let t = DynamicOctree::from_linear(&lin);
    let set: HashSet<Voxel> = t.voxels().into_iter().collect();
    let bytes = round_trip(&t, &set);
    assert_eq!(bytes.len(), 32 + 64 * 4 + 4, "64 full blocks, 4 bytes each");
}

#[test]
fn empty_and_single_voxel_round_trip() {
    let t = DynamicOctree::new();
    let bytes = round_trip(&t, &HashSet::new());
    assert_eq!(bytes.len(), 36);
    for v in [[0, 0, 0], [i64::MIN; 3], [i64::MAX; 3], [-1, 7, 8]] {
        round_trip(&DynamicOctree::from_voxels([v]), &HashSet::from([v]));
    }
}

/// Reseals the checksum of damaged bytes.
fn reseal(bytes: &mut [u8]) {
    let n = bytes.len();
    if n >= 4 {
        let crc = crc32fast::hash(&bytes[..n - 4]);
        bytes[n - 4..].copy_from_slice(&crc.to_le_bytes());
    }
}

#[test]
fn every_truncation_and_bit_flip_is_an_error_or_a_valid_octree() {
    let (t, _) = random_set(9, &[[0, 0, 0], [1 << 30, 0, -(1 << 30)]], 10, 300);
    let mut t2 = t.clone();
    for x in 0..16 {
        for y in 0..8 {
            for z in 0..8 {
                t2.insert([x + 64, y, z]);
            }
        }
    }
    let bytes = t2.encode_tess_dyn();
    for n in 0..bytes.len() {
        assert!(DynamicOctree::decode_tess_dyn(&bytes[..n]).is_err());
        let mut cut = bytes[..n].to_vec();
        reseal(&mut cut);
        if let Ok(d) = DynamicOctree::decode_tess_dyn(&cut) {
            d.assert_valid();
        }
    }
    for i in 0..bytes.len() * 8 {
        let mut b = bytes.clone();
        b[i / 8] ^= 1 << (i % 8);
        assert!(
            DynamicOctree::decode_tess_dyn(&b).is_err(),
            "bit {i} past the CRC"
        );
        reseal(&mut b);
        if let Ok(d) = DynamicOctree::decode_tess_dyn(&b) {
            d.assert_valid();
            // Read again from its own bytes (a padded varint may write shorter).
            let again = DynamicOctree::decode_tess_dyn(&d.encode_tess_dyn()).unwrap();
            assert!(
                again.voxels() == d.voxels(),
                "bit {i}: a different octree read back"
            );
        }
    }
}

/// A file of the given encoded blocks (the voxel count from their masks).
fn file_of(blocks: &[Vec<u8>], voxels: u64) -> Vec<u8> {
    let mut out = crate::io::native::DYN_MAGIC.to_vec();
    out.extend_from_slice(&1u16.to_le_bytes());
    out.extend_from_slice(&[0; 6]);
    out.extend_from_slice(&voxels.to_le_bytes());
    out.extend_from_slice(&(blocks.len() as u64).to_le_bytes());
    for b in blocks {
        out.extend_from_slice(b);
    }
    out.extend_from_slice(&[0; 4]);
    reseal(&mut out);
    out
}

fn error_of(bytes: &[u8]) -> String {
    match DynamicOctree::decode_tess_dyn(bytes) {
        Ok(t) => panic!("decoded {t:?}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn hostile_blocks_are_named_with_their_offsets() {
    let mask = |bits: [u64; 8]| -> Vec<u8> { bits.iter().flat_map(|w| w.to_le_bytes()).collect() };
    let one = [vec![0, 0, 0, 1], mask([1, 0, 0, 0, 0, 0, 0, 0])].concat();
    assert!(DynamicOctree::decode_tess_dyn(&file_of(std::slice::from_ref(&one), 1)).is_ok());
    // Keys must increase: a zero delta repeats block 0 at byte 32 + 68.
    let e = error_of(&file_of(&[one.clone(), one.clone()], 2));
    assert!(
        e.contains("block 1 (byte 100)") && e.contains("increase strictly"),
        "{e}"
    );
    let e = error_of(&file_of(&[[vec![0, 0, 0, 1], mask([0; 8])].concat()], 0));
    assert!(
        e.contains("block 0 (byte 32)") && e.contains("empty mask"),
        "{e}"
    );
    let e = error_of(&file_of(&[[vec![0, 0, 0, 1], mask([!0; 8])].concat()], 512));
    assert!(
        e.contains("block 0 (byte 32)") && e.contains("tag 0"),
        "{e}"
    );
    let e = error_of(&file_of(&[vec![0, 0, 0, 0], vec![2, 0, 0, 7]], 512));
    assert!(
        e.contains("block 1 (byte 36)") && e.contains("tag 7"),
        "{e}"
    );
    let e = error_of(&file_of(&[vec![0, 0, 0, 0]], 511));
    assert!(
        e.contains("voxel count 511") && e.contains("hold 512"),
        "{e}"
    );
    // 2^61 (zigzag 2^62) is past the keys' range −2^60..2^60.
    let far = [vec![0x80; 8], vec![0x40, 0, 0, 0]].concat();
    let e = error_of(&file_of(&[far], 512));
    assert!(
        e.contains("block 0 (byte 32)") && e.contains("past the i64 voxel range"),
        "{e}"
    );
    // A truncated mask, a count the bytes cannot hold, trailing bytes.
    let e = error_of(&file_of(&[vec![0, 0, 0, 1, 1, 2, 3]], 1));
    assert!(
        e.contains("block 0 (byte 32)") && e.contains("truncated"),
        "{e}"
    );
    let mut b = file_of(&[vec![0, 0, 0, 0]], 512);
    b[24] = 2;
    reseal(&mut b);
    assert!(error_of(&b).contains("2 blocks cannot fit"));
    let e = error_of(&file_of(&[vec![0, 0, 0, 0, 9, 9, 9, 9]], 512));
    assert!(e.contains("4 bytes after the last block (byte 36)"), "{e}");
    let mut b = file_of(&[], 0);
    b[8] = 2;
    reseal(&mut b);
    assert!(matches!(
        DynamicOctree::decode_tess_dyn(&b),
        Err(FormatError::Unsupported(_))
    ));
    let mut b = file_of(&[], 0);
    b[40 - 5] ^= 1;
    assert!(error_of(&b).contains("checksum mismatch"));
}

#[test]
fn blocks_spread_far_apart_are_refused_before_memory_runs_out() {
    // Full blocks 2^42 blocks apart along z: 10 bytes of file each, and a chain of
    // about 42 nodes (36 bytes each) that no other block shares.
    let n = 200_000u64;
    let step = 1u64 << 43; // zigzag of 2^42
    let mut delta = Vec::new();
    crate::io::leafstream::put_varint(&mut delta, step);
    let block = [vec![0, 0], delta, vec![0]].concat();
    let bytes = file_of(&vec![block.clone(); n as usize], 512 * n);
    match DynamicOctree::decode_tess_dyn(&bytes) {
        Err(FormatError::TooLarge(m)) => assert!(m.contains("64 times"), "{m}"),
        other => panic!("{:?}", other.map(|t| t.bytes())),
    }
    // The same spread, fewer blocks: read, and what it costs per block.
    let few = 20_000u64;
    let bytes = file_of(&vec![block; few as usize], 512 * few);
    let t = DynamicOctree::decode_tess_dyn(&bytes).unwrap();
    t.assert_valid();
    let per_block = t.bytes() as f64 / few as f64;
    let per_byte = t.bytes() as f64 / bytes.len() as f64;
    eprintln!("spread full blocks: {per_block:.0} bytes a block, {per_byte:.0} times the file");
    assert!(
        per_byte > 64.0,
        "the hostile case is past the budget's ratio"
    );
    // Points scattered over 2^40 (a robot's log): far inside the budget.
    let (t, _) = random_set(11, &[[0, 0, 0]], 1 << 40, 20_000);
    let bytes = t.encode_tess_dyn();
    let back = DynamicOctree::decode_tess_dyn(&bytes).unwrap();
    let ratio = back.bytes() as f64 / bytes.len() as f64;
    eprintln!(
        "scattered points: {} bytes of file, {} in memory ({ratio:.1} times)",
        bytes.len(),
        back.bytes()
    );
    assert!(ratio < 32.0, "{ratio}");
}

#[test]
fn files_hold_wide_octrees_in_their_own_tess_and_others_as_models() {
    let dir = tempfile::tempdir().unwrap();
    let narrow = DynamicOctree::from_voxels([[0, 0, 0], [1000, -3, 5]]);
    let wide = DynamicOctree::from_voxels([[0, 0, 0], [4_000_000, 0, 0]]);
    for (name, t) in [("narrow", &narrow), ("wide", &wide)] {
        let path = dir.path().join(format!("{name}.tess"));
        t.write_file(&path).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(
            bytes.starts_with(&crate::io::native::DYN_MAGIC),
            !t.fits_model()
        );
        let back = DynamicOctree::read_file(&path).unwrap();
        back.assert_valid();
        assert_eq!(back.voxels(), t.voxels());
        let model = crate::io::read_model(&path);
        if t.fits_model() {
            assert_eq!(model.unwrap().tree.voxel_count(), t.voxel_count());
        } else {
            let e = model.unwrap_err().to_string();
            assert!(
                e.contains("wide.tess") && e.contains("DynamicOctree::read_file"),
                "{e}"
            );
        }
    }
    let e = wide
        .write_file(&dir.path().join("wide.bt"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("only .tess"), "{e}");
}
