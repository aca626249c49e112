//! Set operations, translation, resampling and transforms against a `HashSet` model.

// Per-axis loops index several arrays at once.
#![allow(clippy::needless_range_loop)]

use std::collections::HashSet;

use proptest::prelude::*;

use super::tests::shape;
use super::*;

type Model = HashSet<Voxel>;

fn offset(set: &Model, o: Voxel) -> Model {
    set.iter()
        .map(|v| [v[0] + o[0], v[1] + o[1], v[2] + o[2]])
        .collect()
}

fn voxels(t: &LinearOctree) -> Model {
    t.voxels().collect()
}

/// The canonical tree of `model` in the space of `like`: set operations and
/// translations must produce exactly this leaf list.
fn canonical(depth: u8, origin: Voxel, model: &Model) -> LinearOctree {
    LinearOctree::from_voxels(depth, origin, model.iter().copied()).unwrap()
}

fn all_voxels(depth: u8, o: Voxel) -> Model {
    let s = 1i64 << depth;
    let mut m = Model::new();
    for x in 0..s {
        for y in 0..s {
            for z in 0..s {
                m.insert([o[0] + x, o[1] + y, o[2] + z]);
            }
        }
    }
    m
}

fn model_op(op: SetOp, a: &Model, b: &Model) -> Model {
    match op {
        SetOp::Union => a | b,
        SetOp::Intersection => a & b,
        SetOp::Difference => a - b,
        SetOp::SymmetricDifference => a ^ b,
    }
}

