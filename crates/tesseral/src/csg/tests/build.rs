//! Composite solids against the dense model; cost, limits, colours and boxes.

use std::sync::atomic::{AtomicUsize, Ordering};

use super::*;

fn random_solid(rng: &mut Rng, depth_left: u32, scale: f64) -> Solid {
    if depth_left == 0 || rng.next() % 3 == 0 {
        let kind = (rng.next() % SHAPE_KINDS as u64) as usize;
        let shape = random_shape(rng, kind, scale);
        let rot = random_rotation(rng);
        let at = [
            rng.range(-0.2, 0.2) * scale,
            rng.range(-0.2, 0.2) * scale,
            rng.range(-0.2, 0.2) * scale,
        ];
        return Solid::shape(shape).rotate(rot).at(at);
    }
    let n = 1 + (rng.next() % 3) as usize;
    let parts: Vec<Solid> = (0..n)
        .map(|_| random_solid(rng, depth_left - 1, scale))
        .collect();
    let op = rng.next() % 4;
    let mut s = match op {
        0 => Solid::union(parts),
        1 => Solid::intersection(parts),
        2 => Solid::Difference(parts),
        _ => Solid::union(parts).negate(),
    };
    if rng.next() % 2 == 0 {
        s = s
            .scaled(rng.range(0.7, 1.2))
            .rotate(random_rotation(rng))
            .at([
                rng.range(-2.0, 2.0),
                rng.range(-2.0, 2.0),
                rng.range(-2.0, 2.0),
            ]);
    }
    s
}

#[test]
fn composite_scenes_with_every_set_operation_equal_dense() {
    let seed = 0xc0ffee_u64;
    println!("seed {seed:#x}");
    let mut rng = Rng(seed);
    let mut seen_ops = [false; 4];
    for trial in 0..60 {
        let solid = random_solid(&mut rng, 3, 28.0).at([16.0, 16.0, 16.0]);
        fn ops(s: &Solid, seen: &mut [bool; 4]) {
            match s {
                Solid::Union(v) => {
                    seen[0] = true;
                    v.iter().for_each(|c| ops(c, seen));
                }
                Solid::Intersection(v) => {
                    seen[1] = true;
                    v.iter().for_each(|c| ops(c, seen));
                }
                Solid::Difference(v) => {
                    seen[2] = true;
                    v.iter().for_each(|c| ops(c, seen));
                }
                Solid::Not(c) => {
                    seen[3] = true;
                    ops(c, seen);
                }
                Solid::Transformed(c, _) | Solid::Coloured(c, _) => ops(c, seen),
                Solid::Primitive(_) => {}
            }
        }
        ops(&solid, &mut seen_ops);
        let csg = solid.compile().unwrap();
        check_exact(
            &csg,
            5,
            [0, 0, 0],
            &format!("seed {seed:#x} trial {trial}: {solid:?}"),
        );
    }
    assert!(
        seen_ops.iter().all(|&s| s),
        "every operation occurs: {seen_ops:?}"
    );
}

#[test]
fn more_than_64_primitives_equal_dense() {
    let mut rng = Rng(77);
    let balls: Vec<Solid> = (0..80)
        .map(|_| {
            Solid::shape(Shape::sphere(rng.range(1.0, 4.0))).at([
                rng.range(2.0, 30.0),
                rng.range(2.0, 30.0),
                rng.range(2.0, 30.0),
            ])
        })
        .collect();
    let solid = Solid::shape(Shape::cuboid([30.0, 30.0, 30.0]))
        .at([16.0, 16.0, 16.0])
        .difference([Solid::union(balls)]);
    let csg = solid.compile().unwrap();
    assert_eq!(csg.primitive_count(), 81);
    check_exact(&csg, 5, [0, 0, 0], "80 balls");
}
struct Counting<'a>(&'a Csg, AtomicUsize);
impl Classifier for Counting<'_> {
    fn classify(&self, min: Voxel, k: u8) -> CellClass {
        self.1.fetch_add(1, Ordering::Relaxed);
        self.0.classify(min, k)
    }
}

