//! The pointer octree against the linear octree and a `HashSet` model.

// Per-axis loops index several arrays at once.
#![allow(clippy::needless_range_loop)]

use std::collections::HashSet;

use proptest::prelude::*;

use super::*;
use crate::linear::tests::shape;
use crate::linear::{LinearOctree, OctreeError};

fn offset(set: &HashSet<Voxel>, o: Voxel) -> HashSet<Voxel> {
    set.iter()
        .map(|v| [v[0] + o[0], v[1] + o[1], v[2] + o[2]])
        .collect()
}

#[test]
fn table_2_as_printed() {
    // Ahuja & Nash Table 2, "carry label" in octal, columns +X, +Y, +Z.
    let printed: [[u8; 3]; 8] = [
        [0o1, 0o2, 0o4],
        [0o10, 0o3, 0o5],
        [0o3, 0o10, 0o6],
        [0o12, 0o11, 0o7],
        [0o5, 0o6, 0o10],
        [0o14, 0o7, 0o11],
        [0o7, 0o14, 0o12],
        [0o16, 0o15, 0o13],
    ];
    // Table 1: the increments modulo 8.
    let increments: [[u8; 3]; 8] = [
        [1, 2, 4],
        [7, 2, 4],
        [1, 6, 4],
        [7, 6, 4],
        [1, 2, 4],
        [7, 2, 4],
        [1, 6, 4],
        [7, 6, 4],
    ];
    for label in 0..8u8 {
        for axis in 0..3 {
            let (carry, new) = label_transition(label, axis);
            assert_eq!(u8::from(carry) * 8 + new, printed[label as usize][axis]);
            assert_eq!(
                new.wrapping_sub(label) % 8,
                increments[label as usize][axis]
            );
        }
    }
}

#[test]
fn section_3_1_worked_examples() {
    assert_eq!(add_along_axis(&[0, 5, 7], 1, 1), vec![0, 7, 5]);
    assert_eq!(add_along_axis(&[0, 5, 7], 1, 5), vec![2, 7, 5]);
    // -5 in two's complement (011 in three bits); the carry out is lost.
    assert_eq!(add_along_axis(&[2, 7, 5], 1, -5), vec![0, 5, 7]);
}

