//! Every primitive against the dense model and independent formulas.

use super::*;

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
