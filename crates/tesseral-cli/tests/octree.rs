//! The octree commands, run as the real binary in a temporary directory.

use std::collections::BTreeSet;
use std::fs;
use std::path::Path;

mod common;
use common::{ok, run};

type Voxels = BTreeSet<[i64; 3]>;

/// Runs a command that must fail with exit code 2 without panicking; returns stderr.
fn fails(dir: &Path, args: &[&str]) -> String {
    let out = run(dir, args);
    assert_eq!(out.status.code(), Some(2), "{args:?} should fail with 2");
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    err
}

fn write_xyz(dir: &Path, name: &str, voxels: &Voxels) {
    let mut text = String::from("# test input\n\n");
    for v in voxels {
        text.push_str(&format!("{} {} {}\n", v[0], v[1], v[2]));
    }
    fs::write(dir.join(name), text).unwrap();
}

fn read_xyz(dir: &Path, name: &str) -> Voxels {
    fs::read_to_string(dir.join(name))
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let v: Vec<i64> = l.split_whitespace().map(|f| f.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

/// A small solid: a 4 x 3 x 2 box plus a few loose voxels, some negative.
fn solid() -> Voxels {
    let mut s = Voxels::new();
    for x in 0..4 {
        for y in 0..3 {
            for z in 0..2 {
                s.insert([x, y, z]);
            }
        }
    }
    s.extend([[-3, 5, 1], [6, -2, 0], [2, 2, 5]]);
    s
}

fn shifted(s: &Voxels, by: [i64; 3]) -> Voxels {
    s.iter()
        .map(|v| [v[0] + by[0], v[1] + by[1], v[2] + by[2]])
        .collect()
}

fn no_temp_files(dir: &Path) {
    for e in fs::read_dir(dir).unwrap() {
        let name = e.unwrap().file_name().into_string().unwrap();
        assert!(!name.ends_with(".tmp"), "temporary file left: {name}");
    }
}

#[test]
fn convert_and_info() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_xyz(d, "a.xyz", &solid());
    ok(d, &["convert", "a.xyz", "b.xyz"]);
    assert_eq!(read_xyz(d, "b.xyz"), solid());
    let text = ok(d, &["info", "a.xyz"]);
    assert!(text.contains("voxels   27"), "{text}");
    let json: serde_json::Value =
        serde_json::from_str(&ok(d, &["info", "a.xyz", "--json"])).unwrap();
    assert_eq!(json["voxels"], 27);
    assert_eq!(json["bbox_min"], serde_json::json!([-3, -2, 0]));
    assert_eq!(json["bbox_max"], serde_json::json!([6, 5, 5]));
    assert_eq!(json["origin"], serde_json::json!([-3, -2, 0]));
    assert_eq!(json["depth"], 4);
    let leaves = json["leaves"].as_u64().unwrap();
    assert_eq!(json["bytes"], 8 * leaves);
    let by_depth: u64 = json["leaves_by_depth"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap())
        .sum();
    assert_eq!(by_depth, leaves);
    for key in [
        "voxels",
        "leaves",
        "depth",
        "origin",
        "bbox_min",
        "bbox_max",
        "leaves_by_depth",
        "bytes",
    ] {
        assert!(json.get(key).is_some(), "missing key {key}");
    }
    // An empty file: a null bounding box.
    fs::write(d.join("empty.xyz"), "# nothing\n").unwrap();
    let json: serde_json::Value =
        serde_json::from_str(&ok(d, &["info", "empty.xyz", "--json"])).unwrap();
    assert_eq!(json["voxels"], 0);
    assert!(json["bbox_min"].is_null());
    no_temp_files(d);
}

#[test]
fn translate_by_both_methods() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_xyz(d, "a.xyz", &solid());
    for (by, arg) in [
        ([4, -50, 0], "4,-50,0"),
        ([37, -11, 5], "37,-11,5"),
        ([-1, 0, 2], "-1,0,2"),
    ] {
        ok(d, &["translate", "a.xyz", "--by", arg, "-o", "lin.xyz"]);
        assert_eq!(read_xyz(d, "lin.xyz"), shifted(&solid(), by), "{arg}");
        let by_eq = format!("--by={arg}");
        let text = ok(
            d,
            &[
                "translate",
                "a.xyz",
                &by_eq,
                "-o",
                "lab.xyz",
                "--method",
                "labels",
            ],
        );
        assert!(text.contains("nodes visited"), "{text}");
        assert_eq!(read_xyz(d, "lab.xyz"), shifted(&solid(), by), "{arg}");
    }
    // Clipping keeps the space (16^3 from (-3, -2, 0)) and counts what left it.
    let text = ok(
        d,
        &[
            "translate",
            "a.xyz",
            "--by",
            "10,0,0",
            "--clip",
            "-o",
            "clip.xyz",
        ],
    );
    let want: Voxels = shifted(&solid(), [10, 0, 0])
        .into_iter()
        .filter(|v| v[0] < -3 + 16)
        .collect();
    let dropped = 27 - want.len();
    assert!(
        text.contains(&format!("clipped: {dropped} voxels")),
        "{text}"
    );
    assert_eq!(read_xyz(d, "clip.xyz"), want);
    no_temp_files(d);
}

