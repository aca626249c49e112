//! Helpers shared by the CLI integration tests: run the real binary in a directory.
//!
//! Each test file that needs them says `mod common;`; not every file uses every
//! helper, hence the `dead_code` allowance.

#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

/// Runs `tesseral args...` with `dir` as its working directory.
pub fn run(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tesseral"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("run tesseral")
}

/// Runs a command that must succeed and returns its stdout.
pub fn ok(dir: &Path, args: &[&str]) -> String {
    let out = run(dir, args);
    assert!(
        out.status.success(),
        "tesseral {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("utf-8 stdout")
}

/// Asserts that a finished run succeeded, showing its output if not; returns stdout.
pub fn expect_success(out: &Output) -> String {
    assert!(
        out.status.success(),
        "status {:?}\nstdout {}\nstderr {}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout.clone()).expect("utf-8 stdout")
}
