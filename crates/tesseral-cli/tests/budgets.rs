//! Budgets checked before the work, and `render --cut` on the real binary (issue 12
//! items 5 and 6).

mod common;

use std::fs;
use std::path::Path;

use common::{expect_success, run, scenes};

fn refused(dir: &Path, args: &[&str], needles: &[&str]) -> String {
    let out = run(dir, args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    for n in needles {
        assert!(err.contains(n), "{args:?}: expected {n:?} in {err}");
    }
    err
}

/// The tank at depth 16 would need hundreds of millions of leaves: an in-memory
/// build is refused before the work, naming --memory (no fixed leaf limit); an
/// explicit --max-leaves binds when it is the tighter. (A `.tess` output streams:
/// see tests/scale.rs.)
#[test]
fn scene_builds_are_estimated_first() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let tank = fs::read_to_string(scenes().join("tank.tss")).unwrap();
    fs::write(d.join("t16.tss"), tank.replace("depth 7", "depth 16")).unwrap();
    fs::write(d.join("tank.tss"), &tank).unwrap();
    refused(
        d,
        &["build", "t16.tss", "-o", "t.xyz"],
        &["t16.tss", "--memory", ".tess"],
    );
    refused(d, &["render", "t16.tss", "-o", "t.png"], &["--memory"]);
    refused(
        d,
        &["build", "tank.tss", "-o", "t.xyz", "--max-leaves", "1000"],
        &["--max-leaves 1000"],
    );
    refused(
        d,
        &["build", "tank.tss", "-o", "t.tess", "--memory", "10K"],
        &["--memory"],
    );
    refused(
        d,
        &["build", "tank.tss", "-o", "t.tess", "--memory", "ten"],
        &["not a size"],
    );
    assert!(!d.join("t.tess").exists() && !d.join("t.png").exists());
    assert!(!d.join("t.xyz").exists());
    // The real tank has about 7,400 leaves: a budget of 20,000 lets it through.
    let out = expect_success(&run(
        d,
        &[
            "build",
            "tank.tss",
            "-o",
            "t.xyz",
            "--max-leaves",
            "20000",
            "--json",
        ],
    ));
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(v["leaves"].as_u64().unwrap() < 20000);
}

/// `plan --margin 1000000` grew at 90 MB/s; it is refused at once, naming --memory
/// and --margin.
#[test]
fn plan_regions_are_estimated_first() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::write(d.join("wall.xyz"), "10 0 0\n10 1 0\n").unwrap();
    fs::write(d.join("cube.xyz"), "0 0 0\n").unwrap();
    let base = [
        "plan", "wall.xyz", "cube.xyz", "--from", "0,0,0", "--to", "20,0,0",
    ];
    refused(
        d,
        &[&base[..], &["--margin", "1000000"]].concat(),
        &["--memory", "--margin"],
    );
    refused(
        d,
        &[
            &base[..],
            &["--region", "-900000,-900000,-900000,900000,900000,900000"],
        ]
        .concat(),
        &["--memory", "--region"],
    );
    // A modest margin plans as before, and a tiny --memory refuses even that.
    expect_success(&run(d, &[&base[..], &["--margin", "20"]].concat()));
    refused(
        d,
        &[&base[..], &["--margin", "20", "--memory", "1K"]].concat(),
        &["--memory"],
    );
}

