//! One way to say each thing across the commands (issue 12, "CLI consistency"):
//! `-o/--output`, `--size WxH`, `--color`, `--json` everywhere, `-` for stdin and
//! stdout, `.tss` inputs to `info` and `convert`, completions, the man page, grouped
//! help, and flags that do not apply being errors.

mod common;

use std::fs;
use std::path::Path;

use common::{expect_success, fails, json, run, setup};
use serde_json::Value;

/// The keys common to every command that writes an octree with `--json`.
fn assert_written(v: &Value, output: &str) {
    assert_eq!(v["output"], output, "{v}");
    for key in [
        "voxels", "leaves", "depth", "origin", "bbox_min", "bbox_max",
    ] {
        assert!(!v[key].is_null(), "{key} missing in {v}");
    }
}

#[test]
fn json_on_every_octree_command() {
    let dir = setup();
    let d = dir.path();
    let v = json(
        d,
        &[
            "translate",
            "a.xyz",
            "--by",
            "1,2,3",
            "-o",
            "t.xyz",
            "--json",
        ],
    );
    assert_written(&v, "t.xyz");
    assert_eq!(v["by"], serde_json::json!([1, 2, 3]));
    assert_eq!(v["method"], "linear");
    assert_eq!(v["voxels"], 4);
    assert_eq!(v["bbox_min"], serde_json::json!([1, 2, 3]));
    let v = json(
        d,
        &[
            "translate",
            "a.xyz",
            "--by",
            "1,0,0",
            "-o",
            "l.xyz",
            "--json",
            "--method",
            "labels",
        ],
    );
    assert!(v["nodes_visited"].as_u64().unwrap() > 0);
    let v = json(
        d,
        &[
            "translate",
            "a.xyz",
            "--by",
            "3,0,0",
            "-o",
            "c.xyz",
            "--json",
            "--clip",
        ],
    );
    // Only (0, 0, 0) + 3 = (3, 0, 0) stays inside the 4-voxel space.
    assert_eq!(
        (v["dropped"].as_u64(), v["voxels"].as_u64()),
        (Some(3), Some(1))
    );
    let v = json(
        d,
        &[
            "rotate", "a.xyz", "--axis", "z", "--turns", "1", "-o", "r.xyz", "--json",
        ],
    );
    assert_written(&v, "r.xyz");
    assert_eq!(
        (v["axis"].as_str(), v["turns"].as_i64()),
        (Some("z"), Some(1))
    );
    let v = json(
        d,
        &["mirror", "a.xyz", "--axis", "x", "-o", "m.xyz", "--json"],
    );
    assert_eq!(v["axis"], "x");
    let v = json(d, &["scale", "a.xyz", "--by", "2", "-o", "s.xyz", "--json"]);
    assert_eq!(
        (v["scale_log2"].as_i64(), v["voxels"].as_u64()),
        (Some(1), Some(32))
    );
    let v = json(d, &["complement", "a.xyz", "-o", "k.xyz", "--json"]);
    assert_eq!(v["voxels"], 64 - 4);
    let v = json(
        d,
        &["op", "union", "a.xyz", "b.xyz", "-o", "u.xyz", "--json"],
    );
    assert_eq!(
        (v["op"].as_str(), v["voxels"].as_u64()),
        (Some("union"), Some(5))
    );
    // Text output is unchanged without the flag.
    let text = expect_success(&run(d, &["mirror", "a.xyz", "--axis", "x", "-o", "m2.xyz"]));
    assert!(text.starts_with("wrote m2.xyz: 4 voxels"), "{text}");
}

#[test]
fn json_on_calc() {
    let dir = setup();
    let d = dir.path();
    let v = json(d, &["calc", "add", "642", "752", "--json"]);
    assert_eq!(
        (v["result"].as_str(), v["carry"].as_u64()),
        (Some("6530"), Some(0))
    );
    assert!(v["digits"].is_null());
    let v = json(d, &["calc", "add", "275", "022", "--digits", "3", "--json"]);
    assert_eq!(v["result"], "057");
    assert_ne!(v["carry"], 0);
    assert_eq!(v["digits"], 3);
    let v = json(d, &["calc", "decode", "45", "--json"]);
    assert_eq!(v["coordinates"], serde_json::json!([1, 0, 3]));
    let v = json(d, &["calc", "sub", "6530", "642", "--explain", "--json"]);
    assert_eq!(v["result"], "752");
    assert!(v["explanation"].as_array().unwrap().len() > 2);
    // Every command takes --json.
    json(d, &["replay", "-", "--json"]);
}

