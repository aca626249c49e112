//! The traversal against brute force over every block (rays, point queries,
//! beams). The images against analytic silhouettes are in `tests_images.rs`.

use super::*;
use crate::csg::tests::Rng;
use crate::csg::{Shape, Solid};

fn random_tree(rng: &mut Rng, depth: u8, origin: [i64; 3]) -> LinearOctree {
    let side = f64::from(1u32 << depth);
    let o = origin.map(|v| v as f64);
    let parts: Vec<Solid> = (0..1 + rng.next() % 4)
        .map(|_| {
            let s = match rng.next() % 3 {
                0 => Shape::sphere(rng.range(0.1, 0.3) * side),
                1 => Shape::cuboid([
                    rng.range(0.1, 0.5) * side,
                    rng.range(0.1, 0.5) * side,
                    rng.range(0.1, 0.5) * side,
                ]),
                _ => Shape::Torus {
                    major: 0.25 * side,
                    minor: 0.08 * side,
                },
            };
            Solid::shape(s)
                .rotate([rng.range(0.0, 90.0), rng.range(0.0, 90.0), 0.0])
                .at([
                    o[0] + rng.range(0.2, 0.8) * side,
                    o[1] + rng.range(0.2, 0.8) * side,
                    o[2] + rng.range(0.2, 0.8) * side,
                ])
        })
        .collect();
    Solid::union(parts)
        .compile()
        .unwrap()
        .build(depth, origin)
        .unwrap()
}

/// The first block along the ray in `[tmin, tmax]`, over every block: slab tests.
fn brute(tree: &LinearOctree, ray: &Ray, tmin: f64, tmax: f64) -> Option<f64> {
    let mut best: Option<f64> = None;
    for b in tree.blocks() {
        let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
        for a in 0..3 {
            let lo = b.min[a] as f64;
            let hi = lo + b.size() as f64;
            if ray.dir[a] == 0.0 {
                if ray.origin[a] < lo || ray.origin[a] > hi {
                    t0 = f64::INFINITY;
                }
                continue;
            }
            let (mut e, mut x) = (
                (lo - ray.origin[a]) / ray.dir[a],
                (hi - ray.origin[a]) / ray.dir[a],
            );
            if e > x {
                std::mem::swap(&mut e, &mut x);
            }
            t0 = t0.max(e);
            t1 = t1.min(x);
        }
        if t0 <= t1 && t1 >= tmin && t0 <= tmax {
            let t = t0.max(tmin);
            best = Some(best.map_or(t, |b: f64| b.min(t)));
        }
    }
    best
}

#[test]
fn traversal_equals_brute_force_over_blocks() {
    let seed = 0x7ace_u64;
    println!("seed {seed:#x}");
    let mut rng = Rng(seed);
    for trial in 0..12 {
        let origin = if trial % 2 == 0 {
            [0, 0, 0]
        } else {
            [-9, 4, -30]
        };
        let depth = 5;
        let tree = random_tree(&mut rng, depth, origin);
        let rt = RayTree::new(&tree);
        let side = 32.0;
        let c = origin.map(|v| v as f64 + side / 2.0);
        for i in 0..1500 {
            let from = [
                c[0] + rng.range(-40.0, 40.0),
                c[1] + rng.range(-40.0, 40.0),
                c[2] + rng.range(-40.0, 40.0),
            ];
            let mut dir = [
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            ];
            // Some rays along axes, and some with a zero component.
            if i % 7 == 0 {
                dir = [0.0, 0.0, 0.0];
                dir[i % 3] = if i % 2 == 0 { 1.0 } else { -1.0 };
            } else if i % 5 == 0 {
                dir[i % 3] = 0.0;
            }
            // Off the integer lattice, so that no ray grazes a block edge exactly.
            let from = from.map(|v| v.floor() + 0.371);
            let ray = Ray::new(from, dir);
            let (tmin, tmax) = if i % 3 == 0 {
                (rng.range(0.0, 20.0), rng.range(20.0, 80.0))
            } else {
                (0.0, f64::INFINITY)
            };
            let want = brute(&tree, &ray, tmin, tmax);
            let got = rt.cast(&ray, tmin, tmax);
            match (want, got) {
                (None, None) => {}
                (Some(w), Some(h)) => {
                    assert!(
                        (w - h.t).abs() < 1e-6 * (1.0 + w.abs()),
                        "seed {seed:#x} trial {trial} ray {i}: t {} vs brute {w}",
                        h.t
                    );
                    // The hit point lies in the block reported.
                    let p = ray.at(h.t);
                    let s = (1i64 << h.size_log2) as f64;
                    for (&pa, &b) in p.iter().zip(&h.block_min) {
                        let lo = b as f64;
                        assert!(
                            pa >= lo - 1e-6 && pa <= lo + s + 1e-6,
                            "trial {trial} ray {i}"
                        );
                    }
                    let blk = crate::linear::Block {
                        min: h.block_min,
                        size_log2: h.size_log2,
                    };
                    assert!(tree.blocks().any(|b| b == blk), "the block hit is a leaf");
                }
                (w, g) => panic!(
                    "seed {seed:#x} trial {trial} ray {i}: {ray:?} brute {w:?}, traversal {g:?}"
                ),
            }
        }
    }
}

