//! Every model operation against a map of world cubes, on seeded random models with
//! random frames, colours, free space and log-odds.

use std::collections::HashMap;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

use super::*;

/// A world cube's state: black or free, with its colour and log-odds bits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Cell {
    pub(super) black: bool,
    color: Option<Rgba>,
    log_odds: Option<u32>,
}

/// World cubes keyed by their lowest corner in units of 1/1024 (frames in these tests
/// are dyadic, so the keys are exact).
pub(super) type World = HashMap<[i64; 3], Cell>;

pub(super) fn key(p: [f64; 3]) -> [i64; 3] {
    p.map(|c| {
        let k = c * 1024.0;
        assert_eq!(k, k.round(), "world coordinate {c} not on the test grid");
        k as i64
    })
}

pub(super) fn world(m: &Model) -> World {
    let mut w = World::new();
    for v in m.tree.voxels() {
        let cell = Cell {
            black: true,
            color: m.colors.as_ref().and_then(|c| c.get(v)),
            log_odds: m.log_odds.as_ref().and_then(|l| l.get(v)).map(f32::to_bits),
        };
        w.insert(key(m.frame.voxel_corner(v)), cell);
    }
    for v in m.free.iter().flat_map(LinearOctree::voxels) {
        let cell = Cell {
            black: false,
            color: None,
            log_odds: m.log_odds.as_ref().and_then(|l| l.get(v)).map(f32::to_bits),
        };
        assert!(w.insert(key(m.frame.voxel_corner(v)), cell).is_none());
    }
    w
}

const PALETTE: [Rgba; 3] = [[255, 0, 0, 255], [0, 255, 0, 255], [0, 0, 255, 128]];
const ODDS: [f32; 3] = [0.85, -0.405, 3.5];

/// A random model in frame `(h, t)`: black voxels, maybe colours, maybe free space
/// and log-odds.
pub(super) fn random_model(rng: &mut Pcg64Mcg, h: f64, t: [f64; 3]) -> Model {
    let origin: Voxel = std::array::from_fn(|_| rng.random_range(-6..6));
    let depth = 3;
    let mut black = Vec::new();
    let mut free = Vec::new();
    for _ in 0..rng.random_range(0..60) {
        let v: Voxel = std::array::from_fn(|a| origin[a] + rng.random_range(0..8));
        if rng.random_bool(0.7) {
            black.push(v);
        } else {
            free.push(v);
        }
    }
    // Whole blocks too, so that leaves of several sizes occur.
    if rng.random_bool(0.5) {
        let c: Voxel = std::array::from_fn(|a| origin[a] + 2 * rng.random_range(0..4));
        for d in 0..8 {
            black.push([c[0] + (d & 1), c[1] + ((d >> 1) & 1), c[2] + ((d >> 2) & 1)]);
        }
    }
    let tree = LinearOctree::from_voxels(depth, origin, black.iter().copied()).unwrap();
    let colors = rng.random_bool(0.6).then(|| {
        let pairs: Vec<_> = black
            .iter()
            .filter_map(|&v| {
                let c = PALETTE[rng.random_range(0..3)];
                rng.random_bool(0.8).then_some((v, c))
            })
            .collect();
        Layer::from_voxels(depth, origin, pairs).unwrap()
    });
    let with_free = rng.random_bool(0.5);
    let free_tree =
        with_free.then(|| LinearOctree::from_voxels(depth, origin, free.iter().copied()).unwrap());
    let log_odds = (with_free && rng.random_bool(0.7)).then(|| {
        let pairs: Vec<_> = black
            .iter()
            .chain(&free)
            .map(|&v| (v, ODDS[rng.random_range(0..3)]))
            .collect();
        Layer::from_voxels(depth, origin, pairs).unwrap()
    });
    let m = Model::from_parts(tree, Frame::new(h, t), colors, free_tree, log_odds).unwrap();
    m.assert_valid();
    m
}

pub(super) fn random_frame(rng: &mut Pcg64Mcg) -> (f64, [f64; 3]) {
    let h = [0.25, 0.5, 1.0, 2.0][rng.random_range(0..4)];
    let t = std::array::from_fn(|_| h * f64::from(rng.random_range(-8..8)) + 0.125);
    (h, t)
}

fn same_frame_shifted(rng: &mut Pcg64Mcg, h: f64, t: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|a| t[a] + h * f64::from(rng.random_range(-5..5)))
}

/// The world box `[lo, hi)` of the model's space, in keys.
fn space_keys(m: &Model) -> ([i64; 3], [i64; 3]) {
    let o = m.tree.origin();
    let s = 1i64 << m.tree.depth();
    let lo = key(m.frame.voxel_corner(o));
    let hi = key(m.frame.voxel_corner([o[0] + s, o[1] + s, o[2] + s]));
    (lo, hi)
}