const OPS: [SetOp; 4] = [
    SetOp::Union,
    SetOp::Intersection,
    SetOp::Difference,
    SetOp::SymmetricDifference,
];

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn set_ops_in_one_space_match_the_model(
        depth in 0u8..6, ka in 0u8..3, kb in 0u8..3, sa: u64, sb: u64,
        o in prop::array::uniform3(-50i64..50),
    ) {
        let (ma, mb) = (offset(&shape(depth, ka, sa), o), offset(&shape(depth, kb, sb), o));
        let (a, b) = (canonical(depth, o, &ma), canonical(depth, o, &mb));
        for op in OPS {
            let r = a.set_op(&b, op).unwrap();
            r.assert_valid();
            prop_assert_eq!(&r, &canonical(depth, o, &model_op(op, &ma, &mb)), "{:?}", op);
        }
        let c = a.complement();
        c.assert_valid();
        let want: Model = &all_voxels(depth, o) - &ma;
        prop_assert_eq!(&c, &canonical(depth, o, &want));
        prop_assert!(a.same_voxels(&a.complement().complement()).unwrap());
    }

    #[test]
    fn set_ops_across_spaces_match_the_model(
        da in 0u8..5, db in 0u8..5, ka in 0u8..3, kb in 0u8..3, sa: u64, sb: u64,
        oa in prop::array::uniform3(-20i64..20), ob in prop::array::uniform3(-20i64..20),
    ) {
        let (ma, mb) = (offset(&shape(da, ka, sa), oa), offset(&shape(db, kb, sb), ob));
        let (a, b) = (canonical(da, oa, &ma), canonical(db, ob, &mb));
        for op in OPS {
            let r = a.set_op(&b, op).unwrap();
            r.assert_valid();
            let want = match op {
                // Intersection and difference keep a's space and cut b to it.
                SetOp::Intersection | SetOp::Difference => {
                    prop_assert_eq!((r.depth(), r.origin()), (da, oa));
                    model_op(op, &ma, &mb)
                }
                _ => model_op(op, &ma, &mb),
            };
            prop_assert_eq!(&voxels(&r), &want, "{:?}", op);
            prop_assert_eq!(&r, &canonical(r.depth(), r.origin(), &want));
        }
    }

    #[test]
    fn translation_matches_the_model(
        depth in 0u8..6, kind in 0u8..3, seed: u64,
        o in prop::array::uniform3(-30i64..30), by in prop::array::uniform3(-70i64..70),
    ) {
        let m = offset(&shape(depth, kind, seed), o);
        let a = canonical(depth, o, &m);
        let t = a.translate(by).unwrap();
        t.assert_valid();
        let want = offset(&m, by);
        prop_assert_eq!(&t, &canonical(t.depth(), t.origin(), &want));
        // The space is kept whenever the result fits in it.
        let side = 1i64 << depth;
        let fits = want.iter().all(|v| (0..3).all(|i| v[i] >= o[i] && v[i] < o[i] + side));
        prop_assert_eq!(fits, t.depth() == depth && t.origin() == o);
        // Clipped translation keeps the space and counts what left it.
        let (c, dropped) = a.translate_clipped(by).unwrap();
        c.assert_valid();
        let kept: Model = want.iter().copied().filter(|v| (0..3).all(|i| v[i] >= o[i] && v[i] < o[i] + side)).collect();
        prop_assert_eq!(&c, &canonical(depth, o, &kept));
        prop_assert_eq!(dropped, (want.len() - kept.len()) as u64);
        // Moving back restores the tree's voxels.
        prop_assert!(t.translate([-by[0], -by[1], -by[2]]).unwrap().same_voxels(&a).unwrap());
    }

    #[test]
    fn resample_into_any_space_matches_the_model(
        depth in 0u8..6, kind in 0u8..3, seed: u64, nd in 0u8..7,
        o in prop::array::uniform3(-30i64..30), no in prop::array::uniform3(-40i64..40),
    ) {
        let m = offset(&shape(depth, kind, seed), o);
        let a = canonical(depth, o, &m);
        let (r, dropped) = a.resample(nd, no).unwrap();
        r.assert_valid();
        let side = 1i64 << nd;
        let kept: Model = m.iter().copied().filter(|v| (0..3).all(|i| v[i] >= no[i] && v[i] < no[i] + side)).collect();
        prop_assert_eq!(&r, &canonical(nd, no, &kept));
        prop_assert_eq!(dropped, (m.len() - kept.len()) as u64);
        // Both paths (whole-leaf tesseral addition, and the general top-down one)
        // on their own.
        if !a.is_empty() {
            let delta = [no[0] - o[0], no[1] - o[1], no[2] - o[2]];
            prop_assert_eq!(&a.resample_general(nd, delta), r.leaves());
            if let Some(fast) = a.aligned_shift(nd, delta, dropped == 0) {
                prop_assert_eq!(&fast, r.leaves());
            }
        }
    }

    #[test]
    fn rotation_mirror_and_scaling_match_the_model(
        depth in 0u8..6, kind in 0u8..3, seed: u64, turns in -5i32..6, s in 0u8..4,
        o in prop::array::uniform3(-30i64..30),
    ) {
        let m = offset(&shape(depth, kind, seed), o);
        let a = canonical(depth, o, &m);
        let side = 1i64 << depth;
        let last = |v: i64, i: usize| 2 * o[i] + side - 1 - v;
        for axis in [Axis::X, Axis::Y, Axis::Z] {
            let r = a.rotate(axis, turns);
            r.assert_valid();
            prop_assert_eq!(r.leaf_count(), a.leaf_count());
            let (f, t) = match axis { Axis::X => (1, 2), Axis::Y => (2, 0), Axis::Z => (0, 1) };
            let want: Model = m.iter().map(|&v| {
                let mut v = v;
                for _ in 0..turns.rem_euclid(4) {
                    let (u, w) = (v[f], v[t]);
                    v[f] = o[f] + side - 1 - (w - o[t]);
                    v[t] = o[t] + (u - o[f]);
                }
                v
            }).collect();
            prop_assert_eq!(&r, &canonical(depth, o, &want), "{:?} {}", axis, turns);
            let mi = a.mirror(axis);
            mi.assert_valid();
            let ax = axis.index();
            let want: Model = m.iter().map(|&v| { let mut v = v; v[ax] = last(v[ax], ax); v }).collect();
            prop_assert_eq!(&mi, &canonical(depth, o, &want));
        }
        if depth + s <= MAX_DEPTH {
            let up = a.scale_up(s).unwrap();
            up.assert_valid();
            prop_assert_eq!(up.voxel_count(), a.voxel_count() << (3 * s));
            let n = 1i64 << s;
            for v in m.iter().take(20) {
                prop_assert!(up.contains([v[0] * n, v[1] * n + n - 1, v[2] * n]));
            }
            prop_assert_eq!(&up.scale_down(s).unwrap(), &a);
        }
        let down = a.scale_down(s).unwrap();
        down.assert_valid();
        let n = 1i64 << s;
        let want: Model = m.iter().map(|v| v.map(|c| c.div_euclid(n))).collect();
        prop_assert_eq!(&voxels(&down), &want);
    }

    #[test]
    fn crop_and_dense_match_the_model(
        depth in 0u8..6, kind in 0u8..3, seed: u64,
        o in prop::array::uniform3(-30i64..30),
        lo in prop::array::uniform3(-40i64..40), ext in prop::array::uniform3(0i64..40),
    ) {
        let m = offset(&shape(depth, kind, seed), o);
        let a = canonical(depth, o, &m);
        let hi = [lo[0] + ext[0], lo[1] + ext[1], lo[2] + ext[2]];
        // The bounding box against the model's.
        let model_bbox = (!m.is_empty()).then(|| {
            let f = |g: fn(i64, i64) -> i64, init: i64| -> Voxel {
                std::array::from_fn(|i| m.iter().map(|v| v[i]).fold(init, g))
            };
            (f(i64::min, i64::MAX), f(i64::max, i64::MIN))
        });
        prop_assert_eq!(a.bbox(), model_bbox);
        let c = a.crop(lo, hi);
        c.assert_valid();
        let want: Model = m.iter().copied().filter(|v| (0..3).all(|i| v[i] >= lo[i] && v[i] <= hi[i])).collect();
        prop_assert_eq!(&c, &canonical(depth, o, &want));
        // Dense array of the shape's bounding dimensions.
        let side = 1u32 << depth;
        let dims = [side, side.max(1) - side / 2, side];
        let total = (dims[0] * dims[1] * dims[2]) as usize;
        let mut bits = vec![0u64; total.div_ceil(64)];
        let mut want = Model::new();
        for v in &m {
            let r = [v[0] - o[0], v[1] - o[1], v[2] - o[2]];
            if (r[1] as u32) < dims[1] {
                let i = r[0] as usize + dims[0] as usize * (r[1] as usize + dims[1] as usize * r[2] as usize);
                bits[i / 64] |= 1 << (i % 64);
                want.insert(*v);
            }
        }
        let d = LinearOctree::from_dense(depth, o, dims, &bits).unwrap();
        d.assert_valid();
        prop_assert_eq!(&d, &canonical(depth, o, &want));
    }
}

