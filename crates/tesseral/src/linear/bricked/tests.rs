//! The bricked form and its set operations against a `HashSet` model, on seeded
//! random solids built to reach every step of the kernels: bricks at one code
//! (masks that come out empty, mixed or full), runs of one operand (galloping),
//! leaves holding entries of the other operand (kept, dropped, cut), spaces smaller
//! than a brick, clipped and unclipped spheres, porous blocks, operands of
//! different spaces. `assert_valid` (which checks the bricked form, and its
//! agreement with the leaves) follows every operation.

use std::collections::HashSet;

use proptest::prelude::*;

use super::super::tests_merge::{canonical, model_op, next, solid, Model, OPS};
use super::super::tests_ops::ball;
use super::super::*;
use super::Bricked;

/// Which operands hold their bricked form before the operation.
#[derive(Debug, Clone, Copy)]
enum Held {
    Both,
    First,
    Second,
}

/// The operand pair in space `(depth, [0; 3])` with the bricked forms `held` asks.
fn operands(depth: u8, ma: &Model, mb: &Model, held: Held) -> (LinearOctree, LinearOctree) {
    let (a, b) = (canonical(depth, ma), canonical(depth, mb));
    match held {
        Held::Both => {
            a.build_bricks();
            b.build_bricks();
        }
        Held::First => {
            a.build_bricks();
        }
        Held::Second => {
            b.build_bricks();
        }
    }
    (a, b)
}

/// Checks a result of the bricked path: held in bricked form only, valid, equal to
/// the model's canonical tree both as bricks and as leaves.
fn check_result(r: &LinearOctree, depth: u8, want: &Model) -> Result<(), TestCaseError> {
    prop_assert!(r.has_bricked(), "the result is in bricked form");
    r.assert_valid();
    let expected = canonical(depth, want);
    prop_assert_eq!(r.voxel_count(), want.len() as u64);
    prop_assert_eq!(r.leaf_count(), expected.leaf_count());
    prop_assert_eq!(r.is_empty(), want.is_empty());
    prop_assert!(*r.bricked() == Bricked::from_leaves(expected.leaves()));
    prop_assert_eq!(r.leaves(), expected.leaves());
    r.assert_valid();
    Ok(())
}

fn check_all_ops(depth: u8, ma: &Model, mb: &Model, held: Held) -> Result<(), TestCaseError> {
    let (a, b) = operands(depth, ma, mb, held);
    a.assert_valid();
    b.assert_valid();
    for op in OPS {
        for (x, y, mx, my) in [(&a, &b, ma, mb), (&b, &a, mb, ma)] {
            let want = model_op(op, mx, my);
            let r = x.set_op(y, op).unwrap();
            check_result(&r, depth, &want)?;
            // A bricked-only result as an operand again (a chain stays bricked).
            let r2 = x.set_op_same_space(y, op);
            for op2 in OPS {
                let s = r2.set_op(x, op2).unwrap();
                check_result(&s, depth, &model_op(op2, &want, mx))?;
            }
        }
    }
    Ok(())
}

