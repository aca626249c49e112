//! Integration tests of `tesseral collide`, `simulate` and `plan`: the real binary in a
//! temporary folder.

mod common;

use std::collections::HashSet;
use std::fmt::Write as _;
use std::path::Path;
use std::process::Output;

use common::expect_success as ok;

use serde_json::Value;

fn tesseral(args: &[&str], dir: &Path) -> Output {
    common::run(dir, args)
}

fn fails(out: &Output, needle: &str) {
    assert_eq!(
        out.status.code(),
        Some(2),
        "stderr {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let err = String::from_utf8_lossy(&out.stderr);
    // The message is on the first line (clap adds a hint line after its own).
    let first = err.lines().next().unwrap_or("");
    assert!(
        first.starts_with("error: ") && first.contains(needle),
        "stderr {err:?} lacks {needle:?}"
    );
    assert!(!err.contains("panicked"), "{err}");
}

fn json(out: &Output) -> Value {
    serde_json::from_str(&ok(out)).expect("valid JSON")
}

fn write_xyz(dir: &Path, name: &str, voxels: impl IntoIterator<Item = [i64; 3]>) {
    let mut s = String::new();
    for v in voxels {
        writeln!(s, "{} {} {}", v[0], v[1], v[2]).unwrap();
    }
    std::fs::write(dir.join(name), s).unwrap();
}

fn cube(side: i64, at: [i64; 3]) -> Vec<[i64; 3]> {
    (0..side * side * side)
        .map(|i| {
            [
                at[0] + i % side,
                at[1] + i / side % side,
                at[2] + i / side / side,
            ]
        })
        .collect()
}

/// A wall at x = 8, 16 x 16, with a 3 x 3 hole at y, z in 5..8.
fn wall() -> Vec<[i64; 3]> {
    (0..16)
        .flat_map(|y| (0..16).map(move |z| [8, y, z]))
        .filter(|v| !((5..8).contains(&v[1]) && (5..8).contains(&v[2])))
        .collect()
}

#[test]
fn collide_reports_overlap_and_clearance_as_brute_force_does() {
    let dir = tempfile::tempdir().unwrap();
    let a: Vec<[i64; 3]> = cube(4, [0, 0, 0]);
    let b: Vec<[i64; 3]> = vec![[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 2]];
    write_xyz(dir.path(), "a.xyz", a.clone());
    write_xyz(dir.path(), "b.xyz", b.clone());
    let sa: HashSet<[i64; 3]> = a.iter().copied().collect();
    for offset in [[3, 3, 0], [2, -1, 1], [-1, -1, -3], [6, 0, 0], [-4, 5, 9]] {
        let arg = format!("{},{},{}", offset[0], offset[1], offset[2]);
        let v = json(&tesseral(
            &["collide", "a.xyz", "b.xyz", "--offset", &arg, "--json"],
            dir.path(),
        ));
        let moved: Vec<[i64; 3]> = b
            .iter()
            .map(|p| [p[0] + offset[0], p[1] + offset[1], p[2] + offset[2]])
            .collect();
        let shared = moved.iter().filter(|p| sa.contains(*p)).count() as u64;
        let gap = a
            .iter()
            .flat_map(|p| {
                moved.iter().map(move |q| {
                    (0..3)
                        .map(|k| (((p[k] - q[k]).abs() - 1).max(0) as f64).powi(2))
                        .sum::<f64>()
                })
            })
            .fold(f64::INFINITY, f64::min)
            .sqrt();
        assert_eq!(v["intersects"], Value::Bool(shared > 0), "{offset:?}");
        assert_eq!(v["overlap_voxels"].as_u64(), Some(shared), "{offset:?}");
        assert_eq!(v["clearance"].as_f64(), Some(gap), "{offset:?}");
    }
    // Text output, rotation and contacts.
    let text = ok(&tesseral(
        &[
            "collide",
            "a.xyz",
            "b.xyz",
            "--offset",
            "3,3,3",
            "--rotate",
            "z90",
            "--contacts",
        ],
        dir.path(),
    ));
    assert!(text.contains("intersects: yes"), "{text}");
    assert!(text.contains("contact: "), "{text}");
    let v = json(&tesseral(
        &[
            "collide",
            "a.xyz",
            "b.xyz",
            "--offset=4,0,0",
            "--rotate",
            "z90",
            "--json",
        ],
        dir.path(),
    ));
    // z90 turns (1, 0, 0) into (-1, 1, 0) as a voxel: at offset 4 it lands on x = 3.
    assert_eq!(v["intersects"], Value::Bool(true));
    assert_eq!(v["rotation"], Value::String("-y+x+z".into()));
}

#[test]
fn collide_errors_are_one_line_with_exit_code_2() {
    let dir = tempfile::tempdir().unwrap();
    write_xyz(dir.path(), "a.xyz", cube(2, [0, 0, 0]));
    std::fs::write(dir.path().join("bad.xyz"), "0 0 0\n1 x 0\n").unwrap();
    fails(
        &tesseral(&["collide", "a.xyz", "bad.xyz"], dir.path()),
        "bad.xyz:2:",
    );
    fails(
        &tesseral(&["collide", "a.xyz", "missing.xyz"], dir.path()),
        "missing.xyz",
    );
    fails(
        &tesseral(
            &["collide", "a.xyz", "a.xyz", "--offset", "1,2"],
            dir.path(),
        ),
        "X,Y,Z",
    );
    fails(
        &tesseral(
            &["collide", "a.xyz", "a.xyz", "--rotate", "x45"],
            dir.path(),
        ),
        "rotation",
    );
}

#[test]
fn simulate_reports_a_tunnelling_contact_and_writes_frames() {
    let dir = tempfile::tempdir().unwrap();
    let thin: Vec<[i64; 3]> = (0..16)
        .flat_map(|y| (0..16).map(move |z| [30, y, z]))
        .collect();
    write_xyz(dir.path(), "wall.xyz", thin);
    write_xyz(dir.path(), "bullet.xyz", cube(2, [0, 0, 0]));
    write_xyz(dir.path(), "box.xyz", cube(3, [0, 0, 0]));
    let world = r#"{
      "environment": "wall.xyz",
      "time_step": 1,
      "steps": 3,
      "objects": [
        { "name": "bullet", "octree": "bullet.xyz", "start": [0, 4, 4], "velocity": [25, 0, 0] },
        { "name": "crate", "octree": "box.xyz",
          "waypoints": [ { "time": 0, "at": [20, 10, 10] }, { "time": 2, "at": [28, 10, 10] } ] }
      ]
    }"#;
    std::fs::write(dir.path().join("world.json"), world).unwrap();
    let v = json(&tesseral(
        &["simulate", "world.json", "--json", "--frames", "frames"],
        dir.path(),
    ));
    let contacts = v["contacts"].as_array().unwrap();
    // The bullet crosses the wall between steps 1 and 2 (x = 25 -> 50): 3/25 into the
    // step its front face x = 30 meets the wall.
    let bullet: Vec<&Value> = contacts.iter().filter(|c| c["b"] == "bullet").collect();
    assert_eq!(bullet.len(), 1, "{contacts:?}");
    assert_eq!(bullet[0]["a"], "environment");
    assert_eq!(bullet[0]["fraction"], "3/25");
    assert_eq!(bullet[0]["time"].as_f64(), Some(1.12));
    assert_eq!(bullet[0]["between_steps"], Value::Bool(true));
    // The crate reaches the wall (x + 3 > 30 at x = 27.something): in contact at steps 2, 3.
    let crate_hits: Vec<&Value> = contacts.iter().filter(|c| c["b"] == "crate").collect();
    assert_eq!(crate_hits.len(), 1, "{contacts:?}");
    assert_eq!(crate_hits[0]["between_steps"], Value::Bool(false));
    assert_eq!(v["frames"].as_array().unwrap().len(), 4);
    for step in 0..4 {
        let f = dir.path().join(format!("frames/frame_{step:05}.png"));
        let bytes = std::fs::read(&f).unwrap();
        assert_eq!(&bytes[1..4], b"PNG", "{}", f.display());
    }
    let text = ok(&tesseral(&["simulate", "world.json"], dir.path()));
    assert!(text.contains("between steps"), "{text}");
    assert!(text.contains("2 contacts in 3 steps"), "{text}");
    // Linear translation gives the same contacts.
    std::fs::write(
        dir.path().join("world2.json"),
        world.replace(
            "\"steps\": 3,",
            "\"steps\": 3, \"translation\": \"linear\",",
        ),
    )
    .unwrap();
    let w = json(&tesseral(
        &["simulate", "world2.json", "--json"],
        dir.path(),
    ));
    let times = |v: &Value| -> Vec<String> {
        v["contacts"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| format!("{} {} {}", c["time"], c["a"], c["b"]))
            .collect()
    };
    assert_eq!(times(&w), times(&v));
}

