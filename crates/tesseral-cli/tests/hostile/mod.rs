//! Runs the real binary on hostile input under a memory and time cap, so a file that
//! exhausts memory or hangs fails the test instead of the machine.

#![allow(dead_code)]

use std::io::Read;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Runs `tesseral args...` in `dir` with its address space capped at `mem_mb` MiB and
/// its wall time at `secs` seconds; panics (failing the test) when the time runs out.
pub fn run_capped(dir: &Path, args: &[&str], mem_mb: u64, secs: u64) -> Output {
    // `ulimit -v` caps the address space: an allocation beyond it fails instead of
    // taking the machine's memory, which the binary reports as an abort.
    let script = format!("ulimit -v {}; exec \"$0\" \"$@\"", mem_mb * 1024);
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(script)
        .arg(env!("CARGO_BIN_EXE_tesseral"))
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run tesseral");
    // Drain both pipes while waiting, so a long report cannot block the child.
    let drain = |mut r: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut v = Vec::new();
            r.read_to_end(&mut v).expect("read pipe");
            v
        })
    };
    let stdout = drain(Box::new(child.stdout.take().expect("stdout")));
    let stderr = drain(Box::new(child.stderr.take().expect("stderr")));
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait") {
            break status;
        }
        if start.elapsed() > Duration::from_secs(secs) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("tesseral {args:?} ran past {secs} s");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    Output {
        status,
        stdout: stdout.join().expect("stdout reader"),
        stderr: stderr.join().expect("stderr reader"),
    }
}

/// Asserts a clean failure: exit code 2, one `error: ` report naming every one of
/// `names`, and no panic or abort. Returns stderr.
pub fn fails_naming(out: &Output, names: &[&str]) -> String {
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "status {:?}: {err}", out.status);
    assert!(err.starts_with("error: "), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    for n in names {
        assert!(err.contains(n), "{err}\ndoes not name {n:?}");
    }
    err
}