/// Doubling the radius and the resolution quadruples the work (surface), not
/// multiplies it by eight (volume).
#[test]
fn cost_follows_the_surface() {
    let count = |r: f64, depth: u8| {
        let c = f64::from(1u32 << depth) / 2.0;
        let csg = Solid::shape(Shape::sphere(r))
            .at([c, c, c])
            .compile()
            .unwrap();
        let counter = Counting(&csg, AtomicUsize::new(0));
        LinearOctree::from_classifier(depth, [0, 0, 0], &counter).unwrap();
        counter.1.load(Ordering::Relaxed) as f64
    };
    let (a, b) = (count(25.0, 6), count(50.0, 7));
    let ratio = b / a;
    assert!(
        (3.0..5.0).contains(&ratio),
        "cells classified grew by {ratio}"
    );
}

#[test]
fn leaf_limit_stops_a_big_build() {
    let csg = Solid::shape(Shape::sphere(100.0))
        .at([128.0; 3])
        .compile()
        .unwrap();
    assert!(matches!(
        csg.build_limited(8, [0, 0, 0], 1000),
        Err(CsgError::TooManyLeaves { limit: 1000 })
    ));
    assert!(matches!(csg.build(40, [0, 0, 0]), Err(CsgError::Octree(_))));
}

#[test]
fn invalid_solids_are_rejected() {
    assert!(Solid::shape(Shape::sphere(-1.0)).compile().is_err());
    assert!(Solid::Difference(vec![]).compile().is_err());
    assert!(Solid::shape(Shape::sphere(1.0))
        .scaled(0.0)
        .compile()
        .is_err());
    assert!(Shape::half_space([0.0; 3], 1.0).is_none());
}

#[test]
fn colours_and_bounding_boxes() {
    let red = Colour::parse("red").unwrap();
    let blue = Colour::parse("blue").unwrap();
    let s = Solid::union([
        Solid::shape(Shape::sphere(2.0)).colour(red),
        Solid::shape(Shape::cuboid([2.0, 2.0, 2.0]))
            .at([5.0, 0.0, 0.0])
            .colour(blue),
    ]);
    let csg = s.compile().unwrap();
    assert_eq!(csg.colour_at([0.0, 0.0, 0.0]), Some(red));
    assert_eq!(csg.colour_at([5.0, 0.0, 0.0]), Some(blue));
    let (lo, hi) = csg.bbox().unwrap();
    assert!((lo[0] + 2.0).abs() < 1e-9 && (hi[0] - 6.0).abs() < 1e-9);
    let n = csg.normal_at([2.0, 0.0, 0.0]).unwrap();
    assert!((n[0] - 1.0).abs() < 1e-3);
    assert!(Solid::shape(Shape::sphere(1.0))
        .negate()
        .compile()
        .unwrap()
        .bbox()
        .is_none());
    let cube = Shape::polyhedron(&[
        [1.0, 0.0, 0.0, 1.0],
        [-1.0, 0.0, 0.0, 1.0],
        [0.0, 1.0, 0.0, 1.0],
        [0.0, -1.0, 0.0, 1.0],
        [0.0, 0.0, 1.0, 1.0],
        [0.0, 0.0, -1.0, 1.0],
    ])
    .unwrap();
    let h = cube.local_half_extent().unwrap();
    assert!(h.iter().all(|v| (v - 1.0).abs() < 1e-9));
}

