//! Affine maps, integer scaling per axis and box queries against brute force over
//! voxel centres, on seeded random trees.

use std::collections::HashSet;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::{rotation_matrix, BoxState, LinearOctree};
use crate::Voxel;

fn random_tree(rng: &mut Pcg64, depth: u8, density: f64) -> (LinearOctree, HashSet<Voxel>) {
    let origin: Voxel = [0; 3].map(|_| rng.random_range(-20..20));
    let side = 1i64 << depth;
    let mut set = HashSet::new();
    // Blobs as well as scattered voxels, so that large blocks occur.
    for _ in 0..rng.random_range(1..4) {
        let c: Voxel = [0; 3].map(|_| rng.random_range(0..side));
        let r = rng.random_range(0..=side / 2);
        for x in 0..side {
            for y in 0..side {
                for z in 0..side {
                    let d = [x - c[0], y - c[1], z - c[2]];
                    if d.iter().map(|v| v * v).sum::<i64>() <= r * r || rng.random_bool(density) {
                        set.insert([origin[0] + x, origin[1] + y, origin[2] + z]);
                    }
                }
            }
        }
    }
    let t = LinearOctree::from_voxels(depth, origin, set.iter().copied()).unwrap();
    t.assert_valid();
    (t, set)
}

#[test]
fn box_state_is_the_brute_force_answer() {
    let mut rng = Pcg64::seed_from_u64(30);
    for _ in 0..300 {
        let depth = rng.random_range(0..4);
        let (t, set) = random_tree(&mut rng, depth, 0.05);
        for _ in 0..20 {
            let o = t.origin();
            let a: Voxel = [0; 3].map(|i| o[i] + rng.random_range(-3..10));
            let b: Voxel = [0; 3].map(|i| a[i] + rng.random_range(-1..6));
            let (mut black, mut white) = (false, false);
            for x in a[0]..=b[0] {
                for y in a[1]..=b[1] {
                    for z in a[2]..=b[2] {
                        if set.contains(&[x, y, z]) {
                            black = true;
                        } else {
                            white = true;
                        }
                    }
                }
            }
            let want = match (black, white) {
                (false, _) => BoxState::Empty,
                (true, false) => BoxState::Full,
                _ => BoxState::Mixed,
            };
            assert_eq!(t.box_state(a, b), want, "{a:?}..={b:?} of {t:?}");
        }
    }
}

#[test]
fn scaling_per_axis_is_exact() {
    let mut rng = Pcg64::seed_from_u64(31);
    for _ in 0..200 {
        let depth = rng.random_range(0..4);
        let (t, set) = random_tree(&mut rng, depth, 0.1);
        let k: [i64; 3] = [0; 3].map(|_| {
            let f = rng.random_range(1..4);
            if rng.random_bool(0.3) {
                -f
            } else {
                f
            }
        });
        let s = t.scale_axes(k).unwrap();
        s.assert_valid();
        // Each voxel v becomes the block of w with floor((w + 1/2) / k) = v.
        let mut want = HashSet::new();
        for v in &set {
            let range = |a: usize| {
                let (p, q) = (k[a] * v[a], k[a] * (v[a] + 1));
                p.min(q)..p.max(q)
            };
            for x in range(0) {
                for y in range(1) {
                    for z in range(2) {
                        want.insert([x, y, z]);
                    }
                }
            }
        }
        let got: HashSet<Voxel> = s.voxels().collect();
        assert_eq!(got, want, "k = {k:?}");
    }
    let t = LinearOctree::from_voxels(2, [0; 3], [[1, 1, 1]]).unwrap();
    assert!(t.scale_axes([2, 0, 1]).is_err());
}