#[test]
fn rotate_mirror_scale_complement() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // The space of an .xyz input is fitted: here 4^3 from (0, 0, 0).
    let a: Voxels = [[0, 0, 0], [3, 0, 0], [3, 3, 3]].into();
    write_xyz(d, "a.xyz", &a);
    ok(
        d,
        &[
            "rotate", "a.xyz", "--axis", "z", "--turns", "1", "-o", "r.xyz",
        ],
    );
    // About z, +x goes to +y: (x, y) -> (3 - y, x) in a 4-wide space.
    assert_eq!(
        read_xyz(d, "r.xyz"),
        [[3, 0, 0], [3, 3, 0], [0, 3, 3]].into()
    );
    ok(
        d,
        &[
            "rotate", "a.xyz", "--axis", "z", "--turns", "-1", "-o", "r2.xyz",
        ],
    );
    ok(
        d,
        &[
            "rotate", "r2.xyz", "--axis", "z", "--turns", "1", "-o", "r3.xyz",
        ],
    );
    assert_eq!(read_xyz(d, "r3.xyz"), a);
    ok(d, &["mirror", "a.xyz", "--axis", "x", "-o", "m.xyz"]);
    assert_eq!(
        read_xyz(d, "m.xyz"),
        [[3, 0, 0], [0, 0, 0], [0, 3, 3]].into()
    );
    ok(d, &["scale", "a.xyz", "--by", "2^1", "-o", "up.xyz"]);
    let up = read_xyz(d, "up.xyz");
    assert_eq!(up.len(), 24);
    assert!(up.contains(&[7, 7, 7]) && up.contains(&[6, 0, 1]));
    ok(d, &["scale", "up.xyz", "--by", "2^-1", "-o", "down.xyz"]);
    assert_eq!(read_xyz(d, "down.xyz"), a);
    ok(d, &["scale", "a.xyz", "--by", "2^-2", "-o", "tiny.xyz"]);
    assert_eq!(read_xyz(d, "tiny.xyz"), [[0, 0, 0]].into());
    ok(d, &["complement", "a.xyz", "-o", "c.xyz"]);
    let c = read_xyz(d, "c.xyz");
    assert_eq!(c.len(), 64 - 3);
    assert!(c.iter().all(|v| !a.contains(v)));
    no_temp_files(d);
}

