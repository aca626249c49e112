//! `tesseral convert` and the file formats, through the real binary: a round trip
//! for every format, meshes out and in, and the error paths.

use std::collections::BTreeSet;
use std::path::Path;

mod common;
use common::{ok, run};

/// The voxels listed in a `.xyz` file.
fn voxel_set(path: &Path) -> BTreeSet<[i64; 3]> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let v: Vec<i64> = l.split_whitespace().map(|w| w.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

/// A solid with negative coordinates, a merged block and scattered voxels.
fn sample(dir: &Path) -> BTreeSet<[i64; 3]> {
    let mut set = BTreeSet::new();
    for x in -8..0 {
        for y in 0..8 {
            for z in -4..4 {
                set.insert([x, y, z]);
            }
        }
    }
    let mut s = 17u64;
    for _ in 0..200 {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let r = |k: u32| ((s >> k) % 40) as i64 - 20;
        set.insert([r(10), r(20), r(30)]);
    }
    let text: String = set
        .iter()
        .map(|v| format!("{} {} {}\n", v[0], v[1], v[2]))
        .collect();
    std::fs::write(dir.join("a.xyz"), text).unwrap();
    set
}

#[test]
fn every_voxel_format_round_trips() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let want = sample(d);
    for ext in ["tess", "binvox", "vox", "bt", "ot", "xyz"] {
        let file = format!("r.{ext}");
        let back = format!("back_{ext}.xyz");
        ok(d, &["convert", "a.xyz", &file]);
        ok(d, &["convert", &file, &back]);
        assert_eq!(voxel_set(&d.join(&back)), want_for(ext, &want), "{ext}");
    }
}

/// `.vox` has no placement: it keeps the shape, moved to non-negative coordinates.
fn want_for(ext: &str, want: &BTreeSet<[i64; 3]>) -> BTreeSet<[i64; 3]> {
    if ext != "vox" {
        return want.clone();
    }
    let lo = [0, 1, 2].map(|a| want.iter().map(|v| v[a]).min().unwrap());
    want.iter()
        .map(|v| [v[0] - lo[0], v[1] - lo[1], v[2] - lo[2]])
        .collect()
}

#[test]
fn every_command_reads_every_format() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let want = sample(d);
    for ext in ["tess", "binvox", "bt", "ot"] {
        let file = format!("a.{ext}");
        ok(d, &["convert", "a.xyz", &file]);
        let info = ok(d, &["info", &file, "--json"]);
        let json: serde_json::Value = serde_json::from_str(info.trim()).unwrap();
        assert_eq!(json["voxels"], want.len() as u64, "{ext}: {info}");
    }
}

#[test]
fn convert_json_reports_the_frame() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let want = sample(d);
    ok(d, &["convert", "a.xyz", "a.bt"]);
    let out = ok(d, &["convert", "a.bt", "a.tess", "--json"]);
    let json: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    assert_eq!(json["voxels"], want.len() as u64);
    assert_eq!(json["depth"], 16);
    assert_eq!(json["origin"], serde_json::json!([-32768, -32768, -32768]));
    assert_eq!(json["voxel_size"], 1.0);
}

fn box_stl(lo: [f64; 3], hi: [f64; 3], drop_last: bool) -> String {
    let p = |i: usize| {
        [
            if i & 1 == 1 { hi[0] } else { lo[0] },
            if i & 2 == 2 { hi[1] } else { lo[1] },
            if i & 4 == 4 { hi[2] } else { lo[2] },
        ]
    };
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let mut tris: Vec<[usize; 3]> = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    if drop_last {
        tris.pop();
    }
    let mut s = String::from("solid box\n");
    for t in tris {
        s += "facet normal 0 0 0\nouter loop\n";
        for i in t {
            let v = p(i);
            s += &format!("vertex {} {} {}\n", v[0], v[1], v[2]);
        }
        s += "endloop\nendfacet\n";
    }
    s + "endsolid box\n"
}

#[test]
fn an_stl_box_voxelizes_to_the_exact_count() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("box.stl"),
        box_stl([0.0, 0.0, 0.0], [10.0, 6.0, 4.0], false),
    )
    .unwrap();
    let out = ok(
        d,
        &[
            "convert",
            "box.stl",
            "box.xyz",
            "--voxel-size",
            "0.5",
            "--json",
        ],
    );
    let json: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    assert_eq!(json["voxels"], 20 * 12 * 8);
    assert_eq!(voxel_set(&d.join("box.xyz")).len(), 20 * 12 * 8);
    // By depth: 2^4 voxels along the longest side (10 units), 0.625 each. Centres
    // (i + 0.5) · 0.625 inside: x 16, y 10 (below 6), z 6 (below 4).
    let out = ok(
        d,
        &["convert", "box.stl", "box.tess", "--depth", "4", "--json"],
    );
    let json: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    assert_eq!(json["voxels"], 16 * 10 * 6, "{out}");
}

