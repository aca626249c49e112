//! Integration tests of `tesseral map`: the real binary on scan files of every
//! format, its options and errors, and the map it writes used as a model.

use std::fmt::Write as _;
use std::fs;

mod common;
use common::{fails, json, ok, run};
use tesseral::io::scan::{graph, PointFrame, ScanRecord};

/// A room-like scan seen from `origin`: points on the walls of a box around it.
fn room_points(seed: u64, n: usize) -> Vec<[f64; 3]> {
    let mut s = seed;
    let mut next = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 11) as f64) / ((1u64 << 53) as f64)
    };
    (0..n)
        .map(|_| {
            // A direction, scaled until it meets the box [-2, 3] x [-1.5, 2] x [-0.5, 1.2].
            let d = [next() - 0.5, next() - 0.5, next() - 0.5];
            let lo = [-2.0, -1.5, -0.5];
            let hi = [3.0, 2.0, 1.2];
            let t = (0..3)
                .map(|k| {
                    if d[k] > 0.0 {
                        hi[k] / d[k]
                    } else if d[k] < 0.0 {
                        lo[k] / d[k]
                    } else {
                        f64::INFINITY
                    }
                })
                .fold(f64::INFINITY, f64::min);
            d.map(|x| f64::from((x * t) as f32))
        })
        .collect()
}

fn log_text(scans: &[ScanRecord]) -> String {
    let mut s = String::from("# synthetic\n");
    for sc in scans {
        let [x, y, z] = sc.translation;
        let [r, p, w] = sc.rpy;
        writeln!(s, "NODE {x} {y} {z} {r} {p} {w}").unwrap();
        for q in &sc.points {
            writeln!(s, "{} {} {}", q[0], q[1], q[2]).unwrap();
        }
    }
    s
}

fn two_scans() -> Vec<ScanRecord> {
    vec![
        ScanRecord {
            points: room_points(1, 400),
            ..Default::default()
        },
        ScanRecord {
            translation: [0.5, 0.25, 0.0],
            rpy: [0.0, 0.0, 0.5],
            points: room_points(2, 400),
            frame: PointFrame::Sensor,
        },
    ]
}

fn setup() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let scans = two_scans();
    fs::write(dir.path().join("room.log"), log_text(&scans)).unwrap();
    fs::write(dir.path().join("room.graph"), graph::encode(&scans)).unwrap();
    let cloud = &scans[0].points;
    let mut xyz = String::new();
    for p in cloud {
        writeln!(xyz, "{} {} {}", p[0], p[1], p[2]).unwrap();
    }
    fs::write(dir.path().join("cloud.xyz"), &xyz).unwrap();
    let mut ply = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nend_header\n",
        cloud.len()
    )
    .into_bytes();
    for p in cloud {
        for x in p {
            ply.extend_from_slice(&(*x as f32).to_le_bytes());
        }
    }
    fs::write(dir.path().join("cloud.ply"), ply).unwrap();
    let pcd = format!(
        "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA ascii\n{xyz}",
        n = cloud.len()
    );
    fs::write(dir.path().join("cloud.pcd"), pcd).unwrap();
    dir
}

const KEYS: [&str; 9] = [
    "scans",
    "points",
    "rays",
    "occupied",
    "free",
    "leaves",
    "bytes",
    "seconds",
    "rays_per_second",
];

#[test]
fn json_has_exactly_the_keys_and_counts_add_up() {
    let dir = setup();
    let d = dir.path();
    let v = json(
        d,
        &[
            "map",
            "room.log",
            "-o",
            "map.bt",
            "--resolution",
            "0.1",
            "--json",
        ],
    );
    let mut keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
    keys.sort_unstable();
    let mut want = KEYS.to_vec();
    want.sort_unstable();
    assert_eq!(keys, want);
    assert_eq!(v["scans"], 2);
    assert_eq!(v["points"], 800);
    assert_eq!(v["rays"], 800);
    assert!(v["occupied"].as_u64().unwrap() > 100, "{v}");
    assert!(
        v["free"].as_u64().unwrap() > v["occupied"].as_u64().unwrap(),
        "{v}"
    );
    assert!(v["leaves"].as_u64().unwrap() > 0);
    assert!(v["bytes"].as_u64().unwrap() > 0);
    assert!(v["rays_per_second"].as_f64().unwrap() > 0.0);
    assert!(d.join("map.bt").exists());
    // The text report names the file.
    let text = ok(
        d,
        &["map", "room.log", "-o", "map2.bt", "--resolution", "0.1"],
    );
    assert!(
        text.contains("wrote map2.bt: 2 scans, 800 points"),
        "{text}"
    );
}

