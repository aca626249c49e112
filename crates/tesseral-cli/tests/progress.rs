//! The progress bars of the long streamed commands (`convert --parts`, `convert`
//! to `.tess`, `op`, `translate`, `build --parts`): nothing on standard error when
//! it is not a terminal; on a terminal (through `script`, where installed), the
//! leaves and the time left (issue 15).

mod common;

use std::path::Path;
use std::process::Command;

use common::{ok, run, scenes};

/// The streamed commands on a depth-12 spheroid (14.5 M leaves, above the bars'
/// threshold) with standard error a pipe: they succeed and print nothing there.
/// With standard error a terminal, `convert --parts` and `build --parts` draw
/// their bars.
#[test]
fn bars_show_on_a_terminal_only() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = scenes().join("fig4c-spheroid.tss");
    let scene = scene.to_str().unwrap();
    ok(d, &["build", scene, "-o", "s.tess", "--depth", "12"]);
    let commands: [&[&str]; 5] = [
        &["convert", "s.tess", "-o", "ds", "--parts", "4"],
        &["convert", "ds", "-o", "c.tess"],
        &["translate", "s.tess", "--by=3,-5,7", "-o", "t.tess"],
        &["op", "union", "s.tess", "t.tess", "-o", "u.tess"],
        &["build", scene, "--parts", "2", "-o", "b", "--depth", "11"],
    ];
    for args in commands {
        let out = run(d, args);
        assert!(out.status.success(), "{args:?}");
        assert_eq!(String::from_utf8_lossy(&out.stderr), "", "{args:?}");
    }
    if Command::new("script").arg("--version").output().is_err() {
        eprintln!("no `script`: the terminal half is skipped");
        return;
    }
    for (args, what) in [
        ("convert s.tess -o ds --parts 4", "cutting"),
        (
            &format!("build {scene} --parts 2 -o b --depth 12") as &str,
            "building",
        ),
    ] {
        let shown = on_a_terminal(d, args);
        assert!(
            shown.contains(what) && shown.contains("leaves") && shown.contains("eta"),
            "{args}: {shown}"
        );
    }
}

/// Runs `tesseral ARGS` in `dir` under `script`, so that its standard error is a
/// terminal; returns what the terminal showed.
fn on_a_terminal(dir: &Path, args: &str) -> String {
    let exe = env!("CARGO_BIN_EXE_tesseral");
    let out = Command::new("script")
        .args(["-qec", &format!("{exe} {args} >/dev/null"), "/dev/null"])
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(out.status.success(), "{args}");
    String::from_utf8_lossy(&out.stdout).into_owned()
}
