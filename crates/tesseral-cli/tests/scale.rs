//! Streaming builds (`build --stream`, `--depth`) through the real binary (issue 15).

mod common;

use std::fs;

use common::{fails, json, ok, run_capped, scenes};

/// A streamed build writes the same voxels as the in-memory one (compared voxel for
/// voxel through `.xyz`), and its JSON says it streamed; a build to `.tess` streams
/// without `--stream`.
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
    let plain = json(d, &["build", s, "-o", "p.tess", "--depth", "7", "--json"]);
    assert_eq!(plain["streamed"], true);
    let m = json(d, &["build", s, "-o", "m.xyz", "--depth", "7", "--json"]);
    assert!(m.get("streamed").is_none());
    assert_eq!(v["leaves"], m["leaves"]);
    assert_eq!(v["voxels"], m["voxels"]);
    assert_eq!(plain["voxels"], m["voxels"]);
    ok(d, &["convert", "s.tess", "s.xyz"]);
    assert_eq!(
        fs::read_to_string(d.join("s.xyz")).unwrap(),
        fs::read_to_string(d.join("m.xyz")).unwrap()
    );
    assert_eq!(
        fs::read(d.join("s.tess")).unwrap(),
        fs::read(d.join("p.tess")).unwrap()
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
        "'30' for '--depth <D>': 30 is not in 1..=16",
    );
    assert!(!d.join("s.tess").exists() && !d.join("s.xyz").exists());
    // Over --max-leaves, in memory or streamed: refused (a streamed build's memory
    // does not grow with the leaves, but the flag is a limit on them), and the
    // refusal does not suggest a .tess, which --max-leaves binds as well.
    for out in ["s.xyz", "s.tess"] {
        let args = ["build", s, "-o", out, "--depth", "9", "--max-leaves", "100"];
        let out = common::run(d, &args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("more than --max-leaves 100")
                || err.contains("that --max-leaves 100 allows"),
            "{err}"
        );
        assert!(!err.contains("which streams"), "{err}");
    }
    assert!(!d.join("s.tess").exists() && !d.join("s.xyz").exists());
    // Over --memory in memory: the refusal says a .tess file streams.
    fails(
        d,
        &["build", s, "-o", "s.xyz", "--depth", "9", "--memory", "8M"],
        ".tess file, which streams",
    );
    // No fixed leaf limit in memory: the memory budget decides, before the work.
    fails(
        d,
        &[
            "build", s, "-o", "s.xyz", "--depth", "10", "--memory", "10M",
        ],
        "--memory 10.0 MiB",
    );
    assert!(!d.join("s.xyz").exists());
}

/// The command, `build scene.tss -o big.tess --depth D`, streams with no
/// other flag, and its file estimate (about 1.1 bytes a leaf and as much for the
/// colours, not 10) lets a depth whose in-memory build the memory budget refuses
/// through `--max-output`: here scaled down, a 3 MiB limit and a depth-10
/// spheroid of about 0.9 M leaves.
#[test]
fn the_plain_tess_build_streams_within_the_output_estimate() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = scenes().join("fig4c-spheroid.tss");
    let s = scene.to_str().unwrap();
    let args = ["build", s, "-o", "big.tess", "--depth", "10", "--json"];
    let v = json(
        d,
        &[&args[..], &["--max-output", "3M", "--memory", "200M"]].concat(),
    );
    assert_eq!(v["streamed"], true);
    let leaves = v["leaves"].as_u64().unwrap();
    assert!(leaves > 800_000, "{v}");
    let size = fs::metadata(d.join("big.tess")).unwrap().len();
    assert!(size < 3 * leaves, "{size} bytes for {leaves} leaves");
    // The same build in memory needs about 24 bytes a leaf: over 10 MiB.
    fails(
        d,
        &[
            "build", s, "-o", "m.xyz", "--depth", "10", "--memory", "10M",
        ],
        "--memory",
    );
    fails(
        d,
        &[&args[..], &["--max-output", "100K"]].concat(),
        "--max-output",
    );
}

