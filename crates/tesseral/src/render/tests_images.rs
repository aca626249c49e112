//! Images against analytic silhouettes (orthographic and perspective), the
//! drawing modes, PNG output and slices.

use super::*;
use crate::csg::{Shape, Solid};

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
