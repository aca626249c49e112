//! The set-operation merge kernels (`merge.rs`) against a `HashSet` model: every
//! fast path (voxel pairs, galloping over runs, run copies with merging at the
//! front, the one-thread and split paths) on seeded random solids built to reach it.

use std::collections::HashSet;

use proptest::prelude::*;

use super::merge::{self, ending_by, inside, span2};
use super::tests_ops::ball;
use super::*;

pub(crate) type Model = HashSet<Voxel>;

pub(crate) const OPS: [SetOp; 4] = [
    SetOp::Union,
    SetOp::Intersection,
    SetOp::Difference,
    SetOp::SymmetricDifference,
];

pub(crate) fn model_op(op: SetOp, a: &Model, b: &Model) -> Model {
    match op {
        SetOp::Union => a | b,
        SetOp::Intersection => a & b,
        SetOp::Difference => a - b,
        SetOp::SymmetricDifference => a ^ b,
    }
}

pub(crate) fn canonical(depth: u8, model: &Model) -> LinearOctree {
    LinearOctree::from_voxels(depth, [0; 3], model.iter().copied()).unwrap()
}

/// splitmix64.
pub(crate) fn next(s: &mut u64) -> u64 {
    *s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *s;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A random solid in the sub-cube `[lo, lo + side)^3` of a depth-`depth` space:
/// `blocks` aligned blocks of random sizes (so leaves nest across operands) and
/// voxels of the given density in percent (so single voxels interleave).
pub(crate) fn solid(
    depth: u8,
    lo: [i64; 3],
    side: i64,
    blocks: u32,
    density: u64,
    seed: u64,
) -> Model {
    let mut s = seed;
    let mut m = Model::new();
    for _ in 0..blocks {
        let k = (next(&mut s) % u64::from(depth.min(4) + 1)) as u32;
        let bs = (1i64 << k).min(side);
        let p = [0, 1, 2].map(|a| {
            let cells = (side / bs).max(1) as u64;
            lo[a] + (next(&mut s) % cells) as i64 * bs
        });
        for x in 0..bs {
            for y in 0..bs {
                for z in 0..bs {
                    m.insert([p[0] + x, p[1] + y, p[2] + z]);
                }
            }
        }
    }
    for x in 0..side {
        for y in 0..side {
            for z in 0..side {
                if next(&mut s) % 100 < density {
                    m.insert([lo[0] + x, lo[1] + y, lo[2] + z]);
                }
            }
        }
    }
    m
}

fn check_all_ops(depth: u8, ma: &Model, mb: &Model) -> Result<(), TestCaseError> {
    let (a, b) = (canonical(depth, ma), canonical(depth, mb));
    a.assert_valid();
    b.assert_valid();
    for op in OPS {
        for (x, y, mx, my) in [(&a, &b, ma, mb), (&b, &a, mb, ma)] {
            let r = x.set_op(y, op).unwrap();
            r.assert_valid();
            prop_assert_eq!(&r, &canonical(depth, &model_op(op, mx, my)), "{:?}", op);
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Both operands over the whole space: voxels interleave, blocks nest.
    #[test]
    fn interleaved_operands_match_the_model(
        depth in 1u8..6, ba in 0u32..12, bb in 0u32..12, da in 0u64..60, db in 0u64..60,
        sa: u64, sb: u64,
    ) {
        let side = 1i64 << depth;
        let ma = solid(depth, [0; 3], side, ba, da, sa);
        let mb = solid(depth, [0; 3], side, bb, db, sb);
        check_all_ops(depth, &ma, &mb)?;
    }

    /// The second operand in one random sub-cube: long runs that only the first
    /// has, copied or skipped whole (galloping), before and after it.
    #[test]
    fn runs_of_one_operand_match_the_model(
        depth in 3u8..6, sub in 1u8..3, cell: u64, ba in 0u32..8, bb in 0u32..8,
        da in 20u64..90, db in 0u64..90, sa: u64, sb: u64,
    ) {
        let side = 1i64 << depth;
        let sub_side = side >> sub;
        let per = (side / sub_side) as u64;
        let lo = [cell % per, cell / per % per, cell / per / per % per]
            .map(|c| c as i64 * sub_side);
        let ma = solid(depth, [0; 3], side, ba, da, sa);
        let mb = solid(depth, lo, sub_side, bb, db, sb);
        check_all_ops(depth, &ma, &mb)?;
    }

    /// Nearly full operands: big blocks of one cut around the other's leaves, and
    /// unions that complete parents across operands (merges at a run's front).
    #[test]
    fn dense_operands_merge_into_canonical_blocks(
        depth in 2u8..5, da in 70u64..100, db in 70u64..100, sa: u64, sb: u64,
    ) {
        let side = 1i64 << depth;
        let ma = solid(depth, [0; 3], side, 2, da, sa);
        let mb = solid(depth, [0; 3], side, 2, db, sb);
        check_all_ops(depth, &ma, &mb)?;
        // The complement of one inside the other: the union is the whole space.
        let full = solid(depth, [0; 3], side, 0, 100, 0);
        let mc: Model = &full - &ma;
        check_all_ops(depth, &ma, &mc)?;
    }

    /// The galloping searches agree with a scan from the front.
    #[test]
    fn gallop_counts_match_a_scan(depth in 1u8..6, density in 1u64..100, seed: u64, at: u64) {
        let side = 1i64 << depth;
        let t = canonical(depth, &solid(depth, [0; 3], side, 4, density, seed));
        let leaves = t.leaves();
        let at = at % (1u64 << (3 * u32::from(depth)));
        let want = leaves.iter().take_while(|l| span2(**l).1 <= at).count();
        prop_assert_eq!(ending_by(leaves, at), want);
        // `inside`: leaves of the block of side 2^k holding code `at`.
        for k in 0..=depth {
            let cell = 1u64 << (3 * u32::from(k));
            let (start, end) = (at / cell * cell, at / cell * cell + cell);
            let from = leaves.partition_point(|l| span2(*l).1 <= start);
            let rest = &leaves[from..];
            if rest.first().is_some_and(|l| {
                let (s, e) = span2(*l);
                s < start || (s < end && e > end)
            }) {
                continue; // a leaf holds the block: not a case the merge asks
            }
            let want = rest.iter().take_while(|l| span2(**l).0 < end).count();
            prop_assert_eq!(inside(rest, end), want, "k {}", k);
        }
    }
}

/// The kernels on leaf slices directly, against the model, including empty sides.
#[test]
fn kernels_on_slices_match_the_model() {
    let mut seed = 7;
    for depth in 1u8..5 {
        let side = 1i64 << depth;
        for _ in 0..40 {
            let (sa, sb) = (next(&mut seed), next(&mut seed));
            let ma = solid(depth, [0; 3], side, 3, sa % 80, sa);
            let mb = solid(depth, [0; 3], side, 3, sb % 80, sb);
            let (a, b) = (canonical(depth, &ma), canonical(depth, &mb));
            for (op, f) in [
                (
                    SetOp::Union,
                    merge::union as fn(&[Leaf], &[Leaf], &mut Vec<Leaf>),
                ),
                (SetOp::Intersection, merge::intersection),
                (SetOp::Difference, merge::difference),
                (SetOp::SymmetricDifference, merge::symmetric_difference),
            ] {
                for (x, y, mx, my) in [
                    (a.leaves(), b.leaves(), &ma, &mb),
                    (a.leaves(), &[][..], &ma, &Model::new()),
                    (&[][..], b.leaves(), &Model::new(), &mb),
                ] {
                    let mut out = Vec::new();
                    f(x, y, &mut out);
                    let r = LinearOctree::from_parts(depth, [0; 3], out);
                    r.assert_valid();
                    assert_eq!(r, canonical(depth, &model_op(op, mx, my)), "{op:?}");
                }
            }
        }
    }
}

/// Large operands on one thread (one merge, no split) and on three (split by
/// octant, merged across the cuts) give the same canonical trees as the model.
#[test]
fn one_thread_and_split_paths_agree_with_the_model() {
    let a = LinearOctree::from_classifier(7, [0; 3], &ball([64.0, 64.0, 64.0], 50.0)).unwrap();
    let b = LinearOctree::from_classifier(7, [0; 3], &ball([84.0, 60.0, 64.0], 45.0)).unwrap();
    let (ma, mb): (Model, Model) = (a.voxels().collect(), b.voxels().collect());
    for threads in [1, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        for op in OPS {
            let r = pool.install(|| a.set_op(&b, op).unwrap());
            r.assert_valid();
            assert_eq!(r, canonical(7, &model_op(op, &ma, &mb)), "{op:?} {threads}");
        }
        let c = pool.install(|| a.complement());
        c.assert_valid();
        assert_eq!(c.voxel_count(), (1 << 21) - a.voxel_count());
    }
}
