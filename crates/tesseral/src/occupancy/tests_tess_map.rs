//! The map's own `.tess` (`tess_map.rs`): round trips of random maps near and far
//! apart (past a model's 2^21 cells), every block form, the sensor model kept, and
//! every kind of damaged or hostile file refused with its offset, never a panic.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::*;
use crate::io::FormatError;

/// A map of random scans around `centres` (cells), `scans` each, at resolution 1.
fn random_map(seed: u64, sensor: SensorModel, centres: &[[i64; 3]], scans: usize) -> OccupancyMap {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut map = OccupancyMap::new(1.0, sensor).unwrap();
    for &c in centres {
        for _ in 0..scans {
            let o = c.map(|k| k as f64 + rng.random_range(-4.0..4.0));
            let points: Vec<[f64; 3]> = (0..rng.random_range(1..60))
                .map(|_| {
                    let d = rng.random_range(0.0..30.0);
                    [0, 1, 2].map(|a| o[a] + rng.random_range(-d..=d))
                })
                .collect();
            map.insert_scan(o, &points, None);
        }
    }
    map
}

/// Writes and reads back `map`, checking every cell, the model and the validity.
fn round_trip(map: &OccupancyMap) -> Vec<u8> {
    let bytes = map.encode_tess_map();
    let back = OccupancyMap::decode_tess_map(&bytes).unwrap();
    back.assert_valid();
    assert_eq!(back.cells(), map.cells());
    assert_eq!(back.sensor(), map.sensor());
    assert_eq!(back.resolution(), map.resolution());
    assert_eq!(back.counts(), map.counts());
    assert_eq!(
        back.encode_tess_map(),
        bytes,
        "a second write gives the same bytes"
    );
    bytes
}

#[test]
fn random_maps_round_trip_near_and_far_apart() {
    let far = 1i64 << 40;
    let edge = (1i64 << 61) - 1000; // near the edge of a ray's reach
    for (seed, centres) in [
        (1, vec![[0, 0, 0]]),
        (2, vec![[0, 0, 0], [far, -far, 3]]),
        (3, vec![[-edge, 5, edge], [edge, -edge, 0], [0, 0, 0]]),
    ] {
        let map = random_map(seed, SensorModel::octomap(), &centres, 12);
        map.assert_valid();
        assert_eq!(map.fits_model(), centres.len() == 1);
        round_trip(&map);
    }
}

#[test]
fn every_block_form_and_a_sensor_model_of_its_own_round_trip() {
    let sensor = SensorModel::from_probabilities(0.8, 0.3, (0.05, 0.99), 0.7).unwrap();
    let mut map = random_map(4, sensor, &[[100, -50, 7]], 5);
    let fixed = map.fixed;
    // A block of many distinct values (a palette of 9 bits), one of three (2 bits),
    // one cell alone (sparse), and a uniform one.
    for i in 0..300i64 {
        let v = fixed.to_f32(fixed.min + i16::try_from(i).unwrap() * 3);
        map.set_log_odds([800 + i % 8, 800 + (i / 8) % 8, 800 + i / 64], Some(v));
    }
    for i in 0..512i64 {
        let v = [fixed.min, fixed.max, 0][(i % 3) as usize];
        map.set_log_odds([-808 + i % 8, (i / 8) % 8, i / 64], Some(fixed.to_f32(v)));
        map.set_log_odds(
            [i % 8, 1600 + (i / 8) % 8, i / 64],
            Some(fixed.to_f32(fixed.max)),
        );
    }
    map.set_log_odds([5, 5, -4000], Some(1.0));
    map.assert_valid();
    let bytes = round_trip(&map);
    let back = OccupancyMap::decode_tess_map(&bytes).unwrap();
    assert_eq!(back.sensor().threshold(), sensor.threshold());
    assert_eq!(back.state([5, 5, -4000]), map.state([5, 5, -4000]));
}