#[test]
fn simulate_errors_name_the_file_and_place() {
    let dir = tempfile::tempdir().unwrap();
    write_xyz(dir.path(), "wall.xyz", wall());
    std::fs::write(
        dir.path().join("w1.json"),
        "{\n  \"environment\": \"wall.xyz\",\n  \"steps\": -1\n}",
    )
    .unwrap();
    fails(
        &tesseral(&["simulate", "w1.json"], dir.path()),
        "w1.json:3:",
    );
    std::fs::write(
        dir.path().join("w2.json"),
        r#"{"environment": "wall.xyz", "steps": 2, "objects": [{"name": "p", "octree": "wall.xyz", "rotate": "q1"}]}"#,
    )
    .unwrap();
    fails(
        &tesseral(&["simulate", "w2.json"], dir.path()),
        "object \"p\", rotate",
    );
    std::fs::write(
        dir.path().join("w3.json"),
        r#"{"environment": "nowhere.xyz", "steps": 2}"#,
    )
    .unwrap();
    fails(
        &tesseral(&["simulate", "w3.json"], dir.path()),
        "nowhere.xyz",
    );
    std::fs::write(
        dir.path().join("w4.json"),
        r#"{"environment": "wall.xyz", "steps": 99999999999}"#,
    )
    .unwrap();
    fails(&tesseral(&["simulate", "w4.json"], dir.path()), "steps");
}