#[test]
fn open_meshes_need_surface_only() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("open.stl"), box_stl([0.0; 3], [4.0; 3], true)).unwrap();
    let out = run(
        d,
        &["convert", "open.stl", "open.tess", "--voxel-size", "1"],
    );
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("not watertight") && err.contains("--surface-only"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!d.join("open.tess").exists());
    let out = ok(
        d,
        &[
            "convert",
            "open.stl",
            "open.tess",
            "--voxel-size",
            "1",
            "--surface-only",
            "--json",
        ],
    );
    let json: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    // The faces lie on voxel boundaries, so each touches the voxels on both sides:
    // the open box's surface voxels are the 6³ − 4³ shell around [0, 4]³ minus the
    // ones only the missing triangle touched, and at least the 4³ − 2³ inner shell.
    let n = json["voxels"].as_u64().unwrap();
    assert!(
        (4 * 4 * 4 - 2 * 2 * 2..=6 * 6 * 6 - 4 * 4 * 4).contains(&n),
        "{out}"
    );
}

/// Checks an OBJ written by us: closed (every edge twice, opposite directions) and
/// enclosing `volume`.
fn check_obj(path: &Path, volume: f64) -> usize {
    let text = std::fs::read_to_string(path).unwrap();
    let mut pos: Vec<[f64; 3]> = Vec::new();
    let mut tris: Vec<[usize; 3]> = Vec::new();
    for l in text.lines() {
        let w: Vec<&str> = l.split_whitespace().collect();
        match w.first() {
            Some(&"v") => pos.push([
                w[1].parse().unwrap(),
                w[2].parse().unwrap(),
                w[3].parse().unwrap(),
            ]),
            Some(&"f") => tris.push([
                w[1].parse::<usize>().unwrap() - 1,
                w[2].parse::<usize>().unwrap() - 1,
                w[3].parse::<usize>().unwrap() - 1,
            ]),
            _ => {}
        }
    }
    let mut edges = std::collections::HashMap::new();
    let mut vol = 0.0;
    for t in &tris {
        for e in 0..3 {
            *edges.entry((t[e], t[(e + 1) % 3])).or_insert(0) += 1;
        }
        let [a, b, c] = t.map(|i| pos[i]);
        vol += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
            + a[2] * (b[0] * c[1] - b[1] * c[0]))
            / 6.0;
    }
    for (&(a, b), &n) in &edges {
        assert_eq!(n, 1, "edge {a}-{b} used {n} times");
        assert_eq!(edges.get(&(b, a)), Some(&1), "edge {a}-{b} has no twin");
    }
    assert!(
        (vol - volume).abs() < 1e-6 * volume.max(1.0),
        "volume {vol} != {volume}"
    );
    tris.len()
}

#[test]
fn meshes_out_are_watertight_with_the_voxel_volume() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let want = sample(d);
    ok(d, &["convert", "a.xyz", "a.obj"]);
    let tris = check_obj(&d.join("a.obj"), want.len() as f64);
    assert!(
        tris < 12 * want.len(),
        "greedy merging should beat 12 per voxel: {tris}"
    );
    for ext in ["stl", "ply", "glb"] {
        ok(d, &["convert", "a.xyz", &format!("a.{ext}")]);
    }
    assert_eq!(&std::fs::read(d.join("a.glb")).unwrap()[..4], b"glTF");
    assert!(std::fs::read(d.join("a.ply"))
        .unwrap()
        .starts_with(b"ply\n"));
    // Our STL and PLY read back: the voxelized mesh is the voxels again.
    for ext in ["stl", "ply", "obj"] {
        ok(
            d,
            &[
                "convert",
                &format!("a.{ext}"),
                &format!("again_{ext}.xyz"),
                "--voxel-size",
                "1",
            ],
        );
        assert_eq!(
            voxel_set(&d.join(format!("again_{ext}.xyz"))),
            want,
            "{ext}"
        );
    }
    // Smooth output is closed too.
    ok(d, &["convert", "a.xyz", "s.obj", "--smooth"]);
    let text = std::fs::read_to_string(d.join("s.obj")).unwrap();
    assert!(text.lines().any(|l| l.starts_with("f ")));
}

#[test]
fn bad_input_gives_one_line_errors_and_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    sample(d);
    ok(d, &["convert", "a.xyz", "a.tess"]);
    let bytes = std::fs::read(d.join("a.tess")).unwrap();
    std::fs::write(d.join("cut.tess"), &bytes[..bytes.len() / 2]).unwrap();
    std::fs::write(d.join("bad.obj"), "v 0 0 0\nv 1 1 q\n").unwrap();
    std::fs::write(
        d.join("bad.bt"),
        "# Octomap OcTree binary file\nid OcTree\nsize 9\nres 0.1\ndata\n\x03",
    )
    .unwrap();
    for (args, needle) in [
        (vec!["convert", "cut.tess", "x.xyz"], "cut.tess"),
        (vec!["convert", "bad.obj", "x.xyz"], "bad.obj:2:7"),
        (vec!["convert", "bad.bt", "x.xyz"], "bad.bt"),
        (
            vec!["convert", "a.xyz", "x.unknown"],
            "does not write .unknown",
        ),
        (vec!["convert", "missing.binvox", "x.xyz"], "missing.binvox"),
        (
            vec!["convert", "a.xyz", "x.stl", "--depth", "40"],
            "--depth",
        ),
    ] {
        let out = run(d, &args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(!d.join("x.xyz").exists());
    }
}