#[test]
fn an_empty_map_round_trips() {
    let map = OccupancyMap::new(0.25, SensorModel::octomap()).unwrap();
    assert_eq!(round_trip(&map).len(), 60);
}

/// `bytes` with its checksum made right again after an edit.
fn resealed(mut bytes: Vec<u8>) -> Vec<u8> {
    let n = bytes.len() - 4;
    let crc = crc32fast::hash(&bytes[..n]);
    bytes[n..].copy_from_slice(&crc.to_le_bytes());
    bytes
}

fn error_of(bytes: &[u8]) -> String {
    OccupancyMap::decode_tess_map(bytes)
        .map(|_| ())
        .unwrap_err()
        .to_string()
}

#[test]
fn damaged_files_are_refused_never_a_panic() {
    let map = random_map(5, SensorModel::octomap(), &[[0, 0, 0], [1 << 30, 0, 0]], 6);
    let bytes = map.encode_tess_map();
    // Every truncation, and every single byte changed with the checksum resealed:
    // an error or a valid map, never a panic.
    for n in 0..bytes.len() {
        assert!(
            OccupancyMap::decode_tess_map(&bytes[..n]).is_err(),
            "cut at {n}"
        );
    }
    let mut rng = Pcg64::seed_from_u64(6);
    for _ in 0..3000 {
        let mut b = bytes.clone();
        let at = rng.random_range(0..b.len() - 4);
        b[at] ^= 1 << rng.random_range(0..8);
        assert!(
            OccupancyMap::decode_tess_map(&b).is_err(),
            "byte {at}, checksum kept"
        );
        if let Ok(m) = OccupancyMap::decode_tess_map(&resealed(b)) {
            m.assert_valid();
        }
    }
    let edit = |at: usize, with: &[u8]| {
        let mut b = bytes.clone();
        b[at..at + with.len()].copy_from_slice(with);
        error_of(&resealed(b))
    };
    assert!(error_of(&bytes[..30]).contains("truncated"));
    assert!(error_of(b"\x89TESSRL\n0000000000").contains("bad magic"));
    assert!(edit(8, &[2, 0]).contains("version 2"));
    assert!(edit(16, &(-1.0f64).to_le_bytes()).contains("bytes 16..24"));
    assert!(edit(40, &9.0f32.to_le_bytes()).contains("bytes 24..44"));
    assert!(edit(44, &[3, 0, 0, 0]).contains("scale"));
    assert!(edit(48, &u64::MAX.to_le_bytes()).contains("cannot fit"));
    let mut b = bytes.clone();
    b.insert(b.len() - 4, 0);
    assert!(error_of(&resealed(b)).contains("1 bytes after the last block"));
}

/// A file of the given blocks (each its key varints, tag and cells) with OctoMap's
/// sensor model at resolution 1.
fn file_of(blocks: &[Vec<u8>]) -> Vec<u8> {
    let head = OccupancyMap::new(1.0, SensorModel::octomap())
        .unwrap()
        .encode_tess_map();
    let mut b = head[..56].to_vec();
    b[48..56].copy_from_slice(&(blocks.len() as u64).to_le_bytes());
    for block in blocks {
        b.extend_from_slice(block);
    }
    b.extend_from_slice(&[0; 4]);
    resealed(b)
}