/// Boxes whose faces fall on cell faces (sizes in multiples of 4 and whole places,
/// quarter turns, scales of ½, 1 and 2), alone and combined: the box's own cell test
/// (`Prim::box_class`, by the centres' bounding box) decides cells the ball cannot,
/// and must agree with the dense model exactly. (Faces through voxel centres:
/// `quarter_turned_boxes_with_faces_through_centres_equal_dense`.)
#[test]
fn axis_boxes_on_cell_boundaries_equal_dense() {
    let mut rng = Rng(0xb0c5);
    let aligned_box = |rng: &mut Rng| {
        let size = [0, 1, 2].map(|_| f64::from((rng.next() % 10) as u32 + 1) * 4.0);
        let at = [0, 1, 2].map(|_| f64::from((rng.next() % 40) as u32) - 4.0);
        let turn = [0, 1, 2].map(|_| f64::from((rng.next() % 4) as u32) * 90.0);
        let scale = [1.0, 0.5, 2.0][(rng.next() % 3) as usize];
        Solid::shape(Shape::cuboid(size))
            .rotate(turn)
            .scaled(scale)
            .at(at)
    };
    check_boxes_and_pairs(&mut rng, aligned_box);
}

/// Boxes whose faces pass through voxel centres (odd sizes at whole places), turned
/// by quarter turns: a centre on a face is a tie that every test must break the
/// same way. The rotation's sines and cosines of multiples of 90° are exact
/// ([`super::super::Transform::rotation`]), so the pruning builder's masks, the
/// generic classifier and the dense point test see the same face.
#[test]
fn quarter_turned_boxes_with_faces_through_centres_equal_dense() {
    let mut rng = Rng(0xface);
    let odd_box = |rng: &mut Rng| {
        let size = [0, 1, 2].map(|_| f64::from((rng.next() % 10) as u32) * 2.0 + 1.0);
        let at = [0, 1, 2].map(|_| f64::from((rng.next() % 32) as u32));
        let turn = [0, 1, 2].map(|_| f64::from((rng.next() % 8) as u32) * 90.0 - 270.0);
        Solid::shape(Shape::cuboid(size)).rotate(turn).at(at)
    };
    check_boxes_and_pairs(&mut rng, odd_box);
}

/// An infinite angle is refused as a non-finite transform, not taken for a whole
/// number of quarter turns.
#[test]
fn an_infinite_rotation_is_refused() {
    for deg in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
        let e = Solid::shape(Shape::cuboid([2.0; 3]))
            .rotate([0.0, deg, 0.0])
            .compile()
            .unwrap_err();
        assert!(e.to_string().contains("finite"), "{deg}: {e}");
    }
}

/// 80 trials at depth 5, by turns: a box from `make`, then the union, the difference
/// and the intersection of two, each built by both builders and checked against the
/// dense model ([`check_exact`]).
fn check_boxes_and_pairs(rng: &mut Rng, make: impl Fn(&mut Rng) -> Solid) {
    for trial in 0..80 {
        let solid = match trial % 4 {
            0 => make(rng),
            1 => Solid::union(vec![make(rng), make(rng)]),
            2 => Solid::Difference(vec![make(rng), make(rng)]),
            _ => Solid::intersection(vec![make(rng), make(rng)]),
        };
        let csg = solid.compile().unwrap();
        check_exact(&csg, 5, [0, 0, 0], &format!("trial {trial}: {solid:?}"));
    }
}

/// A box that fills its space is one leaf, decided at the root: its faces lie on
/// the cells' faces all the way down, which the ball test could not decide (a
/// `depth 15` scene of one such box took 163 s and then passed the leaf limit).
#[test]
fn a_box_filling_its_space_is_decided_at_the_root() {
    let side = f64::from(1u32 << 15);
    let csg = Solid::shape(Shape::cuboid([side; 3]))
        .at([side / 2.0; 3])
        .compile()
        .unwrap();
    let counter = Counting(&csg, AtomicUsize::new(0));
    let tree = LinearOctree::from_classifier(15, [0, 0, 0], &counter).unwrap();
    assert_eq!(tree.leaf_count(), 1);
    assert_eq!(tree.voxel_count(), 1 << 45);
    assert_eq!(counter.1.load(Ordering::Relaxed), 1, "one cell classified");
    assert_eq!(csg.build(15, [0, 0, 0]).unwrap().leaf_count(), 1);
}
