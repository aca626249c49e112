//! `translate` of a version-2 `.tess` file into a `.tess` file, streamed by an
//! external merge (issue 15), against the in-memory translation through the real
//! binary.

mod common;

use std::fs;

use common::{build_scene, fails, json, ok, run, run_capped, scenes};

/// The streamed translation writes the very file the in-memory one writes (the
/// in-memory path is taken for `-o - --format tess`), colours included, for
/// aligned, unaligned, negative and space-growing displacements, on a file of
/// two chunks (so two runs are merged); its JSON report has the in-memory
/// report's keys and values; the voxels agree through `.xyz`; no temporary file is
/// left beside the output.
#[test]
fn streamed_translation_equals_the_in_memory_one() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = scenes().join("showcase.tss");
    let b = json(
        d,
        &[
            "build",
            scene.to_str().unwrap(),
            "-o",
            "a.tess",
            "--depth",
            "8",
            "--json",
        ],
    );
    assert!(b["leaves"].as_u64().unwrap() > 65_536, "{b}");
    assert!(b["colors"].as_u64().unwrap() >= 4, "{b}");
    for by in [
        "0,0,0",
        "256,0,-256",
        "4,-8,12",
        "3,-5,7",
        "-1,-1,-1",
        "700,-3,1",
    ] {
        let by_arg = format!("--by={by}");
        let v = json(
            d,
            &[
                "translate",
                "a.tess",
                "-o",
                "s.tess",
                &by_arg,
                "--json",
                "--stream",
            ],
        );
        assert_eq!(v["streamed"], true, "{by}");
        assert_eq!(v["colors"], b["colors"], "{by}");
        let out = run(
            d,
            &[
                "translate",
                "a.tess",
                "-o",
                "-",
                "--format",
                "tess",
                &by_arg,
            ],
        );
        assert!(out.status.success(), "{by}");
        assert_eq!(fs::read(d.join("s.tess")).unwrap(), out.stdout, "{by}");
        let m = json(
            d,
            &["translate", "a.tess", "-o", "m.xyz", &by_arg, "--json"],
        );
        assert!(m.get("streamed").is_none());
        for key in [
            "voxels",
            "leaves",
            "depth",
            "origin",
            "bbox_min",
            "bbox_max",
            "voxel_size",
            "translate",
            "by",
            "method",
        ] {
            assert_eq!(v[key], m[key], "{by}: {key}");
        }
        ok(d, &["convert", "s.tess", "s.xyz"]);
        assert_eq!(
            fs::read_to_string(d.join("s.xyz")).unwrap(),
            fs::read_to_string(d.join("m.xyz")).unwrap(),
            "{by}"
        );
    }
    let mut names: Vec<String> = fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["a.tess", "m.xyz", "s.tess", "s.xyz"]);
}

/// A translation past the deepest space is an error naming the input, and leaves
/// no output and no temporary file.
#[test]
fn a_streamed_translation_too_far_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    build_scene(d, "showcase.tss", "a.tess", 6);
    fails(
        d,
        &[
            "translate",
            "a.tess",
            "-o",
            "s.tess",
            "--by=4000000000,0,0",
            "--stream",
        ],
        "a.tess",
    );
    let names: Vec<_> = fs::read_dir(d).unwrap().collect();
    assert_eq!(names.len(), 1);
}

/// Bounded memory: the spheroid at depth 12 (14.5 M leaves, coloured) translated
/// by an unaligned vector streams (by itself: no flag) within a 320 MiB address
/// space, and gives the leaf and voxel counts of the in-memory translation; the
/// in-memory translation (written to standard output) cannot run in that space,
/// so the cap does bound the work.
#[test]
fn a_streamed_translation_fits_in_a_small_address_space() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = scenes().join("fig4c-spheroid.tss");
    let s = scene.to_str().unwrap();
    ok(d, &["build", s, "-o", "s.tess", "--depth", "12"]);
    let args = [
        "translate",
        "s.tess",
        "-o",
        "t.tess",
        "--by=3,-5,7",
        "--json",
    ];
    let out = run_capped(d, &args, 320);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["streamed"], true);
    assert_eq!(v["colors"], 1);
    let info = json(d, &["info", "t.tess", "--json"]);
    assert_eq!(info["leaves"], v["leaves"]);
    assert_eq!(info["voxels"], v["voxels"]);
    let out = run_capped(
        d,
        &[
            "translate",
            "s.tess",
            "-o",
            "-",
            "--format",
            "tess",
            "--by=3,-5,7",
        ],
        320,
    );
    assert!(!out.status.success());
    assert!(out.stdout.is_empty());
}

