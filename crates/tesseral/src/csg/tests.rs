//! The CSG builder against a dense per-voxel evaluation, voxel for voxel.

use std::sync::atomic::{AtomicUsize, Ordering};

use super::*;
use crate::linear::{CellClass, Classifier, LinearOctree};
use crate::Voxel;

/// A small xorshift generator; every test prints its seed. Shared with the render
/// tests.
pub(crate) struct Rng(pub(crate) u64);
impl Rng {
    pub(crate) fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub(crate) fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
}

/// Every voxel of the space whose centre the solid contains.
fn dense(csg: &Csg, depth: u8, origin: Voxel) -> Vec<Voxel> {
    let side = 1i64 << depth;
    let mut out = Vec::new();
    for z in 0..side {
        for y in 0..side {
            for x in 0..side {
                let v = [origin[0] + x, origin[1] + y, origin[2] + z];
                let c = [v[0] as f64 + 0.5, v[1] as f64 + 0.5, v[2] as f64 + 0.5];
                if csg.contains(c) {
                    out.push(v);
                }
            }
        }
    }
    out
}

/// Builds with both the pruning builder and the generic classifier builder, checks
/// both trees, and compares them with the dense evaluation.
fn check_exact(csg: &Csg, depth: u8, origin: Voxel, what: &str) -> LinearOctree {
    let tree = csg.build(depth, origin).unwrap();
    tree.assert_valid();
    let generic = LinearOctree::from_classifier(depth, origin, csg).unwrap();
    generic.assert_valid();
    assert_eq!(tree, generic, "{what}: pruning and generic builders differ");
    let want = LinearOctree::from_voxels(depth, origin, dense(csg, depth, origin)).unwrap();
    if tree != want {
        let got: std::collections::HashSet<Voxel> = tree.voxels().collect();
        let exp: std::collections::HashSet<Voxel> = want.voxels().collect();
        let extra: Vec<_> = got.difference(&exp).take(5).collect();
        let missing: Vec<_> = exp.difference(&got).take(5).collect();
        panic!(
            "{what}: octree differs from dense evaluation; extra {extra:?}, missing {missing:?}"
        );
    }
    tree
}

fn random_shape(rng: &mut Rng, kind: usize, scale: f64) -> Shape {
    let mut r = || rng.range(0.15, 0.5) * scale;
    match kind {
        0 => Shape::sphere(r()),
        1 => Shape::cuboid([2.0 * r(), 2.0 * r(), 2.0 * r()]),
        2 => Shape::Ellipsoid { r: [r(), r(), r()] },
        3 => Shape::Cylinder {
            r: [r(), r()],
            half_h: r(),
        },
        4 => {
            let r1 = r();
            let r2 = if kind % 2 == 0 { 0.0 } else { r() * 0.5 };
            let aspect = r() / r1;
            Shape::Cone {
                r1,
                r2,
                aspect,
                half_h: r(),
            }
        }
        5 => {
            let minor = r() * 0.4;
            Shape::Torus {
                major: r() * 0.6 + minor,
                minor,
            }
        }
        6 => Shape::Capsule {
            r: r() * 0.6,
            half_h: r() * 0.6,
        },
        7 => Shape::half_space(
            [r() - 0.3 * scale, r() - 0.3 * scale, r() - 0.3 * scale],
            r() - 0.3 * scale,
        )
        .unwrap(),
        _ => {
            // A random convex polyhedron: planes tangent to a ball, random directions.
            let n = 4 + (rng.next() % 8) as usize;
            let planes: Vec<[f64; 4]> = (0..n)
                .map(|_| {
                    let d = [
                        rng.range(-1.0, 1.0),
                        rng.range(-1.0, 1.0),
                        rng.range(-1.0, 1.0),
                    ];
                    [d[0], d[1], d[2], rng.range(0.2, 0.45) * scale]
                })
                .collect();
            Shape::polyhedron(&planes).unwrap()
        }
    }
}

const SHAPE_KINDS: usize = 9;

fn random_rotation(rng: &mut Rng) -> [f64; 3] {
    [
        rng.range(-180.0, 180.0),
        rng.range(-180.0, 180.0),
        rng.range(-180.0, 180.0),
    ]
}