fn expected_set_op(a: &Model, b: &Model, op: SetOp) -> World {
    let (wa, wb) = (world(a), world(b));
    let any_free = a.free.is_some() || b.free.is_some();
    let any_lo = a.log_odds.is_some() || b.log_odds.is_some();
    let (lo, hi) = space_keys(a);
    let clipped = matches!(op, SetOp::Intersection | SetOp::Difference);
    let mut out = World::new();
    for k in wa.keys().chain(wb.keys()) {
        if clipped && !(0..3).all(|i| lo[i] <= k[i] && k[i] < hi[i]) {
            continue;
        }
        let (ca, cb) = (wa.get(k), wb.get(k));
        let (ba, bb) = (ca.is_some_and(|c| c.black), cb.is_some_and(|c| c.black));
        let black = match op {
            SetOp::Union => ba || bb,
            SetOp::Intersection => ba && bb,
            SetOp::Difference => ba && !bb,
            SetOp::SymmetricDifference => ba != bb,
        };
        if !black && !any_free {
            continue;
        }
        let log_odds = if any_lo {
            ca.and_then(|c| c.log_odds).or(cb.and_then(|c| c.log_odds))
        } else {
            None
        };
        let color = if black {
            ca.and_then(|c| c.color).or(cb.and_then(|c| c.color))
        } else {
            None
        };
        out.insert(
            *k,
            Cell {
                black,
                color,
                log_odds,
            },
        );
    }
    out
}

pub(super) fn check(m: &Model, expected: &World, what: &str, seed: u64) {
    m.assert_valid();
    let got = world(m);
    assert_eq!(
        got.len(),
        expected.len(),
        "{what} (seed {seed}): cell counts"
    );
    for (k, c) in expected {
        assert_eq!(got.get(k), Some(c), "{what} (seed {seed}) at key {k:?}");
    }
}

#[test]
fn set_operations_follow_the_world_model() {
    for seed in 0..300 {
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        let (h, t) = random_frame(&mut rng);
        let a = random_model(&mut rng, h, t);
        let t2 = same_frame_shifted(&mut rng, h, t);
        let b = random_model(&mut rng, h, t2);
        for op in [
            SetOp::Union,
            SetOp::Intersection,
            SetOp::Difference,
            SetOp::SymmetricDifference,
        ] {
            let r = a.set_op(&b, op).unwrap();
            assert_eq!(r.frame, a.frame);
            check(&r, &expected_set_op(&a, &b, op), &format!("{op:?}"), seed);
        }
    }
}

pub(super) fn moved(w: &World, f: impl Fn([i64; 3]) -> Vec<[i64; 3]>) -> World {
    w.iter()
        .flat_map(|(k, c)| f(*k).into_iter().map(move |k| (k, *c)))
        .collect()
}

#[test]
fn transforms_follow_the_world_model() {
    for seed in 0..300 {
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        let (h, t) = random_frame(&mut rng);
        let m = random_model(&mut rng, h, t);
        let w = world(&m);
        let hk = key([h, 0.0, 0.0])[0];

        let by: [i64; 3] = std::array::from_fn(|_| rng.random_range(-20..20));
        let r = m.translate(by).unwrap();
        check(
            &r,
            &moved(&w, |k| vec![std::array::from_fn(|a| k[a] + by[a] * hk)]),
            "translate",
            seed,
        );
        let world_by = by.map(|c| c as f64 * h);
        assert_eq!(m.translate_world(world_by).unwrap(), r);

        for axis in [Axis::X, Axis::Y, Axis::Z] {
            for turns in -1..4 {
                let r = m.rotate(axis, turns).unwrap();
                let expect = moved(&w, |k| {
                    let p = k.map(|c| c as f64);
                    let q = p.map(|c| c + hk as f64);
                    let (p, q) = (turn_point(p, axis, turns), turn_point(q, axis, turns));
                    vec![std::array::from_fn(|a| p[a].min(q[a]) as i64)]
                });
                check(&r, &expect, &format!("rotate {axis:?} {turns}"), seed);
            }
            let r = m.mirror(axis).unwrap();
            let a = axis.index();
            let expect = moved(&w, |mut k| {
                k[a] = -(k[a] + hk);
                vec![k]
            });
            check(&r, &expect, &format!("mirror {axis:?}"), seed);
        }

        let s = rng.random_range(0..3u8);
        let r = m.scale_up(s).unwrap();
        let n = 1i64 << s;
        let expect = moved(&w, |k| {
            let base = k.map(|c| c * n);
            (0..n * n * n)
                .map(|i| {
                    [
                        base[0] + (i % n) * hk,
                        base[1] + (i / n % n) * hk,
                        base[2] + (i / n / n) * hk,
                    ]
                })
                .collect()
        });
        check(&r, &expect, &format!("scale_up {s}"), seed);
        assert_eq!(
            r.scale_down(s).unwrap().tree.voxel_count(),
            m.tree.voxel_count()
        );

        let c = m.complement();
        c.assert_valid();
        assert_eq!(c.tree.voxel_count() + m.tree.voxel_count(), 512);
        assert_eq!(c.frame, m.frame);
    }
}