#[test]
fn output_spellings() {
    let dir = setup();
    let d = dir.path();
    expect_success(&run(d, &["convert", "a.xyz", "p.tess"]));
    expect_success(&run(d, &["convert", "a.xyz", "-o", "q.tess"]));
    expect_success(&run(d, &["convert", "a.xyz", "--output", "r.tess"]));
    assert_eq!(
        fs::read(d.join("p.tess")).unwrap(),
        fs::read(d.join("q.tess")).unwrap()
    );
    fails(d, &["convert", "a.xyz"], "required");
    fails(
        d,
        &["convert", "a.xyz", "x.tess", "-o", "y.tess"],
        "cannot be used",
    );
    // rsmc: -o/--output, and the older --out.
    for (flag, folder) in [("-o", "r1"), ("--output", "r2"), ("--out", "r3")] {
        expect_success(&run(
            d,
            &[
                "rsmc",
                "--steps",
                "200",
                "--no-picture",
                flag,
                folder,
                "--json",
            ],
        ));
        assert!(d.join(folder).join("series.csv").exists(), "{flag}");
    }
}

/// Reads a PNG's width and height from its header.
fn png_size(path: &Path) -> (u32, u32) {
    let b = fs::read(path).unwrap();
    assert!(b.starts_with(b"\x89PNG"));
    let w = u32::from_be_bytes([b[16], b[17], b[18], b[19]]);
    let h = u32::from_be_bytes([b[20], b[21], b[22], b[23]]);
    (w, h)
}

#[test]
fn size_everywhere() {
    let dir = setup();
    let d = dir.path();
    expect_success(&run(
        d,
        &["render", "s.tss", "-o", "r.png", "--size", "64x48"],
    ));
    assert_eq!(png_size(&d.join("r.png")), (64, 48));
    fs::write(d.join("dot.xyz"), "0 0 0\n").unwrap();
    expect_success(&run(
        d,
        &[
            "plan", "a.xyz", "dot.xyz", "--from", "5,5,5", "--to", "7,7,7", "-o", "p.png",
            "--size", "50x40",
        ],
    ));
    assert_eq!(png_size(&d.join("p.png")), (50, 40));
    fails(
        d,
        &[
            "plan", "a.xyz", "dot.xyz", "--from", "5,5,5", "--to", "7,7,7", "--size", "50x40",
        ],
        "--output",
    );
    fs::write(
        d.join("w.json"),
        r#"{"environment": "a.xyz", "time_step": 1, "steps": 1,
            "objects": [{"name": "b", "octree": "dot.xyz", "start": [9, 0, 0], "velocity": [1, 0, 0]}]}"#,
    )
    .unwrap();
    expect_success(&run(
        d,
        &["simulate", "w.json", "--frames", "f", "--size", "32x24"],
    ));
    assert_eq!(png_size(&d.join("f").join("frame_00000.png")), (32, 24));
    // The older spellings still work, and cannot be mixed with --size.
    expect_success(&run(
        d,
        &[
            "simulate", "w.json", "--frames", "g", "--width", "40", "--height", "30",
        ],
    ));
    assert_eq!(png_size(&d.join("g").join("frame_00001.png")), (40, 30));
    fails(
        d,
        &[
            "simulate", "w.json", "--frames", "h", "--width", "40", "--size", "32x24",
        ],
        "cannot be used",
    );
    fails(d, &["simulate", "w.json", "--size", "32x24"], "--frames");
    expect_success(&run(
        d,
        &["rsmc", "--steps", "100", "-o", "rs", "--size", "48x36"],
    ));
    assert_eq!(png_size(&d.join("rs").join("surface.png")), (48, 36));
    expect_success(&run(
        d,
        &["rsmc", "--steps", "100", "-o", "rw", "--render-width", "40"],
    ));
    assert_eq!(png_size(&d.join("rw").join("surface.png")), (40, 30));
    for bad in ["64", "0x10", "9000x10", "axb"] {
        fails(
            d,
            &["render", "s.tss", "-o", "z.png", "--size", bad],
            "--size",
        );
    }
}

