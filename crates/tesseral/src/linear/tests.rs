//! The linear octree against a `HashSet` of voxels.

use std::collections::HashSet;

use proptest::prelude::*;

use super::*;

/// Random shapes of three kinds: sparse points, dense noise, and blobs (unions of
/// balls), so that both tiny and large merged blocks occur.
pub(crate) fn shape(depth: u8, kind: u8, seed: u64) -> HashSet<Voxel> {
    let side = 1i64 << depth;
    let mut s = seed | 1;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        s
    };
    let mut set = HashSet::new();
    match kind % 3 {
        0 => {
            for _ in 0..next() % 64 {
                let r = next();
                set.insert([
                    (r % side as u64) as i64,
                    (r >> 20) as i64 % side,
                    (r >> 40) as i64 % side,
                ]);
            }
        }
        1 => {
            for x in 0..side {
                for y in 0..side {
                    for z in 0..side {
                        if next() % 4 != 0 {
                            set.insert([x, y, z]);
                        }
                    }
                }
            }
        }
        _ => {
            for _ in 0..1 + next() % 4 {
                let c = [
                    next() as i64 % side,
                    next() as i64 % side,
                    next() as i64 % side,
                ]
                .map(i64::abs);
                let r = 1 + (next() % (side as u64 / 2 + 1)) as i64;
                for x in 0..side {
                    for y in 0..side {
                        for z in 0..side {
                            let d = [x - c[0], y - c[1], z - c[2]];
                            if d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= r * r {
                                set.insert([x, y, z]);
                            }
                        }
                    }
                }
            }
        }
    }
    set
}

fn offset(set: &HashSet<Voxel>, o: Voxel) -> HashSet<Voxel> {
    set.iter()
        .map(|v| [v[0] + o[0], v[1] + o[1], v[2] + o[2]])
        .collect()
}

proptest! {
    #[test]
    fn from_voxels_matches_set(depth in 0u8..6, kind in 0u8..3, seed: u64, o in prop::array::uniform3(-100i64..100)) {
        let model = offset(&shape(depth, kind, seed), o);
        let tree = LinearOctree::from_voxels(depth, o, model.iter().copied()).unwrap();
        tree.assert_valid();
        prop_assert_eq!(tree.voxel_count(), model.len() as u64);
        let got: HashSet<Voxel> = tree.voxels().collect();
        prop_assert_eq!(&got, &model);
        let side = 1i64 << depth;
        for x in -1..=side {
            for y in [-1, 0, side / 2, side - 1, side] {
                for z in [-1, 0, side - 1, side] {
                    let v = [x + o[0], y + o[1], z + o[2]];
                    prop_assert_eq!(tree.contains(v), model.contains(&v));
                }
            }
        }
        prop_assert_eq!(tree.leaves_by_depth().iter().sum::<u64>(), tree.leaf_count() as u64);
    }

    #[test]
    fn classifier_matches_voxels(depth in 0u8..6, kind in 0u8..3, seed: u64) {
        let model = shape(depth, kind, seed);
        let set = &model;
        let classify = |min: Voxel, k: u8| {
            let s = 1i64 << k;
            let mut n = 0;
            for x in 0..s { for y in 0..s { for z in 0..s {
                n += i64::from(set.contains(&[min[0] + x, min[1] + y, min[2] + z]));
            }}}
            if n == 0 { CellClass::Outside } else if n == s * s * s { CellClass::Inside } else { CellClass::Partial }
        };
        let a = LinearOctree::from_classifier(depth, [0, 0, 0], &classify).unwrap();
        a.assert_valid();
        let b = LinearOctree::from_voxels(depth, [0, 0, 0], model.iter().copied()).unwrap();
        prop_assert_eq!(a, b);
    }
}