#[test]
fn every_primitive_at_random_rotations_and_sizes_equals_dense() {
    let seed = 0x05ee_dc59_u64;
    println!("seed {seed:#x}");
    let mut rng = Rng(seed);
    for kind in 0..SHAPE_KINDS {
        for trial in 0..10 {
            let depth = 5;
            let side = 32.0;
            let shape = random_shape(&mut rng, kind, side);
            let rot = random_rotation(&mut rng);
            let at = [
                rng.range(10.0, 22.0),
                rng.range(10.0, 22.0),
                rng.range(10.0, 22.0),
            ];
            let origin = if trial % 2 == 0 {
                [0, 0, 0]
            } else {
                [-7, 3, -20]
            };
            let at = [
                at[0] + origin[0] as f64,
                at[1] + origin[1] as f64,
                at[2] + origin[2] as f64,
            ];
            let csg = Solid::shape(shape.clone())
                .rotate(rot)
                .at(at)
                .compile()
                .unwrap();
            let what = format!(
                "seed {seed:#x} kind {kind} trial {trial}: {shape:?} rot {rot:?} at {at:?}"
            );
            check_exact(&csg, depth, origin, &what);
        }
    }
}

/// The exact predicate against formulas written out independently, with the rotation
/// undone one axis at a time (z, then y, then x).
#[test]
fn point_predicate_matches_independent_formulas() {
    let seed = 0xfeed_u64;
    println!("seed {seed:#x}");
    let mut rng = Rng(seed);
    for _ in 0..200 {
        let (a, b, g) = (
            rng.range(-90.0, 90.0),
            rng.range(-90.0, 90.0),
            rng.range(-90.0, 90.0),
        );
        let at = [
            rng.range(-5.0, 5.0),
            rng.range(-5.0, 5.0),
            rng.range(-5.0, 5.0),
        ];
        let (rx, ry, rz) = (
            rng.range(1.0, 6.0),
            rng.range(1.0, 6.0),
            rng.range(1.0, 6.0),
        );
        let undo = |p: [f64; 3]| {
            let mut q = [p[0] - at[0], p[1] - at[1], p[2] - at[2]];
            let (s, c) = (-g.to_radians()).sin_cos();
            q = [c * q[0] - s * q[1], s * q[0] + c * q[1], q[2]];
            let (s, c) = (-b.to_radians()).sin_cos();
            q = [c * q[0] + s * q[2], q[1], -s * q[0] + c * q[2]];
            let (s, c) = (-a.to_radians()).sin_cos();
            [q[0], c * q[1] - s * q[2], s * q[1] + c * q[2]]
        };
        let ell = Solid::shape(Shape::Ellipsoid { r: [rx, ry, rz] })
            .rotate([a, b, g])
            .at(at)
            .compile()
            .unwrap();
        let bx = Solid::shape(Shape::cuboid([rx, ry, rz]))
            .rotate([a, b, g])
            .at(at)
            .compile()
            .unwrap();
        let cone = Solid::shape(Shape::Cone {
            r1: rx,
            r2: 0.0,
            aspect: 1.0,
            half_h: rz,
        })
        .rotate([a, b, g])
        .at(at)
        .compile()
        .unwrap();
        for _ in 0..50 {
            let p = [
                rng.range(-12.0, 12.0),
                rng.range(-12.0, 12.0),
                rng.range(-12.0, 12.0),
            ];
            let q = undo(p);
            let e = (q[0] / rx).powi(2) + (q[1] / ry).powi(2) + (q[2] / rz).powi(2);
            if (e - 1.0).abs() > 1e-9 {
                assert_eq!(ell.contains(p), e <= 1.0, "ellipsoid at {p:?}");
            }
            let m = (q[0].abs() / (rx / 2.0))
                .max(q[1].abs() / (ry / 2.0))
                .max(q[2].abs() / (rz / 2.0));
            if (m - 1.0).abs() > 1e-9 {
                assert_eq!(bx.contains(p), m <= 1.0, "box at {p:?}");
            }
            // Cone: apex at z = +rz, base radius rx at z = -rz.
            let t = (rz - q[2]) / (2.0 * rz);
            let rad = (q[0] * q[0] + q[1] * q[1]).sqrt();
            let margin = (rad - rx * t).abs().min((q[2].abs() - rz).abs());
            if margin > 1e-9 {
                assert_eq!(
                    cone.contains(p),
                    q[2].abs() <= rz && rad <= rx * t,
                    "cone at {p:?}"
                );
            }
        }
    }
}

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