#[test]
fn path_addition_is_tesseral_addition() {
    let mut s = 0x2545_f491_4f6c_dd1d_u64;
    for _ in 0..2000 {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        let digits = 1 + (s % 7) as usize;
        let path: Vec<u8> = (0..digits)
            .map(|i| ((s >> (8 + 3 * i)) & 7) as u8)
            .collect();
        let axis = (s >> 40) as usize % 3;
        let t = ((s >> 43) % 200) as i64 - 100;
        let code = path.iter().fold(0u64, |c, &d| (c << 3) | u64::from(d));
        let mut tv = [0i64; 3];
        tv[axis] = t;
        let space = crate::code::Space::<u64>::full();
        let want = space.add(code, space.encode_wrapping(tv)) & ((1u64 << (3 * digits)) - 1);
        let got = add_along_axis(&path, axis, t)
            .iter()
            .fold(0u64, |c, &d| (c << 3) | u64::from(d));
        assert_eq!(got, want, "path {path:?} axis {axis} t {t}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn conversions_round_trip(depth in 0u8..6, kind in 0u8..3, seed: u64, o in prop::array::uniform3(-20i64..20)) {
        let m = offset(&shape(depth, kind, seed), o);
        let lin = LinearOctree::from_voxels(depth, o, m.iter().copied()).unwrap();
        let p = PointerOctree::from_linear(&lin);
        p.assert_valid();
        prop_assert_eq!(p.black_count(), lin.leaf_count());
        prop_assert_eq!(p.to_linear(), lin.clone());
        for v in m.iter().take(50) {
            prop_assert!(p.contains(*v));
        }
        prop_assert_eq!(p.bbox(), lin.bbox());
    }

    #[test]
    fn pointer_translation_equals_linear_translation_and_the_model(
        depth in 0u8..6, kind in 0u8..3, seed: u64,
        o in prop::array::uniform3(-20i64..20), by in prop::array::uniform3(-40i64..40),
    ) {
        let m = offset(&shape(depth, kind, seed), o);
        let lin = LinearOctree::from_voxels(depth, o, m.iter().copied()).unwrap();
        let mut p = PointerOctree::from_linear(&lin);
        let stats = p.translate(by).unwrap();
        p.assert_valid();
        let moved = lin.translate(by).unwrap();
        prop_assert_eq!(&p.to_linear(), &moved);
        let want = offset(&m, by);
        prop_assert_eq!(moved.voxels().collect::<HashSet<_>>(), want);
        for a in 0..3 {
            let s = stats.axes[a];
            prop_assert_eq!(s.displacement, by[a]);
            if by[a] != 0 && !m.is_empty() {
                prop_assert_eq!(u32::from(s.moved_size_log2), by[a].unsigned_abs().trailing_zeros());
                // Each moved node costs one root-to-node path: O(N_f · H).
                prop_assert_eq!(s.path_steps, s.moved * u64::from(p.depth() - s.moved_size_log2));
                prop_assert!(s.traversed >= s.moved);
            }
        }
    }
}

#[test]
fn ahuja_nash_fig_4_parallelepiped() {
    // Fig. 4: a parallelepiped with faces parallel to the coordinate planes,
    // translated by (4, -50, 0). The figure's exact extents are not legible in our
    // copy of the paper; this box is of the same kind, in a 128^3 space.
    let (lo, hi) = ([8i64, 64, 16], [39i64, 111, 31]);
    let mut model = HashSet::new();
    for x in lo[0]..=hi[0] {
        for y in lo[1]..=hi[1] {
            for z in lo[2]..=hi[2] {
                model.insert([x, y, z]);
            }
        }
    }
    let lin = LinearOctree::from_voxels(7, [0, 0, 0], model.iter().copied()).unwrap();
    let mut p = PointerOctree::from_linear(&lin);
    let stats = p.translate([4, -50, 0]).unwrap();
    p.assert_valid();
    // The moved box still fits the 128^3 space: no root growth.
    assert_eq!(stats.root_expansions, 0);
    assert_eq!((p.depth(), p.origin()), (7, [0, 0, 0]));
    // x moves by 4 = 100b: nodes of side 4; y by -50 = ...1110b: nodes of side 2.
    assert_eq!(stats.axes[0].moved_size_log2, 2);
    assert_eq!(stats.axes[1].moved_size_log2, 1);
    assert_eq!(stats.axes[2].moved, 0);
    let want = offset(&model, [4, -50, 0]);
    let got = p.to_linear();
    assert_eq!(got.voxels().collect::<HashSet<_>>(), want);
    assert_eq!(got, lin.translate([4, -50, 0]).unwrap());
    assert_eq!(got.bbox(), Some(([12, 14, 16], [43, 61, 31])));
    // The node counts of the result: the same box shape at a new position.
    assert_eq!(p.black_count(), got.leaf_count());
}

#[test]
fn growing_past_the_maximum_depth_is_an_error() {
    let lin = LinearOctree::from_voxels(21, [0, 0, 0], [[0, 0, 0]]).unwrap();
    let mut p = PointerOctree::from_linear(&lin);
    assert_eq!(p.translate([-1, 0, 0]), Err(OctreeError::DepthTooLarge(22)));
}

#[test]
fn a_translated_full_space_grows_the_root() {
    let lin = LinearOctree::full(2, [0, 0, 0]).unwrap();
    let mut p = PointerOctree::from_linear(&lin);
    let stats = p.translate([-3, 1, 0]).unwrap();
    p.assert_valid();
    assert_eq!(stats.root_expansions, 1);
    assert_eq!((p.depth(), p.origin()), (3, [-4, 0, 0]));
    assert_eq!(p.to_linear(), lin.translate([-3, 1, 0]).unwrap());
    assert!(stats.nodes_visited() > 0);
}