#[test]
fn scale_down_is_conservative_and_keeps_values_on_black_voxels() {
    for seed in 0..100 {
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        let m = random_model(&mut rng, 0.5, [0.0; 3]);
        let d = m.scale_down(1).unwrap();
        d.assert_valid();
        for v in m.tree.voxels() {
            assert!(d.tree.contains(v.map(|c| c.div_euclid(2))), "seed {seed}");
        }
        assert_eq!(d.frame.voxel_size, 0.5);
    }
}

#[test]
fn frames_that_do_not_line_up_are_refused_naming_both() {
    let t = LinearOctree::from_voxels(1, [0, 0, 0], [[0, 0, 0]]).unwrap();
    let a = Model::new(t.clone()).with_frame(Frame::new(0.05, [0.0; 3]));
    let b = Model::new(t.clone()).with_frame(Frame::new(0.1, [0.0; 3]));
    let e = a.union(&b).unwrap_err().to_string();
    assert!(
        e.contains("0.05") && e.contains("0.1") && e.contains("voxel sizes differ"),
        "{e}"
    );
    let c = Model::new(t).with_frame(Frame::new(0.05, [0.025, 0.0, 0.0]));
    let e = a.intersection(&c).unwrap_err().to_string();
    assert!(e.contains("fraction of a voxel"), "{e}");
    let e = a.translate_world([0.07, 0.0, 0.0]).unwrap_err().to_string();
    assert!(e.contains("nearest whole vector is (1, 0, 0)"), "{e}");
}

#[test]
fn layers_with_many_distinct_values_stay_exact() {
    let mut rng = Pcg64Mcg::seed_from_u64(7);
    let pairs: Vec<(Voxel, Rgba)> = (0..20_000)
        .map(|_| {
            let v: Voxel = std::array::from_fn(|_| rng.random_range(0..64));
            (v, rng.random::<u32>().to_le_bytes())
        })
        .collect();
    let layer = Layer::from_voxels(6, [0; 3], pairs.iter().copied()).unwrap();
    layer.assert_valid();
    let mut last = HashMap::new();
    for (v, c) in &pairs {
        last.insert(*v, *c);
    }
    for (v, c) in &last {
        assert_eq!(layer.get(*v), Some(*c));
    }
    assert_eq!(layer.voxel_count(), last.len() as u64);
    // From any hint, near or far, and for voxels with no value (some outside the
    // space), get_near answers as the map does, in order and out of it.
    let mut near = 0;
    for round in 0..20_000 {
        let v: Voxel = std::array::from_fn(|_| rng.random_range(-2..66));
        if round % 3 == 0 {
            near = rng.random_range(0..30_000);
        }
        assert_eq!(layer.get_near(v, &mut near), last.get(&v).copied(), "{v:?}");
    }
}

#[test]
fn layers_from_overlapping_regions_are_refused_unless_the_values_agree() {
    // Random voxel sets, two values: the layer must be refused exactly when a voxel
    // holds both (a HashSet says which), and otherwise hold every voxel's value.
    let mut rng = Pcg64Mcg::seed_from_u64(11);
    for round in 0..200 {
        let set = |rng: &mut Pcg64Mcg| -> Vec<Voxel> {
            let n = rng.random_range(0..40);
            (0..n)
                .map(|_| std::array::from_fn(|_| rng.random_range(0..8)))
                .collect()
        };
        let (a, b) = (set(&mut rng), set(&mut rng));
        let tree = |v: &[Voxel]| LinearOctree::from_voxels(3, [0; 3], v.iter().copied()).unwrap();
        let (red, blue) = ([255, 0, 0, 255], [0, 0, 255, 255]);
        let sa: std::collections::HashSet<Voxel> = a.iter().copied().collect();
        let shared = b.iter().any(|v| sa.contains(v));
        match Layer::from_regions(3, [0; 3], [(red, tree(&a)), (blue, tree(&b))]) {
            Ok(layer) => {
                assert!(!shared, "round {round}: overlapping regions accepted");
                layer.assert_valid();
                for v in &a {
                    assert_eq!(layer.get(*v), Some(red));
                }
                for v in &b {
                    assert_eq!(layer.get(*v), Some(blue));
                }
            }
            Err(e) => {
                assert!(shared, "round {round}: disjoint regions refused: {e}");
                assert!(e.to_string().contains("overlap"), "{e}");
            }
        }
        // The same value twice is one region, whatever the overlap.
        let same = Layer::from_regions(3, [0; 3], [(red, tree(&a)), (red, tree(&b))]).unwrap();
        same.assert_valid();
        assert_eq!(
            same.region_count(),
            usize::from(!(a.is_empty() && b.is_empty()))
        );
    }
}