#[test]
fn graph_and_log_make_the_same_map_and_clouds_agree_across_formats() {
    let dir = setup();
    let d = dir.path();
    ok(
        d,
        &["map", "room.log", "-o", "log.tess", "--resolution", "0.1"],
    );
    ok(
        d,
        &[
            "map",
            "room.graph",
            "-o",
            "graph.tess",
            "--resolution",
            "0.1",
        ],
    );
    assert_eq!(
        fs::read(d.join("log.tess")).unwrap(),
        fs::read(d.join("graph.tess")).unwrap()
    );
    // One scan at the origin: the same map from every cloud format.
    let mut first = None;
    for f in ["cloud.xyz", "cloud.ply", "cloud.pcd"] {
        let out = format!("{f}.tess");
        ok(d, &["map", f, "-o", &out, "--resolution", "0.1"]);
        let bytes = fs::read(d.join(&out)).unwrap();
        assert_eq!(first.get_or_insert_with(|| bytes.clone()), &bytes, "{f}");
    }
    // Several files make one map: the log equals its two scans given one by one.
    let mut log1 = String::new();
    let scans = two_scans();
    log1.push_str(&log_text(&scans[..1]));
    fs::write(d.join("a.log"), log1).unwrap();
    fs::write(d.join("b.log"), log_text(&scans[1..])).unwrap();
    let v = json(
        d,
        &[
            "map",
            "a.log",
            "b.log",
            "-o",
            "ab.tess",
            "--resolution",
            "0.1",
            "--json",
        ],
    );
    assert_eq!(v["scans"], 2);
    assert_eq!(
        fs::read(d.join("ab.tess")).unwrap(),
        fs::read(d.join("log.tess")).unwrap()
    );
}

