//! `translate` of a version-2 `.tess` file into a `.tess` file, streamed by an
//! external merge (issue 15), against the in-memory translation through the real
//! binary.

mod common;

use std::fs;
use std::path::{Path, PathBuf};

use common::{fails, json, ok, run, run_capped};

fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

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
    let scene = scenes().join("showcase.tss");
    ok(
        d,
        &[
            "build",
            scene.to_str().unwrap(),
            "-o",
            "a.tess",
            "--depth",
            "6",
        ],
    );
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
/// by an unaligned vector streams within a 384 MiB address space, and gives the
/// leaf and voxel counts of the in-memory translation; the in-memory translation
/// (written to standard output) cannot run in that space, so the cap does bound
/// the work.
#[test]
fn a_streamed_translation_fits_in_a_small_address_space() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = scenes().join("fig4c-spheroid.tss");
    let s = scene.to_str().unwrap();
    ok(d, &["build", s, "-o", "s.tess", "--depth", "12"]);
    // No --stream: the in-memory estimate (48 B a leaf) passes --memory 300M, so the
    // command chooses to stream by itself.
    let args = [
        "translate",
        "s.tess",
        "-o",
        "t.tess",
        "--by=3,-5,7",
        "--json",
        "--memory",
        "300M",
    ];
    let out = run_capped(d, &args, 384);
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
        384,
    );
    assert!(!out.status.success());
    assert!(out.stdout.is_empty());
}

/// A small file translates in memory unless --stream is given (it is several times
/// faster); --stream with an input that cannot stream is an error naming the flag.
#[test]
fn translation_streams_when_asked_or_over_the_memory_budget() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = scenes().join("tank.tss");
    ok(
        d,
        &[
            "build",
            scene.to_str().unwrap(),
            "-o",
            "a.tess",
            "--depth",
            "6",
        ],
    );
    let v = json(
        d,
        &[
            "translate",
            "a.tess",
            "-o",
            "m.tess",
            "--by=3,1,2",
            "--json",
        ],
    );
    assert!(v.get("streamed").is_none() || v["streamed"] == false, "{v}");
    let v = json(
        d,
        &[
            "translate",
            "a.tess",
            "-o",
            "s.tess",
            "--by=3,1,2",
            "--json",
            "--memory",
            "1K",
        ],
    );
    assert_eq!(v["streamed"], true, "{v}");
    assert_eq!(
        fs::read(d.join("m.tess")).unwrap(),
        fs::read(d.join("s.tess")).unwrap()
    );
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
}
