//! `tesseral map` on every scan format: the JSON report, graph and log against
//! clouds, and an origin or a pose placing a cloud.

use super::*;

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
fn missing_returns_are_skipped_and_counted_in_every_cloud_format() {
    let dir = setup();
    let d = dir.path();
    ok(
        d,
        &[
            "map",
            "cloud.xyz",
            "-o",
            "clean.tess",
            "--resolution",
            "0.1",
        ],
    );
    let clean = fs::read(d.join("clean.tess")).unwrap();
    // The same cloud with a NaN point, an infinite one and a NaN coordinate among
    // finite ones, as sensors write missing returns.
    let mut cloud = two_scans()[0].points.clone();
    let n = cloud.len();
    cloud.insert(3, [f64::NAN; 3]);
    cloud.insert(10, [1.0, f64::INFINITY, 0.0]);
    cloud.push([0.5, 0.5, f64::NAN]);
    let text = |p: &[f64; 3]| {
        let s = |x: f64| {
            if x.is_nan() {
                "nan".to_string()
            } else {
                x.to_string()
            }
        };
        format!("{} {} {}\n", s(p[0]), s(p[1]), s(p[2]))
    };
    let ascii: String = cloud.iter().map(text).collect();
    fs::write(d.join("holes.xyz"), &ascii).unwrap();
    let head = |format: &str| {
        format!(
            "ply\nformat {format} 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nend_header\n",
            cloud.len()
        )
    };
    fs::write(d.join("holes-ascii.ply"), head("ascii") + &ascii).unwrap();
    let mut ply = head("binary_little_endian").into_bytes();
    let mut pcd = format!(
        "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH {m}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {m}\nDATA binary\n",
        m = cloud.len()
    )
    .into_bytes();
    for p in &cloud {
        for x in p {
            ply.extend_from_slice(&(*x as f32).to_le_bytes());
            pcd.extend_from_slice(&(*x as f32).to_le_bytes());
        }
    }
    fs::write(d.join("holes.ply"), ply).unwrap();
    fs::write(d.join("holes.pcd"), pcd).unwrap();
    for f in ["holes.xyz", "holes-ascii.ply", "holes.ply", "holes.pcd"] {
        let out = format!("{f}.tess");
        let v = json(d, &["map", f, "-o", &out, "--resolution", "0.1", "--json"]);
        assert_eq!(v["points"], n + 3, "{f}: {v}");
        assert_eq!(v["rays"], n, "{f}: {v}");
        assert_eq!(v["skipped"], 3, "{f}: {v}");
        assert_eq!(fs::read(d.join(&out)).unwrap(), clean, "{f}");
    }
    let text = ok(
        d,
        &["map", "holes.ply", "-o", "h.bt", "--resolution", "0.1"],
    );
    assert!(
        text.contains("(3 skipped: NaN, infinite, or past ±2^61 cells)"),
        "{text}"
    );
    // A mesh is still refused with a NaN vertex: it is not a cloud.
    fails(d, &["convert", "holes.ply", "h.stl"], "not finite");
}
