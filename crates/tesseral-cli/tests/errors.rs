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
