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