fn held(h: u8) -> Held {
    [Held::Both, Held::First, Held::Second][usize::from(h % 3)]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// The bricked form of random canonical trees (spaces smaller than a brick
    /// included) gives back their leaves and counts.
    #[test]
    fn bricked_form_round_trips(
        depth in 0u8..7, blocks in 0u32..10, density in 0u64..100, seed: u64,
    ) {
        let side = 1i64 << depth;
        let t = canonical(depth, &solid(depth, [0; 3], side, blocks, density, seed));
        let b = Bricked::from_leaves(t.leaves());
        b.assert_valid(depth);
        prop_assert_eq!(b.to_leaves(), t.leaves().to_vec());
        prop_assert_eq!(b.leaf_count(), t.leaf_count());
        prop_assert_eq!(b.voxel_count(), t.voxel_count());
        prop_assert_eq!(b.is_empty(), t.is_empty());
        let only = LinearOctree::from_bricked(depth, [0; 3], b);
        only.assert_valid();
        prop_assert_eq!(&only, &t);
        prop_assert_eq!(only.heap_bytes() > 0, !t.is_empty());
    }

    /// Both operands over the whole space: bricks meet bricks, blocks nest.
    #[test]
    fn interleaved_operands_match_the_model(
        depth in 0u8..7, ba in 0u32..12, bb in 0u32..12, da in 0u64..60, db in 0u64..60,
        sa: u64, sb: u64, h: u8,
    ) {
        let side = 1i64 << depth;
        let ma = solid(depth, [0; 3], side, ba, da, sa);
        let mb = solid(depth, [0; 3], side, bb, db, sb);
        check_all_ops(depth, &ma, &mb, held(h))?;
    }

    /// The second operand in one random sub-cube: runs that only the first has.
    #[test]
    fn runs_of_one_operand_match_the_model(
        depth in 3u8..7, sub in 1u8..3, cell: u64, ba in 0u32..8, bb in 0u32..8,
        da in 20u64..90, db in 0u64..90, sa: u64, sb: u64, h: u8,
    ) {
        let side = 1i64 << depth;
        let sub_side = side >> sub;
        let per = (side / sub_side) as u64;
        let lo = [cell % per, cell / per % per, cell / per / per % per]
            .map(|c| c as i64 * sub_side);
        let ma = solid(depth, [0; 3], side, ba, da, sa);
        let mb = solid(depth, lo, sub_side, bb, db, sb);
        check_all_ops(depth, &ma, &mb, held(h))?;
    }

    /// Nearly full operands, and an operand with its complement: masks that come
    /// out full (union, symmetric difference) become leaves of side 8 and merge up
    /// to the root; masks that come out empty are dropped.
    #[test]
    fn full_and_empty_masks_match_the_model(
        depth in 0u8..6, da in 70u64..100, sa: u64, sb: u64, h: u8,
    ) {
        let side = 1i64 << depth;
        let ma = solid(depth, [0; 3], side, 2, da, sa);
        let mb = solid(depth, [0; 3], side, 2, da, sb);
        check_all_ops(depth, &ma, &mb, held(h))?;
        let full = solid(depth, [0; 3], side, 0, 100, 0);
        let mc: Model = &full - &ma;
        check_all_ops(depth, &ma, &mc, held(h))?;
        // The complement of a bricked tree stays bricked.
        let (a, _) = operands(depth, &ma, &mc, Held::Both);
        check_result(&a.complement(), depth, &mc)?;
    }

    /// Operands of different spaces (depths and origins): the second is resampled
    /// into the first's lattice (grown for union), and the bricked path is kept.
    #[test]
    fn operands_of_different_spaces_match_the_model(
        da in 2u8..6, db in 1u8..6, off in prop::array::uniform3(-20i64..20),
        dens_a in 10u64..90, dens_b in 10u64..90, sa: u64, sb: u64,
    ) {
        let (side_a, side_b) = (1i64 << da, 1i64 << db);
        let ma = solid(da, [0; 3], side_a, 3, dens_a, sa);
        let mb: Model = solid(db, [0; 3], side_b, 3, dens_b, sb)
            .into_iter()
            .map(|v| [v[0] + off[0], v[1] + off[1], v[2] + off[2]])
            .collect();
        let a = canonical(da, &ma);
        let b = LinearOctree::from_voxels(db, off, mb.iter().copied()).unwrap();
        a.build_bricks();
        for op in OPS {
            let r = a.set_op(&b, op).unwrap();
            r.assert_valid();
            prop_assert!(r.has_bricked());
            let got: Model = r.voxels().collect();
            prop_assert_eq!(got, model_op(op, &ma, &mb), "{:?}", op);
        }
    }
}

