//! `tesseral render --cut`, `--slice` and `--sheet` of version-2 `.tess` files and
//! datasets, streamed (only the chunks the cut, the slice or the rays reach are
//! read) against the in-memory drawings, byte for byte (issue 15).

mod common;

use std::fs;

use common::{json, ok, run, run_capped, scenes};

/// Streamed and in-memory PNGs of one drawing, and the streamed run's JSON.
fn both(d: &std::path::Path, input: &str, extra: &[&str]) -> serde_json::Value {
    let (v, w) = common::render_both(d, input, extra);
    assert_eq!(v["width"], w["width"]);
    v
}

#[test]
fn streamed_cuts_slices_and_sheets_equal_the_in_memory_ones() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = scenes().join("showcase.tss");
    let s = scene.to_str().unwrap();
    // The showcase's frame: 8 world units per voxel at depth 7.
    ok(d, &["build", s, "-o", "m.tess", "--depth", "7"]);
    ok(d, &["build", s, "-o", "ds", "--depth", "7", "--parts", "3"]);
    for input in ["m.tess", "ds"] {
        for extra in [
            &["--cut", "x<500", "--size", "160x120"][..],
            &["--cut", "y>300.5", "--size", "160x120", "--view", "front"][..],
            &["--cut", "z<100", "--perspective", "--size", "120x90"][..],
            &["--cut", "z>5000", "--size", "80x60"][..],
            &["--cut", "x>-20", "--size", "80x60", "--outline"][..],
            &["--slice", "z=40", "--slice-scale", "1"][..],
            &["--slice", "x=512", "--slice-scale", "2"][..],
            &["--slice", "y=1023"][..],
            &["--slice", "y=-3", "--slice-scale", "1"][..],
            &["--sheet", "--size", "100x75"][..],
            &["--sheet", "--size", "100x75", "--cut", "y<520"][..],
        ] {
            let v = both(d, input, extra);
            let decoded = v["chunks_decoded"].as_u64().unwrap();
            let chunks = v["chunks"].as_u64().unwrap();
            assert!(decoded <= chunks * 8, "{v}");
        }
    }
    // A slice and a cut read only the chunks they reach (and those the bounding
    // box needs at open).
    ok(d, &["build", s, "-o", "m10.tess", "--depth", "10"]);
    for extra in [&["--slice", "x=40"][..], &["--cut", "x<40"][..]] {
        let mut a = vec!["render", "m10.tess", "-o", "t.png", "--json"];
        a.extend_from_slice(extra);
        let v = json(d, &a);
        let decoded = v["chunks_decoded"].as_u64().unwrap();
        let chunks = v["chunks"].as_u64().unwrap();
        assert!(chunks >= 4 && decoded < chunks, "{extra:?}: {v}");
    }
}

#[test]
fn a_cut_outside_the_solid_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = scenes().join("fig4c-spheroid.tss");
    ok(
        d,
        &[
            "build",
            scene.to_str().unwrap(),
            "-o",
            "s.tess",
            "--depth",
            "6",
        ],
    );
    for (cut, says) in [("z>5000", "keeps nothing"), ("z<5000", "keeps all")] {
        let out = run(d, &["render", "s.tess", "-o", "c.png", "--cut", cut]);
        assert!(out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(says), "{cut}: {err}");
    }
}

/// A depth-12 spheroid (14.5 M leaves) is cut, sliced and drawn as a contact sheet
/// in 256 MiB of address space when streamed; loaded whole it cannot be.
#[test]
fn streamed_cuts_and_slices_fit_in_a_small_address_space() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = scenes().join("fig4c-spheroid.tss");
    let s = scene.to_str().unwrap();
    let out = run_capped(d, &["build", s, "-o", "s.tess", "--depth", "12"], 256);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The slice is a picture of 4096 × 4096 pixels: about 156 MiB with the rest.
    for extra in [
        &["--cut", "x<500", "--memory", "64M"][..],
        &["--slice", "z=500", "--slice-scale", "1", "--memory", "192M"][..],
        &[
            "--sheet", "--size", "200x150", "--cut", "y>480", "--memory", "64M",
        ][..],
    ] {
        let mut a = vec!["render", "s.tess", "-o", "s.png", "--json"];
        a.extend_from_slice(extra);
        let out = run_capped(d, &a, 256);
        assert!(
            out.status.success(),
            "{extra:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["streamed"], true);
        assert!(fs::metadata(d.join("s.png")).unwrap().len() > 1000);
        fs::remove_file(d.join("s.png")).unwrap();
        a.push("--in-memory");
        let out = run_capped(d, &a, 256);
        assert!(!out.status.success(), "{extra:?} loaded whole in 256 MiB");
        assert!(!d.join("s.png").exists());
    }
}
