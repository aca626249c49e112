//! Integration tests of `tesseral map`: the real binary on scan files of every
//! format (`formats.rs`), its options and errors (`options.rs`), and the map it
//! writes used as a model (`model.rs`). Here: the scans they share.

use std::fmt::Write as _;
use std::fs;

#[path = "../common/mod.rs"]
mod common;
mod formats;
mod model;
mod options;

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

const KEYS: [&str; 10] = [
    "scans",
    "points",
    "rays",
    "occupied",
    "free",
    "leaves",
    "bytes",
    "seconds",
    "rays_per_second",
    "skipped",
];