/// Issue 12, item 5: on the tank (x up to 48), `x<100` and `y>-1000` show the whole
/// tank, `x>100` nothing (with a note); a plane through it differs from both.
#[test]
fn cuts_outside_the_solid_keep_all_or_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::copy(scenes().join("tank.tss"), d.join("tank.tss")).unwrap();
    let render = |name: &str, extra: &[&str]| -> (Vec<u8>, String) {
        let out = run(
            d,
            &[
                &["render", "tank.tss", "-o", name, "--size", "160x120"][..],
                extra,
            ]
            .concat(),
        );
        expect_success(&out);
        (
            fs::read(d.join(name)).unwrap(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    let (whole, _) = render("whole.png", &[]);
    let (below, note) = render("below.png", &["--cut", "x<100"]);
    assert_eq!(below, whole);
    assert!(note.contains("keeps all"), "{note}");
    let (above, _) = render("above.png", &["--cut", "y>-1000"]);
    assert_eq!(above, whole);
    let (none, note) = render("none.png", &["--cut", "x>100"]);
    assert_ne!(none, whole);
    assert!(note.contains("keeps nothing"), "{note}");
    let (half, note) = render("half.png", &["--cut", "x<10"]);
    assert_ne!(half, whole);
    assert_ne!(half, none);
    assert!(note.is_empty(), "{note}");
}

/// A streamed build on many threads under a tight `--memory` builds fewer cells at
/// once instead of being refused (on 16 threads the depth-11 spheroid's default
/// window needs about 158 MiB), and writes the same file as on two threads; a
/// dataset build too.
#[test]
fn a_streamed_build_on_many_threads_fits_its_window_to_memory() {
    use std::process::Command;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = scenes().join("fig4c-spheroid.tss");
    let build = |threads: &str, out: &str, extra: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_tesseral"))
            .current_dir(d)
            .env("RAYON_NUM_THREADS", threads)
            .args(["build", scene.to_str().unwrap(), "-o", out, "--depth", "11"])
            .args(["--memory", "64M"])
            .args(extra)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{threads} threads: {err}");
        out.stdout
    };
    let estimate = |json: Vec<u8>| {
        let v: serde_json::Value = serde_json::from_slice(&json).unwrap();
        v["memory_estimate"].as_u64().unwrap()
    };
    assert!(estimate(build("16", "a.tess", &["--json"])) <= 64 << 20);
    assert!(estimate(build("2", "b.tess", &["--json"])) <= 64 << 20);
    let read = |p: &str| fs::read(d.join(p)).unwrap();
    assert_eq!(read("a.tess"), read("b.tess"));
    // A dataset build likewise.
    build("16", "ds16", &["--parts", "3"]);
    build("2", "ds2", &["--parts", "3"]);
    for name in [
        "manifest.json",
        "part-00000.tess",
        "part-00001.tess",
        "part-00002.tess",
    ] {
        let (a, b) = (format!("ds16/{name}"), format!("ds2/{name}"));
        assert_eq!(read(&a), read(&b), "{name}");
    }
}

/// An in-memory render counts its picture and its tree against `--memory` before
/// it draws: a picture too big for the budget is refused before the scene is
/// built, a `.tess` file read whole by its header's leaves, and nothing is written.
#[test]
fn an_in_memory_render_counts_its_picture_and_tree() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let tank = scenes().join("tank.tss");
    let tank = tank.to_str().unwrap();
    // 12 M pixels: about 96 MB while drawn.
    let big = ["--size", "4000x3000", "--memory", "64M"];
    let err = refused(
        d,
        &[&["render", tank, "-o", "t.png"][..], &big].concat(),
        &["rendering"],
    );
    assert!(err.contains("more than --memory 64.0 MiB"), "{err}");
    assert!(!d.join("t.png").exists());
    common::ok(
        d,
        &[
            "render", tank, "-o", "t.png", "--size", "400x300", "--memory", "64M",
        ],
    );
    // The depth-10 spheroid, 903,334 leaves: about 71 MiB estimated when read
    // whole (52 MB measured), 19 MB measured when streamed.
    common::build_scene(d, "fig4c-spheroid.tss", "s.tess", 10);
    let whole = [
        "render",
        "s.tess",
        "-o",
        "s.png",
        "--in-memory",
        "--memory",
        "48M",
    ];
    refused(d, &whole, &["rendering s.tess", "without --in-memory"]);
    assert!(!d.join("s.png").exists());
    common::ok(d, &["render", "s.tess", "-o", "s.png", "--memory", "48M"]);
}

/// An in-memory render of a scene whose estimated leaves, with the picture, are
/// over `--memory` is refused before the scene is built: the depth-11 spheroid
/// (3.6 M leaves, about 130 MB drawn; within the 4.4 M leaves that 100M allows a
/// build alone) is refused with the process's peak far below its build's.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
#[test]
fn a_scene_over_the_render_budget_is_refused_before_its_build() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let spheroid = fs::read_to_string(scenes().join("fig4c-spheroid.tss")).unwrap();
    fs::write(d.join("s11.tss"), spheroid.replace("depth 6", "depth 11")).unwrap();
    let args = ["render", "s11.tss", "-o", "s.png", "--memory", "100M"];
    let (code, err, peak, floor) = common::run_peak(d, &args);
    assert_eq!(code, Some(2), "{err}");
    // Refused by the build's leaf estimate (48 bytes a leaf) or by the drawing's.
    assert!(
        err.contains("s11.tss") && err.contains("--memory 100.0 MiB"),
        "{err}"
    );
    assert!(!d.join("s.png").exists());
    // The estimate's build, three levels coarser, takes a few MB; the build
    // itself over 80 MB.
    assert!(
        peak < (40 << 20).max(floor),
        "peak resident memory {peak}: built first?"
    );
}