#[test]
fn set_operations() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let a = solid();
    let b = shifted(&solid(), [2, 1, 0]);
    write_xyz(d, "a.xyz", &a);
    write_xyz(d, "b.xyz", &b);
    let cases: [(&str, Voxels); 4] = [
        ("union", a.union(&b).copied().collect()),
        ("intersection", a.intersection(&b).copied().collect()),
        ("difference", a.difference(&b).copied().collect()),
        ("xor", a.symmetric_difference(&b).copied().collect()),
    ];
    for (op, want) in cases {
        ok(d, &["op", op, "a.xyz", "b.xyz", "-o", "out.xyz"]);
        assert_eq!(read_xyz(d, "out.xyz"), want, "{op}");
    }
    no_temp_files(d);
}

#[test]
fn errors_exit_2_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_xyz(d, "a.xyz", &solid());
    fs::write(d.join("bad.xyz"), "0 0 0\n1 2 x\n").unwrap();
    let err = fails(d, &["info", "bad.xyz"]);
    assert!(err.contains("bad.xyz:2:5:"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    let err = fails(d, &["convert", "missing.xyz", "out.xyz"]);
    assert!(err.contains("missing.xyz"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    let err = fails(d, &["convert", "a.xyz", "out.unknown"]);
    assert!(err.contains("out.unknown"), "{err}");
    let err = fails(d, &["convert", "a.xyz", "no/such/dir/out.xyz"]);
    assert!(err.contains("out.xyz"), "{err}");
    fails(d, &["translate", "a.xyz", "--by", "1,2", "-o", "o.xyz"]);
    fails(d, &["translate", "a.xyz", "--by", "1,x,2", "-o", "o.xyz"]);
    let err = fails(
        d,
        &[
            "translate",
            "a.xyz",
            "--by",
            "1,2,3",
            "-o",
            "o.xyz",
            "--method",
            "labels",
            "--clip",
        ],
    );
    assert!(err.contains("--clip"), "{err}");
    // Far enough to need a space deeper than 21: refused, never wrapped.
    let err = fails(
        d,
        &["translate", "a.xyz", "--by", "4000000,0,0", "-o", "o.xyz"],
    );
    assert!(err.contains("depth"), "{err}");
    fails(
        d,
        &[
            "rotate", "a.xyz", "--axis", "w", "--turns", "1", "-o", "o.xyz",
        ],
    );
    fails(d, &["mirror", "a.xyz", "-o", "o.xyz"]);
    fails(d, &["scale", "a.xyz", "--by", "0", "-o", "o.xyz"]);
    fails(d, &["scale", "a.xyz", "--by", "1.5", "-o", "o.xyz"]);
    fails(d, &["scale", "a.xyz", "--by", "2^x", "-o", "o.xyz"]);
    let err = fails(d, &["scale", "a.xyz", "--by", "2^20", "-o", "o.xyz"]);
    assert!(err.contains("depth"), "{err}");
    // A voxel list that would be absurdly long is refused before writing.
    let err = fails(d, &["scale", "a.xyz", "--by", "2^9", "-o", "o.xyz"]);
    assert!(err.contains("--max-output"), "{err}");
    fails(d, &["op", "nand", "a.xyz", "a.xyz", "-o", "o.xyz"]);
    fails(d, &["op", "union", "a.xyz", "bad.xyz", "-o", "o.xyz"]);
    fails(d, &["complement", "bad.xyz", "-o", "o.xyz"]);
    assert!(!d.join("o.xyz").exists(), "no output on failure");
    no_temp_files(d);
}

fn info_json(dir: &Path, file: &str) -> serde_json::Value {
    serde_json::from_str(&ok(dir, &["info", file, "--json"])).unwrap()
}

#[test]
fn native_format_keeps_the_space_through_every_command() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_xyz(d, "a.xyz", &solid());
    ok(d, &["convert", "a.xyz", "a.tess"]);
    let json = info_json(d, "a.tess");
    assert_eq!(json["voxels"], 27);
    assert_eq!(json["origin"], serde_json::json!([-3, -2, 0]));
    assert_eq!(json["depth"], 4);
    // Translation within the 16^3 space keeps it (a .tess remembers its space).
    ok(d, &["translate", "a.tess", "--by", "1,1,1", "-o", "t.tess"]);
    let json = info_json(d, "t.tess");
    assert_eq!(
        (json["depth"].clone(), json["origin"].clone()),
        (serde_json::json!(4), serde_json::json!([-3, -2, 0]))
    );
    ok(d, &["convert", "t.tess", "t.xyz"]);
    assert_eq!(read_xyz(d, "t.xyz"), shifted(&solid(), [1, 1, 1]));
    // Leaving the space grows it by root expansion; both methods agree exactly.
    ok(d, &["translate", "a.tess", "--by=-20,0,3", "-o", "g.tess"]);
    ok(
        d,
        &[
            "translate",
            "a.tess",
            "--by=-20,0,3",
            "-o",
            "g2.tess",
            "--method",
            "labels",
        ],
    );
    assert_eq!(
        fs::read(d.join("g.tess")).unwrap(),
        fs::read(d.join("g2.tess")).unwrap()
    );
    let json = info_json(d, "g.tess");
    assert_eq!(json["depth"], 6);
    // Two root expansions downwards in x: -3 - 16 - 32.
    assert_eq!(json["origin"], serde_json::json!([-51, -2, 0]));
    ok(d, &["convert", "g.tess", "g.xyz"]);
    assert_eq!(read_xyz(d, "g.xyz"), shifted(&solid(), [-20, 0, 3]));
    // The complement is taken within the stored space.
    ok(d, &["complement", "a.tess", "-o", "c.tess"]);
    assert_eq!(info_json(d, "c.tess")["voxels"], 4096 - 27);
    // Set operations between .tess and .xyz operands.
    ok(d, &["op", "union", "a.tess", "t.xyz", "-o", "u.tess"]);
    ok(d, &["convert", "u.tess", "u.xyz"]);
    let want: Voxels = solid()
        .union(&shifted(&solid(), [1, 1, 1]))
        .copied()
        .collect();
    assert_eq!(read_xyz(d, "u.xyz"), want);
    ok(
        d,
        &[
            "rotate", "a.tess", "--axis", "x", "--turns", "2", "-o", "r.tess",
        ],
    );
    ok(
        d,
        &[
            "rotate", "r.tess", "--axis", "x", "--turns", "2", "-o", "r2.tess",
        ],
    );
    assert_eq!(
        fs::read(d.join("a.tess")).unwrap(),
        fs::read(d.join("r2.tess")).unwrap()
    );
    no_temp_files(d);
}

#[test]
fn corrupt_native_files_are_errors_not_panics() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_xyz(d, "a.xyz", &solid());
    ok(d, &["convert", "a.xyz", "a.tess"]);
    let bytes = fs::read(d.join("a.tess")).unwrap();
    // Truncated at every length, and with one byte flipped at every offset.
    for cut in [0, 7, 8, 20, 56, bytes.len() - 5, bytes.len() - 1] {
        fs::write(d.join("cut.tess"), &bytes[..cut]).unwrap();
        for cmd in [
            vec!["info", "cut.tess"],
            vec!["translate", "cut.tess", "--by", "1,0,0", "-o", "o.tess"],
            vec!["op", "union", "a.tess", "cut.tess", "-o", "o.tess"],
        ] {
            let err = fails(d, &cmd);
            assert!(err.contains("cut.tess"), "{cut}: {err}");
            assert_eq!(err.trim().lines().count(), 1, "{err}");
        }
    }
    for i in (0..bytes.len()).step_by(3) {
        let mut b = bytes.clone();
        b[i] ^= 0x5a;
        fs::write(d.join("flip.tess"), &b).unwrap();
        let err = fails(d, &["info", "flip.tess"]);
        assert!(err.contains("flip.tess"), "{i}: {err}");
    }
    assert!(!d.join("o.tess").exists());
    no_temp_files(d);
}
