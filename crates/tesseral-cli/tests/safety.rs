//! Output safety, running the real binary (issue 12 items 4, 6 and 7; issue 19 item
//! 6): inputs are never outputs, formats follow extensions, outputs are estimated
//! before they are written, temporaries never follow links and are removed on
//! SIGINT/SIGTERM (a closed pipe: `pipes.rs`).

mod common;

use std::fs;
use std::io::Read;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::{expect_success, run};

fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Runs a command that must fail with status 2 and an error containing `needle`.
fn refused(dir: &Path, args: &[&str], needle: &str) -> String {
    let out = run(dir, args);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert!(
        err.contains(needle),
        "{args:?}: expected {needle:?} in {err}"
    );
    err
}

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn small_scene(dir: &Path) {
    fs::write(
        dir.join("good.tss"),
        "depth 5\nbox(size = [16, 12, 8]) at [0, 0, 4] colour \"olive\"\n",
    )
    .unwrap();
}

/// Issue 12, item 4: inputs are destroyed.
#[test]
fn an_input_is_never_an_output() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    small_scene(d);
    let scene = fs::read(d.join("good.tss")).unwrap();
    refused(
        d,
        &["render", "good.tss", "-o", "good.tss"],
        "--output good.tss",
    );
    assert_eq!(fs::read(d.join("good.tss")).unwrap(), scene);

    expect_success(&run(d, &["build", "good.tss", "-o", "a.xyz"]));
    let a = fs::read(d.join("a.xyz")).unwrap();
    // The same path, a path through `.`, a symbolic link and a hard link.
    fs::create_dir(d.join("sub")).unwrap();
    std::os::unix::fs::symlink(d.join("a.xyz"), d.join("link.xyz")).unwrap();
    fs::hard_link(d.join("a.xyz"), d.join("hard.xyz")).unwrap();
    for out in ["a.xyz", "./sub/../a.xyz", "link.xyz", "hard.xyz"] {
        let err = refused(
            d,
            &["translate", "a.xyz", "--by", "1,0,0", "-o", out],
            "refusing to overwrite an input",
        );
        assert!(err.contains("a.xyz"), "{err}");
        refused(d, &["op", "union", "b.xyz", "a.xyz", "-o", out], "input");
        refused(d, &["convert", "a.xyz", out], "input");
    }
    refused(
        d,
        &[
            "rotate", "a.xyz", "--axis", "z", "--turns", "1", "-o", "a.xyz",
        ],
        "input",
    );
    refused(
        d,
        &["mirror", "a.xyz", "--axis", "z", "-o", "hard.xyz"],
        "input",
    );
    refused(
        d,
        &["scale", "a.xyz", "--by", "2", "-o", "link.xyz"],
        "input",
    );
    refused(d, &["complement", "a.xyz", "-o", "a.xyz"], "input");
    refused(d, &["build", "good.tss", "-o", "good.tss"], "");
    assert_eq!(fs::read(d.join("a.xyz")).unwrap(), a);
    assert!(fs::symlink_metadata(d.join("link.xyz"))
        .unwrap()
        .file_type()
        .is_symlink());
    // A different file of the same content is fine.
    expect_success(&run(
        d,
        &["translate", "a.xyz", "--by", "1,0,0", "-o", "sub/a.xyz"],
    ));
}

/// Issue 12, item 4: `plan ... -o wall.xyz` overwrote the environment.
#[test]
fn plan_never_overwrites_its_environment() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::write(d.join("wall.xyz"), "10 0 0\n10 1 0\n").unwrap();
    fs::write(d.join("cube.xyz"), "0 0 0\n").unwrap();
    let wall = fs::read(d.join("wall.xyz")).unwrap();
    let args = [
        "plan", "wall.xyz", "cube.xyz", "--from", "0,0,0", "--to", "20,0,0",
    ];
    refused(
        d,
        &[&args[..], &["-o", "wall.xyz"]].concat(),
        "does not write .xyz",
    );
    assert_eq!(fs::read(d.join("wall.xyz")).unwrap(), wall);
    // Nor does simulate write its frames over the world file.
    fs::write(
        d.join("w.json"),
        r#"{"environment": "wall.xyz", "time_step": 1, "steps": 1, "objects": []}"#,
    )
    .unwrap();
    refused(
        d,
        &["simulate", "w.json", "--frames", "w.json"],
        "world file",
    );
    refused(
        d,
        &["simulate", "w.json", "--frames", "f", "--max-output", "1K"],
        "--max-output",
    );
    assert!(d.join("w.json").is_file() && !d.join("f").exists());
}