#[test]
fn parallel_classifier_build_is_canonical() {
    // A ball at depth 7 exercises the rayon path (cells of size >= 2^5).
    let ball = |min: Voxel, k: u8| {
        let s = (1i64 << k) - 1;
        let d2 = |lo: i64, hi: i64| {
            let (lo, hi) = (2 * lo + 1 - 128, 2 * hi + 1 - 128);
            let near = if lo > 0 {
                lo
            } else if hi < 0 {
                hi
            } else {
                0
            };
            let far = lo.abs().max(hi.abs());
            (near * near, far * far)
        };
        let (mut near, mut far) = (0, 0);
        for m in min {
            let (n, f) = d2(m, m + s);
            near += n;
            far += f;
        }
        let r2 = 100 * 100;
        if far <= r2 {
            CellClass::Inside
        } else if near > r2 {
            CellClass::Outside
        } else {
            CellClass::Partial
        }
    };
    let tree = LinearOctree::from_classifier(7, [0, 0, 0], &ball).unwrap();
    tree.assert_valid();
    let mut model = Vec::new();
    for x in 0..128i64 {
        for y in 0..128i64 {
            for z in 0..128i64 {
                let c = |v: i64| 2 * v + 1 - 128;
                if c(x) * c(x) + c(y) * c(y) + c(z) * c(z) <= 100 * 100 {
                    model.push([x, y, z]);
                }
            }
        }
    }
    assert_eq!(
        tree,
        LinearOctree::from_voxels(7, [0, 0, 0], model).unwrap()
    );
}

#[test]
fn full_space_is_one_leaf_and_out_of_bounds_is_an_error() {
    let all =
        (0..4).flat_map(|x| (0..4).flat_map(move |y| (0..4).map(move |z| [x - 2, y - 2, z - 2])));
    let tree = LinearOctree::from_voxels(2, [-2, -2, -2], all).unwrap();
    tree.assert_valid();
    assert_eq!(tree, LinearOctree::full(2, [-2, -2, -2]).unwrap());
    assert_eq!(tree.bbox(), Some(([-2, -2, -2], [1, 1, 1])));
    assert_eq!(
        LinearOctree::from_voxels(2, [0, 0, 0], [[4, 0, 0]]),
        Err(OctreeError::OutOfBounds([4, 0, 0]))
    );
    assert_eq!(
        LinearOctree::empty(22, [0, 0, 0]),
        Err(OctreeError::DepthTooLarge(22))
    );
}

#[test]
fn fitted_space_holds_the_voxels() {
    let vs = [[-5, 3, 9], [2, 3, 9], [-5, -1, 0]];
    let tree = LinearOctree::from_voxels_fitted(&vs).unwrap();
    tree.assert_valid();
    assert_eq!(tree.depth(), 4);
    assert!(vs.iter().all(|&v| tree.contains(v)));
    assert_eq!(tree.voxel_count(), 3);
}

/// Translation moves aligned leaves with `Space::<u64>::full()`: its `add` of a code
/// and `encode_wrapping` of a displacement is per-axis addition modulo `2^21`.
#[test]
fn translation_code_sum_is_per_axis_modular_addition() {
    use crate::code::{decode, encode, Space};
    let space = Space::<u64>::full();
    let mut s = 0x1234_5678_9abc_def1_u64;
    for _ in 0..10_000 {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        let a = [
            s as u32 & 0x1f_ffff,
            (s >> 21) as u32 & 0x1f_ffff,
            (s >> 42) as u32 & 0x1f_ffff,
        ];
        let t = [
            (s >> 3) as i64 % 5000 - 2500,
            (s >> 17) as i64 % 70,
            -((s >> 29) as i64 % 1000),
        ];
        let sum = space.add(encode(a[0], a[1], a[2]), space.encode_wrapping(t));
        let want: [u32; 3] =
            std::array::from_fn(|i| ((i64::from(a[i]) + t[i]).rem_euclid(1 << 21)) as u32);
        assert_eq!(decode(sum), want, "seed-free xorshift, a={a:?} t={t:?}");
    }
}

/// The x-bit mask the transforms use is every third bit of the low 63.
#[test]
fn x_mask_is_every_third_bit() {
    use crate::code::CodeWord;
    assert_eq!(
        <u64 as CodeWord>::X_MASK,
        0x9249_2492_4924_9249 & ((1 << 63) - 1)
    );
}