/// A ball of radius `r` centred at `c` (voxel centres inside), as a classifier.
pub(crate) fn ball(c: [f64; 3], r: f64) -> impl Fn(Voxel, u8) -> CellClass + Sync {
    move |min: Voxel, k: u8| {
        let s = (1i64 << k) as f64;
        let (mut near, mut far) = (0.0, 0.0);
        for a in 0..3 {
            let lo = min[a] as f64 + 0.5 - c[a];
            let hi = min[a] as f64 + s - 0.5 - c[a];
            let n = if lo > 0.0 {
                lo
            } else if hi < 0.0 {
                -hi
            } else {
                0.0
            };
            near += n * n;
            far += lo.abs().max(hi.abs()).powi(2);
        }
        if far <= r * r {
            CellClass::Inside
        } else if near > r * r {
            CellClass::Outside
        } else {
            CellClass::Partial
        }
    }
}

#[test]
fn large_inputs_take_the_parallel_paths_and_stay_exact() {
    // Two balls at depth 7 have well over PARALLEL_MIN_LEAVES leaves together.
    let a = LinearOctree::from_classifier(7, [0, 0, 0], &ball([64.0, 64.0, 64.0], 50.0)).unwrap();
    let b = LinearOctree::from_classifier(7, [0, 0, 0], &ball([84.0, 60.0, 64.0], 45.0)).unwrap();
    assert!(a.leaf_count() + b.leaf_count() > 1 << 14);
    let (ma, mb) = (voxels(&a), voxels(&b));
    for op in OPS {
        let r = a.set_op(&b, op).unwrap();
        r.assert_valid();
        assert_eq!(
            r,
            canonical(7, [0, 0, 0], &model_op(op, &ma, &mb)),
            "{op:?}"
        );
    }
    let c = a.complement();
    c.assert_valid();
    assert_eq!(c.voxel_count(), (1 << 21) - a.voxel_count());
    for by in [[37, -11, 5], [50, 0, 0], [-64, 32, 0], [1, 1, 1]] {
        let t = a.translate(by).unwrap();
        t.assert_valid();
        assert_eq!(
            t,
            canonical(t.depth(), t.origin(), &offset(&ma, by)),
            "{by:?}"
        );
    }
}