#[test]
fn affine_maps_are_point_sampled_exactly() {
    let mut rng = Pcg64::seed_from_u64(32);
    for case in 0..120 {
        let depth = rng.random_range(1..5);
        let (t, set) = random_tree(&mut rng, depth, 0.05);
        let axis: [f64; 3] = [0; 3].map(|_| rng.random_range(-1.0..1.0));
        let m = if case % 3 == 0 {
            // A general map: rotation, shear and scale.
            let mut m = rotation_matrix(axis, rng.random_range(-180.0..180.0));
            m[0][1] += rng.random_range(-0.5..0.5);
            m[2][2] *= rng.random_range(0.5..2.0);
            m
        } else {
            rotation_matrix(axis, rng.random_range(-180.0..180.0))
        };
        let off: [f64; 3] = [0; 3].map(|_| rng.random_range(-5.0..5.0));
        let out = t.affine(m, off).unwrap();
        out.assert_valid();
        // Brute force: every voxel of a box around the image, by its centre.
        let inv = super::affine::tests_support::inverse(m);
        let (blo, bhi) = t.bbox().unwrap();
        let r = (0..3)
            .map(|a| (bhi[a] - blo[a] + 1) as f64)
            .fold(0.0, f64::max)
            * 4.0
            + 10.0;
        let c: [f64; 3] = std::array::from_fn(|i| {
            (0..3)
                .map(|j| m[i][j] * (blo[j] + bhi[j] + 1) as f64 / 2.0)
                .sum::<f64>()
                + off[i]
        });
        let mut want = 0u64;
        let lo = c.map(|v| (v - r) as i64);
        for x in lo[0]..lo[0] + 2 * r as i64 {
            for y in lo[1]..lo[1] + 2 * r as i64 {
                for z in lo[2]..lo[2] + 2 * r as i64 {
                    let q = [x, y, z].map(|v| v as f64 + 0.5);
                    let d = [0, 1, 2].map(|j| q[j] - off[j]);
                    let p: [i64; 3] = std::array::from_fn(|i| {
                        (0..3).map(|j| inv[i][j] * d[j]).sum::<f64>().floor() as i64
                    });
                    let black = set.contains(&p);
                    want += u64::from(black);
                    assert_eq!(
                        out.contains([x, y, z]),
                        black,
                        "case {case}: {:?}",
                        [x, y, z]
                    );
                }
            }
        }
        assert_eq!(
            out.voxel_count(),
            want,
            "case {case}: voxels outside the box"
        );
    }
}

#[test]
fn quarter_turns_agree_with_the_exact_rotation() {
    let mut rng = Pcg64::seed_from_u64(33);
    for _ in 0..50 {
        let (t, _) = random_tree(&mut rng, 3, 0.1);
        let m = rotation_matrix([0.0, 0.0, 1.0], 90.0);
        let r = t.affine(m, [0.0; 3]).unwrap();
        // (x, y, z) -> (-y - 1, x, z) on voxels.
        let want: HashSet<Voxel> = t.voxels().map(|v| [-v[1] - 1, v[0], v[2]]).collect();
        assert_eq!(r.voxels().collect::<HashSet<_>>(), want);
    }
}

#[test]
fn voxels_into_is_voxels() {
    let mut rng = Pcg64::seed_from_u64(34);
    for _ in 0..100 {
        let depth = rng.random_range(0..7);
        let (t, _) = random_tree(&mut rng, depth.min(5), 0.02);
        let mut v = Vec::new();
        t.voxels_into(&mut v);
        assert_eq!(v, t.voxels().collect::<Vec<_>>());
    }
    // Leaves larger than the table's 16³.
    let big = LinearOctree::full(6, [-3, 5, 7]).unwrap();
    let mut v = Vec::new();
    big.voxels_into(&mut v);
    assert_eq!(v, big.voxels().collect::<Vec<_>>());
}

