//! The traversal against brute force over every block, and images against analytic
//! silhouettes.

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

fn coverage(tree: &LinearOctree, opts: &RenderOptions) -> (f64, f64) {
    let rt = RayTree::new(tree);
    let hits = primary_hits(&rt, opts) as f64;
    let frame = Frame::new(&rt, opts);
    let pixel_area =
        (2.0 * frame.half_w / opts.width as f64) * (2.0 * frame.half_h / opts.height as f64);
    (hits, pixel_area)
}

#[test]
fn sphere_silhouette_matches_the_disc() {
    let r = 60.0;
    let tree = Solid::shape(Shape::sphere(r))
        .at([64.0, 64.0, 64.0])
        .compile()
        .unwrap()
        .build(7, [0, 0, 0])
        .unwrap();
    for view in [View::Front, View::Top, View::Side] {
        let opts = RenderOptions {
            width: 480,
            height: 400,
            camera: Camera::view(view),
            ..Default::default()
        };
        let (hits, px) = coverage(&tree, &opts);
        let want = std::f64::consts::PI * r * r / px;
        let err = (hits - want).abs() / want;
        assert!(
            err < 0.005,
            "{view:?}: {hits} pixels, disc {want:.0}, error {err:.4}"
        );
    }
}

#[test]
fn box_silhouette_matches_its_projection() {
    let (lo, size) = ([20i64, 30, 10], [20.0, 40.0, 80.0]);
    let tree = LinearOctree::from_voxels(
        7,
        [0, 0, 0],
        (0..20).flat_map(|x| {
            (0..40).flat_map(move |y| (0..80).map(move |z| [lo[0] + x, lo[1] + y, lo[2] + z]))
        }),
    )
    .unwrap();
    for (view, az, el) in [
        (Some(View::Iso), 0.0, 0.0),
        (Some(View::Front), 0.0, 0.0),
        (None, 30.0, 20.0),
        (None, 200.0, -50.0),
    ] {
        let mut camera = view.map_or(
            Camera {
                azimuth_deg: az,
                elevation_deg: el,
                zoom: 1.0,
                projection: Projection::Orthographic,
            },
            Camera::view,
        );
        if view.is_some() {
            camera.zoom = 1.0;
        }
        let opts = RenderOptions {
            width: 500,
            height: 500,
            camera,
            ..Default::default()
        };
        let (a, e) = (
            camera.azimuth_deg.to_radians(),
            camera.elevation_deg.to_radians(),
        );
        let u = [e.cos() * a.cos(), e.cos() * a.sin(), e.sin()];
        let area = u[0].abs() * size[1] * size[2]
            + u[1].abs() * size[0] * size[2]
            + u[2].abs() * size[0] * size[1];
        let (hits, px) = coverage(&tree, &opts);
        let want = area / px;
        let err = (hits - want).abs() / want;
        assert!(
            err < 0.005,
            "{view:?} {az} {el}: {hits} pixels, projection {want:.0}, error {err:.4}"
        );
    }
}

#[test]
fn perspective_sphere_silhouette() {
    let r = 60.0;
    let tree = Solid::shape(Shape::sphere(r))
        .at([64.0, 64.0, 64.0])
        .compile()
        .unwrap()
        .build(7, [0, 0, 0])
        .unwrap();
    let opts = RenderOptions {
        width: 400,
        height: 400,
        camera: Camera {
            projection: Projection::Perspective { fov_deg: 40.0 },
            ..Camera::view(View::Front)
        },
        ..Default::default()
    };
    let rt = RayTree::new(&tree);
    let hits = primary_hits(&rt, &opts) as f64;
    let frame = Frame::new(&rt, &opts);
    let dist = dot(
        add(frame.eye, scale([64.0, 64.0, 64.0], -1.0)),
        add(frame.eye, scale([64.0, 64.0, 64.0], -1.0)),
    )
    .sqrt();
    // The silhouette is the disc of angular radius asin(r / dist), centred on the
    // image; on the image plane at distance 1 its radius is tan of that.
    let rad = (r / dist).asin().tan();
    let px = 2.0 * frame.half_h / opts.height as f64;
    let want = std::f64::consts::PI * rad * rad / (px * px);
    let err = (hits - want).abs() / want;
    // The voxel staircase shows its side walls to diverging rays: a little larger.
    assert!(err < 0.03, "{hits} pixels, cone {want:.0}, error {err:.4}");
}

