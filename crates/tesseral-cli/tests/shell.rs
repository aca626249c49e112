//! `-` for standard input and output, shell completions, the man page and the
//! grouped `--help` (issue 12, "CLI consistency"), on the real binary.

mod common;

use std::fs;
use std::io::Write;
use std::path::Path;
use std::process::{Command, Stdio};

use common::{expect_success, fails, run, setup};
use serde_json::Value;

/// Runs tesseral with `input` on stdin; returns (status, stdout, stderr).
fn piped(dir: &Path, args: &[&str], input: &[u8]) -> (Option<i32>, Vec<u8>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_tesseral"))
        .current_dir(dir)
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let input = input.to_vec();
    let writer = std::thread::spawn(move || {
        let _ = stdin.write_all(&input);
    });
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap();
    (
        out.status.code(),
        out.stdout,
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn dash_is_stdin_and_stdout() {
    let dir = setup();
    let d = dir.path();
    expect_success(&run(d, &["convert", "a.xyz", "a.tess"]));
    let tess = fs::read(d.join("a.tess")).unwrap();
    // Every format we write is read back from stdin.
    for ext in [
        "tess", "xyz", "binvox", "vox", "bt", "ot", "ply", "stl", "obj",
    ] {
        let file = format!("via.{ext}");
        expect_success(&run(d, &["convert", "a.xyz", &file]));
        let (code, out, err) = piped(
            d,
            &["info", "-", "--json"],
            &fs::read(d.join(&file)).unwrap(),
        );
        assert_eq!(code, Some(0), "{ext}: {err}");
        let v: Value = serde_json::from_slice(&out).unwrap();
        assert!(v["voxels"].as_u64().unwrap() >= 4, "{ext}: {v}");
    }
    // A pipeline: stdin to stdout, then the same bytes as a file would give.
    let (code, out, err) = piped(
        d,
        &[
            "translate",
            "-",
            "--by",
            "1,1,1",
            "-o",
            "-",
            "--format",
            "tess",
        ],
        &tess,
    );
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains("wrote <stdout>"), "{err}");
    expect_success(&run(
        d,
        &["translate", "a.tess", "--by", "1,1,1", "-o", "t.tess"],
    ));
    assert_eq!(out, fs::read(d.join("t.tess")).unwrap());
    let (code, out, _) = piped(
        d,
        &["convert", "-", "-o", "-", "--format", "xyz"],
        b"# hand-made\n5 6 7\n",
    );
    assert_eq!(code, Some(0));
    assert!(String::from_utf8(out).unwrap().contains("5 6 7"));
    let (code, out, _) = piped(d, &["render", "-", "-o", "-", "--size", "20x10"], &tess);
    assert_eq!(code, Some(0));
    assert!(out.starts_with(b"\x89PNG"));
    // Errors name <stdin>, and stdout needs a format.
    let (code, _, err) = piped(d, &["info", "-"], b"\x00\x01\x02 not a format");
    assert_eq!(code, Some(2));
    assert!(err.contains("<stdin>"), "{err}");
    let (code, _, err) = piped(d, &["info", "-"], b"\x89TESSRL\n broken");
    assert_eq!(code, Some(2));
    assert!(
        err.contains("<stdin>") && !err.contains("stdin.tess"),
        "{err}"
    );
    fails(d, &["convert", "a.xyz", "-o", "-"], "--format");
    fails(
        d,
        &[
            "plan", "a.xyz", "a.xyz", "--from", "5,0,0", "--to", "9,0,0", "-o", "-",
        ],
        "standard output",
    );
    fails(
        d,
        &["convert", "a.xyz", "-o", "-", "--format", "jpg"],
        "--format jpg",
    );
    fails(
        d,
        &["convert", "a.xyz", "-o", "-", "--format", "xyz", "--json"],
        "--json",
    );
}

#[test]
fn completions_man_and_grouped_help() {
    let dir = setup();
    let d = dir.path();
    for shell in ["bash", "zsh", "fish"] {
        let script = expect_success(&run(d, &["completions", shell]));
        assert!(
            script.contains("translate") && script.contains("max-output"),
            "{shell}"
        );
        // Values from a fixed list complete as those values (render --view).
        let listed = if shell == "fish" {
            script.contains("iso\\t") && script.contains("side\\t")
        } else {
            script.contains("iso front top side")
        };
        assert!(listed, "{shell}: --view");
    }
    fails(d, &["completions", "cmd.exe"], "invalid value");
    let page = expect_success(&run(d, &["man"]));
    assert!(
        page.starts_with(".ie") || page.contains(".TH tesseral"),
        "{page}"
    );
    assert!(page.contains("render"));
    let page = expect_success(&run(d, &["man", "render"]));
    assert!(
        page.contains("tesseral\\-render") && page.contains("\\-\\-cut"),
        "{page}"
    );
    fails(d, &["man", "nosuch"], "no such command");
    let help = expect_success(&run(d, &["--help"]));
    let mut last = 0;
    for heading in [
        "Build and view:",
        "Octree operations:",
        "Motion:",
        "Tesseral arithmetic:",
    ] {
        let at = help
            .find(heading)
            .unwrap_or_else(|| panic!("{heading} missing: {help}"));
        assert!(at > last, "groups out of order");
        last = at;
    }
    for command in [
        "build",
        "render",
        "translate",
        "collide",
        "rsmc",
        "calc",
        "completions",
    ] {
        assert_eq!(
            help.lines()
                .filter(|l| l.trim_start().starts_with(&format!("{command} ")))
                .count(),
            1,
            "{command}: {help}"
        );
    }
}
