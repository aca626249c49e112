//! Helpers shared by the CLI integration tests: run the real binary in a directory.
//!
//! Each test file that needs them says `mod common;`; not every file uses every
//! helper, hence the `dead_code` allowance.

#![allow(dead_code)]

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use serde_json::Value;

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

/// Runs a command that must fail with status 2 and `needle` in its error.
pub fn fails(dir: &Path, args: &[&str], needle: &str) {
    let out = run(dir, args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert!(
        err.contains(needle),
        "{args:?}: expected {needle:?} in {err}"
    );
}

/// Runs a command that must succeed and prints one JSON object.
pub fn json(dir: &Path, args: &[&str]) -> Value {
    let out = expect_success(&run(dir, args));
    // One object on the last line, or (info) one pretty-printed object.
    let last = out.lines().last().unwrap_or_default();
    serde_json::from_str(last)
        .or_else(|_| serde_json::from_str(&out))
        .unwrap_or_else(|e| panic!("{args:?}: {e}: {out}"))
}

/// A folder with `a.xyz`, `b.xyz` and a small scene `s.tss`.
pub fn setup() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::write(d.join("a.xyz"), "0 0 0\n1 0 0\n1 1 0\n3 3 3\n").unwrap();
    fs::write(d.join("b.xyz"), "1 0 0\n5 5 5\n").unwrap();
    fs::write(
        d.join("s.tss"),
        "depth 5\nbox(size = [10, 8, 6]) at [0, 0, 3] colour \"olive\"\n",
    )
    .unwrap();
    dir
}

/// Runs the binary in `dir` with its address space capped at `mib` MiB (`ulimit
/// -v`), two threads and two malloc arenas, so the cap bounds what it allocates.
pub fn run_capped(dir: &Path, args: &[&str], mib: u64) -> std::process::Output {
    std::process::Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {}; exec \"$0\" \"$@\"", mib * 1024))
        .arg(env!("CARGO_BIN_EXE_tesseral"))
        .args(args)
        .env("RAYON_NUM_THREADS", "2")
        .env("MALLOC_ARENA_MAX", "2")
        .current_dir(dir)
        .output()
        .expect("run tesseral")
}

/// The repository's `scenes/` folder.
pub fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

/// Builds `scenes/SCENE` at `depth` into `dir/out` (which must succeed); returns
/// the command's output.
pub fn build_scene(dir: &Path, scene: &str, out: &str, depth: u8) -> String {
    let path = scenes().join(scene);
    let depth = depth.to_string();
    ok(
        dir,
        &[
            "build",
            path.to_str().unwrap(),
            "-o",
            out,
            "--depth",
            &depth,
        ],
    )
}

/// `render INPUT` with `extra` flags twice, streamed to `s.png` and `--in-memory` to
/// `m.png`, in `dir`: checks that each took its path and that the PNGs are the same
/// bytes; returns the streamed and the in-memory runs' JSON.
pub fn render_both(dir: &Path, input: &str, extra: &[&str]) -> (Value, Value) {
    let mut a = vec!["render", input, "-o", "s.png", "--json"];
    a.extend_from_slice(extra);
    let v = json(dir, &a);
    assert_eq!(v["streamed"], true, "{v}");
    let mut b = vec!["render", input, "-o", "m.png", "--json", "--in-memory"];
    b.extend_from_slice(extra);
    let w = json(dir, &b);
    assert_eq!(w["streamed"], false, "{w}");
    assert!(
        fs::read(dir.join("s.png")).unwrap() == fs::read(dir.join("m.png")).unwrap(),
        "{input} {extra:?}: the streamed PNG differs from the in-memory one"
    );
    (v, w)
}

/// Runs `tesseral args...` in `dir` with the file `input` as standard input.
pub fn run_stdin(dir: &Path, args: &[&str], input: &str) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tesseral"))
        .current_dir(dir)
        .args(args)
        .stdin(Stdio::from(fs::File::open(dir.join(input)).unwrap()))
        .output()
        .expect("run tesseral")
}

/// The standard output of a run that must succeed (`what` names it on failure).
pub fn stdout_of(out: Output, what: &str) -> Vec<u8> {
    assert!(
        out.status.success(),
        "{what}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}

/// Runs `tesseral args...` in `dir` (its standard output discarded) and gives its
/// exit code, its standard error, its peak resident memory in bytes (from
/// `wait4`) and the floor of that figure. Linux keeps, across the `exec` of a
/// child spawned with `vfork` (as `Command` does), the high-water mark of the test
/// process that spawned it, so a peak is at least that: the floor, measured as
/// the peak of `tesseral --version` spawned just before. A limit `L` on the
/// child's memory is checked as `peak <= L.max(floor)`.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
pub fn run_peak(dir: &Path, args: &[&str]) -> (Option<i32>, String, i64, i64) {
    let floor = peak_of(dir, &["--version"]).2;
    let (code, err, peak) = peak_of(dir, args);
    (code, err, peak, floor)
}

#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn peak_of(dir: &Path, args: &[&str]) -> (Option<i32>, String, i64) {
    use std::io::Read as _;
    #[expect(clippy::zombie_processes, reason = "reaped by wait4 below")]
    let mut child = Command::new(env!("CARGO_BIN_EXE_tesseral"))
        .current_dir(dir)
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run tesseral");
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    let mut status = 0;
    // SAFETY: rusage is plain data, filled in by wait4 for this child alone.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: the pid is our child's, not yet waited for; the pointers are live.
    let pid = unsafe { libc::wait4(child.id() as i32, &mut status, 0, &mut usage) };
    assert_eq!(pid, child.id() as i32);
    let code = libc::WIFEXITED(status).then(|| libc::WEXITSTATUS(status));
    // ru_maxrss is in KiB on Linux.
    (code, err, usage.ru_maxrss * 1024)
}
