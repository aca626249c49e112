//! The map `tesseral map` writes is a model with its frame; far points are budgeted.

use super::*;

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
    assert!(String::from_utf8_lossy(&out.stderr).contains("wrote <stdout>"));
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
        "the longest is 1.000e9 m",
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