#[test]
fn hostile_blocks_are_refused_with_their_offset() {
    let fixed = Fixed::new(&SensorModel::octomap());
    let v = |x: i16| x.to_le_bytes().to_vec();
    let uniform = |key: [u8; 3], x: i16| [key.to_vec(), vec![0], v(x)].concat();
    assert!(OccupancyMap::decode_tess_map(&file_of(&[uniform([0, 0, 0], fixed.max)])).is_ok());
    let e = error_of(&file_of(&[
        uniform([0, 0, 0], fixed.max),
        uniform([0, 0, 0], fixed.max),
    ]));
    assert!(
        e.contains("block 1 (byte 62)") && e.contains("does not follow"),
        "{e}"
    );
    let e = error_of(&file_of(&[uniform([0, 0, 0], fixed.max + 1)]));
    assert!(e.contains("outside the clamps"), "{e}");
    let e = error_of(&file_of(&[uniform([0, 0, 0], UNKNOWN)]));
    assert!(e.contains("outside the clamps"), "{e}");
    let e = error_of(&file_of(&[[vec![0, 0, 0, 7], v(0)].concat()]));
    assert!(e.contains("tag 7"), "{e}");
    // Sparse: indices must increase.
    let sparse = [
        vec![0, 0, 0, 1],
        2u16.to_le_bytes().to_vec(),
        v(9),
        v(0),
        v(3),
        v(0),
    ]
    .concat();
    assert!(error_of(&file_of(&[sparse])).contains("not increasing"));
    // Palette: a number past its values, and a block of unknown cells only.
    let mut palette = [
        vec![0, 0, 0, 2],
        3u16.to_le_bytes().to_vec(),
        v(0),
        v(1),
        v(2),
    ]
    .concat();
    palette.extend(std::iter::repeat_n(0xff, 128));
    assert!(error_of(&file_of(&[palette])).contains("palette number 3 past its 3 values"));
    let mut unknown = [
        vec![0, 0, 0, 2],
        2u16.to_le_bytes().to_vec(),
        v(UNKNOWN),
        v(UNKNOWN),
    ]
    .concat();
    unknown.extend(std::iter::repeat_n(0, 64));
    assert!(error_of(&file_of(&[unknown])).contains("every cell is unknown"));
    // A key past the i64 cell range (block keys are cells >> 3).
    let mut far = vec![0xfe; 9];
    far.extend_from_slice(&[0x01, 0, 0, 0]);
    far.extend(v(fixed.max));
    assert!(error_of(&file_of(&[far])).contains("past the i64 cell range"));
}

#[test]
fn blocks_spread_one_to_a_table_are_refused_before_memory_runs_out() {
    // Each block 5 bytes of file, 2 KiB of table in memory: past 64 times the file.
    let fixed = Fixed::new(&SensorModel::octomap());
    let step = [16u8, 0, 0, 0]; // x += 8 blocks: a new superblock each time
    let blocks: Vec<Vec<u8>> = (0..60_000)
        .map(|_| {
            [
                step[..3].to_vec(),
                vec![0],
                fixed.max.to_le_bytes().to_vec(),
            ]
            .concat()
        })
        .collect();
    let bytes = file_of(&blocks);
    match OccupancyMap::decode_tess_map(&bytes) {
        Err(FormatError::TooLarge(m)) => assert!(m.contains("64 times"), "{m}"),
        other => panic!("{:?}", other.map(|m| m.block_count())),
    }
}

#[test]
fn files_hold_wide_maps_in_their_own_tess_and_others_as_models() {
    let dir = tempfile::tempdir().unwrap();
    let narrow = random_map(7, SensorModel::octomap(), &[[0, 0, 0]], 4);
    let wide = random_map(8, SensorModel::octomap(), &[[0, 0, 0], [0, 0, 1 << 22]], 4);
    for (name, map) in [("narrow", &narrow), ("wide", &wide)] {
        let path = dir.path().join(format!("{name}.tess"));
        map.write_file(&path).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(
            bytes.starts_with(&crate::io::native::MAP_MAGIC),
            !map.fits_model()
        );
        let back = OccupancyMap::read_file(&path).unwrap();
        back.assert_valid();
        assert_eq!(back.cells(), map.cells());
        let model = crate::io::read_model(&path);
        if map.fits_model() {
            assert_eq!(model.unwrap().tree.voxel_count(), map.occupied_count());
        } else {
            let e = model.unwrap_err().to_string();
            assert!(
                e.contains("wide.tess") && e.contains("OccupancyMap.read"),
                "{e}"
            );
            let e = crate::io::TessFile::open(&path)
                .map(|_| ())
                .unwrap_err()
                .to_string();
            assert!(e.contains("wider than a model holds"), "{e}");
        }
    }
}
