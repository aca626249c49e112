//! Issue "one world through every command": `collide`, `plan` and `simulate` follow
//! the frame rule. The second solid sits where its frame puts it in the first's
//! lattice (equal voxel sizes, a whole-voxel offset), offsets move it from there, and
//! anything else is an error naming both frames. Each test runs the real binary.

mod common;

use common::{fails, json};
use tesseral::io::write_model;
use tesseral::linear::LinearOctree;
use tesseral::model::{Frame, Model};

#[test]
fn collisions_follow_the_frame_rule() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let tree = LinearOctree::from_voxels(3, [0; 3], (0..4).map(|x| [x, 0, 0])).unwrap();
    let a = Model::new(tree.clone()).with_frame(Frame::new(0.5, [0.0; 3]));
    // B's frame places it 3 voxels along x from A's: the solids overlap in one voxel.
    let b = Model::new(tree.clone()).with_frame(Frame::new(0.5, [1.5, 0.0, 0.0]));
    write_model(&d.join("a.tess"), &a).unwrap();
    write_model(&d.join("b.tess"), &b).unwrap();
    write_model(
        &d.join("b0.tess"),
        &Model::new(tree.clone()).with_frame(Frame::new(0.5, [0.0; 3])),
    )
    .unwrap();
    let framed = json(d, &["collide", "a.tess", "b.tess", "--json"]);
    let moved = json(
        d,
        &[
            "collide", "a.tess", "b0.tess", "--offset", "3,0,0", "--json",
        ],
    );
    assert_eq!(framed["overlap_voxels"], 1, "{framed}");
    assert_eq!(framed["overlap_voxels"], moved["overlap_voxels"]);
    write_model(
        &d.join("c.tess"),
        &Model::new(tree).with_frame(Frame::new(0.25, [0.0; 3])),
    )
    .unwrap();
    fails(d, &["collide", "a.tess", "c.tess"], "voxel sizes differ");
}

#[test]
fn plans_follow_the_frame_rule() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A wall at x = 4 with a way round it at y = 6; a one-voxel object.
    let wall = LinearOctree::from_voxels(4, [0; 3], (0..6).map(|y| [4, y, 0])).unwrap();
    let dot = LinearOctree::from_voxels(3, [0; 3], [[0, 0, 0]]).unwrap();
    let env = Model::new(wall).with_frame(Frame::new(0.5, [0.0; 3]));
    write_model(&d.join("env.tess"), &env).unwrap();
    // The object's frame puts it 2 voxels along x from the environment's.
    let placed = Model::new(dot.clone()).with_frame(Frame::new(0.5, [1.0, 0.0, 0.0]));
    write_model(&d.join("obj.tess"), &placed).unwrap();
    write_model(
        &d.join("obj0.tess"),
        &Model::new(dot.clone()).with_frame(Frame::new(0.5, [0.0; 3])),
    )
    .unwrap();
    let plan = |obj: &str, from: &str, to: &str| {
        json(
            d,
            &[
                "plan", "env.tess", obj, "--from", from, "--to", to, "--margin", "2", "--json",
            ],
        )
    };
    let framed = plan("obj.tess", "0,0,0", "6,0,0");
    let moved = plan("obj0.tess", "2,0,0", "8,0,0");
    assert_eq!(framed["found"], true, "{framed}");
    assert_eq!(framed["length"], moved["length"]);
    let shift = |v: &serde_json::Value| -> Vec<[i64; 3]> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|w| std::array::from_fn(|a| w[a].as_i64().unwrap()))
            .collect()
    };
    let got: Vec<[i64; 3]> = shift(&framed["waypoints"])
        .into_iter()
        .map(|w| [w[0] + 2, w[1], w[2]])
        .collect();
    assert_eq!(got, shift(&moved["waypoints"]));
    // World units: each waypoint is its offset times the voxel size.
    for (w, world) in shift(&framed["waypoints"])
        .iter()
        .zip(framed["waypoints_world"].as_array().unwrap())
    {
        for a in 0..3 {
            assert_eq!(world[a].as_f64().unwrap(), w[a] as f64 * 0.5);
        }
    }
    assert_eq!(framed["voxel_size"], 0.5);
    write_model(
        &d.join("fine.tess"),
        &Model::new(dot).with_frame(Frame::new(0.25, [0.0; 3])),
    )
    .unwrap();
    fails(
        d,
        &[
            "plan",
            "env.tess",
            "fine.tess",
            "--from",
            "0,0,0",
            "--to",
            "6,0,0",
        ],
        "voxel sizes differ",
    );
}

#[test]
fn simulations_follow_the_frame_rule() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let wall = LinearOctree::from_voxels(4, [0; 3], (0..4).map(|y| [6, y, 0])).unwrap();
    let dot = LinearOctree::from_voxels(3, [0; 3], [[0, 0, 0]]).unwrap();
    write_model(
        &d.join("env.tess"),
        &Model::new(wall).with_frame(Frame::new(0.5, [0.0; 3])),
    )
    .unwrap();
    // Placed 2 voxels along x by its frame, the dot touches the wall at x = 6 after
    // 3 steps of 1 voxel and enters it at step 4; unplaced it would take 5 and 6.
    let placed = |name: &str, h: f64, x: f64| {
        write_model(
            &d.join(name),
            &Model::new(dot.clone()).with_frame(Frame::new(h, [x, 0.0, 0.0])),
        )
        .unwrap();
        let world = format!(
            r#"{{"environment": "env.tess", "steps": 8, "objects": [
                {{"name": "dot", "octree": "{name}", "start": [0, 0, 0], "velocity": [1, 0, 0]}}]}}"#
        );
        std::fs::write(d.join("world.json"), world).unwrap();
    };
    placed("dot.tess", 0.5, 1.0);
    let report = json(d, &["simulate", "world.json", "--json"]);
    assert_eq!(report["voxel_size"], 0.5, "{report}");
    assert_eq!(report["contacts"][0]["time"], 3.0, "{report}");
    assert_eq!(report["frames"][4]["overlaps"][0][2], 1, "{report}");
    placed("fine.tess", 0.25, 0.0);
    fails(d, &["simulate", "world.json"], "voxel sizes differ");
}

/// Issue 16 §5: a long bar passes an L-shaped corridor only by turning.
#[test]
fn plan_turns_a_bar_through_an_l_shaped_corridor() {
    let scenes = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let d = scenes.as_path();
    let args = |extra: &[&'static str]| -> Vec<&'static str> {
        let mut a = vec![
            "plan",
            "l-corridor.xyz",
            "bar.xyz",
            "--from",
            "-12,0,0",
            "--to",
            "6,20,0",
            "--json",
        ];
        a.extend_from_slice(extra);
        a
    };
    let out = common::run(d, &args(&[]));
    assert_eq!(out.status.code(), Some(1), "no path without turning");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["reason"].as_str().unwrap().contains("at the goal"), "{v}");
    let v = json(d, &args(&["--rotations"]));
    assert_eq!(v["found"], true, "{v}");
    assert!(v["turns"].as_u64().unwrap() >= 1);
    let w = v["waypoints"].as_array().unwrap();
    assert_eq!(w.first().unwrap(), &serde_json::json!([-12, 0, 0]));
    assert_eq!(w.last().unwrap(), &serde_json::json!([6, 20, 0]));
    assert_eq!(w.len(), v["orientations"].as_array().unwrap().len());
}
