//! The CSG builder against a dense per-voxel evaluation, voxel for voxel.
//!
//! The shared generators and the dense model are here; the tests are in one file per
//! topic: `primitives.rs` (each shape), `build.rs` (composite solids, cost, limits,
//! colours), `scenes.rs` (the scene format), `scene_errors.rs` (every located
//! parser error).

mod build;
mod primitives;
mod scene_errors;
mod scenes;

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

fn parse(src: &str) -> Result<Scene, SceneError> {
    Scene::parse(src, "t.tss".as_ref())
}