#[test]
fn ray_tree_contains_equals_the_linear_octree() {
    let mut rng = Rng(99);
    for _ in 0..4 {
        let tree = random_tree(&mut rng, 5, [3, -2, 0]);
        let rt = RayTree::new(&tree);
        assert!(rt.same_tree(&RayTree::new_by_partition(&tree)));
        for x in -1..34 {
            for y in -3..32 {
                for z in -1..33 {
                    assert_eq!(
                        rt.contains([x, y, z]),
                        tree.contains([x, y, z]),
                        "{x} {y} {z}"
                    );
                }
            }
        }
    }
    // The one-pass index against the top-down one, on many shapes and depths.
    for depth in 1..7u8 {
        for seed in 1..6u64 {
            let mut r = Rng(seed * 7919 + u64::from(depth));
            let side = 1i64 << depth;
            let voxels: Vec<[i64; 3]> = (0..(r.next() % 300))
                .map(|_| [0, 1, 2].map(|_| (r.next() % side as u64) as i64))
                .collect();
            let tree = LinearOctree::from_voxels(depth, [0, 0, 0], voxels).unwrap();
            let (a, b) = (RayTree::new(&tree), RayTree::new_by_partition(&tree));
            assert!(a.same_tree(&b), "depth {depth} seed {seed}");
            assert_eq!(a.gray_nodes(), b.gray_nodes());
        }
    }
    let full = LinearOctree::full(3, [0, 0, 0]).unwrap();
    let rt = RayTree::new(&full);
    assert!(rt.contains([7, 7, 7]) && !rt.contains([8, 0, 0]));
    assert_eq!(rt.gray_nodes(), 0);
    let hit = rt
        .cast(&Ray::new([-1.0, 4.5, 4.5], [1.0, 0.0, 0.0]), 0.0, 9.0)
        .unwrap();
    assert!((hit.t - 1.0).abs() < 1e-12 && hit.size_log2 == 3);
    let empty = LinearOctree::empty(3, [0, 0, 0]).unwrap();
    assert!(RayTree::new(&empty)
        .cast(&Ray::new([-1.0, 4.5, 4.5], [1.0, 0.0, 0.0]), 0.0, 9.0)
        .is_none());
}

/// The beams only skip space: every primary ray hits what a ray cast alone hits.
#[test]
fn beams_change_no_hit() {
    let seed = 0xbea4_u64;
    println!("seed {seed:#x}");
    let mut rng = Rng(seed);
    for trial in 0..8 {
        let tree = random_tree(&mut rng, 6, [0, 0, 0]);
        let rt = RayTree::new(&tree);
        let camera = Camera {
            azimuth_deg: rng.range(-180.0, 180.0),
            elevation_deg: rng.range(-80.0, 80.0),
            zoom: rng.range(0.8, 2.5),
            projection: if trial % 2 == 0 {
                Projection::Orthographic
            } else {
                Projection::Perspective {
                    fov_deg: rng.range(20.0, 70.0),
                }
            },
        };
        let opts = RenderOptions {
            width: 90,
            height: 70,
            camera,
            ..Default::default()
        };
        let frame = Frame::new(&rt, &opts);
        let mut stack = TraversalStack::default();
        let mut checked = 0;
        trace_block(
            &rt,
            &frame,
            &opts,
            [0, 90],
            [0, 70],
            &mut stack,
            |x, y, ray, hit| {
                let alone = rt.cast(ray, 0.0, f64::INFINITY);
                match (hit, alone) {
                    (None, None) => {}
                    (Some(a), Some(b)) => assert!(
                        (a.t - b.t).abs() < 1e-6 * (1.0 + b.t.abs()) && a.at_start == b.at_start,
                        "seed {seed:#x} trial {trial} pixel {x},{y}: {a:?} vs {b:?}"
                    ),
                    (a, b) => panic!(
                        "seed {seed:#x} trial {trial} pixel {x},{y}: beam {a:?}, alone {b:?}"
                    ),
                }
                checked += 1;
            },
        );
        assert_eq!(checked, 90 * 70);
    }
}