/// Issue 12, item 4: `render -o x.jpg` and `-o out.tess` wrote PNG bytes.
#[test]
fn formats_follow_the_extension() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    small_scene(d);
    for out in ["x.jpg", "out.tess", "noext", "x.PNG.txt"] {
        refused(d, &["render", "good.tss", "-o", out], "--output");
        assert!(!d.join(out).exists());
    }
    expect_success(&run(
        d,
        &["render", "good.tss", "-o", "X.PNG", "--size", "40x30"],
    ));
    assert!(fs::read(d.join("X.PNG")).unwrap().starts_with(b"\x89PNG"));
    refused(
        d,
        &["build", "good.tss", "-o", "g.png"],
        "does not write .png",
    );
    expect_success(&run(d, &["build", "good.tss", "-o", "g.tess"]));
    refused(d, &["convert", "g.tess", "g.jpg"], "does not write .jpg");
    refused(
        d,
        &["translate", "g.tess", "--by", "0,0,0", "-o", "g.txt"],
        ".txt",
    );
    fs::write(d.join("o.xyz"), "0 0 0\n").unwrap();
    refused(
        d,
        &[
            "plan", "g.tess", "o.xyz", "--from", "0,0,0", "--to", "1,0,0", "-o", "p.jpg",
        ],
        "does not write .jpg",
    );
}

/// Issue 12, item 6 and issue 19, item 6: a depth-16 leaf as `.xyz` is refused at
/// once, with the flag that raises the limit; nothing is written.
#[test]
fn huge_outputs_are_refused_before_writing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::write(d.join("one.xyz"), "0 0 0\n").unwrap();
    expect_success(&run(
        d,
        &["scale", "one.xyz", "--by", "2^16", "-o", "m16.tess"],
    ));
    let err = refused(d, &["convert", "m16.tess", "m16.xyz"], "--max-output");
    assert!(err.contains("m16.xyz"), "{err}");
    refused(
        d,
        &["convert", "m16.tess", "m16.stl", "--max-output", "10"],
        "--max-output",
    );
    refused(
        d,
        &["scale", "one.xyz", "--by", "2^12", "-o", "s.xyz"],
        "--max-output",
    );
    fs::write(d.join("two.xyz"), "0 0 0\n7 7 7\n").unwrap();
    refused(
        d,
        &["complement", "two.xyz", "-o", "c.xyz", "--max-output", "1K"],
        "--max-output",
    );
    assert_eq!(names(d), ["m16.tess", "one.xyz", "two.xyz"]);
    // Raising the limit lets a moderate output through.
    refused(
        d,
        &[
            "scale",
            "one.xyz",
            "--by",
            "2^5",
            "-o",
            "s.xyz",
            "--max-output",
            "100K",
        ],
        "--max-output",
    );
    expect_success(&run(
        d,
        &[
            "scale",
            "one.xyz",
            "--by",
            "2^5",
            "-o",
            "s.xyz",
            "--max-output",
            "2M",
        ],
    ));
    assert_eq!(
        fs::read_to_string(d.join("s.xyz")).unwrap().lines().count(),
        1 + 32 * 32 * 32
    );
    refused(
        d,
        &["convert", "m16.tess", "x.xyz", "--max-output", "lots"],
        "not a size",
    );
}

