//! `simulate` on hostile worlds (issue 19, item 4): a depth-10 sphere resting in
//! itself for 100 steps kept every step's overlap boxes in memory; 1,024 objects had
//! no total budget.

use std::path::Path;

mod hostile;
use hostile::{fails_naming, run_capped};

/// A sphere (at depth 10: 3.3 M leaves), and a world where it rests inside itself.
fn resting_world(d: &Path, depth: u8, steps: u64) {
    std::fs::write(
        d.join("sph.tss"),
        format!("depth {depth}\nsphere(r = 100)\n"),
    )
    .unwrap();
    let out = run_capped(d, &["build", "sph.tss", "-o", "sph.tess"], 4096, 120);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let world = format!(
        r#"{{"environment": "sph.tess", "steps": {steps}, "objects": [
            {{"name": "s", "octree": "sph.tess", "start": [0, 0, 0], "velocity": [0, 0, 0]}}]}}"#
    );
    std::fs::write(d.join("w.json"), world).unwrap();
}

#[test]
fn a_sphere_resting_in_itself_runs_in_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    resting_world(d, 10, 100);
    let out = run_capped(d, &["simulate", "w.json"], 1536, 300);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{:?}: {}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    // In contact from the start, and only then: one contact line and the summary.
    assert!(text.contains("1 contact in 100 steps"), "{text}");
}

#[test]
fn json_of_a_sphere_resting_in_itself_streams_within_max_output() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    resting_world(d, 8, 100);
    // Every step's overlap boxes are written out: far over a 4 MiB output budget,
    // refused while streaming, in bounded memory.
    let out = run_capped(
        d,
        &["simulate", "w.json", "--json", "--max-output", "4M"],
        1536,
        300,
    );
    fails_naming(&out, &["--max-output"]);
    // A short run fits, and is one JSON document with every frame.
    resting_world(d, 8, 2);
    let out = run_capped(d, &["simulate", "w.json", "--json"], 1536, 300);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["frames"].as_array().unwrap().len(), 3);
    assert_eq!(v["contacts"].as_array().unwrap().len(), 1);
    assert!(!v["frames"][1]["contact_boxes"]
        .as_array()
        .unwrap()
        .is_empty());
}

#[test]
fn many_large_objects_exceed_the_world_budget_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    resting_world(d, 10, 1);
    let objects: Vec<String> = (0..1024)
        .map(|i| format!(r#"{{"name": "o{i}", "octree": "sph.tess", "start": [0, 0, 0]}}"#))
        .collect();
    let world = format!(
        r#"{{"environment": "sph.tess", "steps": 1, "objects": [{}]}}"#,
        objects.join(",")
    );
    std::fs::write(d.join("many.json"), world).unwrap();
    let out = run_capped(d, &["simulate", "many.json"], 2048, 120);
    fails_naming(&out, &["many.json", "leaves", "--max-leaves"]);
}

/// Octree paths that leave the world file's folder (issue 19, item 9) are refused
/// unless `--allow-outside` is given.
#[test]
fn paths_outside_the_world_folder_need_allow_outside() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir(d.join("w")).unwrap();
    std::fs::write(d.join("dot.xyz"), "0 0 0\n").unwrap();
    std::fs::write(d.join("w/dot.xyz"), "0 0 0\n").unwrap();
    let abs = d.join("dot.xyz").display().to_string();
    for (env, obj) in [("../dot.xyz", "dot.xyz"), ("dot.xyz", abs.as_str())] {
        let world = format!(
            r#"{{"environment": "{env}", "steps": 1, "objects": [{{"octree": "{obj}", "start": [5, 0, 0]}}]}}"#
        );
        std::fs::write(d.join("w/world.json"), world).unwrap();
        let out = run_capped(d, &["simulate", "w/world.json"], 1024, 30);
        fails_naming(&out, &["world.json", "--allow-outside"]);
        let out = run_capped(
            d,
            &["simulate", "w/world.json", "--allow-outside"],
            1024,
            30,
        );
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}
