//! Integration tests of `tesseral rsmc`: the real binary in a temporary folder.

mod common;

use std::path::Path;
use std::process::Output;

use common::expect_success as ok;

fn tesseral(args: &[&str], dir: &Path) -> Output {
    common::run(dir, args)
}

fn fails(out: &Output, needle: &str) {
    assert_eq!(
        out.status.code(),
        Some(2),
        "stderr {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(needle), "stderr {err:?} lacks {needle:?}");
    assert!(!err.contains("panicked"), "{err}");
}

fn csv_rows(path: &Path) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("step,area,volume,radius_of_gyration,acceptance_rate")
    );
    lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect()
}

#[test]
fn json_summary_and_output_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = tesseral(
        &[
            "rsmc", "--steps", "20000", "--beta", "0.3", "--seed", "4", "--out", "o", "--json",
        ],
        dir.path(),
    );
    let text = ok(&out);
    let v: serde_json::Value = serde_json::from_str(text.trim()).unwrap();
    for key in [
        "steps",
        "accepted",
        "area",
        "volume",
        "euler",
        "seconds",
        "steps_per_second",
    ] {
        assert!(v.get(key).is_some(), "missing {key} in {v}");
    }
    assert_eq!(v["steps"], 20000);
    assert_eq!(v["euler"], 2);
    assert_eq!(v["output"], v["out"]);
    let o = dir.path().join("o");
    let rows = csv_rows(&o.join("series.csv"));
    assert_eq!(rows.len(), 21, "a row at 0 and every 1000 steps");
    assert_eq!(rows[0], vec![0.0, 6.0, 1.0, 0.0, 0.0]);
    let last = rows.last().unwrap();
    assert_eq!(last[0], 20000.0);
    assert_eq!(last[1], v["area"].as_f64().unwrap());
    assert_eq!(last[2], v["volume"].as_f64().unwrap());
    assert!(rows.iter().all(|r| (0.0..=1.0).contains(&r[4])));
    let png = std::fs::read(o.join("area.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let obj = std::fs::read_to_string(o.join("surface.obj")).unwrap();
    let faces = obj.lines().filter(|l| l.starts_with("f ")).count();
    assert_eq!(faces as u64, v["area"].as_u64().unwrap());
    assert!(o.join("checkpoint.json").exists());
    let pic = std::fs::read(o.join("surface.png")).unwrap();
    assert_eq!(&pic[..8], b"\x89PNG\r\n\x1a\n");
    // IHDR: width and height, big-endian, at bytes 16..24.
    let width = u32::from_be_bytes(pic[16..20].try_into().unwrap());
    let height = u32::from_be_bytes(pic[20..24].try_into().unwrap());
    assert_eq!((width, height), (800, 600));
    // No temporary files are left behind.
    for e in std::fs::read_dir(&o).unwrap() {
        let name = e.unwrap().file_name().into_string().unwrap();
        assert!(!name.contains(".tmp"), "{name}");
    }
}

#[test]
fn resumed_run_equals_uninterrupted_run() {
    let dir = tempfile::tempdir().unwrap();
    let common = [
        "rsmc",
        "--beta",
        "-0.1",
        "--seed",
        "9",
        "--checkpoint-every",
        "15000",
        "--sample-every",
        "500",
    ];
    let mut a: Vec<&str> = common.to_vec();
    a.extend(["--steps", "45000", "--out", "a"]);
    ok(&tesseral(&a, dir.path()));
    let mut b: Vec<&str> = common.to_vec();
    b.extend(["--steps", "30000", "--out", "b"]);
    ok(&tesseral(&b, dir.path()));
    ok(&tesseral(
        &["rsmc", "--steps", "45000", "--out", "b", "--resume"],
        dir.path(),
    ));
    for f in ["series.csv", "surface.obj", "checkpoint.json", "area.png"] {
        let x = std::fs::read(dir.path().join("a").join(f)).unwrap();
        let y = std::fs::read(dir.path().join("b").join(f)).unwrap();
        assert!(
            x == y,
            "{f} differs between the resumed and the uninterrupted run"
        );
    }
}

#[test]
fn max_area_cap_and_checks_and_ply() {
    let dir = tempfile::tempdir().unwrap();
    let out = tesseral(
        &[
            "rsmc",
            "--steps",
            "30000",
            "--beta",
            "-2",
            "--max-area",
            "60",
            "--check-every",
            "1000",
            "--sample-every",
            "100",
            "--mesh",
            "ply",
            "--out",
            "o",
            "--json",
        ],
        dir.path(),
    );
    let v: serde_json::Value = serde_json::from_str(ok(&out).trim()).unwrap();
    assert!(v["capped"].as_u64().unwrap() > 0);
    let rows = csv_rows(&dir.path().join("o/series.csv"));
    assert!(rows.iter().all(|r| r[1] <= 60.0));
    assert!(
        rows.iter().any(|r| r[1] >= 50.0),
        "β = -2 should push to the cap"
    );
    let ply = std::fs::read_to_string(dir.path().join("o/surface.ply")).unwrap();
    assert!(ply.starts_with("ply\nformat ascii 1.0\n"));
    assert!(ply.contains(&format!("element face {}", v["area"])));
}

#[test]
fn start_shape_box() {
    let dir = tempfile::tempdir().unwrap();
    let out = tesseral(
        &[
            "rsmc",
            "--steps",
            "0",
            "--start",
            "box:3x2x1",
            "--out",
            "o",
            "--json",
        ],
        dir.path(),
    );
    let v: serde_json::Value = serde_json::from_str(ok(&out).trim()).unwrap();
    assert_eq!(
        (v["area"].as_u64(), v["volume"].as_u64()),
        (Some(22), Some(6))
    );
}

#[test]
fn bad_input_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fails(
        &tesseral(&["rsmc", "--start", "box:0x1x1", "--out", "o"], d),
        "--start",
    );
    fails(
        &tesseral(&["rsmc", "--start", "ball", "--out", "o"], d),
        "--start",
    );
    fails(
        &tesseral(&["rsmc", "--beta", "nan", "--out", "o"], d),
        "beta",
    );
    fails(
        &tesseral(&["rsmc", "--max-area", "4", "--out", "o"], d),
        "max_area",
    );
    fails(
        &tesseral(&["rsmc", "--sample-every", "0", "--out", "o"], d),
        "--sample-every",
    );
    fails(
        &tesseral(&["rsmc", "--resume", "--out", "nothing"], d),
        "checkpoint.json",
    );
    fails(&tesseral(&["rsmc", "--steps", "abc"], d), "--steps");
    fails(
        &tesseral(
            &["rsmc", "--steps", "10", "--render-width", "5", "--out", "o"],
            d,
        ),
        "--render-width",
    );
    fails(
        &tesseral(
            &[
                "rsmc",
                "--steps",
                "100000000000",
                "--sample-every",
                "1",
                "--out",
                "o",
            ],
            d,
        ),
        "--sample-every",
    );
    // A damaged checkpoint.
    ok(&tesseral(&["rsmc", "--steps", "1000", "--out", "c"], d));
    std::fs::write(d.join("c/checkpoint.json"), "{\"chain\": 3}").unwrap();
    fails(
        &tesseral(&["rsmc", "--steps", "2000", "--resume", "--out", "c"], d),
        "checkpoint.json",
    );
    // A checkpoint whose voxels are not a sphere.
    ok(&tesseral(&["rsmc", "--steps", "1000", "--out", "e"], d));
    let text = std::fs::read_to_string(d.join("e/checkpoint.json")).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["chain"]["voxels"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!([500, 500, 500]));
    std::fs::write(d.join("e/checkpoint.json"), v.to_string()).unwrap();
    fails(
        &tesseral(&["rsmc", "--steps", "2000", "--resume", "--out", "e"], d),
        "checkpoint",
    );
    // Conflicting options on resume.
    ok(&tesseral(
        &["rsmc", "--steps", "1000", "--beta", "0.2", "--out", "f"],
        d,
    ));
    fails(
        &tesseral(
            &[
                "rsmc", "--steps", "2000", "--beta", "0.3", "--resume", "--out", "f",
            ],
            d,
        ),
        "--beta",
    );
}

#[test]
fn octree_and_dense_backends_write_identical_outputs() {
    let dir = tempfile::tempdir().unwrap();
    for backend in ["octree", "dense"] {
        let out = tesseral(
            &[
                "rsmc",
                "--steps",
                "40000",
                "--beta",
                "-0.1",
                "--seed",
                "3",
                "--backend",
                backend,
                "--out",
                backend,
                "--json",
            ],
            dir.path(),
        );
        let v: serde_json::Value = serde_json::from_str(ok(&out).trim()).unwrap();
        assert_eq!(v["backend"], backend);
    }
    for f in ["series.csv", "surface.obj", "checkpoint.json"] {
        let x = std::fs::read(dir.path().join("octree").join(f)).unwrap();
        let y = std::fs::read(dir.path().join("dense").join(f)).unwrap();
        assert!(x == y, "{f} differs between the backends");
    }
}