/// Harakal & Chmúrny Fig. 4a: the cone of dimensions 330, 400, 444 with β = 20, at
/// depth 6 in a space of 1000 units. Its voxel count follows the analytic volume.
#[test]
fn paper_fig4a_cone() {
    let src = "depth 6\nbounds [0, 0, 0] [1000, 1000, 1000]\n\
               cone(r1 = [165, 200], h = 444) rotate [0, 20, 0] at [500, 500, 500]\n";
    let scene = Scene::parse(src, "fig4a.tss".as_ref()).unwrap();
    let tree = scene.build().unwrap();
    tree.assert_valid();
    let csg = scene.csg().unwrap();
    check_exact(&csg, 6, [0, 0, 0], "fig 4a cone");
    let volume = std::f64::consts::PI * 165.0 * 200.0 * 444.0 / 3.0;
    let voxel = 1000.0f64 / 64.0;
    let expect = volume / voxel.powi(3);
    let got = tree.voxel_count() as f64;
    assert!(
        (got - expect).abs() / expect < 0.05,
        "{got} voxels, expected about {expect}"
    );
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

// ---------------------------------------------------------------- scenes

fn parse(src: &str) -> Result<Scene, SceneError> {
    Scene::parse(src, "t.tss".as_ref())
}

#[test]
fn scene_with_every_construct_builds_as_the_api_does() {
    let src = r##"
# every construct
depth 5
bounds [0, 0, 0] [32, 32, 32]
let r = 6          # a named parameter
let c = [16, 16, 16]
difference {
  box(size = 20)
  sphere(r = r + 1) at c - [16, 16, 16]
} at c colour "steel"
union {
  cylinder(r = [2, 3], h = 10) rotate [90, 0, 0]
  cone(r1 = 3, r2 = 1, h = 6) at [0, 0, 8]
} scale 0.5 rotate [0, 0, 45] at [8, 8, 8] colour [255, 0, 0]
intersection { torus(major = 5, minor = 2) halfspace(normal = [0, 0, 1], offset = 0.5) } at [24, 24, 24]
not { capsule(r = 100, h = 1) } colour "#00ff00"
polyhedron(planes = [[1,0,0,2],[-1,0,0,2],[0,1,0,2],[0,-1,0,2],[0,0,1,2],[0,0,-1,2]]) at [4, 28, 4]
ellipsoid(r = [4, 2, 3]) at [28, 4, 28]
prism(size = [2, 3, 4]) at [28, 28, 4]
spheroid(r = 3) at [4, 4, 28]
"##;
    let scene = parse(src).unwrap();
    assert_eq!((scene.depth, scene.objects), (5, 8));
    assert_eq!(scene.voxel, 1.0);
    let csg = scene.csg().unwrap();
    let tree = check_exact(&csg, 5, [0, 0, 0], "every construct");
    // The first object by the API.
    let api = Solid::shape(Shape::cuboid([20.0; 3]))
        .difference([Solid::shape(Shape::sphere(7.0))])
        .at([16.0; 3])
        .compile()
        .unwrap();
    assert!(tree.contains([16, 16, 6]) == api.contains([16.5, 16.5, 6.5]));
    assert!(!tree.contains([16, 16, 16]));
    assert_eq!(csg.colour_at([7.0, 16.0, 16.0]), Colour::parse("steel"));
}

#[test]
fn scene_space_from_voxel_size_and_bounding_box() {
    let s = parse("voxel 0.5\nsphere(r = 4) at [10, 0, 0]").unwrap();
    assert_eq!(s.depth, 4);
    assert_eq!(s.bounds_min, [6.0, -4.0, -4.0]);
    let t = s.build().unwrap();
    assert!(t.contains([8, 8, 8]));
    let s = parse("depth 3\nbox(size = [8, 4, 2])").unwrap();
    assert_eq!(s.voxel, 1.0);
}

/// Every error path of the parser: (source, line, column, words in the message,
/// words in the hint).
#[test]
fn every_scene_error_is_located_with_a_hint() {
    let cases: &[(&str, usize, usize, &str, &str)] = &[
        (
            "depth 6\ncilinder(r = 1, h = 2)",
            2,
            1,
            "unknown shape or keyword `cilinder`",
            "did you mean `cylinder`",
        ),
        (
            "depth 6\nsphere(radius = 1)",
            2,
            8,
            "has no parameter `radius`",
            "sphere` takes: r",
        ),
        (
            "depth 6\ncylinder(r = 1, hh = 2)",
            2,
            17,
            "no parameter `hh`",
            "did you mean `h`",
        ),
        (
            "depth 6\nsphere()",
            2,
            8,
            "needs the parameter `r`",
            "sphere(r = 10)",
        ),
        (
            "depth 6\nsphere(r = 1, r = 2)",
            2,
            15,
            "given twice",
            "keep one",
        ),
        (
            "depth 6\nsphere(r = -1)",
            2,
            12,
            "must be positive",
            "greater than zero",
        ),
        (
            "depth 6\nsphere(r = [1, 2])",
            2,
            12,
            "must be a number, not a list",
            "brackets",
        ),
        (
            "depth 6\nbox(size = [1, 2])",
            2,
            12,
            "must hold 3 numbers, got 2",
            "[x, y, z]",
        ),
        (
            "depth 6\nsphere(r = 1) at 5",
            2,
            18,
            "must be a list of 3 numbers",
            "[x, y, z]",
        ),
        (
            "depth 6\nsphere(r = 1) at [1, 2, 3] at [1, 2, 3]",
            2,
            28,
            "`at` is given twice",
            "union",
        ),
        (
            "depth 6\nsphere(r = 1) colour \"rde\"",
            2,
            22,
            "unknown colour \"rde\"",
            "did you mean \"red\"",
        ),
        (
            "depth 6\nsphere(r = 1) colour \"#12\"",
            2,
            22,
            "unknown colour",
            "six hex digits",
        ),
        (
            "depth 6\nsphere(r = 1) colour [300, 0, 0]",
            2,
            22,
            "0..=255",
            "[r, g, b]",
        ),
        (
            "depth 6\nsphere(r = 1) scale 0",
            2,
            21,
            "scale must be positive",
            "doubles",
        ),
        (
            "depth 6\nlet radius = 2\nsphere(r = radias)",
            3,
            12,
            "unknown name `radias`",
            "did you mean `radius`",
        ),
        (
            "depth 6\nsphere(r = q)",
            2,
            12,
            "unknown name `q`",
            "let q =",
        ),
        (
            "depth 6\nlet a = 1\nlet a = 2\nsphere(r = a)",
            3,
            5,
            "already defined",
            "line 2",
        ),
        (
            "depth 6\nlet sphere = 1",
            2,
            5,
            "reserved word",
            "another name",
        ),
        (
            "depth 6\nlet 5 = 1",
            2,
            5,
            "expected a name after `let`",
            "let name = value",
        ),
        ("depth 6\nlet a 1", 2, 7, "expected `=`", "let name = value"),
        ("depth 6\nsphere(r = 1 / 0)", 2, 14, "division by zero", ""),
        (
            "depth 6\nsphere(r = [1] * [2])",
            2,
            16,
            "cannot combine",
            "lists of equal length",
        ),
        (
            "depth 6\nsphere(r = \"one\")",
            2,
            12,
            "string is not allowed",
            "colours",
        ),
        (
            "depth 6\nsphere(r = ,)",
            2,
            12,
            "expected a value",
            "a value is a number",
        ),
        (
            "depth 6\nsphere(r = (1)",
            2,
            15,
            "expected `,`",
            "separate parameters",
        ),
        (
            "depth 6\nsphere(r = (1 2))",
            2,
            15,
            "expected `)`",
            "close the parenthesis",
        ),
        (
            "depth 6\nbox(size = [1, 2 3])",
            2,
            18,
            "expected `,`",
            "separate list items",
        ),
        (
            "depth 6\nsphere r = 1",
            2,
            8,
            "expected `(`",
            "sphere(name = value",
        ),
        (
            "depth 6\nsphere(5)",
            2,
            8,
            "expected a parameter name",
            "takes: r",
        ),
        (
            "depth 6\nunion sphere(r = 1)",
            2,
            7,
            "expected `{`",
            "union { ... }",
        ),
        (
            "depth 6\nunion { sphere(r = 1)",
            2,
            22,
            "not closed",
            "line 2",
        ),
        (
            "depth 6\nunion { }",
            2,
            1,
            "group is empty",
            "at least one solid",
        ),
        (
            "depth 6\nnot { sphere(r = 1) sphere(r = 2) }",
            2,
            1,
            "exactly one solid",
            "union",
        ),
        (
            "depth 6\nunion { depth 5 sphere(r = 1) }",
            2,
            9,
            "only allowed at the top level",
            "move it",
        ),
        ("depth 6\nrotate [1, 2, 3]", 2, 1, "must follow a solid", ""),
        (
            "depth 6\n42",
            2,
            1,
            "expected a shape, a group or a setting",
            "statement starts",
        ),
        (
            "depth 6\nsphere(r = 1) @",
            2,
            15,
            "unexpected character `@`",
            "comments start with `#`",
        ),
        (
            "depth 6\nsphere(r = 1) colour \"red",
            2,
            22,
            "unterminated string",
            "close the string",
        ),
        (
            "depth 6\nsphere(r = 1.2.3)",
            2,
            12,
            "is not a number",
            "one decimal point",
        ),
        (
            "depth 6\nsphere(r = 10mm)",
            2,
            12,
            "`10mm` is not a number",
            "units",
        ),
        (
            "depth 0\nsphere(r = 1)",
            1,
            7,
            "whole number from 1 to 16",
            "2^D voxels",
        ),
        ("depth 6.5\nsphere(r = 1)", 1, 7, "whole number", "2^D"),
        (
            "depth 6\ndepth 7\nsphere(r = 1)",
            2,
            1,
            "`depth` is set twice",
            "line 1",
        ),
        (
            "voxel -1\nsphere(r = 1)",
            1,
            7,
            "voxel size must be positive",
            "half a unit",
        ),
        (
            "voxel 0.5\nvoxel 1\nsphere(r = 1)",
            2,
            1,
            "`voxel` is set twice",
            "line 1",
        ),
        (
            "voxel 0.000001\nsphere(r = 1000)",
            1,
            1,
            "more than the limit",
            "larger voxel",
        ),
        (
            "depth 6\nbounds [0, 0, 0] [1, -1, 1]\nsphere(r = 1)",
            2,
            18,
            "must exceed the lower",
            "bounds [xmin",
        ),
        (
            "depth 6\nbounds [0, 0, 0] [1, 1, 1]\nbounds [0, 0, 0] [1, 1, 1]\nsphere(r = 1)",
            3,
            1,
            "`bounds` is set twice",
            "line 2",
        ),
        (
            "depth 6\nvoxel 1\nsphere(r = 1)",
            1,
            1,
            "both `depth` and `voxel`",
            "keep one",
        ),
        (
            "sphere(r = 1)",
            1,
            1,
            "neither `depth` nor `voxel`",
            "depth 8",
        ),
        ("depth 6\n# nothing", 2, 10, "no solid", "sphere(r = 10)"),
        (
            "depth 6\nhalfspace(normal = [0, 0, 1])",
            2,
            1,
            "unbounded",
            "add `bounds",
        ),
        (
            "depth 6\nhalfspace(normal = [0, 0, 0])",
            2,
            20,
            "normal must not be zero",
            "normal = [0, 0, 1]",
        ),
        (
            "depth 6\npolyhedron(planes = 3)",
            2,
            21,
            "must be a list of [nx, ny, nz, d]",
            "planes = [[",
        ),
        (
            "depth 6\npolyhedron(planes = [])",
            2,
            21,
            "`planes` is empty",
            "four planes",
        ),
        (
            "depth 6\npolyhedron(planes = [[0, 0, 0, 1]])",
            2,
            21,
            "zero normal",
            "n·p ≤ d",
        ),
        (
            "depth 6\npolyhedron(planes = [[1, 2, 3]])",
            2,
            21,
            "must hold 4 numbers",
            "[nx, ny, nz, d]",
        ),
        (
            "depth 6\ncone(r1 = 1, r2 = -1, h = 2)",
            2,
            19,
            "`r2` must be zero or positive",
            "pointed cone",
        ),
        (
            "depth 6\ncone(r1 = [1, 2], r2 = 0, h = 2)\ncapsule(r = 1, h = -2)",
            3,
            20,
            "`h` must be zero or positive",
            "end caps",
        ),
        (
            "depth 6\nsphere(r = 1) at [1, 2, 3] + [1, 2]",
            2,
            28,
            "cannot combine",
            "equal length",
        ),
    ];
    for (i, (src, line, col, msg, hint)) in cases.iter().enumerate() {
        let err = match parse(src) {
            Ok(_) => panic!("case {i} parsed: {src:?}"),
            Err(e) => e,
        };
        let d = err
            .diagnostic()
            .unwrap_or_else(|| panic!("case {i}: not a parse error: {err}"));
        assert_eq!((d.line, d.column), (*line, *col), "case {i} {src:?}: {err}");
        assert!(d.message.contains(msg), "case {i}: message {:?}", d.message);
        let h = d.hint.clone().unwrap_or_default();
        assert!(h.contains(hint), "case {i}: hint {h:?}");
        let shown = err.to_string();
        assert!(
            shown.starts_with(&format!("t.tss:{line}:{col}: ")),
            "{shown}"
        );
        assert!(shown.contains('^'), "case {i} has a caret: {shown}");
    }
}

#[test]
fn caret_sits_under_the_fault() {
    let err = parse("depth 6\n  sphere(r = 1) colour \"rde\"\n").unwrap_err();
    let text = err.to_string();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "t.tss:2:24: unknown colour \"rde\"");
    assert_eq!(lines[2], "2 |   sphere(r = 1) colour \"rde\"");
    assert_eq!(lines[3], "  |                        ^^^^^");
    assert_eq!(lines[4], "  = hint: did you mean \"red\"?");
}

