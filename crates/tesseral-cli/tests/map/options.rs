//! `tesseral map`'s sensor options, its errors on bad scans, and OctoMap's key range.

use super::*;

#[test]
fn sensor_options_change_the_map() {
    let dir = setup();
    let d = dir.path();
    let base = ["map", "room.log", "--resolution", "0.1", "--json", "-o"];
    let with = |out: &str, extra: &[&str]| {
        let mut a: Vec<&str> = base.to_vec();
        a.push(out);
        a.extend_from_slice(extra);
        json(d, &a)
    };
    let plain = with("plain.ot", &[]);
    // Rays cut at 1 m: fewer hits, the cut rays free only up to the range.
    let cut = with("cut.ot", &["--max-range", "1"]);
    assert!(
        cut["occupied"].as_u64() < plain["occupied"].as_u64(),
        "{cut} {plain}"
    );
    assert!(cut["free"].as_u64() < plain["free"].as_u64());
    // A threshold above a single hit's probability: one hit is not occupied.
    let strict = with("strict.ot", &["--threshold", "0.9"]);
    assert!(
        strict["occupied"].as_u64() < plain["occupied"].as_u64(),
        "{strict}"
    );
    // Other hit and miss probabilities change the log-odds stored in the .ot.
    with(
        "odds.ot",
        &[
            "--prob-hit",
            "0.9",
            "--prob-miss",
            "0.2",
            "--clamp",
            "0.05,0.99",
        ],
    );
    assert_ne!(
        fs::read(d.join("odds.ot")).unwrap(),
        fs::read(d.join("plain.ot")).unwrap()
    );
    fails(
        d,
        &[
            "map",
            "room.log",
            "-o",
            "x.bt",
            "--resolution",
            "0.1",
            "--prob-hit",
            "0.4",
        ],
        "hit",
    );
    fails(
        d,
        &[
            "map",
            "room.log",
            "-o",
            "x.bt",
            "--resolution",
            "0.1",
            "--clamp",
            "0.9,0.1",
        ],
        "clamp",
    );
    fails(
        d,
        &["map", "room.log", "-o", "x.bt", "--resolution", "0"],
        "--resolution",
    );
    fails(
        d,
        &[
            "map",
            "room.log",
            "-o",
            "x.bt",
            "--resolution",
            "0.1",
            "--max-range",
            "-1",
        ],
        "--max-range",
    );
    assert!(!d.join("x.bt").exists());
}

#[test]
fn bad_scans_are_errors_naming_file_and_place() {
    let dir = setup();
    let d = dir.path();
    fs::write(d.join("bad.log"), "NODE 0 0 0 0 0 0\n1 2 3\n1 zz 3\n").unwrap();
    fails(
        d,
        &["map", "bad.log", "-o", "m.bt", "--resolution", "0.1"],
        "bad.log:3:3",
    );
    fs::write(d.join("orphan.log"), "1 2 3\n").unwrap();
    fails(
        d,
        &["map", "orphan.log", "-o", "m.bt", "--resolution", "0.1"],
        "before the first `NODE",
    );
    let mut g = graph::encode(&two_scans());
    g.truncate(5000);
    fs::write(d.join("cut.graph"), g).unwrap();
    fails(
        d,
        &["map", "cut.graph", "-o", "m.bt", "--resolution", "0.1"],
        "cut.graph: byte 4: node 0 claims 400 points; the file is too short",
    );
    fs::write(d.join("z.pcd"), "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nPOINTS 1\nDATA binary_compressed\n").unwrap();
    fails(
        d,
        &["map", "z.pcd", "-o", "m.bt", "--resolution", "0.1"],
        "z.pcd: byte 91: `binary_compressed` data needs its two sizes (8 bytes)",
    );
    fails(
        d,
        &["map", "room.txt", "-o", "m.bt", "--resolution", "0.1"],
        "not a scan file",
    );
    fails(
        d,
        &["map", "missing.log", "-o", "m.bt", "--resolution", "0.1"],
        "missing.log",
    );
    fails(
        d,
        &["map", "room.log", "-o", "m.jpg", "--resolution", "0.1"],
        "does not write .jpg",
    );
    fails(
        d,
        &["map", "cloud.xyz", "-o", "cloud.xyz", "--resolution", "0.1"],
        "refusing to overwrite an input",
    );
    assert!(!d.join("m.bt").exists());
}

#[test]
fn a_map_beyond_octomap_keys_is_refused_in_bt_and_kept_in_tess() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // 2,000 m at 1 cm is 200,000 cells from the origin: past OctoMap's 32,768.
    fs::write(d.join("far.log"), "NODE 0 0 0 0 0 0\n2000 0 0\n").unwrap();
    // Refused before the scan is cast, naming the scan and the cell.
    fails(
        d,
        &["map", "far.log", "-o", "far.bt", "--resolution", "0.01"],
        "far.log: scan 1 of 1: a ray reaches cell (200000, 0, 0), outside OctoMap's key range (cells −32768..32767",
    );
    fails(
        d,
        &["map", "far.log", "-o", "far.ot", "--resolution", "0.01"],
        "−32768..32767",
    );
    fails(
        d,
        &[
            "map",
            "far.log",
            "-o",
            "-",
            "--format",
            "bt",
            "--resolution",
            "0.01",
        ],
        "−32768..32767",
    );
    assert!(!d.join("far.bt").exists() && !d.join("far.ot").exists());
    // Cut at 300 m (30,000 cells) the rays stay inside: written.
    let v = json(
        d,
        &[
            "map",
            "far.log",
            "-o",
            "cut.bt",
            "--resolution",
            "0.01",
            "--max-range",
            "300",
            "--json",
        ],
    );
    assert_eq!(
        (v["occupied"].as_u64(), v["free"].as_u64()),
        (Some(0), Some(30_000))
    );
    // A sensor outside the range is refused whatever the range of its rays.
    fs::write(d.join("off.log"), "NODE 400 0 0 0 0 0\n1 0 0\n").unwrap();
    fails(
        d,
        &[
            "map",
            "off.log",
            "-o",
            "off.bt",
            "--resolution",
            "0.01",
            "--max-range",
            "1",
        ],
        "reaches cell (40000, 0, 0)",
    );
    let v = json(
        d,
        &[
            "map",
            "far.log",
            "-o",
            "far.tess",
            "--resolution",
            "0.01",
            "--json",
        ],
    );
    assert_eq!(v["occupied"], 1);
    assert_eq!(v["free"], 200_000);
    let info = json(d, &["info", "--json", "far.tess"]);
    assert_eq!(info["voxels"], 1);
    assert_eq!(info["free_voxels"], 200_000);
}