/// Issue 19, item 6: a planted link is never followed, and the output is a regular
/// file afterwards.
#[test]
fn planted_links_are_not_followed() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::write(d.join("victim"), "precious").unwrap();
    fs::write(d.join("in.xyz"), "1 2 3\n").unwrap();
    // The output itself is a link to the victim, and so is the name the old writer
    // chose for its temporary, `out.xyz.<pid>.tmp`: the shell plants it under its
    // own pid, which `exec` hands on to tesseral.
    std::os::unix::fs::symlink(d.join("victim"), d.join("out.xyz")).unwrap();
    let out = Command::new("sh")
        .current_dir(d)
        .arg("-c")
        .arg(r#"ln -s victim "out.xyz.$$.tmp" && exec "$0" translate in.xyz --by 1,1,1 -o out.xyz"#)
        .arg(env!("CARGO_BIN_EXE_tesseral"))
        .output()
        .unwrap();
    expect_success(&out);
    assert_eq!(names(d).iter().filter(|n| n.ends_with(".tmp")).count(), 1);
    assert_eq!(fs::read_to_string(d.join("victim")).unwrap(), "precious");
    let meta = fs::symlink_metadata(d.join("out.xyz")).unwrap();
    assert!(meta.file_type().is_file());
    assert!(fs::read_to_string(d.join("out.xyz"))
        .unwrap()
        .contains("2 3 4"));
    // No temporary of ours is left (only the planted link).
    assert!(
        names(d).iter().all(|n| !n.starts_with('.')),
        "{:?}",
        names(d)
    );
    assert!(
        fs::symlink_metadata(d.join(names(d).iter().find(|n| n.ends_with(".tmp")).unwrap()))
            .unwrap()
            .file_type()
            .is_symlink()
    );
}

/// Sends `signal` to a long `convert` once its temporary exists; checks the exit
/// status and that no temporary is left and the target never appeared.
fn interrupted_convert(signal: &str, status: i32) {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::write(d.join("one.xyz"), "0 0 0\n").unwrap();
    // A 2^10 cube: 10^9 lines of `.xyz`, minutes of writing.
    expect_success(&run(
        d,
        &["scale", "one.xyz", "--by", "2^10", "-o", "big.tess"],
    ));
    let args = ["convert", "big.tess", "big.xyz", "--max-output", "1T"];
    interrupted(d, &args, signal, status);
    assert_eq!(names(d), ["big.tess", "one.xyz"]);
}

/// Runs `args` in `d`, sends `signal` once a temporary (`*.tmp`) exists and has had a
/// moment to fill, and checks the exit status.
fn interrupted(d: &Path, args: &[&str], signal: &str, status: i32) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_tesseral"))
        .current_dir(d)
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let temporary = || names(d).into_iter().find(|n| n.ends_with(".tmp"));
    while temporary().is_none() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no temporary appeared"
        );
        assert!(child.try_wait().unwrap().is_none(), "{args:?} ended early");
        std::thread::sleep(Duration::from_millis(20));
    }
    // Let it write for a moment, so the temporary holds data.
    std::thread::sleep(Duration::from_millis(200));
    let kill = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let exit = child.wait().unwrap();
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    assert_eq!(exit.code(), Some(status), "{err}");
}

/// Ctrl-C during `build --parts` removes the staged dataset directory with the parts
/// written so far; the dataset never appears.
#[test]
fn sigint_removes_a_staged_dataset() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = common::scenes().join("fig4c-spheroid.tss");
    let scene = scene.to_str().unwrap();
    let args = ["build", scene, "--parts", "4", "-o", "ds", "--depth", "13"];
    interrupted(d, &args, "-INT", 130);
    assert_eq!(names(d), Vec::<String>::new());
}

/// Issue 12, item 6: Ctrl-C during a long `convert` left `big.xyz.<pid>.tmp`.
#[test]
fn sigint_removes_the_temporary() {
    interrupted_convert("-INT", 130);
}

/// Issue 19, item 6: every SIGTERM left a `.tmp` behind.
#[test]
fn sigterm_removes_the_temporary() {
    interrupted_convert("-TERM", 143);
}

/// A closed terminal (SIGHUP) is handled the same way.
#[test]
fn sighup_removes_the_temporary() {
    interrupted_convert("-HUP", 129);
}
