//! A closed pipe ends the program quietly, running the real binary (issue 12 item
//! 7): no panic, no "Broken pipe" message, status 0, and the files a command still
//! has to write are written.

use std::fs;
use std::path::Path;
use std::process::{Command, Stdio};

/// Runs a command whose stdout is closed before it writes; it must exit 0 with
/// nothing on stderr.
fn quiet_on_broken_pipe(dir: &Path, args: &[&str]) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_tesseral"))
        .current_dir(dir)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Close the reading end at once: the program's first write fails with EPIPE.
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{args:?}: stderr {err}");
    assert_eq!(err, "", "{args:?}");
}

/// `a.xyz`, two voxels, and `world.json`: a copy of them moving into them for
/// `steps` steps.
fn two_voxel_world(d: &Path, steps: u32) {
    fs::write(d.join("a.xyz"), "0 0 0\n1 0 0\n").unwrap();
    let world = format!(
        r#"{{"environment": "a.xyz", "time_step": 1, "steps": {steps},
            "objects": [{{"name": "b", "octree": "a.xyz", "start": [5, 0, 0], "velocity": [-1, 0, 0]}}]}}"#
    );
    fs::write(d.join("world.json"), world).unwrap();
}

/// Issue 12, item 7: a broken pipe panicked (exit 101) or printed "Broken pipe".
#[test]
fn a_closed_pipe_ends_quietly() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::write(
        d.join("good.tss"),
        "depth 4\nsphere(r = 6) at [8, 8, 8] colour \"teal\"\n",
    )
    .unwrap();
    fs::write(d.join("ops.txt"), "+ 0 0 0\n? 0 0 0\n? 1 0 0\n").unwrap();
    two_voxel_world(d, 3);
    let commands: &[&[&str]] = &[
        &["tables"],
        &["tables", "--json"],
        &["info", "a.xyz", "--json"],
        &["info", "a.xyz"],
        &["calc", "add", "642", "752", "--explain"],
        &["collide", "a.xyz", "a.xyz", "--contacts"],
        &["collide", "a.xyz", "a.xyz", "--json"],
        &["simulate", "world.json"],
        &["simulate", "world.json", "--json"],
        &["replay", "ops.txt"],
        &[
            "rsmc",
            "--steps",
            "2000",
            "--out",
            "rs",
            "--render-width",
            "0",
        ],
        &[
            "rsmc",
            "--steps",
            "2000",
            "--out",
            "rs2",
            "--render-width",
            "0",
            "--json",
        ],
        &["build", "good.tss", "-o", "g.tess", "--json"],
        // A .tess file into .xyz streams (it said "writing <stdout>: Broken pipe").
        &["convert", "g.tess", "-o", "-", "--format", "xyz"],
        &["translate", "a.xyz", "--by", "1,0,0", "-o", "t.xyz"],
        &["plan", "a.xyz", "a.xyz", "--from", "5,0,0", "--to", "9,0,0"],
        &["convert", "a.xyz", "-o", "-", "--format", "xyz"],
        &["render", "a.xyz", "-o", "-", "--size", "64x48"],
        &["completions", "bash"],
        &["man"],
    ];
    for args in commands {
        quiet_on_broken_pipe(d, args);
    }
}

/// A reader that leaves early (`tesseral replay ops -o F | head`) ended the replay
/// before F was written; it ends only what goes to standard output now, and the
/// files still to write are written.
#[test]
fn a_closed_pipe_does_not_stop_the_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // 80 KB of answers, more than a pipe holds.
    let ops: String = (0..40_000)
        .map(|i| format!("+ {i} 0 0\n? {i} 0 0\n"))
        .collect();
    fs::write(d.join("ops.txt"), ops).unwrap();
    quiet_on_broken_pipe(d, &["replay", "ops.txt", "-o", "r.xyz"]);
    let saved = fs::read_to_string(d.join("r.xyz")).unwrap();
    assert_eq!(
        saved.lines().filter(|l| !l.starts_with('#')).count(),
        40_000
    );

    two_voxel_world(d, 1000);
    // Both outputs pass a pipe's 64 KiB buffer, so the closed pipe is met midway
    // whenever the reader leaves: with --json each step's frame is printed as it
    // comes.
    quiet_on_broken_pipe(
        d,
        &[
            "simulate",
            "world.json",
            "--json",
            "--frames",
            "f",
            "--size",
            "16x12",
        ],
    );
    let frames = fs::read_dir(d.join("f")).unwrap().count();
    assert_eq!(frames, 1001, "the start and every step");
}