/// The perspective silhouette of a box (exactly voxelized) against the convex hull of
/// its projected corners.
#[test]
fn perspective_box_silhouette_matches_projected_hull() {
    let (lo, size) = ([20i64, 30, 10], [30i64, 40, 70]);
    let tree = LinearOctree::from_voxels(
        7,
        [0, 0, 0],
        (0..size[0]).flat_map(|x| {
            (0..size[1])
                .flat_map(move |y| (0..size[2]).map(move |z| [lo[0] + x, lo[1] + y, lo[2] + z]))
        }),
    )
    .unwrap();
    for (az, el, fov) in [
        (-45.0, 35.0, 40.0),
        (20.0, 10.0, 60.0),
        (-120.0, 60.0, 30.0),
    ] {
        let opts = RenderOptions {
            width: 400,
            height: 300,
            camera: Camera {
                azimuth_deg: az,
                elevation_deg: el,
                zoom: 1.0,
                projection: Projection::Perspective { fov_deg: fov },
            },
            ..Default::default()
        };
        let rt = RayTree::new(&tree);
        let hits = primary_hits(&rt, &opts) as f64;
        let f = Frame::new(&rt, &opts);
        let mut pts: Vec<(f64, f64)> = (0..8)
            .map(|c| {
                let q =
                    [0, 1, 2].map(|a| (lo[a] + if c & (1 << a) != 0 { size[a] } else { 0 }) as f64);
                let v = add(q, scale(f.eye, -1.0));
                let z = dot(v, f.forward);
                (dot(v, f.right) / z, dot(v, f.up) / z)
            })
            .collect();
        pts.sort_by(|a, b| a.partial_cmp(b).unwrap());
        let cross2 = |o: (f64, f64), a: (f64, f64), b: (f64, f64)| {
            (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
        };
        let mut hull: Vec<(f64, f64)> = Vec::new();
        for pass in 0..2 {
            let start = hull.len();
            let it: Vec<_> = if pass == 0 {
                pts.clone()
            } else {
                pts.iter().rev().copied().collect()
            };
            for p in it {
                while hull.len() >= start + 2
                    && cross2(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
                {
                    hull.pop();
                }
                hull.push(p);
            }
            hull.pop();
        }
        let area: f64 = (0..hull.len())
            .map(|i| {
                let (a, b) = (hull[i], hull[(i + 1) % hull.len()]);
                a.0 * b.1 - a.1 * b.0
            })
            .sum::<f64>()
            .abs()
            / 2.0;
        let px = (2.0 * f.half_w / opts.width as f64) * (2.0 * f.half_h / opts.height as f64);
        let want = area / px;
        let err = (hits - want).abs() / want;
        assert!(
            err < 0.005,
            "az {az} el {el} fov {fov}: {hits} pixels, hull {want:.0}, error {err:.4}"
        );
    }
}

#[test]
fn images_modes_and_png() {
    let csg = Solid::union([
        Solid::shape(Shape::cuboid([20.0, 20.0, 20.0])).at([16.0, 16.0, 12.0]),
        Solid::shape(Shape::sphere(8.0)).at([16.0, 16.0, 26.0]),
    ])
    .compile()
    .unwrap();
    let tree = csg.build(5, [0, 0, 0]).unwrap();
    let red = |_: [f64; 3]| [200u8, 30, 30];
    let base = RenderOptions {
        width: 96,
        height: 64,
        ..Default::default()
    };
    let plain = render(
        &tree,
        Surface {
            colour: Some(&red),
            normal: None,
        },
        &base,
    );
    // The centre pixel shows the solid in a shade of red.
    let c = plain.get(48, 32);
    assert!(c[0] > c[1] && c[0] > c[2], "{c:?}");
    let outlined = render(
        &tree,
        Surface {
            colour: Some(&red),
            normal: None,
        },
        &RenderOptions {
            outline: true,
            ..base.clone()
        },
    );
    let dark = |img: &Image| {
        img.pixels
            .iter()
            .filter(|p| p.iter().all(|&v| v < 60))
            .count()
    };
    assert!(
        dark(&outlined) > dark(&plain) + 50,
        "outlines draw dark lines"
    );
    let ao = render(
        &tree,
        Surface {
            colour: Some(&red),
            normal: None,
        },
        &RenderOptions {
            ao_samples: 8,
            ..base.clone()
        },
    );
    assert!(ao != plain, "occlusion darkens");
    // A cut through the middle shows hatched cut faces.
    let cut = render(
        &tree,
        Surface {
            colour: Some(&red),
            normal: None,
        },
        &RenderOptions {
            clip: Some(Clip {
                axis: 1,
                at: 16.0,
                keep_above: true,
            }),
            camera: Camera::view(View::Front),
            ..base.clone()
        },
    );
    let front = render(
        &tree,
        Surface {
            colour: Some(&red),
            normal: None,
        },
        &RenderOptions {
            camera: Camera::view(View::Front),
            ..base.clone()
        },
    );
    assert!(cut != front, "the cut face shows");
    // Clipping everything away leaves no solid.
    let none = RenderOptions {
        clip: Some(Clip {
            axis: 2,
            at: -1.0,
            keep_above: false,
        }),
        shadows: false,
        ..base.clone()
    };
    let kept = crop_to_clip(&tree, none.clip.unwrap());
    assert_eq!(primary_hits(&RayTree::new(&kept), &none), 0);
    let persp = render(
        &tree,
        Surface::default(),
        &RenderOptions {
            camera: Camera {
                projection: Projection::Perspective { fov_deg: 35.0 },
                ..Camera::default()
            },
            ..base.clone()
        },
    );
    assert!(persp != render(&tree, Surface::default(), &base));
    // Contact sheet: four views with gutters.
    let sheet = contact_sheet(&tree, Surface::default(), &base, &View::ALL, 2);
    assert_eq!((sheet.width, sheet.height), (2 * 96 + 12, 2 * 64 + 12));
    // PNG round trip.
    let mut bytes = Vec::new();
    plain.encode_png(&mut bytes).unwrap();
    let dec = png::Decoder::new(std::io::Cursor::new(bytes));
    let mut reader = dec.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), (96, 64));
    assert_eq!(&buf[..3], &plain.pixels[0]);
    let dir = tempfile::tempdir().unwrap();
    plain.write_png(&dir.path().join("a.png")).unwrap();
    assert!(dir.path().join("a.png").exists());
}

#[test]
fn section_shows_the_layer_and_its_blocks() {
    let tree = Solid::shape(Shape::cuboid([8.0, 8.0, 8.0]))
        .at([8.0, 8.0, 8.0])
        .compile()
        .unwrap()
        .build(4, [0, 0, 0])
        .unwrap();
    let img = section(&tree, Surface::default(), 2, 8, 3);
    assert_eq!((img.width, img.height), (48, 48));
    let filled = img.pixels.iter().filter(|&&p| p == DEFAULT_COLOUR).count();
    let lines = img.pixels.iter().filter(|&&p| p == [60, 60, 70]).count();
    // 64 voxels of 9 pixels each, less the outline pixels drawn over them.
    assert_eq!(filled + lines, 64 * 9);
    assert!(lines > 0);
    let empty = section(&tree, Surface::default(), 2, 15, 1);
    assert!(empty.pixels.iter().all(|&p| p == [255, 255, 255]));
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
