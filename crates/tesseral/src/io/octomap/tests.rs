//! Tests of `.bt` and `.ot`: round trips against a voxel set, layout, bad input.

use super::*;
use rand::{Rng, SeedableRng};
use std::collections::HashSet;

pub(super) fn random_model(seed: u64) -> Model {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let origin = [
        rng.random_range(-40..40),
        rng.random_range(-40..40),
        rng.random_range(-40..40),
    ];
    let n = rng.random_range(0..400);
    let voxels: Vec<_> = (0..n)
        .map(|_| {
            [
                origin[0] + rng.random_range(0..16),
                origin[1] + rng.random_range(0..16),
                origin[2] + rng.random_range(0..8),
            ]
        })
        .collect();
    let mut tree = LinearOctree::from_voxels(4, origin, voxels).unwrap();
    if seed % 5 == 0 {
        tree = LinearOctree::full(3, [origin[0] & !7, origin[1] & !7, origin[2] & !7]).unwrap();
    }
    // Free voxels around the black ones, and log-odds on both.
    let free_voxels: Vec<_> = (0..rng.random_range(0..300))
        .map(|_| {
            [
                origin[0] - 8 + rng.random_range(0..32),
                origin[1] - 8 + rng.random_range(0..32),
                origin[2] + rng.random_range(0..8),
            ]
        })
        .filter(|&v| !tree.contains(v))
        .collect();
    let free = LinearOctree::from_voxels(6, [origin[0] - 8, origin[1] - 8, origin[2]], free_voxels)
        .unwrap();
    let model =
        Model::from_parts(tree, Frame::new(0.05, [0.0; 3]), None, Some(free), None).unwrap();
    let known: Vec<_> = model.known().voxels().collect();
    let odds = [0.85f32, 3.5, -0.405, -2.0];
    let pairs = known.iter().map(|&v| {
        let x = if model.tree.contains(v) {
            odds[(v[0] & 1) as usize]
        } else {
            odds[2 + (v[1] & 1) as usize]
        };
        (v, x)
    });
    let layer = Layer::from_voxels(model.tree.depth(), model.tree.origin(), pairs).unwrap();
    let m = Model {
        log_odds: Some(layer),
        ..model
    };
    m.assert_valid();
    m
}

fn odds(m: &Model) -> Vec<(crate::Voxel, u32)> {
    let mut v: Vec<_> = m
        .log_odds
        .as_ref()
        .unwrap()
        .to_voxels()
        .into_iter()
        .map(|(v, k, _)| (v, k as u32))
        .collect();
    v.sort_unstable();
    v
}

fn set(t: &LinearOctree) -> HashSet<crate::Voxel> {
    t.voxels().collect()
}

#[test]
fn bt_and_ot_round_trip_random_trees() {
    for seed in 0..80 {
        let m = random_model(seed);
        let bt = decode_bt(&encode_bt(&m).unwrap()).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        bt.tree.assert_valid();
        assert_eq!(set(&bt.tree), set(&m.tree), "seed {seed}");
        assert_eq!(bt.frame.voxel_size, 0.05);
        assert_eq!(
            set(bt.free.as_ref().unwrap()),
            set(m.free.as_ref().unwrap()),
            "seed {seed}"
        );
        bt.assert_valid();
        let ot = decode_ot(&encode_ot(&m).unwrap()).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        ot.assert_valid();
        assert_eq!(set(&ot.tree), set(&m.tree), "seed {seed}");
        assert_eq!(
            set(ot.free.as_ref().unwrap()),
            set(m.free.as_ref().unwrap()),
            "seed {seed}"
        );
        assert_eq!(odds(&ot), odds(&m), "seed {seed}: log-odds bit for bit");
        // Written again, the file is the same bytes.
        assert_eq!(
            encode_ot(&ot).unwrap(),
            encode_ot(&m).unwrap(),
            "seed {seed}"
        );
    }
}

#[test]
fn colour_ot_round_trip() {
    let m = random_model(3);
    let pairs = m
        .tree
        .voxels()
        .map(|v| (v, [v[0] as u8, v[1] as u8, 7, 255]));
    let colors = Layer::from_voxels(m.tree.depth(), m.tree.origin(), pairs).unwrap();
    let m = Model {
        colors: Some(colors.clone()),
        ..m
    };
    let back = decode_ot(&encode_ot(&m).unwrap()).unwrap();
    back.assert_valid();
    let got: Vec<_> = back
        .colors
        .unwrap()
        .to_voxels()
        .into_iter()
        .map(|(v, k, _)| (v, k))
        .collect();
    let want: Vec<_> = colors
        .to_voxels()
        .into_iter()
        .map(|(v, k, _)| (v, k))
        .collect();
    assert_eq!(got, want);
}

#[test]
fn a_hand_made_bt_decodes() {
    // Root with child 0 inner; that child (depth 1) has child 7 occupied: the
    // block of size 2^14 at keys (16384, 16384, 16384), i.e. voxel -16384.
    let mut b = b"# Octomap OcTree binary file\nid OcTree\nsize 3\nres 0.1\ndata\n".to_vec();
    b.extend_from_slice(&[0b0000_0011, 0, 0, 0b1000_0000]);
    let m = decode_bt(&b).unwrap();
    assert_eq!(m.tree.leaf_count(), 1);
    let blk = m.tree.blocks().next().unwrap();
    assert_eq!((blk.min, blk.size_log2), ([-16384; 3], 14));
    // Wrong node count, truncation, too deep.
    let mut w = b.clone();
    w[b.len() - 9] = b'4';
    assert!(decode_bt(&w).is_err());
    assert!(decode_bt(&b[..b.len() - 1]).is_err());
    let mut deep = b"# Octomap OcTree binary file\nid OcTree\nsize 99\nres 0.1\ndata\n".to_vec();
    deep.extend(std::iter::repeat_n([3u8, 0], 20).flatten());
    assert!(decode_bt(&deep).is_err());
}

#[test]
fn out_of_key_range_is_refused() {
    let t = LinearOctree::from_voxels(17, [0; 3], [[40000, 0, 0]]).unwrap();
    assert!(encode_bt(&Model::new(t)).is_err());
}

#[test]
fn clamp_log_odds_are_octomaps_defaults_as_it_computes_them() {
    // OctoMap reads a .bt's cells at its clamping thresholds, logodds(0.971) and
    // logodds(0.1192) in f32; ours must be the same numbers, as the maps' clamps are.
    use crate::occupancy::{log_odds, SensorModel};
    assert_eq!(super::OCCUPIED_LOG_ODDS, log_odds(0.971));
    assert_eq!(super::FREE_LOG_ODDS, log_odds(0.1192));
    let m = SensorModel::octomap();
    assert_eq!(
        (m.clamp_min(), m.clamp_max()),
        (super::FREE_LOG_ODDS, super::OCCUPIED_LOG_ODDS)
    );
}

#[test]
fn voxels_past_the_keys_are_named_not_the_space_corner() {
    let tree = LinearOctree::from_voxels(17, [0; 3], [[50_000, 0, 0], [50_010, 3, 0]]).unwrap();
    let e = super::encode_bt(&crate::model::Model::new(tree)).unwrap_err();
    assert!(
        e.contains("reach [50000, 0, 0] to [50010, 3, 0]") && e.contains("−32768..32767"),
        "{e}"
    );
}