#[test]
fn hostile_scenes_are_refused() {
    let deep = format!(
        "depth 6\n{}sphere(r = 1){}",
        "union { ".repeat(100),
        " }".repeat(100)
    );
    let e = parse(&deep).unwrap_err();
    assert!(e.to_string().contains("nesting deeper"), "{e}");
    let brackets = format!(
        "depth 6\nlet a = {}1{}\nsphere(r = 1)",
        "(".repeat(100),
        ")".repeat(100)
    );
    assert!(parse(&brackets)
        .unwrap_err()
        .to_string()
        .contains("nesting deeper"));
    let many = format!(
        "depth 6\n{}",
        "sphere(r = 1)\n".repeat(MAX_PRIMITIVES_TEST + 1)
    );
    assert!(parse(&many).unwrap_err().to_string().contains("primitives"));
    let long = format!("depth 6\nlet a = [{}]\nsphere(r = 1)", "1, ".repeat(5000));
    assert!(parse(&long).unwrap_err().to_string().contains("4096"));
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("bad.tss");
    std::fs::write(&p, b"depth 6\nsphere(r = 1) \xff\n").unwrap();
    let e = Scene::read(&p).unwrap_err();
    assert!(
        e.to_string().contains(":2:15: the file is not valid UTF-8"),
        "{e}"
    );
    assert!(matches!(
        Scene::read(&dir.path().join("missing.tss")),
        Err(SceneError::Io { .. })
    ));
}