/// Spheres, unclipped and clipped by the space's faces, and porous blocks of random
/// voxels overlapping by half, as the benchmark's workloads are.
#[test]
fn spheres_and_porous_blocks_match_the_model() {
    let depth = 7;
    let pairs = [
        // Unclipped: both wholly inside.
        (
            ball([64.0, 64.0, 64.0], 40.0),
            ball([84.0, 64.0, 64.0], 40.0),
        ),
        // Clipped: the second runs past the faces x = 128 and z = 0.
        (
            ball([60.0, 64.0, 64.0], 50.0),
            ball([110.0, 70.0, 10.0], 45.0),
        ),
    ];
    let mut cases: Vec<(LinearOctree, LinearOctree)> = pairs
        .into_iter()
        .map(|(a, b)| {
            (
                LinearOctree::from_classifier(depth, [0; 3], &a).unwrap(),
                LinearOctree::from_classifier(depth, [0; 3], &b).unwrap(),
            )
        })
        .collect();
    let mut seed = 11;
    let mut porous = |lo: [i64; 3]| -> LinearOctree {
        let voxels: Vec<Voxel> = (0..32 * 32 * 32)
            .filter(|_| next(&mut seed) % 10 < 3)
            .map(|i| [lo[0] + i % 32, lo[1] + i / 32 % 32, lo[2] + i / 1024])
            .collect();
        LinearOctree::from_voxels(depth, [0; 3], voxels).unwrap()
    };
    cases.push((porous([8, 8, 8]), porous([24, 8, 8])));
    // Unaligned to bricks: the blocks start off the grid of 8.
    cases.push((porous([3, 5, 7]), porous([21, 2, 9])));
    for (a, b) in &cases {
        let (ma, mb): (Model, Model) = (a.voxels().collect(), b.voxels().collect());
        a.build_bricks();
        b.build_bricks();
        for op in OPS {
            for (x, y, mx, my) in [(a, b, &ma, &mb), (b, a, &mb, &ma)] {
                let r = x.set_op(y, op).unwrap();
                check_result(&r, depth, &model_op(op, mx, my)).unwrap();
            }
        }
    }
}

/// Empty operands on either side, and spaces of one voxel up to one brick.
#[test]
fn empty_and_tiny_operands_match_the_model() {
    for depth in 0u8..5 {
        let side = 1i64 << depth;
        let mut seed = u64::from(depth);
        for _ in 0..20 {
            let s = next(&mut seed);
            let m = solid(depth, [0; 3], side, 2, s % 100, s);
            let none = Model::new();
            let all = solid(depth, [0; 3], side, 0, 100, 0);
            for (ma, mb) in [(&m, &none), (&none, &m), (&m, &all), (&all, &m)] {
                check_all_ops(depth, ma, mb, Held::Both).unwrap();
            }
        }
    }
    // A model of one voxel per brick corner, so every brick is mixed.
    let corners: HashSet<Voxel> = (0..4)
        .flat_map(|x| (0..4).flat_map(move |y| (0..4).map(move |z| [8 * x, 8 * y, 8 * z])))
        .collect();
    let all = solid(5, [0; 3], 32, 0, 100, 0);
    let rest: Model = &all - &corners;
    check_all_ops(5, &corners, &rest, Held::Both).unwrap();
}