/// A `.tess` into a `.tess` streams by itself and writes the in-memory path's
/// bytes; --stream with an output that cannot stream is an error naming the flag;
/// an in-memory translation over --memory is refused before the work, naming it.
#[test]
fn translation_streams_by_itself_and_in_memory_is_budgeted() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    build_scene(d, "tank.tss", "a.tess", 6);
    let v = json(
        d,
        &[
            "translate",
            "a.tess",
            "-o",
            "s.tess",
            "--by=3,1,2",
            "--json",
        ],
    );
    assert_eq!(v["streamed"], true, "{v}");
    let out = run(
        d,
        &[
            "translate",
            "a.tess",
            "-o",
            "-",
            "--format",
            "tess",
            "--by=3,1,2",
        ],
    );
    assert!(out.status.success());
    assert_eq!(fs::read(d.join("s.tess")).unwrap(), out.stdout);
    ok(d, &["translate", "a.tess", "-o", "a.xyz", "--by=0,0,0"]);
    fails(
        d,
        &[
            "translate",
            "a.tess",
            "-o",
            "x.xyz",
            "--by=1,0,0",
            "--stream",
        ],
        "--stream",
    );
    fails(
        d,
        &[
            "translate",
            "a.tess",
            "-o",
            "x.xyz",
            "--by=1,0,0",
            "--memory",
            "1K",
        ],
        "--memory",
    );
    assert!(!d.join("x.xyz").exists());
}

/// The streamed `translate`, `op` and `convert` check `--max-output` before the
/// work (estimated from the inputs' sizes): an error naming the flag, and no
/// output or temporary file left.
#[test]
fn streamed_outputs_over_max_output_are_refused_before_the_work() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = scenes().join("showcase.tss");
    let s = scene.to_str().unwrap();
    ok(d, &["build", s, "-o", "a.tess", "--depth", "7"]);
    ok(d, &["build", s, "--parts", "3", "-o", "ds", "--depth", "7"]);
    for args in [
        &["translate", "a.tess", "-o", "o.tess", "--by=3,-5,7"][..],
        &["op", "union", "a.tess", "ds", "-o", "o.tess"][..],
        &["op", "union", "ds", "a.tess", "-o", "o.tess"][..],
        &["convert", "ds", "o.tess"][..],
        &["convert", "a.tess", "o.tess"][..],
    ] {
        let mut args = args.to_vec();
        args.extend(["--max-output", "2K"]);
        fails(d, &args, "--max-output");
        let mut names: Vec<String> = fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(names, ["a.tess", "ds"], "{args:?}");
        // With room, the same command succeeds.
        args.truncate(args.len() - 2);
        ok(d, &args);
        fs::remove_file(d.join("o.tess")).unwrap();
    }
}

/// `op` with a dataset operand streams (its parts read in order as one stream)
/// and writes the bytes the in-memory operation writes, colours included (an
/// empty result: the same, empty, model).
#[test]
fn streamed_set_operations_take_datasets() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let a = scenes().join("showcase.tss");
    let a = a.to_str().unwrap();
    ok(d, &["build", a, "--parts", "3", "-o", "ds", "--depth", "7"]);
    // A second operand in the same space and frame, other colours: the showcase
    // moved (within its space).
    ok(d, &["build", a, "-o", "a.tess", "--depth", "7"]);
    ok(
        d,
        &[
            "translate",
            "a.tess",
            "-o",
            "b.tess",
            "--by=-5,3,-2",
            "--clip",
        ],
    );
    for op in ["union", "intersection", "difference", "xor"] {
        for (x, y) in [("ds", "b.tess"), ("b.tess", "ds"), ("ds", "ds")] {
            let v = json(d, &["op", op, x, y, "-o", "s.tess", "--json"]);
            assert_eq!(v["streamed"], true, "{op} {x} {y}");
            let out = run(d, &["op", op, x, y, "-o", "-", "--format", "tess"]);
            assert!(out.status.success(), "{op} {x} {y}");
            if v["voxels"] == 0 {
                // Empty: the in-memory file keeps an empty colour layer, the
                // streamed one writes none; both mean no colours.
                let m = json(d, &["op", op, x, y, "-o", "m.xyz", "--json"]);
                assert_eq!(m["voxels"], 0);
                continue;
            }
            assert_eq!(
                fs::read(d.join("s.tess")).unwrap(),
                out.stdout,
                "{op} {x} {y}"
            );
        }
    }
}
