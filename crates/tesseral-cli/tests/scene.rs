//! Runs the real `tesseral` binary: `build` and `render`, good and bad input.

use std::path::{Path, PathBuf};

mod common;
use common::{ok, run};

const TANK: &str = include_str!("../../../scenes/tank.tss");

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

/// Fails with exit code 2, naming `names`, without a panic; returns stderr.
fn bad(dir: &Path, args: &[&str], names: &str) -> String {
    let o = run(dir, args);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert!(err.starts_with("error: "), "{args:?}: {err}");
    assert!(err.contains(names), "{args:?}: {err} does not name {names}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    err
}

fn png_size(path: &Path) -> (u32, u32) {
    let bytes = std::fs::read(path).expect("png written");
    assert_eq!(&bytes[1..4], b"PNG");
    let w = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    let h = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
    (w, h)
}

fn json(s: &str) -> serde_json::Value {
    serde_json::from_str(s.trim()).expect("json")
}

#[test]
fn build_writes_an_octree_that_render_draws_without_rebuilding() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("tank.tss"), TANK).unwrap();
    let built = json(&ok(d, &["build", "tank.tss", "-o", "tank.tess", "--json"]));
    assert_eq!(built["depth"], 7);
    assert_eq!(built["objects"], 3);
    let leaves = built["leaves"].as_u64().unwrap();
    assert!(leaves > 1000);
    // The same tree, written in another format too.
    ok(d, &["build", "tank.tss", "-o", "tank.xyz"]);
    let from_scene = json(&ok(
        d,
        &[
            "render", "tank.tss", "-o", "a.png", "--size", "160x120", "--json",
        ],
    ));
    let from_file = json(&ok(
        d,
        &[
            "render",
            "tank.tess",
            "-o",
            "b.png",
            "--size",
            "160x120",
            "--json",
        ],
    ));
    assert_eq!(from_scene["rebuilt_from_scene"], true);
    assert_eq!(from_file["rebuilt_from_scene"], false);
    assert_eq!(from_file["leaves"], leaves);
    assert_eq!(from_scene["voxels"], from_file["voxels"]);
    assert_eq!(png_size(&d.join("a.png")), (160, 120));
    assert_eq!(png_size(&d.join("b.png")), (160, 120));
    // No temporary file is left beside the outputs.
    let names: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert!(names.iter().all(|n| !n.contains(".tmp")), "{names:?}");
}

#[test]
fn every_render_mode_writes_a_png() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("tank.tss"), TANK).unwrap();
    let cases: &[(&[&str], (u32, u32))] = &[
        (&["--view", "front"], (120, 90)),
        (&["--view", "top", "--outline"], (120, 90)),
        (
            &["--view", "side", "--no-shadows", "--normals", "faces"],
            (120, 90),
        ),
        (
            &["--azimuth", "30", "--elevation", "-20", "--zoom", "2"],
            (120, 90),
        ),
        (&["--perspective", "--fov", "50", "--ao", "4"], (120, 90)),
        (&["--cut", "y<0", "--normals", "smooth"], (120, 90)),
        (&["--cut", "z>10", "--background", "#000000"], (120, 90)),
        (&["--sheet"], (2 * 120 + 12, 2 * 90 + 12)),
    ];
    for (i, (extra, size)) in cases.iter().enumerate() {
        let out = format!("m{i}.png");
        let mut args = vec!["render", "tank.tss", "-o", &out, "--size", "120x90"];
        args.extend_from_slice(extra);
        ok(d, &args);
        assert_eq!(png_size(&d.join(&out)), *size, "{extra:?}");
    }
    // A slice: one square of 2 pixels per voxel, 128 voxels across at depth 7.
    ok(
        d,
        &[
            "render",
            "tank.tss",
            "-o",
            "s.png",
            "--slice",
            "z=8",
            "--slice-scale",
            "2",
        ],
    );
    assert_eq!(png_size(&d.join("s.png")), (256, 256));
}

#[test]
fn every_shipped_scene_builds() {
    let dir = tempfile::tempdir().unwrap();
    let mut count = 0;
    for entry in std::fs::read_dir(scenes_dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "tss") && !path.ends_with("showcase.tss") {
            let p = path.to_str().unwrap();
            let out = json(&ok(dir.path(), &["build", p, "-o", "out.tess", "--json"]));
            assert!(out["voxels"].as_u64().unwrap() > 0, "{p}");
            count += 1;
        }
    }
    assert!(count >= 7, "{count} scenes");
}

#[test]
fn scene_errors_name_file_line_and_column_with_a_caret() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("bad.tss"), "depth 6\nspere(r = 4)\n").unwrap();
    for cmd in ["build", "render"] {
        let out = if cmd == "build" { "o.tess" } else { "o.png" };
        let err = bad(
            d,
            &[cmd, "bad.tss", "-o", out],
            "bad.tss:2:1: unknown shape or keyword `spere`",
        );
        assert!(err.contains("2 | spere(r = 4)"), "{err}");
        assert!(err.contains("  | ^^^^^"), "{err}");
        assert!(err.contains("hint: did you mean `sphere`?"), "{err}");
        assert!(!d.join(out).exists());
    }
}

#[test]
fn bad_arguments_and_files_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("t.tss"), TANK).unwrap();
    let r = |extra: &[&str], names: &str| {
        let mut args = vec!["render", "t.tss", "-o", "x.png"];
        args.extend_from_slice(extra);
        bad(d, &args, names);
    };
    r(&["--size", "12"], "--size");
    r(&["--size", "0x5"], "--size");
    r(&["--size", "99999x5"], "--size");
    r(&["--size", "8000x8000"], "--size");
    r(&["--slice", "z=3", "--slice-scale", "100"], "--slice");
    r(&["--view", "isometric"], "--view");
    r(&["--zoom", "0"], "--zoom");
    r(&["--zoom", "-1"], "--zoom -1: must be a positive number");
    r(&["--fov", "200", "--perspective"], "--fov");
    r(
        &["--fov", "-5", "--perspective"],
        "--fov -5: must lie between",
    );
    r(&["--ao", "1000"], "--ao");
    r(&["--cut", "w<3"], "--cut");
    r(&["--cut", "z=3"], "--cut");
    r(&["--cut", "z<abc"], "--cut");
    r(&["--slice", "z<3"], "--slice");
    r(&["--background", "nope"], "--background");
    r(&["--normals", "bumpy"], "--normals");
    bad(d, &["render", "missing.tss", "-o", "x.png"], "missing.tss");
    bad(
        d,
        &["render", "missing.tess", "-o", "x.png"],
        "missing.tess",
    );
    std::fs::write(d.join("junk.xyz"), "1 2\n").unwrap();
    bad(d, &["render", "junk.xyz", "-o", "x.png"], "junk.xyz");
    bad(d, &["render", "t.tss", "-o", "no/such/dir/x.png"], "x.png");
    bad(d, &["build", "t.tss", "-o", "x.unknown"], "x.unknown");
    std::fs::write(d.join("huge.tss"), "voxel 0.001\nsphere(r = 10000)\n").unwrap();
    bad(d, &["build", "huge.tss", "-o", "x.tess"], "huge.tss:1:1");
}
