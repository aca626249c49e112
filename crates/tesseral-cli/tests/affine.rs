//! Runs the real binary: `scale --by KX,KY,KZ`, `rotate --degrees` and `transform`
//! (issue 16 §2, §3), checked against the library's model operations.

mod common;

use common::{fails, json, ok};
use tesseral::io::{read_model, write_model};
use tesseral::linear::{rotation_matrix, scale_space, LinearOctree};
use tesseral::model::{Frame, Model};

fn ball(dir: &std::path::Path) -> Model {
    let voxels = (-6i64..6).flat_map(|x| {
        (-6i64..6).flat_map(move |y| {
            (-6i64..6)
                .filter(move |z| x * x + y * y + z * z < 30)
                .map(move |z| [x, y, z])
        })
    });
    let t = LinearOctree::from_voxels(4, [-8; 3], voxels).unwrap();
    let m = Model::new(t).with_frame(Frame::new(0.5, [1.0, 2.0, 0.0]));
    write_model(&dir.join("ball.tess"), &m).unwrap();
    m
}

#[test]
fn scale_by_any_integer_per_axis() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let m = ball(d);
    let out = json(
        d,
        &[
            "scale",
            "ball.tess",
            "--by",
            "3,1,-2",
            "-o",
            "s.tess",
            "--json",
        ],
    );
    assert_eq!(out["scale"], serde_json::json!([3, 1, -2]));
    let got = read_model(&d.join("s.tess")).unwrap();
    let want = m.scale_axes([3, 1, -2]).unwrap();
    assert!(got.tree.same_voxels(&want.tree).unwrap());
    assert_eq!(got.frame, want.frame);
    assert_eq!(got.tree.voxel_count(), 6 * m.tree.voxel_count());
    // 2^K keeps its meaning; a single whole number scales every axis.
    ok(d, &["scale", "ball.tess", "--by", "2", "-o", "two.tess"]);
    assert_eq!(
        read_model(&d.join("two.tess")).unwrap().tree.voxel_count(),
        8 * m.tree.voxel_count()
    );
    // The 2^K fast path gives the general builder's voxels, and the frame follows:
    // the placement scales about the world origin, the voxel size is kept.
    ok(
        d,
        &["scale", "ball.tess", "--by", "4,4,4", "-o", "four.tess"],
    );
    let four = read_model(&d.join("four.tess")).unwrap();
    let (depth, origin) = scale_space(m.tree.bbox().unwrap(), [4; 3]).unwrap();
    let general = m.tree.scale_axes_in([4; 3], depth, origin).unwrap();
    assert!(four.tree.same_voxels(&general).unwrap());
    assert_eq!(four.frame, Frame::new(0.5, [4.0, 8.0, 0.0]));
    // Any factor: the same world point stays under the same voxel.
    let s = read_model(&d.join("s.tess")).unwrap();
    assert_eq!(s.frame, Frame::new(0.5, [3.0, 2.0, 0.0]));
    ok(d, &["scale", "ball.tess", "--by", "3", "-o", "three.tess"]);
    assert_eq!(
        read_model(&d.join("three.tess"))
            .unwrap()
            .tree
            .voxel_count(),
        27 * m.tree.voxel_count()
    );
    fails(
        d,
        &["scale", "ball.tess", "--by", "3,0,1", "-o", "z.tess"],
        "along y",
    );
}

#[test]
fn rotate_by_any_angle_reports_fragmentation() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let m = ball(d);
    let out = json(
        d,
        &[
            "rotate",
            "ball.tess",
            "--degrees",
            "30",
            "--axis",
            "1,1,0",
            "--roundtrip",
            "-o",
            "r.tess",
            "--json",
        ],
    );
    assert_eq!(out["leaves_before"], m.tree.leaf_count());
    assert!(out["roundtrip_lost"].as_u64().is_some());
    let got = read_model(&d.join("r.tess")).unwrap();
    let want = m
        .rotate_about(rotation_matrix([1.0, 1.0, 0.0], 30.0), m.bbox_centre())
        .unwrap();
    assert!(got.tree.same_voxels(&want.tree).unwrap());
    assert_eq!(got.frame, m.frame);
    assert_eq!(out["leaves_after"], want.tree.leaf_count());
    // --about is in world units; --turns stays exact and needs a named axis.
    ok(
        d,
        &[
            "rotate",
            "ball.tess",
            "--degrees",
            "-45",
            "--axis",
            "z",
            "--about",
            "1,2,0",
            "-o",
            "a.tess",
        ],
    );
    fails(
        d,
        &[
            "rotate",
            "ball.tess",
            "--turns",
            "1",
            "--axis",
            "1,1,0",
            "-o",
            "t.tess",
        ],
        "--degrees",
    );
    fails(
        d,
        &[
            "rotate",
            "ball.tess",
            "--degrees",
            "nan",
            "--axis",
            "z",
            "-o",
            "n.tess",
        ],
        "degrees",
    );
}

#[test]
fn transform_applies_a_world_matrix() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let m = ball(d);
    let matrix = "1 0.5 0; 0 1 0; 0 0 2";
    let out = json(
        d,
        &[
            "transform",
            "ball.tess",
            "--matrix",
            matrix,
            "--offset",
            "0.5,0,-1",
            "--roundtrip",
            "-o",
            "t.tess",
            "--json",
        ],
    );
    assert!(out["roundtrip_gained"].as_u64().is_some());
    let got = read_model(&d.join("t.tess")).unwrap();
    let want = m
        .affine_world(
            [[1.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 2.0]],
            [0.5, 0.0, -1.0],
        )
        .unwrap();
    assert!(got.tree.same_voxels(&want.tree).unwrap());
    fails(
        d,
        &[
            "transform",
            "ball.tess",
            "--matrix",
            "1 0 0; 0 1 0",
            "-o",
            "x.tess",
        ],
        "three rows",
    );
    fails(
        d,
        &[
            "transform",
            "ball.tess",
            "--matrix",
            "1 0 0; 0 1 0; 0 0 0",
            "-o",
            "x.tess",
        ],
        "singular",
    );
}