#[test]
fn a_map_wider_than_a_model_is_kept_whole_in_its_own_tess() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // 3,000,000 cells apart at 1 m: past a model's 2^21 cells on an axis.
    fs::write(
        d.join("wide.log"),
        "NODE 0.5 0.5 0.5 0 0 0\n1 0 0\nNODE 3000000.5 0.5 0.5 0 0 0\n1 0 0\n",
    )
    .unwrap();
    let v = json(
        d,
        &[
            "map",
            "wide.log",
            "-o",
            "wide.tess",
            "--resolution",
            "1",
            "--json",
        ],
    );
    assert_eq!(
        (v["occupied"].as_u64(), v["free"].as_u64()),
        (Some(2), Some(2))
    );
    let info = json(d, &["info", "--json", "wide.tess"]);
    assert_eq!(info["kind"], "occupancy_map");
    assert_eq!(
        (info["voxels"].as_u64(), info["blocks"].as_u64()),
        (Some(2), Some(2))
    );
    assert_eq!(info["bbox_max"][0], 3_000_007);
    assert_eq!(info["threshold"], 0.5);
    // Every command that needs a model says why it cannot have one, and what reads it.
    fails(
        d,
        &["render", "wide.tess", "-o", "wide.png", "--size", "8x8"],
        "wider than a model holds (2^21 cells on an axis), in the map's own .tess",
    );
    fails(
        d,
        &["convert", "wide.tess", "wide.bt"],
        "tesseral.OccupancyMap.read",
    );
    assert!(!d.join("wide.png").exists() && !d.join("wide.bt").exists());
}

#[test]
fn an_ot_of_a_map_with_its_own_threshold_is_written_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::write(d.join("one.xyz"), "1.05 0.05 0.05\n").unwrap();
    let args = |out: &'static str, threshold: &'static str| {
        [
            "map",
            "one.xyz",
            "--origin",
            "0.05,0.05,0.05",
            "-o",
            out,
            "--resolution",
            "0.1",
            "--threshold",
            threshold,
        ]
    };
    let out = run(d, &args("t.ot", "0.75"));
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("warning: t.ot") && err.contains("not the threshold"),
        "{err}"
    );
    for (file, threshold) in [("t.bt", "0.75"), ("d.ot", "0.5")] {
        let out = run(d, &args(file, threshold));
        assert!(out.status.success() && out.stderr.is_empty(), "{out:?}");
    }
}

#[test]
fn max_output_counts_the_free_space_and_log_odds_of_a_map() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::write(d.join("line.xyz"), "1000 0 0\n").unwrap();
    // 20,000 free cells: their leaves and log-odds, not the one occupied cell, make
    // the file's size.
    fails(
        d,
        &[
            "map",
            "line.xyz",
            "--origin",
            "0,0,0",
            "-o",
            "k.tess",
            "--resolution",
            "0.05",
            "--max-output",
            "1K",
        ],
        "--max-output",
    );
    assert!(!d.join("k.tess").exists());
    ok(
        d,
        &[
            "map",
            "line.xyz",
            "--origin",
            "0,0,0",
            "-o",
            "k.tess",
            "--resolution",
            "0.05",
        ],
    );
    fails(
        d,
        &["convert", "k.tess", "k2.tess", "--max-output", "1K"],
        "--max-output",
    );
    assert!(!d.join("k2.tess").exists());
}

#[test]
fn negative_probabilities_are_read_and_refused_and_empty_scans_warned() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::write(d.join("one.xyz"), "1 0 0\n").unwrap();
    fs::write(d.join("empty.xyz"), "").unwrap();
    let base = [
        "map",
        "one.xyz",
        "--origin",
        "0,0,0",
        "-o",
        "m.bt",
        "--resolution",
        "0.1",
    ];
    // A negative value after the flag is the value, refused by the sensor model.
    for (flag, needle) in [
        ("--prob-hit", "hit probability -1 is not in (0, 1)"),
        ("--prob-miss", "miss probability -1 is not in (0, 1)"),
        ("--threshold", "threshold -1 is not in (0, 1)"),
    ] {
        let mut args = base.to_vec();
        args.extend([flag, "-1"]);
        fails(d, &args, needle);
    }
    let out = run(
        d,
        &[
            "map",
            "empty.xyz",
            "--origin",
            "0,0,0",
            "-o",
            "e.bt",
            "--resolution",
            "0.1",
        ],
    );
    assert!(out.status.success(), "{out:?}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("warning: the scans hold no points"), "{err}");
}
