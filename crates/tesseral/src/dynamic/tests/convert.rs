//! Conversions to and from voxel lists and linear octrees, memory, and the voxel
//! hash table.

use std::collections::HashSet;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::*;

#[test]
fn conversions_to_and_from_voxel_lists() {
    let mut rng = Pcg64::seed_from_u64(3);
    let vs: Vec<Voxel> = (0..2000)
        .map(|_| std::array::from_fn(|_| rng.random_range(-1000..1000)))
        .collect();
    let t = DynamicOctree::from_voxels(vs.iter().copied());
    t.assert_valid();
    let mut got = t.voxels();
    let mut want = vs.clone();
    want.sort_unstable();
    want.dedup();
    got.sort_unstable();
    assert_eq!(got, want);
    let u: DynamicOctree = got.iter().copied().collect();
    assert_eq!(u.voxel_count(), want.len() as u64);
}

#[test]
fn memory_per_voxel_is_small_for_random_cells() {
    // Not a timing test: a structural bound. 20,000 random cells in a 128³ box.
    let mut rng = Pcg64::seed_from_u64(4);
    let mut t = DynamicOctree::new();
    for _ in 0..20_000 {
        t.insert(std::array::from_fn(|_| rng.random_range(-64..64)));
    }
    t.shrink_to_fit();
    let per = t.bytes() as f64 / t.voxel_count() as f64;
    assert!(per < 30.0, "{per} bytes per voxel");
}

#[test]
fn fill_then_drain_a_block_in_random_order() {
    // Full octants appear and are split again; every operation is checked.
    for (seed, lo, side) in [
        (40u64, [-4i64, -4, -4], 12i64),
        (41, [0, 0, 0], 8),
        (42, [-9, 3, 5], 10),
    ] {
        eprintln!("fill/drain seed {seed}");
        let mut rng = Pcg64::seed_from_u64(seed);
        let mut cells: Vec<Voxel> = Vec::new();
        for x in 0..side {
            for y in 0..side {
                for z in 0..side {
                    cells.push([lo[0] + x, lo[1] + y, lo[2] + z]);
                }
            }
        }
        let mut t = DynamicOctree::with_faces();
        let mut m = Model::default();
        for round in 0..2 {
            for i in (1..cells.len()).rev() {
                cells.swap(i, rng.random_range(0..=i));
            }
            for &c in &cells {
                if round == 0 {
                    assert_eq!(t.insert(c), m.insert(c));
                } else {
                    assert_eq!(t.remove(c), m.remove(c));
                }
                t.assert_valid();
                check_against(
                    &t,
                    &m,
                    &[
                        c,
                        Direction::PosX.step(c),
                        Direction::NegY.step(c),
                        [lo[0] + 3, lo[1] + 3, lo[2] + 3],
                    ],
                );
            }
            if round == 0 {
                assert_eq!(t.face_count() as i64, 6 * side * side);
            }
        }
        assert!(t.is_empty());
        assert_eq!(t.node_count(), 0);
    }
}

#[test]
fn voxel_table_matches_a_hashmap() {
    // Small key range so probe runs collide, wrap around and get backward-shifted.
    // The table keeps hashes and values; the keys live in `keys[value]`.
    let seed = 17;
    eprintln!("voxel table seed {seed}");
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut t = crate::dynamic::faces::VoxelTable::default();
    let mut keys: Vec<Voxel> = Vec::new();
    let mut m = std::collections::HashMap::new();
    for _ in 0..20_000u32 {
        let k: Voxel = std::array::from_fn(|_| rng.random_range(-6..6));
        match rng.random_range(0..3) {
            0 => {
                let got = t.get(k, |v| keys[v as usize]);
                assert_eq!(got, m.get(&k).copied());
                if got.is_none() {
                    keys.push(k);
                    let v = (keys.len() - 1) as u32;
                    t.insert(k, v);
                    m.insert(k, v);
                }
            }
            1 => assert_eq!(t.remove(k, |v| keys[v as usize]), m.remove(&k)),
            _ => assert_eq!(t.get(k, |v| keys[v as usize]), m.get(&k).copied()),
        }
        assert_eq!(t.len(), m.len());
    }
    let mut a: Vec<u32> = t.values().collect();
    let mut b: Vec<u32> = m.values().copied().collect();
    a.sort_unstable();
    b.sort_unstable();
    assert_eq!(a, b);
    t.shrink_to_fit();
    for (k, v) in m {
        assert_eq!(t.get(k, |v| keys[v as usize]), Some(v));
    }
}

