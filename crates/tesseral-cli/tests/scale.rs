//! Streaming builds (`build --stream`, `--depth`) through the real binary (issue 15).

mod common;

use std::fs;
use std::path::{Path, PathBuf};

use common::{fails, json, ok};

fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

/// A streamed build writes the same voxels as the in-memory one (compared voxel for
/// voxel through `.xyz`), without colours, and its JSON says it streamed.
#[test]
fn streamed_build_equals_the_in_memory_build() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = scenes().join("showcase.tss");
    let s = scene.to_str().unwrap();
    let v = json(
        d,
        &[
            "build", s, "-o", "s.tess", "--stream", "--depth", "7", "--json",
        ],
    );
    assert_eq!(v["streamed"], true);
    assert_eq!(v["depth"], 7);
    let m = json(d, &["build", s, "-o", "m.tess", "--depth", "7", "--json"]);
    assert_eq!(v["leaves"], m["leaves"]);
    assert_eq!(v["voxels"], m["voxels"]);
    ok(d, &["convert", "s.tess", "s.xyz"]);
    ok(d, &["convert", "m.tess", "m.xyz"]);
    assert_eq!(
        fs::read_to_string(d.join("s.xyz")).unwrap(),
        fs::read_to_string(d.join("m.xyz")).unwrap()
    );
    let info = json(d, &["info", "s.tess", "--json"]);
    assert_eq!(info["voxels"], m["voxels"]);
    assert_eq!(info["voxel_size"], m["voxel_size"]);
}

/// The memory budget is checked before the work; --stream needs a .tess file; a
/// bad --depth is an error naming it.
#[test]
fn streamed_build_budgets_and_refusals() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = scenes().join("fig4c-spheroid.tss");
    let s = scene.to_str().unwrap();
    fails(
        d,
        &["build", s, "-o", "s.tess", "--stream", "--memory", "1M"],
        "--memory",
    );
    fails(d, &["build", s, "-o", "s.xyz", "--stream"], "--stream");
    fails(
        d,
        &["build", s, "-o", "s.tess", "--depth", "30"],
        "depth 30",
    );
    assert!(!d.join("s.tess").exists() && !d.join("s.xyz").exists());
    // Over the leaf limit in memory: the refusal names --stream.
    fails(
        d,
        &[
            "build",
            s,
            "-o",
            "s.tess",
            "--depth",
            "9",
            "--max-leaves",
            "100",
        ],
        "--stream",
    );
    let v = json(
        d,
        &[
            "build",
            s,
            "-o",
            "s.tess",
            "--depth",
            "9",
            "--max-leaves",
            "100",
            "--stream",
            "--json",
        ],
    );
    assert!(v["leaves"].as_u64().unwrap() > 100);
}

/// `build --parts K` writes a dataset directory; `info`, `convert`, `op` and
/// `render` read it as one model, equal voxel for voxel to the plain build.
#[test]
fn partitioned_datasets_read_as_one_model() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = scenes().join("showcase.tss");
    let s = scene.to_str().unwrap();
    let v = json(
        d,
        &[
            "build", s, "--parts", "3", "-o", "ds", "--depth", "7", "--json",
        ],
    );
    assert_eq!(v["parts"], 3);
    assert!(d.join("ds/manifest.json").is_file() && d.join("ds/part-00002.tess").is_file());
    let m = json(d, &["build", s, "-o", "m.tess", "--depth", "7", "--json"]);
    assert_eq!(v["voxels"], m["voxels"]);
    let info = json(d, &["info", "ds", "--json"]);
    assert_eq!(info["voxels"], m["voxels"]);
    assert_eq!(info["leaves"], m["leaves"]);
    ok(d, &["convert", "ds", "ds.xyz"]);
    ok(d, &["convert", "m.tess", "m.xyz"]);
    assert_eq!(
        fs::read_to_string(d.join("ds.xyz")).unwrap(),
        fs::read_to_string(d.join("m.xyz")).unwrap()
    );
    ok(d, &["op", "difference", "ds", "m.tess", "-o", "empty.xyz"]);
    let empty = fs::read_to_string(d.join("empty.xyz")).unwrap();
    assert!(empty.lines().all(|l| l.starts_with('#')), "{empty}");
    ok(d, &["render", "ds", "-o", "ds.png", "--size", "64x48"]);
    assert!(d.join("ds.png").is_file());
    // A damaged part is named; a non-dataset directory is refused as an output.
    let part = d.join("ds/part-00001.tess");
    let mut bytes = fs::read(&part).unwrap();
    bytes[60] ^= 0x10;
    fs::write(&part, bytes).unwrap();
    fails(d, &["info", "ds"], "part-00001.tess");
    fs::create_dir(d.join("full")).unwrap();
    fs::write(d.join("full/x.txt"), "x").unwrap();
    fails(
        d,
        &["build", s, "--parts", "2", "-o", "full"],
        "not a dataset",
    );
}

/// `op` on two chunked `.tess` files into a `.tess` file merges the two streams;
/// the result equals the in-memory operation voxel for voxel.
#[test]
fn streamed_set_operations_equal_the_in_memory_ones() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let a = scenes().join("showcase.tss");
    let b = scenes().join("fig4c-spheroid.tss");
    for (scene, out) in [(&a, "a.tess"), (&b, "b.tess")] {
        ok(
            d,
            &[
                "build",
                scene.to_str().unwrap(),
                "-o",
                out,
                "--stream",
                "--depth",
                "7",
            ],
        );
    }
    // The spheroid's frame differs from the showcase's: give b a's frame by
    // building it from a scene with a's bounds.
    let text = fs::read_to_string(&b).unwrap().replace(
        "bounds [0, 0, 0] [1000, 1000, 1000]",
        "bounds [0, 0, 0] [1024, 1024, 1024]",
    );
    fs::write(d.join("b.tss"), text).unwrap();
    ok(
        d,
        &["build", "b.tss", "-o", "b.tess", "--stream", "--depth", "7"],
    );
    for op in ["union", "intersection", "difference", "xor"] {
        let v = json(d, &["op", op, "a.tess", "b.tess", "-o", "s.tess", "--json"]);
        assert_eq!(v["streamed"], true, "{op}");
        let m = json(d, &["op", op, "a.tess", "b.tess", "-o", "m.xyz", "--json"]);
        assert_eq!(v["voxels"], m["voxels"], "{op}");
        assert_eq!(v["leaves"], m["leaves"], "{op}");
        ok(d, &["convert", "s.tess", "s.xyz"]);
        assert_eq!(
            fs::read_to_string(d.join("s.xyz")).unwrap(),
            fs::read_to_string(d.join("m.xyz")).unwrap(),
            "{op}"
        );
    }
}
