//! Error reporting shared by every command: one line, each cause once, exit code 2.

mod common;

#[test]
fn a_missing_file_is_named_once_with_its_cause_once() {
    let dir = tempfile::tempdir().unwrap();
    for args in [
        &["info", "missing.tess"][..],
        &["render", "missing.tess", "-o", "x.png"],
        &["collide", "missing.tess", "missing.tess"],
        &["render", "missing.tss", "-o", "x.png"],
        // No extension: still "no such file", not "unknown format".
        &["info", "missing"],
    ] {
        let out = common::run(dir.path(), args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8(out.stderr).unwrap();
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(err.starts_with("error: "), "{args:?}: {err}");
        assert_eq!(err.matches("No such file").count(), 1, "{args:?}: {err}");
        assert!(!dir.path().join("x.png").exists());
    }
}

/// A UTF-8 byte order mark (editors on Windows write one) is skipped in every text
/// input: an operations log, a scene, a world file; columns count after it.
#[test]
fn a_byte_order_mark_is_skipped_in_logs_scenes_and_worlds() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let bom = "\u{feff}";
    std::fs::write(d.join("ops.txt"), format!("{bom}+ 0 0 0\n? 0 0 0\n")).unwrap();
    std::fs::write(
        d.join("a.tss"),
        format!("{bom}depth 3\nbox(size = [4, 4, 4])\n"),
    )
    .unwrap();
    std::fs::write(
        d.join("bad.tss"),
        format!("{bom}depth q\nbox(size = [4, 4, 4])\n"),
    )
    .unwrap();
    std::fs::write(d.join("a.xyz"), "0 0 0\n").unwrap();
    std::fs::write(
        d.join("world.json"),
        format!(
            r#"{bom}{{"environment": "a.xyz", "time_step": 1, "steps": 2,
                "objects": [{{"name": "b", "octree": "a.xyz", "start": [5, 0, 0], "velocity": [-1, 0, 0]}}]}}"#
        ),
    )
    .unwrap();
    for args in [
        &["replay", "ops.txt"][..],
        &["build", "a.tss", "-o", "a.tess"],
        &["simulate", "world.json"],
    ] {
        let out = common::run(d, args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{args:?}: {err}");
    }
    let out = common::run(d, &["build", "bad.tss", "-o", "b.tess"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.tss:1:7"), "{err}");
}

/// A folder with no manifest is named as a folder, not as an unknown format.
#[test]
fn a_folder_that_is_no_dataset_is_named_as_a_folder() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("empty")).unwrap();
    let out = common::run(dir.path(), &["info", "empty"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains("empty: a folder, not an octree file"), "{err}");
}

/// An output into a folder that does not exist is refused before any work, by
/// every command that writes a file (it used to come after the drawing or the
/// replay, whose answers were already printed).
#[test]
fn an_output_folder_that_does_not_exist_is_refused_first() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("a.xyz"), "0 0 0\n1 0 0\n").unwrap();
    std::fs::write(d.join("ops.txt"), "+ 0 0 0\n? 0 0 0\n").unwrap();
    std::fs::write(d.join("file"), "").unwrap();
    for args in [
        &["render", "a.xyz", "-o", "nodir/x.png"][..],
        &["replay", "ops.txt", "-o", "nodir/r.tess"],
        &["convert", "a.xyz", "-o", "nodir/c.ply"],
        &["view", "a.xyz", "-o", "file/v.html"],
    ] {
        let out = common::run(d, args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(out.stdout.is_empty(), "{args:?}: work done first");
        let err = String::from_utf8(out.stderr).unwrap();
        assert!(err.contains("cannot create a file in"), "{args:?}: {err}");
    }
}

/// Flags that do not apply are errors: `rotate --about` and `--roundtrip` go with
/// `--degrees` only; `build --depth` is 1 to 16 (it said "the maximum of 21").
#[test]
fn flags_out_of_place_or_range_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("a.xyz"), "0 0 0\n1 0 0\n").unwrap();
    std::fs::write(d.join("s.tss"), "depth 3\nbox(size = [4, 4, 4])\n").unwrap();
    let refused = |args: &[&str], needle: &str| {
        let out = common::run(d, args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8(out.stderr).unwrap();
        assert!(err.contains(needle), "{args:?}: {err}");
    };
    let turn = [
        "rotate", "a.xyz", "--axis", "z", "--turns", "1", "-o", "r.xyz",
    ];
    refused(
        &[&turn[..], &["--about", "0,0,0"]].concat(),
        "--about applies only with --degrees",
    );
    refused(
        &[&turn[..], &["--roundtrip"]].concat(),
        "--roundtrip applies only with --degrees",
    );
    for parts in ["0", "65537", "18446744073709551615"] {
        refused(
            &["build", "s.tss", "-o", "ds", "--parts", parts],
            "from 1 to 65536",
        );
    }
    for depth in ["0", "17"] {
        refused(
            &["build", "s.tss", "-o", "b.tess", "--depth", depth],
            "not in 1..=16",
        );
    }
    assert!(!d.join("r.xyz").exists() && !d.join("b.tess").exists());
}

/// A slice outside the space draws a blank picture, and says so.
#[test]
fn a_slice_outside_the_space_is_noted() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("a.xyz"), "0 0 0\n1 0 0\n").unwrap();
    let out = common::run(d, &["render", "a.xyz", "-o", "s.png", "--slice", "z=500"]);
    assert!(out.status.success());
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(
        err.contains("--slice 'z=500' lies outside the space"),
        "{err}"
    );
    let out = common::run(d, &["render", "a.xyz", "-o", "s.png", "--slice", "z=0"]);
    assert!(String::from_utf8(out.stderr).unwrap().is_empty());
}