/// A random solid with some full octants: random voxels plus a few filled cubes.
fn random_solid(rng: &mut Pcg64, lo: i64, side: i64) -> HashSet<Voxel> {
    let mut set = HashSet::new();
    for _ in 0..rng.random_range(0..400) {
        set.insert(std::array::from_fn(|_| lo + rng.random_range(0..side)));
    }
    for _ in 0..3 {
        let c: Voxel = std::array::from_fn(|_| lo + rng.random_range(0..side));
        let s = rng.random_range(1..12);
        for x in 0..s {
            for y in 0..s {
                for z in 0..s {
                    let v = [c[0] + x, c[1] + y, c[2] + z];
                    if (0..3).all(|a| v[a] < lo + side) {
                        set.insert(v);
                    }
                }
            }
        }
    }
    set
}

#[test]
fn linear_round_trip_and_windows_match_the_model() {
    use crate::linear::LinearOctree;
    for seed in 50..62u64 {
        eprintln!("linear seed {seed}");
        let mut rng = Pcg64::seed_from_u64(seed);
        let lo = rng.random_range(-40..10);
        let set = random_solid(&mut rng, lo, 32);
        let t = DynamicOctree::from_voxels(set.iter().copied());
        t.assert_valid();
        // A window that holds everything, on a grid not aligned with the tree's.
        let origin = [lo - 3, lo - 1, lo - 2];
        let lin = t.to_linear(6, origin).unwrap();
        lin.assert_valid();
        let want = LinearOctree::from_voxels(6, origin, set.iter().copied()).unwrap();
        assert_eq!(lin, want);
        // Back again.
        let back = DynamicOctree::from_linear(&lin);
        back.assert_valid();
        let mut a = back.voxels();
        let mut b: Vec<Voxel> = set.iter().copied().collect();
        a.sort_unstable();
        b.sort_unstable();
        assert_eq!(a, b);
        // A window that cuts the solid.
        let o2: Voxel = std::array::from_fn(|_| lo + rng.random_range(0..24));
        let d2 = rng.random_range(0..5u8);
        let cut = t.to_linear(d2, o2).unwrap();
        let side = 1i64 << d2;
        let want = LinearOctree::from_voxels(
            d2,
            o2,
            set.iter()
                .copied()
                .filter(|v| (0..3).all(|a| v[a] >= o2[a] && v[a] < o2[a] + side)),
        )
        .unwrap();
        assert_eq!(cut, want);
        // Every cell class agrees with the model on random cubes.
        for _ in 0..200 {
            let m: Voxel = std::array::from_fn(|_| lo - 4 + rng.random_range(0..40));
            let k = rng.random_range(0..4u8);
            let s = 1i64 << k;
            let mut black = 0;
            for x in 0..s {
                for y in 0..s {
                    for z in 0..s {
                        black += i64::from(set.contains(&[m[0] + x, m[1] + y, m[2] + z]));
                    }
                }
            }
            let want = if black == 0 {
                crate::linear::CellClass::Outside
            } else if black == s * s * s {
                crate::linear::CellClass::Inside
            } else {
                crate::linear::CellClass::Partial
            };
            assert_eq!(t.classify(m, k), want, "cube {m:?} size 2^{k}");
        }
    }
}

#[test]
fn linear_conversion_of_big_solids_and_far_coordinates() {
    use crate::linear::LinearOctree;
    // A 2^20 cube costs one full slot each way.
    let e = 1i64 << 62;
    let lin = LinearOctree::from_sorted_leaves(20, [-e, 5, e], [crate::linear::Leaf::new(0, 20)])
        .unwrap();
    let t = DynamicOctree::from_linear(&lin);
    t.assert_valid();
    assert_eq!(t.voxel_count(), 1 << 60);
    assert_eq!(t.node_count(), 0);
    assert!(t.contains([-e + 12345, 5 + 777, e + (1 << 20) - 1]));
    assert!(!t.contains([-e - 1, 5, e]));
    assert_eq!(t.to_linear(20, [-e, 5, e]).unwrap(), lin);
    // A window shifted by one voxel: the cube is cut and misaligned.
    let w = t.to_linear(3, [-e - 1, 4, e - 1]).unwrap();
    assert_eq!(w.voxel_count(), 7 * 7 * 7);
    // Small depths use the logical root inside one block.
    for depth in 0..4u8 {
        let vs = [[-3, 0, 0], [-3 + (1 << depth) - 1, 0, 0]];
        let lin = LinearOctree::from_voxels(depth, [-3, 0, 0], vs).unwrap();
        let t = DynamicOctree::from_linear(&lin);
        t.assert_valid();
        assert!(vs.iter().all(|&v| t.contains(v)));
        assert_eq!(t.voxel_count(), lin.voxel_count());
    }
}
