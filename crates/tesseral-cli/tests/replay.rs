//! Integration tests of `tesseral replay`: the real binary, in a temporary directory.

use std::collections::HashSet;
use std::io::Write;
use std::process::{Command, Output, Stdio};

fn tesseral() -> Command {
    Command::new(env!("CARGO_BIN_EXE_tesseral"))
}

fn replay_file(body: &str, extra: &[&str]) -> (Output, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ops.txt");
    std::fs::write(&path, body).unwrap();
    let out = tesseral()
        .arg("replay")
        .arg(&path)
        .args(extra)
        .current_dir(dir.path())
        .output()
        .unwrap();
    (out, dir)
}

fn stdout_lines(out: &Output) -> Vec<String> {
    String::from_utf8(out.stdout.clone())
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect()
}

fn report(out: &Output) -> serde_json::Value {
    let lines = stdout_lines(out);
    serde_json::from_str(lines.last().expect("a JSON line")).expect("valid JSON")
}

#[test]
fn queries_print_in_order_and_the_report_has_every_key() {
    let body = "# two cubes side by side\n+ 0 0 0\n+ 1 0 0\n? 1 0 0\n? 2 0 0\n\n- 1 0 0\n? 1 0 0\n? 0 0 0\n";
    for extra in [&[][..], &["--track-faces"][..]] {
        let (out, _dir) = replay_file(body, extra);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let lines = stdout_lines(&out);
        assert_eq!(&lines[..4], &["1", "0", "0", "1"]);
        assert_eq!(lines.len(), 5);
        let r = report(&out);
        assert_eq!(r["voxels"], 1);
        assert_eq!(r["faces"], 6);
        assert_eq!(r["root_size_log2"], 0);
        assert_eq!(r["root_min"], serde_json::json!([0, 0, 0]));
        assert_eq!(r["expansions"], 1);
        assert_eq!(r["contractions"], 1);
        assert_eq!(r["nodes"], 1);
        assert!(r["bytes"].as_u64().unwrap() > 0);
    }
}

#[test]
fn a_string_to_two_to_the_60_costs_sixty_expansions() {
    let mut body = String::from("+ 0 0 0\n");
    for i in 0..60 {
        body.push_str(&format!("+ {} 0 0\n", 1u64 << i));
    }
    body.push_str(&format!(
        "+ {} 0 0\n? {} 0 0\n",
        (1u64 << 60) - 1,
        1u64 << 59
    ));
    let (out, _dir) = replay_file(&body, &[]);
    assert!(out.status.success());
    let r = report(&out);
    assert_eq!(r["expansions"], 60);
    assert_eq!(r["root_size_log2"], 60);
    assert_eq!(r["voxels"], 62);
    assert_eq!(stdout_lines(&out)[0], "1");
}

#[test]
fn random_log_matches_a_hashset_model() {
    // A seeded pseudo-random log, its expected query answers and final counts computed
    // with a HashSet.
    let mut s = 12345u64;
    let mut next = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        s >> 33
    };
    let mut set = HashSet::new();
    let mut body = String::new();
    let mut answers = Vec::new();
    for _ in 0..3000 {
        let v = [
            (next() % 9) as i64 - 4,
            (next() % 9) as i64 - 4,
            ((next() % 9) as i64 - 4) * 1_000_000_007,
        ];
        match next() % 3 {
            0 => {
                body.push_str(&format!("+ {} {} {}\n", v[0], v[1], v[2]));
                set.insert(v);
            }
            1 => {
                body.push_str(&format!("-\t{}  {} {}\n", v[0], v[1], v[2]));
                set.remove(&v);
            }
            _ => {
                body.push_str(&format!("? {} {} {}\n", v[0], v[1], v[2]));
                answers.push(if set.contains(&v) { "1" } else { "0" }.to_string());
            }
        }
    }
    let (out, _dir) = replay_file(&body, &[]);
    assert!(out.status.success());
    let lines = stdout_lines(&out);
    assert_eq!(&lines[..lines.len() - 1], &answers[..]);
    let pairs: usize = set
        .iter()
        .map(|v| {
            [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
                .iter()
                .filter(|d| set.contains(&[v[0] + d[0], v[1] + d[1], v[2] + d[2]]))
                .count()
        })
        .sum();
    let r = report(&out);
    assert_eq!(r["voxels"], set.len());
    assert_eq!(r["faces"], 6 * set.len() - 2 * pairs);
}