#[test]
fn origin_and_pose_place_a_cloud() {
    let dir = setup();
    let d = dir.path();
    // The second scan's pose given on the command line equals the log's node.
    let scans = two_scans();
    fs::write(d.join("second.log"), log_text(&scans[1..])).unwrap();
    let mut xyz = String::new();
    for p in &scans[1].points {
        writeln!(xyz, "{} {} {}", p[0], p[1], p[2]).unwrap();
    }
    fs::write(d.join("second.xyz"), xyz).unwrap();
    ok(
        d,
        &["map", "second.log", "-o", "a.tess", "--resolution", "0.1"],
    );
    ok(
        d,
        &[
            "map",
            "second.xyz",
            "-o",
            "b.tess",
            "--resolution",
            "0.1",
            "--pose",
            "0.5,0.25,0,0,0,0.5",
        ],
    );
    assert_eq!(
        fs::read(d.join("a.tess")).unwrap(),
        fs::read(d.join("b.tess")).unwrap()
    );
    // --origin moves the sensor, not the points: the occupied cells stay.
    let a = json(
        d,
        &[
            "map",
            "cloud.xyz",
            "-o",
            "o1.bt",
            "--resolution",
            "0.1",
            "--json",
        ],
    );
    let b = json(
        d,
        &[
            "map",
            "cloud.xyz",
            "-o",
            "o2.bt",
            "--resolution",
            "0.1",
            "--origin",
            "-1,-1,0",
            "--json",
        ],
    );
    assert_eq!(a["rays"], b["rays"]);
    assert_ne!(
        fs::read(d.join("o1.bt")).unwrap(),
        fs::read(d.join("o2.bt")).unwrap(),
        "the free space differs"
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
            "--origin",
            "0,0,0",
        ],
        "carries a pose",
    );
    fails(
        d,
        &[
            "map",
            "cloud.xyz",
            "-o",
            "x.bt",
            "--resolution",
            "0.1",
            "--origin",
            "0,0",
        ],
        "3 comma-separated",
    );
    fails(
        d,
        &[
            "map",
            "cloud.xyz",
            "-o",
            "x.bt",
            "--resolution",
            "0.1",
            "--origin",
            "0,0,0",
            "--pose",
            "0,0,0,0,0,0",
        ],
        "cannot be used with",
    );
}

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
        "line 7: PCD `DATA binary_compressed` is not supported",
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
    fails(
        d,
        &["map", "far.log", "-o", "far.bt", "--resolution", "0.01"],
        "−32768..32767",
    );
    fails(
        d,
        &["map", "far.log", "-o", "far.ot", "--resolution", "0.01"],
        "−32768..32767",
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
fn the_map_is_a_model_with_its_frame() {
    let dir = setup();
    let d = dir.path();
    let v = json(
        d,
        &[
            "map",
            "room.graph",
            "-o",
            "map.ot",
            "--resolution",
            "0.05",
            "--json",
        ],
    );
    // info reads the frame, the free space and the log-odds.
    let info = json(d, &["info", "--json", "map.ot"]);
    assert_eq!(info["voxel_size"], 0.05);
    assert_eq!(info["voxels"], v["occupied"]);
    assert_eq!(info["free_voxels"], v["free"]);
    assert_eq!(info["log_odds"], true);
    // convert keeps it; .bt (maximum likelihood) has the same cells.
    ok(d, &["convert", "map.ot", "map.tess"]);
    ok(d, &["convert", "map.tess", "map.bt"]);
    let bt = json(d, &["info", "--json", "map.bt"]);
    assert_eq!(bt["voxels"], v["occupied"]);
    assert_eq!(bt["free_voxels"], v["free"]);
    assert_eq!(bt["voxel_size"], 0.05);
    // render draws it; the world box is in metres.
    ok(d, &["render", "map.bt", "-o", "map.png", "--size", "64x48"]);
    let png = fs::read(d.join("map.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG"));
    // The world box is in metres: the room's walls at x = -2 and 3 are in it.
    let lo = info["world_min"][0].as_f64().unwrap();
    let hi = info["world_max"][0].as_f64().unwrap();
    assert!(
        (-2.5..=-2.0).contains(&lo) && (3.0..4.0).contains(&hi),
        "{info}"
    );
    // Standard output takes the map with --format.
    let out = run(
        d,
        &[
            "map",
            "room.graph",
            "-o",
            "-",
            "--format",
            "tess",
            "--resolution",
            "0.05",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out
        .stdout
        .starts_with(&fs::read(d.join("map.tess")).unwrap()[..4]));
    assert!(String::from_utf8_lossy(&out.stderr).contains("wrote -"));
}

#[test]
fn a_far_point_is_refused_before_it_is_cast_unless_cut_or_budgeted() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A corrupt return a million kilometres away: 2·10^10 cells at 5 cm.
    fs::write(
        d.join("far.log"),
        "NODE 0 0 0 0 0 0\n1 0 0\nNODE 0 0 0 0 0 0\n1 1 0\n1e9 0 0\n",
    )
    .unwrap();
    let args = ["map", "far.log", "-o", "far.tess", "--resolution", "0.05"];
    fails(d, &args, "far.log: scan 2 of 2: its 2 rays may cross");
    fails(
        d,
        &args,
        "past --max-cells 10000000000: cut long rays with --max-range",
    );
    assert!(!d.join("far.tess").exists());
    // The same point, posed in the sensor frame by --pose: lengths do not change.
    fs::write(d.join("far.xyz"), "1 0 0\n0 0 1e9\n").unwrap();
    fails(
        d,
        &[
            "map",
            "far.xyz",
            "-o",
            "far.tess",
            "--resolution",
            "0.05",
            "--pose",
            "5,5,5,0.1,0.2,0.3",
        ],
        "the longest is 1.000000e9 m",
    );
    // Cut by --max-range, it is a free ray of 200 cells.
    let mut cut = args.to_vec();
    cut.extend(["--max-range", "10", "--json"]);
    let v = json(d, &cut);
    assert_eq!(v["rays"], 3);
    // A smaller budget refuses an ordinary scan, naming the flag.
    let mut small = args.to_vec();
    small.extend(["--max-range", "10", "--max-cells", "30"]);
    fails(d, &small, "scan 1 of 2: its ray may cross");
}
