//! A writer of a dataset killed by SIGKILL (which no program can catch) leaves
//! its staged directory (`.DIR.*.tmp`); the next `build --parts` or `convert
//! --parts` into the same DIR removes it, and only the staged directories whose
//! writer is provably gone (issue 15).

mod common;

use std::fs;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::{ok, run};

fn staged(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".ds.") && n.ends_with(".tmp"))
        .collect();
    v.sort();
    v
}

fn proc_line(path: &str) -> String {
    fs::read_to_string(path).unwrap().trim().to_owned()
}

/// A staged directory of `ds` whose marker names process `pid` (started at
/// `start` clock ticks after boot), on this host, boot and pid namespace: the
/// marker's format, which `io::staged` writes.
fn plant(d: &Path, name: &str, pid: u32, start: &str) {
    let dir = d.join(name);
    fs::create_dir(&dir).unwrap();
    fs::write(dir.join("part-0000.tess"), b"half a part").unwrap();
    let marker = format!(
        "tesseral staged dataset directory\npid {pid}\nstart {start}\nboot {}\npidns {}\nhost {}\n",
        proc_line("/proc/sys/kernel/random/boot_id"),
        fs::read_link("/proc/self/ns/pid").unwrap().display(),
        proc_line("/proc/sys/kernel/hostname"),
    );
    fs::write(dir.join(".tesseral-staged"), marker).unwrap();
}

/// This process's start time (field 22 of `/proc/self/stat`).
fn my_start() -> String {
    let stat = fs::read_to_string("/proc/self/stat").unwrap();
    let rest = &stat[stat.rfind(')').unwrap() + 1..];
    rest.split_whitespace().nth(19).unwrap().to_owned()
}

/// `build --parts` killed by SIGKILL leaves its staged directory; the next
/// `convert --parts` into the same directory removes it (and a planted one of a
/// dead process), keeps the one of a live process (this test), says what it
/// removed, and writes the dataset; `build --parts` sweeps too.
#[test]
#[cfg(target_os = "linux")]
fn the_next_writer_removes_a_killed_writers_staged_directory() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = common::scenes().join("fig4c-spheroid.tss");
    let scene = scene.to_str().unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_tesseral"))
        .current_dir(d)
        .args(["build", scene, "--parts", "4", "-o", "ds", "--depth", "13"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while staged(d).is_empty() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no staged directory"
        );
        assert!(child.try_wait().unwrap().is_none(), "the build ended early");
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(200));
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    let killed = staged(d);
    assert_eq!(killed.len(), 1, "{killed:?}");
    assert!(d.join(&killed[0]).join(".tesseral-staged").is_file());
    assert!(!d.join("ds").exists());
    // A dead process's directory, and a live one's (this test's own pid).
    let mut dead = Command::new("true").spawn().unwrap();
    dead.wait().unwrap();
    plant(d, ".ds.dead01.tmp", dead.id(), "7");
    plant(d, ".ds.live01.tmp", std::process::id(), &my_start());
    ok(d, &["build", scene, "-o", "s.tess", "--depth", "5"]);
    let out = run(d, &["convert", "s.tess", "-o", "ds", "--parts", "2"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert_eq!(staged(d), [".ds.live01.tmp"], "{err}");
    assert!(
        err.contains(&killed[0]) && err.contains(".ds.dead01.tmp"),
        "{err}"
    );
    assert!(err.contains("killed"), "{err}");
    assert!(d.join("ds/manifest.json").is_file());
    assert!(!d.join("ds/.tesseral-staged").exists());
    // `build --parts` sweeps too.
    plant(d, ".ds.dead02.tmp", dead.id(), "-");
    ok(
        d,
        &["build", scene, "--parts", "2", "-o", "ds", "--depth", "5"],
    );
    assert_eq!(staged(d), [".ds.live01.tmp"]);
}
