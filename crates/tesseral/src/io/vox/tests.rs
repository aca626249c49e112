//! Tests of `.vox`: round trips against a voxel set, scenes, and bad files.

use super::*;
use rand::{Rng, SeedableRng};
use std::collections::HashSet;

#[test]
fn colours_survive_a_round_trip() {
    for seed in 0..30u64 {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let colours: std::collections::BTreeMap<Voxel, [u8; 4]> = (0..rng.random_range(1..300))
            .map(|_| {
                let v = [
                    rng.random_range(0..40),
                    rng.random_range(0..40),
                    rng.random_range(0..40),
                ];
                (
                    v,
                    [
                        rng.random_range(0..4) * 60,
                        10,
                        rng.random_range(0..8) * 30,
                        255,
                    ],
                )
            })
            .collect();
        let tree = LinearOctree::from_voxels(6, [0; 3], colours.keys().copied()).unwrap();
        let layer = Layer::from_voxels(6, [0; 3], colours.iter().map(|(v, c)| (*v, *c))).unwrap();
        let model = Model::new(tree).with_colors(layer).unwrap();
        let back = decode(&encode(&model).unwrap()).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        back.tree.assert_valid();
        assert_eq!(
            back.tree.voxels().collect::<HashSet<_>>(),
            colours.keys().copied().collect(),
            "seed {seed}"
        );
        let back_colours: std::collections::BTreeMap<Voxel, [u8; 4]> = back
            .colors
            .unwrap()
            .to_voxels()
            .into_iter()
            .map(|(v, _, c)| (v, c))
            .collect();
        assert_eq!(back_colours, colours, "seed {seed}");
    }
}

#[test]
fn negative_coordinates_are_shifted_and_too_wide_is_refused() {
    let tree = LinearOctree::from_voxels(4, [-8; 3], [[-8, -8, -8], [7, 7, 7]]).unwrap();
    let back = decode(&encode(&Model::new(tree)).unwrap()).unwrap();
    assert_eq!(
        back.tree.voxels().collect::<Vec<_>>(),
        vec![[0, 0, 0], [15, 15, 15]]
    );
    let wide = LinearOctree::from_voxels(9, [0; 3], [[0, 0, 0], [300, 0, 0]]).unwrap();
    assert!(encode(&Model::new(wide)).is_err());
}

#[test]
fn hostile_chunks_are_errors() {
    let tree = LinearOctree::from_voxels(2, [0; 3], [[1, 2, 3]]).unwrap();
    let good = encode(&Model::new(tree)).unwrap();
    for len in 0..good.len() {
        let _ = decode(&good[..len]);
    }
    // A voxel count of 2^32-1 in a tiny XYZI chunk.
    let mut b = good.clone();
    let at = b.windows(4).position(|w| w == b"XYZI").unwrap() + 12;
    b[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
    assert!(decode(&b).is_err());
}