#[test]
fn plan_goes_through_the_hole_and_draws_it() {
    let dir = tempfile::tempdir().unwrap();
    let w = wall();
    write_xyz(dir.path(), "wall.xyz", w.clone());
    write_xyz(dir.path(), "cube.xyz", cube(2, [0, 0, 0]));
    let v = json(&tesseral(
        &[
            "plan", "wall.xyz", "cube.xyz", "--from", "0,0,0", "--to", "14,0,0", "--json", "-o",
            "path.png",
        ],
        dir.path(),
    ));
    assert_eq!(v["found"], Value::Bool(true));
    // Through the hole: up to (y, z) in 5..=6 and back down, across 14.
    assert_eq!(v["steps"].as_u64(), Some(14 + 2 * 5 + 2 * 5));
    let bytes = std::fs::read(dir.path().join("path.png")).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    // Every unit step of the raw path keeps the cube out of the wall, voxel by voxel.
    let walls: HashSet<[i64; 3]> = w.into_iter().collect();
    let raw: Vec<[i64; 3]> = v["raw"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let p = p.as_array().unwrap();
            [0, 1, 2].map(|k| p[k].as_i64().unwrap())
        })
        .collect();
    let mut moves = 0;
    for pair in raw.windows(2) {
        let mut p = pair[0];
        for k in 0..3 {
            while p[k] != pair[1][k] {
                p[k] += (pair[1][k] - p[k]).signum();
                moves += 1;
                assert!(
                    cube(2, p).iter().all(|q| !walls.contains(q)),
                    "blocked at {p:?}"
                );
            }
        }
    }
    assert_eq!(moves, 34);
    assert!(v["length"].as_f64().unwrap() < 34.0);
    let text = ok(&tesseral(
        &[
            "plan", "wall.xyz", "cube.xyz", "--from", "0,0,0", "--to", "14,0,0", "--margin", "2",
        ],
        dir.path(),
    ));
    // With room around the wall's edge the path is shorter.
    assert!(text.contains("(18 unit moves before smoothing)"), "{text}");
}

#[test]
fn plan_says_no_path_and_why() {
    let dir = tempfile::tempdir().unwrap();
    write_xyz(dir.path(), "wall.xyz", wall());
    write_xyz(dir.path(), "big.xyz", cube(4, [0, 0, 0]));
    // The 4-cube does not fit through the 3x3 hole, and there is no margin.
    let out = tesseral(
        &[
            "plan", "wall.xyz", "big.xyz", "--from", "0,0,0", "--to", "12,0,0",
        ],
        dir.path(),
    );
    assert_eq!(out.status.code(), Some(1));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.starts_with("no path: the goal is not reachable"),
        "{text}"
    );
    let out = tesseral(
        &[
            "plan", "wall.xyz", "big.xyz", "--from", "6,0,0", "--to", "12,0,0", "--json",
        ],
        dir.path(),
    );
    assert_eq!(out.status.code(), Some(1));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["found"], Value::Bool(false));
    assert!(
        v["reason"]
            .as_str()
            .unwrap()
            .contains("at the start the object overlaps"),
        "{v}"
    );
    fails(
        &tesseral(
            &[
                "plan", "wall.xyz", "big.xyz", "--from", "0,0", "--to", "1,1,1",
            ],
            dir.path(),
        ),
        "X,Y,Z",
    );
    fails(
        &tesseral(
            &[
                "plan",
                "wall.xyz",
                "big.xyz",
                "--from",
                "0,0,0",
                "--to",
                "1,1,1",
                "--region",
                "5,0,0,1,1,1",
            ],
            dir.path(),
        ),
        "region",
    );
}