#[test]
fn the_brick_view_answers_as_the_tree() {
    let mut rng = Pcg64::seed_from_u64(35);
    for _ in 0..150 {
        // Up to 32³, so that leaves of side 8 and 16 occur.
        let depth = rng.random_range(0..6);
        let (t, set) = random_tree(&mut rng, depth, 0.02);
        let view = super::bricks::BrickView::new(&t, usize::MAX).expect("small view");
        let o = t.origin();
        let side = 1i64 << t.depth();
        for _ in 0..300 {
            let v: Voxel = [0; 3].map(|a| o[a] + rng.random_range(-9..side + 9));
            assert_eq!(view.contains(v), set.contains(&v), "{v:?}");
        }
        for _ in 0..30 {
            let a: Voxel = [0; 3].map(|i| o[i] + rng.random_range(-9..side + 3));
            let b: Voxel = [0; 3].map(|i| a[i] + rng.random_range(-1..20));
            assert_eq!(view.box_state(a, b), t.box_state(a, b), "{a:?}..={b:?}");
        }
    }
    // The widest boxes: the cost saturates, the answer is the tree's.
    use super::bricks::BrickView;
    assert_eq!(
        BrickView::bricks_in([i64::MIN; 3], [i64::MAX; 3]),
        u128::MAX
    );
    let t = LinearOctree::from_voxels(3, [-4; 3], [[0, 0, 0], [3, 3, 3]]).unwrap();
    let view = BrickView::new(&t, usize::MAX).unwrap();
    for (lo, hi) in [
        ([i64::MIN; 3], [i64::MAX; 3]),
        ([0; 3], [i64::MAX; 3]),
        ([i64::MIN; 3], [0; 3]),
    ] {
        assert_eq!(
            view.box_state(lo, hi),
            t.box_state(lo, hi),
            "{lo:?}..={hi:?}"
        );
    }
    // Too many bricks: no view.
    let t = LinearOctree::from_voxels(10, [0; 3], [[0, 0, 0], [1000, 1000, 1000]]).unwrap();
    assert!(super::bricks::BrickView::new(&t, 1000).is_none());
}

#[test]
fn floor_without_the_call_is_floor() {
    let mut rng = Pcg64::seed_from_u64(36);
    let special = [
        0.0,
        -0.0,
        0.5,
        -0.5,
        1.0,
        -1.0,
        -1e-300,
        1e-300,
        2f64.powi(52) + 1.0,
        -(2f64.powi(52)) - 1.0,
        2f64.powi(63),
        -(2f64.powi(63)),
        -(2f64.powi(63)) - 4096.0,
        1e300,
        -1e300,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
    ];
    let random = (0..10_000).map(|_| rng.random_range(-1e6..1e6) * f64::from(rng.random_bool(0.5)));
    for c in special.into_iter().chain(random) {
        assert_eq!(super::affine::floor_i64(c), c.floor() as i64, "{c}");
    }
}

#[test]
fn affine_without_the_view_is_the_same() {
    // The builder's other path (an input too sparse for a view) against the view's.
    let mut rng = Pcg64::seed_from_u64(37);
    for _ in 0..60 {
        let depth = rng.random_range(1..5);
        let (t, _) = random_tree(&mut rng, depth, 0.05);
        let axis: [f64; 3] = [0; 3].map(|_| rng.random_range(-1.0..1.0));
        let m = rotation_matrix(axis, rng.random_range(-180.0..180.0));
        let off: [f64; 3] = [0; 3].map(|_| rng.random_range(-5.0..5.0));
        let with = t.affine(m, off).unwrap();
        let without = t.affine_without_view(m, off);
        without.assert_valid();
        assert_eq!(with, without);
        let k: [i64; 3] =
            [0; 3].map(|_| rng.random_range(1..4) * if rng.random_bool(0.3) { -1 } else { 1 });
        let s = t.scale_axes_without_view(k);
        s.assert_valid();
        assert!(
            t.scale_axes(k).unwrap().same_voxels(&s).unwrap(),
            "k = {k:?}"
        );
    }
}

#[test]
fn scaling_by_a_power_of_two_keeps_its_fast_path_and_its_answer() {
    // Equal positive powers of two go to scale_up; the general builder agrees.
    let mut rng = Pcg64::seed_from_u64(38);
    for _ in 0..40 {
        let depth = rng.random_range(0..5);
        let (t, _) = random_tree(&mut rng, depth, 0.05);
        for s in 0..3u8 {
            let f = 1i64 << s;
            let fast = t.scale_axes([f; 3]).unwrap();
            fast.assert_valid();
            assert_eq!(fast, t.scale_up(s).unwrap(), "the fast path");
            let general = t.scale_axes_without_view([f; 3]);
            assert!(fast.same_voxels(&general).unwrap(), "2^{s}");
        }
    }
}