/// A coloured scene built streamed (a `.tess` file, and a dataset of parts) keeps its
/// colours: the same voxel colours as the in-memory build, compared voxel for voxel
/// through `.vox` (which writes each voxel's colour), and the same colour count.
#[test]
fn streamed_builds_keep_the_scene_colours() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // The showcase at depth 7 (the same space, voxels 8 times larger).
    let text = fs::read_to_string(scenes().join("showcase.tss")).unwrap();
    assert!(text.contains("\ndepth 10\n"));
    fs::write(
        d.join("s7.tss"),
        text.replace("\ndepth 10\n", "\ndepth 7\n"),
    )
    .unwrap();
    let s = "s7.tss";
    let v = json(d, &["build", s, "-o", "s.tess", "--json"]);
    assert_eq!(v["streamed"], true);
    let m = json(d, &["build", s, "-o", "m.vox", "--json"]);
    assert!(m["colors"].as_u64().unwrap() >= 4, "{m}");
    assert_eq!(v["colors"], m["colors"]);
    ok(d, &["convert", "s.tess", "s.vox"]);
    let want = fs::read(d.join("m.vox")).unwrap();
    assert_eq!(fs::read(d.join("s.vox")).unwrap(), want);
    // `info` streams the file (chunks and colour regions read as streams) and
    // says what the in-memory model of the scene says, key for key.
    // (`streamed` says which path was taken: the only key that differs.)
    let info = |input: &str, streamed: bool| {
        let mut v = json(d, &["info", input, "--json"]);
        assert_eq!(v["streamed"], streamed, "{input}");
        v.as_object_mut().unwrap().remove("streamed");
        v
    };
    assert_eq!(info("s.tess", true), info(s, false));
    assert!(ok(d, &["info", "s.tess"]).contains("colours  8 distinct"));
    ok(d, &["build", s, "--parts", "3", "-o", "ds"]);
    assert_eq!(info("ds", true), info(s, false));
    ok(d, &["convert", "ds", "ds.vox"]);
    assert_eq!(fs::read(d.join("ds.vox")).unwrap(), want);
    // `convert` to .tess streams a .tess file or a dataset (parts joined chunk by
    // chunk, colour regions as streams): the same file as the streamed build.
    for (input, copy) in [("s.tess", "c.tess"), ("ds", "dc.tess")] {
        let v = json(d, &["convert", input, copy, "--json"]);
        assert_eq!(v["streamed"], true, "{input}");
        assert_eq!(
            fs::read(d.join(copy)).unwrap(),
            fs::read(d.join("s.tess")).unwrap(),
            "{input}"
        );
    }
    // A render of the streamed file shows the colours: the same picture as the
    // in-memory model's (convert builds the scene in memory).
    ok(d, &["convert", s, "m.tess"]);
    ok(d, &["render", "s.tess", "-o", "s.png", "--size", "96x64"]);
    ok(d, &["render", "m.tess", "-o", "m.png", "--size", "96x64"]);
    assert_eq!(
        fs::read(d.join("s.png")).unwrap(),
        fs::read(d.join("m.png")).unwrap()
    );
    ok(d, &["render", "ds", "-o", "ds.png", "--size", "96x64"]);
    assert_eq!(
        fs::read(d.join("ds.png")).unwrap(),
        fs::read(d.join("m.png")).unwrap()
    );
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

/// `op` on two chunked, coloured `.tess` files into a `.tess` file merges the two
/// streams; the result equals the in-memory operation voxel for voxel, colours
/// included.
#[test]
fn streamed_set_operations_equal_the_in_memory_ones() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let a = scenes().join("showcase.tss");
    let b = scenes().join("fig4c-spheroid.tss");
    // The spheroid's frame differs from the showcase's: give b a's frame by
    // building it from a scene with a's bounds. Both are coloured.
    let text = fs::read_to_string(&b).unwrap().replace(
        "bounds [0, 0, 0] [1000, 1000, 1000]",
        "bounds [0, 0, 0] [1024, 1024, 1024]",
    );
    fs::write(d.join("b.tss"), text).unwrap();
    ok(
        d,
        &["build", a.to_str().unwrap(), "-o", "a.tess", "--depth", "7"],
    );
    ok(d, &["build", "b.tss", "-o", "b.tess", "--depth", "7"]);
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
        // The colours too, voxel for voxel (.vox writes each voxel's colour).
        ok(d, &["op", op, "a.tess", "b.tess", "-o", "m.vox"]);
        ok(d, &["convert", "s.tess", "s.vox"]);
        assert_eq!(
            fs::read(d.join("s.vox")).unwrap(),
            fs::read(d.join("m.vox")).unwrap(),
            "{op}"
        );
    }
}

/// Bounded memory: the spheroid at depth 12 (14.5 M leaves, with its colours)
/// builds streamed within a 256 MiB address space; the in-memory build of the same
/// scene (to .xyz) cannot, so the cap does bound the work.
#[test]
fn a_streamed_build_fits_in_a_small_address_space() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = scenes().join("fig4c-spheroid.tss");
    let s = scene.to_str().unwrap();
    let out = run_capped(
        d,
        &["build", s, "-o", "s.tess", "--depth", "12", "--json"],
        256,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["leaves"], 14_520_164);
    assert_eq!(v["colors"], 1);
    let out = run_capped(d, &["build", s, "-o", "m.xyz", "--depth", "12"], 256);
    assert!(!out.status.success());
    assert!(!d.join("m.xyz").exists());
}