#[test]
fn color_and_colour() {
    let dir = setup();
    let d = dir.path();
    expect_success(&run(
        d,
        &[
            "render", "a.xyz", "-o", "c1.png", "--size", "40x30", "--colour", "red",
        ],
    ));
    expect_success(&run(
        d,
        &[
            "render", "a.xyz", "-o", "c2.png", "--size", "40x30", "--color", "red",
        ],
    ));
    expect_success(&run(
        d,
        &["render", "a.xyz", "-o", "c3.png", "--size", "40x30"],
    ));
    let (c1, c2, c3) = (
        fs::read(d.join("c1.png")).unwrap(),
        fs::read(d.join("c2.png")).unwrap(),
        fs::read(d.join("c3.png")).unwrap(),
    );
    assert_eq!(c1, c2);
    assert_ne!(c1, c3);
}

#[test]
fn flags_that_do_not_apply_are_errors() {
    let dir = setup();
    let d = dir.path();
    let r = ["render", "s.tss", "-o", "x.png", "--size", "40x30"];
    fails(d, &[&r[..], &["--fov", "30"]].concat(), "--perspective");
    fails(d, &[&r[..], &["--slice-scale", "2"]].concat(), "--slice");
    fails(
        d,
        &[&r[..], &["--slice", "z=3", "--slice-scale", "0"]].concat(),
        "--slice-scale",
    );
    fails(d, &[&r[..], &["--azimuth", "nan"]].concat(), "--azimuth");
    fails(
        d,
        &[&r[..], &["--elevation", "inf"]].concat(),
        "--elevation",
    );
    fails(
        d,
        &[&r[..], &["--sheet", "--azimuth", "10"]].concat(),
        "--sheet",
    );
    expect_success(&run(
        d,
        &[&r[..], &["--perspective", "--fov", "30"]].concat(),
    ));
    fails(
        d,
        &["convert", "a.xyz", "a.tess", "--depth", "5"],
        "--depth",
    );
    fails(
        d,
        &["convert", "a.xyz", "a.tess", "--voxel-size", "0.5"],
        "--voxel-size",
    );
    fails(
        d,
        &["convert", "a.xyz", "a.tess", "--surface-only"],
        "--surface-only",
    );
    fails(d, &["convert", "a.xyz", "a.tess", "--smooth"], "--smooth");
    fails(
        d,
        &["convert", "a.xyz", "a.tess", "--format", "xyz"],
        "--format",
    );
    assert!(!d.join("a.tess").exists());
}

#[test]
fn tss_scenes_in_info_and_convert() {
    let dir = setup();
    let d = dir.path();
    let info = json(d, &["info", "s.tss", "--json"]);
    let built = json(d, &["build", "s.tss", "-o", "s.tess", "--json"]);
    assert_eq!(info["voxels"], built["voxels"]);
    assert_eq!(info["leaves"], built["leaves"]);
    let conv = json(d, &["convert", "s.tss", "s2.tess", "--json"]);
    assert_eq!(conv["voxels"], built["voxels"]);
    assert_eq!(conv["voxel_size"], built["voxel_size"]);
    fails(d, &["info", "s.tss", "--max-leaves", "2"], "--max-leaves");
    fails(
        d,
        &["convert", "s.tss", "s3.tess", "--max-leaves", "2"],
        "--max-leaves",
    );
    fails(
        d,
        &["convert", "s.tss", "s3.tess", "--memory", "1K"],
        "--memory",
    );
    fails(
        d,
        &["build", "s.tss", "-o", "-", "--format", "tess", "--json"],
        "--json",
    );
    assert!(!d.join("s3.tess").exists());
}

/// "(1 objects)" said "1 object".
#[test]
fn singular_counts() {
    let dir = setup();
    let d = dir.path();
    fs::write(d.join("dot.xyz"), "0 0 0\n").unwrap();
    fs::write(
        d.join("w.json"),
        r#"{"environment": "a.xyz", "time_step": 1, "steps": 1,
            "objects": [{"name": "b", "octree": "dot.xyz", "start": [9, 0, 0], "velocity": [1, 0, 0]}]}"#,
    )
    .unwrap();
    let out = expect_success(&run(d, &["simulate", "w.json"]));
    assert!(
        out.contains("0 contacts in 1 step of 1 (1 object)"),
        "{out}"
    );
}