/// A solid of a depth-`depth` space (7 or 8) that reaches the top level: `big`
/// blocks of side 32 to 128 (leaves of the top level, which hold the other
/// operand's chunks, or chunks of one operand only), small blocks, and noise of
/// `density` percent in one random 16³ cube.
fn chunky(depth: u8, big: u32, density: u64, seed: u64) -> Model {
    let mut s = seed;
    let side = 1i64 << depth;
    let mut m = Model::new();
    let block = |m: &mut Model, k: u32, s: &mut u64| {
        let bs = 1i64 << k;
        let p = [0, 1, 2].map(|_| (next(s) % (side / bs) as u64) as i64 * bs);
        for x in 0..bs {
            for y in 0..bs {
                for z in 0..bs {
                    m.insert([p[0] + x, p[1] + y, p[2] + z]);
                }
            }
        }
    };
    for _ in 0..big {
        let k = 5 + (next(&mut s) % 3) as u32;
        block(&mut m, k.min(u32::from(depth) - 1), &mut s);
    }
    for _ in 0..6 {
        let k = (next(&mut s) % 5) as u32;
        block(&mut m, k, &mut s);
    }
    let lo = [0, 1, 2].map(|_| (next(&mut s) % (side as u64 - 16)) as i64);
    for x in 0..16 {
        for y in 0..16 {
            for z in 0..16 {
                if next(&mut s) % 100 < density {
                    m.insert([lo[0] + x, lo[1] + y, lo[2] + z]);
                }
            }
        }
    }
    m
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(6))]

    /// Operands with several chunks and leaves of the top level: chunks combined,
    /// shared whole, dropped, cut out of a leaf (their complement), and chunks that
    /// come out full merging into leaves of side 64 and more.
    #[test]
    fn chunks_and_top_leaves_match_the_model(
        big_a in 0u32..4, big_b in 0u32..4, da in 0u64..90, db in 0u64..90,
        sa: u64, sb: u64, h: u8, complementary: bool,
    ) {
        let depth = 7;
        let ma = chunky(depth, big_a, da, sa);
        let mb = if complementary {
            // Every chunk that both hold comes out full in their union.
            let all = solid(depth, [0; 3], 1 << depth, 0, 100, 0);
            &all - &ma
        } else {
            chunky(depth, big_b, db, sb)
        };
        let (a, b) = operands(depth, &ma, &mb, held(h));
        for op in OPS {
            for (x, y, mx, my) in [(&a, &b, &ma, &mb), (&b, &a, &mb, &ma)] {
                let r = x.set_op(y, op).unwrap();
                check_result(&r, depth, &model_op(op, mx, my))?;
            }
        }
        check_result(&a.complement(), depth, &(&solid(depth, [0; 3], 128, 0, 100, 0) - &ma))?;
    }
}

/// Larger random solids (spheres of random centres and radii, clipped or not, with
/// blocks added and cut out) at depths 9 and 10: the bricked path gives the leaf
/// path's trees (which `tests_merge.rs` checks against the model), chained too.
#[test]
fn bricked_path_matches_the_leaf_path_on_larger_solids() {
    let mut s = 5;
    for case in 0..12 {
        let depth = 9 + (case % 2) as u8;
        let side = (1u64 << depth) as f64;
        let mut sphere = || {
            let c = [0, 1, 2].map(|_| (next(&mut s) % 1000) as f64 / 1000.0 * side);
            let r = 8.0 + (next(&mut s) % 1000) as f64 / 1000.0 * side / 2.5;
            LinearOctree::from_classifier(depth, [0; 3], &ball(c, r)).unwrap()
        };
        let (a, b, c) = (sphere(), sphere(), sphere());
        let (ab, bb, cb) = (a.clone(), b.clone(), c.clone());
        for t in [&ab, &bb, &cb] {
            t.build_bricks();
        }
        for op in OPS {
            let leaf = a.set_op(&b, op).unwrap();
            let brick = ab.set_op(&bb, op).unwrap();
            brick.assert_valid();
            assert!(brick.has_bricked());
            for op2 in OPS {
                let leaf2 = leaf.set_op(&c, op2).unwrap();
                let brick2 = brick.set_op(&cb, op2).unwrap();
                brick2.assert_valid();
                assert_eq!(
                    brick2.leaves(),
                    leaf2.leaves(),
                    "case {case} {op:?} {op2:?}"
                );
            }
            assert_eq!(brick.leaves(), leaf.leaves(), "case {case} {op:?}");
            brick.assert_valid();
        }
    }
}