#[test]
fn malformed_lines_name_the_line_and_how_many_were_applied() {
    let cases = [
        (
            "+ 0 0 0\n? 0 0 0\n+ 1 2\n",
            "line 3",
            "2 lines applied",
            "3 coordinates",
        ),
        (
            "+ 0 0 0\n* 1 2 3\n",
            "line 2",
            "1 lines applied",
            "unknown operation '*'",
        ),
        ("# c\n+ 0 0 zz\n", "line 2", "1 lines applied", "'zz'"),
        (
            "+ 0 0 99999999999999999999\n",
            "line 1",
            "0 lines applied",
            "not an integer",
        ),
        ("+ 0 0 0 0\n", "line 1", "0 lines applied", "found 4"),
    ];
    for (body, line, applied, what) in cases {
        let (out, _dir) = replay_file(body, &[]);
        assert_eq!(out.status.code(), Some(2), "{body:?}");
        let err = String::from_utf8(out.stderr).unwrap();
        assert_eq!(err.lines().count(), 1, "one-line message: {err}");
        assert!(err.contains(line), "{err}");
        assert!(err.contains(applied), "{err}");
        assert!(err.contains(what), "{err}");
        assert!(err.contains("ops.txt"), "{err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    // Queries before the bad line were still printed.
    let (out, _dir) = replay_file("+ 0 0 0\n? 0 0 0\nbad\n", &[]);
    assert_eq!(stdout_lines(&out), vec!["1"]);
}

#[test]
fn an_overlong_line_is_an_error_not_a_memory_sink() {
    let body = format!("+ 0 0 0\n+ 1 1 {}\n", "1".repeat(100_000));
    let (out, _dir) = replay_file(&body, &[]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(
        err.contains("line 2") && err.contains("longer than"),
        "{err}"
    );
}

#[test]
fn missing_file_and_stdin() {
    let dir = tempfile::tempdir().unwrap();
    let out = tesseral()
        .args(["replay", "no-such-file.ops"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no-such-file.ops"));

    let mut child = tesseral()
        .args(["replay", "-"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(b"+ -4611686018427387904 4611686018427387904 0\n? -4611686018427387904 4611686018427387904 0\n")
        .unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success());
    assert_eq!(stdout_lines(&out)[0], "1");
    assert_eq!(
        report(&out)["root_min"],
        serde_json::json!([-4611686018427387904i64, 4611686018427387904i64, 0])
    );
}

/// `tesseral info --json FILE` in `dir`, which must succeed.
fn info_json(dir: &std::path::Path, file: &str) -> serde_json::Value {
    let info = tesseral()
        .args(["info", "--json", file])
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        info.status.success(),
        "{}",
        String::from_utf8_lossy(&info.stderr)
    );
    serde_json::from_slice(&info.stdout).unwrap()
}

#[test]
fn replay_o_saves_the_octree_it_built() {
    let body = "+ 0 0 0\n+ 1 0 0\n+ -5 3 2\n+ 7 7 7\n- 7 7 7\n";
    for ext in ["tess", "xyz", "bt", "ot"] {
        let name = format!("built.{ext}");
        let (out, dir) = replay_file(body, &["-o", &name]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(report(&out)["output"], serde_json::json!(name));
        let v = info_json(dir.path(), &name);
        assert_eq!(v["voxels"], 3, "{ext}: {v}");
    }
}

#[test]
fn replay_o_refuses_stdout_an_unknown_format_and_the_input() {
    let (out, _dir) = replay_file("+ 0 0 0\n", &["-o", "-"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("standard output holds the queries"));
    let (out, dir) = replay_file("+ 0 0 0\n", &["-o", "x.jpg"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("does not write .jpg"));
    assert!(!dir.path().join("x.jpg").exists());
    let (out, dir) = replay_file("+ 0 0 0\n", &["-o", "ops.txt"]);
    assert!(!out.status.success());
    let _ = dir;
    // A map beyond OctoMap's keys is refused in .bt, kept in .tess.
    let (out, _dir) = replay_file("+ 40000 0 0\n+ 40001 0 0\n", &["-o", "far.bt"]);
    assert!(!out.status.success());
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("−32768..32767"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (out, _dir) = replay_file("+ 40000 0 0\n+ 40001 0 0\n", &["-o", "far.tess"]);
    assert!(out.status.success());
}

#[test]
fn replay_o_keeps_an_octree_wider_than_a_model_in_its_own_tess() {
    let body = "+ 0 0 0\n+ 4000000 0 0\n+ -3 1099511627776 -9\n+ 1 0 0\n";
    let (out, dir) = replay_file(body, &["-o", "d.tess"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = std::fs::read(dir.path().join("d.tess")).unwrap();
    assert!(bytes.starts_with(b"\x89TESSDY\n"));
    // Three blocks: two voxels share one, each other voxel has its own.
    assert_eq!(bytes.len(), 32 + 3 * 65 + 4 + 9 + 12, "{}", bytes.len());
    let v = info_json(dir.path(), "d.tess");
    assert_eq!(v["kind"], "dynamic_octree");
    assert_eq!(v["voxels"], 4);
    assert_eq!(v["blocks"], 3);
    assert_eq!(v["bbox_min"], serde_json::json!([-3, 0, -9]));
    assert_eq!(
        v["bbox_max"],
        serde_json::json!([4000000, 1099511627776i64, 0])
    );
    let text = tesseral()
        .args(["info", "d.tess"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&text.stdout).contains("unbounded dynamic octree"));
    // A command that needs a model names the file's kind and how to read it.
    let conv = tesseral()
        .args(["convert", "d.tess", "d.xyz"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(!conv.status.success());
    let e = String::from_utf8_lossy(&conv.stderr);
    assert!(e.contains("DynamicOctree::read_file"), "{e}");
    // Other formats cannot hold it; a narrow octree stays a model .tess.
    let (out, dir) = replay_file(body, &["-o", "d.xyz"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("only .tess keeps it"));
    assert!(!dir.path().join("d.xyz").exists());
    let (out, dir) = replay_file("+ 0 0 0\n+ 2000000 0 0\n", &["-o", "n.tess"]);
    assert!(out.status.success());
    let bytes = std::fs::read(dir.path().join("n.tess")).unwrap();
    assert!(bytes.starts_with(b"\x89TESSRL\n"));
}