#[test]
fn from_voxels_radix_path_matches_std_sort() {
    // Many voxels, unsorted, with duplicates: the radix sort path.
    let m = shape(5, 1, 0x5eed);
    let mut v: Vec<Voxel> = m.iter().copied().collect();
    v.extend(m.iter().take(100).copied());
    v.reverse();
    let t = LinearOctree::from_voxels(5, [0, 0, 0], v).unwrap();
    t.assert_valid();
    assert_eq!(voxels(&t), m);
}

#[test]
fn rotation_labels_match_the_bitwise_rotation() {
    // Applying the label table digit by digit equals rotate() on every voxel.
    for axis in [Axis::X, Axis::Y, Axis::Z] {
        for turns in 0..4 {
            let table = rotation_labels(axis, turns);
            for c in 0..512u64 {
                let t = LinearOctree::from_sorted_leaves(3, [0, 0, 0], [Leaf::new(c, 0)]).unwrap();
                let r = t.rotate(axis, turns);
                let want = (0..3).fold(0, |acc, i| {
                    acc | (u64::from(table[((c >> (3 * i)) & 7) as usize]) << (3 * i))
                });
                assert_eq!(r.leaves()[0].code(), want);
            }
        }
    }
    assert_eq!(rotation_labels(Axis::Z, 1), [1, 3, 0, 2, 5, 7, 4, 6]);
}

#[test]
fn errors_are_reported_not_panics() {
    let a = LinearOctree::from_voxels(21, [0, 0, 0], [[0, 0, 0]]).unwrap();
    assert_eq!(a.translate([-1, 0, 0]), Err(OctreeError::DepthTooLarge(22)));
    assert_eq!(a.scale_up(1), Err(OctreeError::DepthTooLarge(22)));
    let b = LinearOctree::from_voxels(0, [i64::MAX, 0, 0], [[i64::MAX, 0, 0]]).unwrap();
    assert_eq!(b.translate([1, 0, 0]), Err(OctreeError::Overflow));
    assert!(matches!(
        LinearOctree::from_dense(1, [0, 0, 0], [2, 2, 2], &[]),
        Err(OctreeError::DenseTooShort { .. })
    ));
    assert!(matches!(
        LinearOctree::from_dense(1, [0, 0, 0], [3, 2, 2], &[0]),
        Err(OctreeError::OutOfBounds(_))
    ));
}

#[test]
fn fast_sibling_check_matches_the_reference() {
    let mut s = 0x7777_1234_u64;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        s
    };
    for _ in 0..20_000 {
        // Mostly near-sibling runs: a random parent, sizes and gaps perturbed.
        let k = (next() % 4) as u8;
        let parent = (next() % 64) << (3 * (u32::from(k) + 1));
        let mut run = Vec::new();
        let mut code = parent;
        for _ in 0..8 {
            let kk = if next() % 10 == 0 {
                k.saturating_sub(1)
            } else {
                k
            };
            if next() % 12 == 0 {
                code += 1 << (3 * u32::from(kk));
            }
            // A leaf starts at a multiple of its size (`Leaf::new`'s contract).
            code = code.next_multiple_of(1 << (3 * u32::from(kk)));
            run.push(Leaf::new(code, kk));
            code += 1 << (3 * u32::from(kk));
        }
        if next() % 5 == 0 {
            run[0] = Leaf::new(parent + (1 << (3 * u32::from(k))), k);
        }
        assert_eq!(
            super::canonical::completes_parent_fast(&run),
            super::canonical::completes_parent(&run),
            "{run:?}"
        );
    }
}