/// `--max-leaves` binds a streamed build (a `.tess` output) and a dataset build
/// too, though their memory does not grow with the leaves: refused from the
/// estimate, nothing written.
#[test]
fn max_leaves_binds_a_streamed_build() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let sphere = scenes().join("sphere.tss");
    let sphere = sphere.to_str().unwrap();
    for out in [&["-o", "s.tess"][..], &["-o", "ds", "--parts", "2"]] {
        let args = [
            &["build", sphere, "--depth", "8", "--max-leaves", "1000"][..],
            out,
        ]
        .concat();
        refused(d, &args, &["more than --max-leaves 1000 allows"]);
    }
    assert!(!d.join("s.tess").exists() && !d.join("ds").exists());
    let v = common::json(
        d,
        &[
            "build",
            sphere,
            "-o",
            "s.tess",
            "--depth",
            "4",
            "--max-leaves",
            "1000",
            "--json",
        ],
    );
    assert!(v["leaves"].as_u64().unwrap() <= 1000, "{v}");
}

/// A model held whole counts the command's work on it: a mesh written from the
/// depth-9 spheroid (224 k leaves, about 100 MB with its vertex maps) is refused
/// at `--memory 64M` before the build, where a `.bt` of it fits; each run that
/// fits stays within its budget (the process's peak resident memory).
#[cfg(all(target_os = "linux", target_env = "gnu"))]
#[test]
fn an_in_memory_output_counts_its_writing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let spheroid = fs::read_to_string(scenes().join("fig4c-spheroid.tss")).unwrap();
    fs::write(d.join("s9.tss"), spheroid.replace("depth 6", "depth 9")).unwrap();
    common::ok(d, &["build", "s9.tss", "-o", "s9.tess"]);
    for input in ["s9.tss", "s9.tess"] {
        let _ = fs::remove_file(d.join("m.ply"));
        let (verb, what) = if input == "s9.tss" {
            ("build", "s9.tss at depth 9")
        } else {
            ("convert", "reading s9.tess whole")
        };
        let mesh = [verb, input, "-o", "m.ply", "--memory", "64M"];
        let (code, err, peak, floor) = common::run_peak(d, &mesh);
        assert_eq!(code, Some(2), "{err}");
        assert!(
            err.contains(what) && err.contains("with the work on it"),
            "{err}"
        );
        assert!(
            peak < (32 << 20).max(floor),
            "{mesh:?}: peak {peak}: built first?"
        );
        assert!(!d.join("m.ply").exists());
        for (args, budget) in [
            ([verb, input, "-o", "m.bt", "--memory", "64M"], 64i64 << 20),
            ([verb, input, "-o", "m.ply", "--memory", "128M"], 128 << 20),
            (["view", input, "-o", "v.html", "--memory", "64M"], 64 << 20),
        ] {
            let (code, err, peak, floor) = common::run_peak(d, &args);
            assert_eq!(code, Some(0), "{args:?}: {err}");
            assert!(
                peak <= budget.max(floor),
                "{args:?}: peak {peak} over the budget"
            );
        }
    }
}

/// An in-memory `op` counts its two operands together (and the result), from
/// the files' headers before either is read: the depth-9 spheroid twice fits
/// `--memory 32M` one at a time but not together.
#[test]
fn an_in_memory_op_counts_both_operands() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    common::build_scene(d, "fig4c-spheroid.tss", "a.tess", 9);
    fs::copy(d.join("a.tess"), d.join("b.tess")).unwrap();
    let op = ["op", "union", "a.tess", "b.tess", "-o", "u.xyz", "--memory"];
    refused(
        d,
        &[&op[..], &["32M"]].concat(),
        &["a.tess and b.tess together"],
    );
    assert!(!d.join("u.xyz").exists());
    common::ok(d, &[&op[..], &["64M"]].concat());
}