const MAX_PRIMITIVES_TEST: usize = scene::MAX_PRIMITIVES;

#[test]
fn closest_names() {
    assert_eq!(
        scene::closest("spere", scene::SHAPES.iter().copied()),
        Some("sphere")
    );
    assert_eq!(scene::closest("xyzzy", scene::SHAPES.iter().copied()), None);
    assert_eq!(
        scene::closest("Box", scene::SHAPES.iter().copied()),
        Some("box")
    );
}

/// Seeded mutations of the shipped scenes: the parser answers every one with a scene
/// or a located error, never a panic, and the location lies inside the text.
#[test]
fn mutated_scenes_never_panic() {
    let sources = [
        include_str!("../../../../scenes/tank.tss"),
        include_str!("../../../../scenes/truck.tss"),
        include_str!("../../../../scenes/aircraft.tss"),
        include_str!("../../../../scenes/showcase.tss"),
        include_str!("../../../../scenes/fig4a-cone.tss"),
    ];
    let alphabet: Vec<char> = "()[]{},=+-*/#\"\n 0123456789.eE_abcxyzrh-éλ\u{0}"
        .chars()
        .collect();
    let seed = 0xf022_u64;
    println!("seed {seed:#x}");
    let mut rng = Rng(seed);
    for round in 0..600 {
        let src = sources[round % sources.len()];
        let mut chars: Vec<char> = src.chars().collect();
        for _ in 0..1 + rng.next() % 4 {
            let i = (rng.next() % (chars.len() as u64 + 1)) as usize;
            let c = alphabet[(rng.next() % alphabet.len() as u64) as usize];
            match rng.next() % 3 {
                0 if i < chars.len() => {
                    chars.remove(i);
                }
                1 if i < chars.len() => chars[i] = c,
                _ => chars.insert(i, c),
            }
        }
        let text: String = chars.into_iter().collect();
        match Scene::parse(&text, "m.tss".as_ref()) {
            Ok(scene) => {
                // Small enough ones also build.
                if scene.depth <= 7 {
                    let _ = scene.build();
                }
            }
            Err(e) => {
                let d = e.diagnostic().expect("a parse error");
                let lines: Vec<&str> = text.split('\n').collect();
                assert!(
                    d.line >= 1 && d.line <= lines.len(),
                    "round {round}: line {}",
                    d.line
                );
                let _ = e.to_string();
            }
        }
    }
}
