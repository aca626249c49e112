use super::*;
use crate::io::FormatError;
use rand::{Rng, SeedableRng};

fn random_scans(seed: u64) -> Vec<ScanRecord> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    (0..rng.random_range(0..5))
        .map(|_| ScanRecord {
            translation: std::array::from_fn(|_| rng.random_range(-20.0..20.0)),
            rpy: [
                rng.random_range(-3.0..3.0),
                rng.random_range(-1.5..1.5),
                rng.random_range(-3.0..3.0),
            ],
            points: (0..rng.random_range(0..50))
                .map(|_| std::array::from_fn(|_| rng.random_range(-10.0..10.0)))
                .collect(),
            frame: PointFrame::Sensor,
        })
        .collect()
}

fn round32(p: [f64; 3]) -> [f64; 3] {
    p.map(|x| f64::from(x as f32))
}

fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
    (0..3).all(|k| (a[k] - b[k]).abs() <= tol)
}

#[test]
fn graph_round_trips_random_scans() {
    for seed in 0..40 {
        let scans = random_scans(seed);
        let back = graph::decode(&graph::encode(&scans)).unwrap();
        assert_eq!(back.len(), scans.len(), "seed {seed}");
        for (a, b) in scans.iter().zip(&back) {
            assert_eq!(b.frame, PointFrame::Sensor);
            assert_eq!(b.translation, round32(a.translation), "seed {seed}");
            let want: Vec<_> = a.points.iter().map(|&p| round32(p)).collect();
            assert_eq!(b.points, want, "seed {seed}: points are OctoMap's f32");
            assert!(
                close(b.rpy, a.rpy, 1e-5),
                "seed {seed}: {:?} vs {:?}",
                b.rpy,
                a.rpy
            );
            for (p, q) in a.world_points().iter().zip(b.world_points().iter()) {
                assert!(close(*p, *q, 1e-4), "seed {seed}");
            }
        }
    }
}

#[test]
fn rpy_matrix_is_the_quaternion_rotation() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(9);
    for _ in 0..200 {
        let rpy = [
            rng.random_range(-3.1..3.1),
            rng.random_range(-1.5..1.5),
            rng.random_range(-3.1..3.1),
        ];
        let [w, x, y, z] = graph::rpy_to_quaternion(rpy);
        // v' = q v q*, expanded.
        let v: [f64; 3] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
        let t = [
            2.0 * (y * v[2] - z * v[1]),
            2.0 * (z * v[0] - x * v[2]),
            2.0 * (x * v[1] - y * v[0]),
        ];
        let q = [
            v[0] + w * t[0] + (y * t[2] - z * t[1]),
            v[1] + w * t[1] + (z * t[0] - x * t[2]),
            v[2] + w * t[2] + (x * t[1] - y * t[0]),
        ];
        let m = rpy_matrix(rpy);
        let r: [f64; 3] = std::array::from_fn(|i| (0..3).map(|j| m[i][j] * v[j]).sum());
        assert!(close(q, r, 1e-12), "{rpy:?}");
        let back = graph::quaternion_to_rpy([w, x, y, z]);
        assert!(close(back, rpy, 1e-9), "{rpy:?} -> {back:?}");
        // Any norm: the quaternion is normalised first.
        let back2 = graph::quaternion_to_rpy([3.0 * w, 3.0 * x, 3.0 * y, 3.0 * z]);
        assert!(close(back2, rpy, 1e-9));
    }
    assert_eq!(graph::quaternion_to_rpy([0.0; 4]), [0.0; 3]);
}

#[test]
fn graph_cut_anywhere_is_an_error_naming_a_byte() {
    let scans = random_scans(3);
    let bytes = graph::encode(&scans);
    for n in 0..bytes.len() - 4 {
        // Without its edge count a file is whole; anything shorter is cut.
        match graph::decode(&bytes[..n]) {
            Err(FormatError::Corrupt(m)) => assert!(m.contains("byte"), "{n}: {m}"),
            other => panic!("{n}: {other:?}"),
        }
    }
    assert_eq!(
        graph::decode(&bytes[..bytes.len() - 4]).unwrap().len(),
        scans.len()
    );
}

#[test]
fn graph_lying_counts_are_refused_before_allocating() {
    let mut b = u32::MAX.to_le_bytes().to_vec();
    b.extend_from_slice(&[0; 100]);
    let e = graph::decode(&b).unwrap_err().to_string();
    assert!(e.contains("4294967295 nodes claimed"), "{e}");
    // One node claiming 2^32 − 1 points.
    let mut b = 1u32.to_le_bytes().to_vec();
    b.extend_from_slice(&u32::MAX.to_le_bytes());
    b.extend_from_slice(&[0; 200]);
    let e = graph::decode(&b).unwrap_err().to_string();
    assert!(e.contains("byte 4: node 0 claims 4294967295 points"), "{e}");
    // Edges the bytes cannot hold.
    let mut b = graph::encode(&[]);
    b.truncate(4);
    b.extend_from_slice(&7u32.to_le_bytes());
    let e = graph::decode(&b).unwrap_err().to_string();
    assert!(e.contains("byte 4: 7 edges claimed"), "{e}");
}

#[test]
fn graph_pose_must_be_finite() {
    let s = ScanRecord {
        translation: [f64::NAN, 0.0, 0.0],
        ..Default::default()
    };
    let e = graph::decode(&graph::encode(&[s])).unwrap_err().to_string();
    assert!(
        e.contains("byte 8: the pose of node 0 is not finite"),
        "{e}"
    );
}

const LOG: &str = "# a log\nNODE 1 2 3 0 0 1.5\n0.5 0 0\n\n 9 9 9 skipped: begins with a space\n1 1 1 intensity\r\nNODE 0 0 0 0.1 0.2 0.3\n2 3 4";

#[test]
fn log_parses_as_log2graph_does() {
    let s = log::parse(LOG.as_bytes()).unwrap();
    assert_eq!(s.len(), 2);
    assert_eq!(s[0].translation, [1.0, 2.0, 3.0]);
    assert_eq!(s[0].rpy, [0.0, 0.0, 1.5]);
    assert_eq!(s[0].points, vec![[0.5, 0.0, 0.0], [1.0, 1.0, 1.0]]);
    assert_eq!(s[1].rpy, [0.1f32, 0.2f32, 0.3f32].map(f64::from));
    assert_eq!(
        s[1].points,
        vec![[2.0, 3.0, 4.0]],
        "a last line without newline"
    );
    // The log and the graph it makes hold the same scans.
    let g = graph::decode(&graph::encode(&s)).unwrap();
    for (a, b) in s.iter().zip(&g) {
        assert_eq!(a.points, b.points);
        assert!(close(a.rpy, b.rpy, 1e-6));
    }
}

fn syntax_at(r: Result<impl std::fmt::Debug, FormatError>) -> (usize, usize, String) {
    match r {
        Err(FormatError::Syntax {
            line,
            column,
            message,
        }) => (line, column, message),
        other => panic!("not a syntax error: {other:?}"),
    }
}

#[test]
fn log_errors_name_line_and_column() {
    let (l, c, m) = syntax_at(log::parse(b"1 2 3\n"));
    assert_eq!((l, c), (1, 1));
    assert!(m.contains("before the first `NODE"), "{m}");
    let (l, c, m) = syntax_at(log::parse(b"NODE 0 0 0 0 0 0\n1 2 x3\n"));
    assert_eq!((l, c), (2, 5), "{m}");
    let (l, _, m) = syntax_at(log::parse(b"NODE 0 0 0 0 0\n"));
    assert_eq!(l, 1);
    assert!(m.contains("found 5"), "{m}");
    let (l, _, m) = syntax_at(log::parse(b"NODE 0 0 0 0 0 0\n1 2\n"));
    assert_eq!(l, 2);
    assert!(m.contains("found 2"), "{m}");
    let (_, _, m) = syntax_at(log::parse(b"NODE 0 0 inf 0 0 0\n"));
    assert!(m.contains("not finite"), "{m}");
    let (l, c, _) = syntax_at(log::parse(b"NODE 0 0 0 0 0 0\n\xff\n"));
    assert_eq!((l, c), (2, 1));
}

#[test]
fn xyz_points_with_commas_comments_and_columns() {
    let s = cloud::parse_xyz(b"# head\n1 2 3\n\n4,5,6,7 # c\n  -1e-3\t2.5 nan 9\r\n").unwrap();
    assert_eq!(s.points.len(), 3);
    assert_eq!(s.points[1], [4.0, 5.0, 6.0]);
    assert!(s.points[2][2].is_nan());
    assert_eq!(s.frame, PointFrame::Sensor);
    assert_eq!((s.translation, s.rpy), ([0.0; 3], [0.0; 3]));
    let (l, c, _) = syntax_at(cloud::parse_xyz(b"1 2 3\n1 two 3\n"));
    assert_eq!((l, c), (2, 3));
    let (l, _, m) = syntax_at(cloud::parse_xyz(b"1 2 3\n1 2\n"));
    assert_eq!(l, 2);
    assert!(m.contains("found 2"), "{m}");
}

fn ply_binary(points: &[[f32; 3]], declared: u64) -> Vec<u8> {
    let mut b = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {declared}\nproperty float x\nproperty float y\nproperty float z\nproperty uchar intensity\nend_header\n"
    )
    .into_bytes();
    for p in points {
        for x in p {
            b.extend_from_slice(&x.to_le_bytes());
        }
        b.push(7);
    }
    b
}

#[test]
fn ply_ascii_and_binary_clouds() {
    let a = cloud::parse_ply(
        b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n-4 5.5 6\n",
    )
    .unwrap();
    assert_eq!(a.points, vec![[1.0, 2.0, 3.0], [-4.0, 5.5, 6.0]]);
    let pts = [[0.25f32, -1.0, 3.0], [7.0, 8.0, 9.5]];
    let b = cloud::parse_ply(&ply_binary(&pts, 2)).unwrap();
    assert_eq!(b.points, vec![[0.25, -1.0, 3.0], [7.0, 8.0, 9.5]]);
    // A header that claims more than the bytes hold, or billions.
    assert!(cloud::parse_ply(&ply_binary(&pts, 3)).is_err());
    assert!(cloud::parse_ply(&ply_binary(&pts, 4_000_000_000)).is_err());
    let full = ply_binary(&pts, 2);
    for n in 0..full.len() {
        assert!(cloud::parse_ply(&full[..n]).is_err(), "{n}");
    }
}

fn pcd_header(fields: &str, size: &str, ty: &str, points: u64, data: &str) -> String {
    format!(
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS {fields}\nSIZE {size}\nTYPE {ty}\nCOUNT {}\nWIDTH {points}\nHEIGHT 1\nVIEWPOINT 1 2 3 1 0 0 0\nPOINTS {points}\nDATA {data}\n",
        vec!["1"; fields.split(' ').count()].join(" ")
    )
}

#[test]
fn pcd_ascii_and_binary() {
    let text = pcd_header("x y z rgb", "4 4 4 4", "F F F U", 3, "ascii")
        + "1 2 3 4294967295\nnan nan nan 0\n-1.5 0 2e1 7\n";
    let s = pcd::parse(text.as_bytes()).unwrap();
    assert_eq!(s.frame, PointFrame::World);
    assert_eq!(s.translation, [1.0, 2.0, 3.0]);
    assert_eq!(s.points.len(), 3);
    assert_eq!(s.points[0], [1.0, 2.0, 3.0]);
    assert!(s.points[1][0].is_nan());
    assert_eq!(s.points[2], [-1.5, 0.0, 20.0]);
    // Binary: fields in another order, mixed types and sizes.
    let mut b = pcd_header("intensity z x y", "2 8 4 4", "I F F F", 2, "binary").into_bytes();
    for (i, z, x, y) in [(-3i16, 1.5f64, 2.0f32, -4.0f32), (9, -0.5, 0.0, 8.0)] {
        b.extend_from_slice(&i.to_le_bytes());
        b.extend_from_slice(&z.to_le_bytes());
        b.extend_from_slice(&x.to_le_bytes());
        b.extend_from_slice(&y.to_le_bytes());
    }
    let s = pcd::parse(&b).unwrap();
    assert_eq!(s.points, vec![[2.0, -4.0, 1.5], [0.0, 8.0, -0.5]]);
    for n in 0..b.len() {
        assert!(pcd::parse(&b[..n]).is_err(), "{n}");
    }
}

/// A `DATA binary_compressed` PCD as PCL writes it: each field's values for every
/// point together, one field after another, LZF-compressed, after the two sizes.
fn pcd_compressed(fields: &str, size: &str, ty: &str, columns: &[Vec<u8>], n: u64) -> Vec<u8> {
    let raw: Vec<u8> = columns.concat();
    let packed = lzf::compress(&raw).unwrap_or_else(|_| raw.clone());
    assert!(packed.len() < raw.len(), "the test data compresses");
    let mut b = pcd_header(fields, size, ty, n, "binary_compressed").into_bytes();
    b.extend_from_slice(&(packed.len() as u32).to_le_bytes());
    b.extend_from_slice(&(raw.len() as u32).to_le_bytes());
    b.extend_from_slice(&packed);
    b
}

#[test]
fn pcd_binary_compressed_reads_as_binary() {
    // Fields in another order, mixed types and sizes, an organised cloud's NaN rows.
    let n = 300usize;
    let pts: Vec<[f32; 3]> = (0..n)
        .map(|i| {
            if i % 7 == 3 {
                [f32::NAN; 3]
            } else {
                [(i % 10) as f32 * 0.5, (i / 10) as f32 - 4.0, 1.25]
            }
        })
        .collect();
    let intensity: Vec<u8> = (0..n)
        .flat_map(|i| ((i % 5) as u16).to_le_bytes())
        .collect();
    let col = |a: usize| -> Vec<u8> { pts.iter().flat_map(|p| p[a].to_le_bytes()).collect() };
    let b = pcd_compressed(
        "y intensity x z",
        "4 2 4 4",
        "F U F F",
        &[col(1), intensity, col(0), col(2)],
        n as u64,
    );
    let s = pcd::parse(&b).unwrap();
    assert_eq!(s.points.len(), n);
    for (got, want) in s.points.iter().zip(&pts) {
        for a in 0..3 {
            let w = f64::from(want[a]);
            assert!(
                got[a] == w || (got[a].is_nan() && w.is_nan()),
                "{got:?} {want:?}"
            );
        }
    }
    assert_eq!(s.translation, [1.0, 2.0, 3.0]);
    // Cut anywhere or with a byte changed in the sizes or the data: an error or
    // the same number of points, never a panic.
    for k in 0..b.len() {
        assert!(pcd::parse(&b[..k]).is_err(), "cut at {k}");
    }
    let header = b
        .windows(18)
        .position(|w| w == b"binary_compressed\n")
        .unwrap()
        + 18;
    for k in header..b.len() {
        for x in [0x00u8, 0x1f, 0x20, 0xe0, 0xff] {
            let mut c = b.clone();
            c[k] ^= x;
            if let Ok(s) = pcd::parse(&c) {
                assert_eq!(s.points.len(), n);
            }
        }
    }
    // An empty cloud: both sizes 0.
    let mut e = pcd_header("x y z", "4 4 4", "F F F", 0, "binary_compressed").into_bytes();
    e.extend_from_slice(&[0; 8]);
    assert!(pcd::parse(&e).unwrap().points.is_empty());
}

#[test]
fn pcd_errors() {
    // Compressed data whose sizes disagree with the header.
    let c = pcd_header("x y z", "4 4 4", "F F F", 1, "binary_compressed") + "\x05\0\0\0\x0b\0\0\0";
    let e = pcd::parse(c.as_bytes()).unwrap_err().to_string();
    assert!(e.contains("1 points of 12 bytes make 12 bytes"), "{e}");
    let e = pcd::parse(pcd_header("x y z", "4 4 4", "F F F", 1 << 40, "binary").as_bytes())
        .unwrap_err()
        .to_string();
    assert!(e.contains("declares 1099511627776 points"), "{e}");
    let e = pcd::parse(pcd_header("x y z", "4 4 4", "F F F", 1 << 40, "ascii").as_bytes())
        .unwrap_err()
        .to_string();
    assert!(e.contains("declares 1099511627776 points"), "{e}");
    let (l, _, m) = syntax_at(pcd::parse(
        pcd_header("x y w", "4 4 4", "F F F", 0, "ascii").as_bytes(),
    ));
    assert_eq!(l, 3, "the `FIELDS` line");
    assert!(m.contains("lacks `z`"), "{m}");
    let (l, c, _) = syntax_at(pcd::parse(
        pcd_header("x y z", "4 3 4", "F F F", 0, "ascii").as_bytes(),
    ));
    assert_eq!((l, c), (4, 8));
    let text = pcd_header("x y z", "4 4 4", "F F F", 2, "ascii") + "1 2 3\n1 2\n";
    let (l, _, m) = syntax_at(pcd::parse(text.as_bytes()));
    assert_eq!(l, 13);
    assert!(m.contains("needs 3 values"), "{m}");
    let text = pcd_header("x y z", "4 4 4", "F F F", 2, "ascii") + "1 2 3\n";
    assert!(pcd::parse(text.as_bytes()).is_err());
    let (l, c, _) = syntax_at(pcd::parse(b"VERSION 0.7\nFIELDS x y z\nBOGUS 1\n"));
    assert_eq!((l, c), (3, 1));
}

#[test]
fn formats_by_extension() {
    assert_eq!(ScanFormat::from_extension("graph"), Some(ScanFormat::Graph));
    assert_eq!(ScanFormat::from_extension("pcd"), Some(ScanFormat::Pcd));
    assert_eq!(ScanFormat::from_extension("bt"), None);
    assert!(ScanFormat::Log.has_poses() && !ScanFormat::Xyz.has_poses());
    let s = parse(LOG.as_bytes(), ScanFormat::Log).unwrap();
    assert_eq!(s.len(), 2);
}

#[test]
fn random_bytes_never_panic() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
    let seeds: Vec<(ScanFormat, Vec<u8>)> = vec![
        (ScanFormat::Graph, graph::encode(&random_scans(5))),
        (ScanFormat::Log, LOG.as_bytes().to_vec()),
        (ScanFormat::Xyz, b"1 2 3\n4 5 6\n".to_vec()),
        (ScanFormat::Ply, ply_binary(&[[1.0, 2.0, 3.0]], 1)),
        (
            ScanFormat::Pcd,
            (pcd_header("x y z", "4 4 4", "F F F", 1, "ascii") + "1 2 3\n").into_bytes(),
        ),
    ];
    for (format, seed) in &seeds {
        assert!(parse(seed, *format).is_ok(), "{format:?}");
        for _ in 0..2000 {
            let mut b = seed.clone();
            for _ in 0..rng.random_range(1..4) {
                if b.is_empty() {
                    break;
                }
                let i = rng.random_range(0..b.len());
                match rng.random_range(0..3) {
                    0 => b[i] = rng.random(),
                    1 => b.truncate(i),
                    _ => b[i..].iter_mut().take(4).for_each(|x| *x = 0xff),
                }
            }
            let _ = parse(&b, *format);
        }
    }
}

#[test]
fn ascii_ply_errors_name_line_and_column_and_clouds_keep_missing_returns() {
    let head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    let (l, c, m) = syntax_at(cloud::parse_ply(
        format!("{head}1 2 3\n4.0 5.0 abc\n7 8 9\n").as_bytes(),
    ));
    assert_eq!((l, c), (9, 9), "{m}");
    assert!(m.contains("abc"), "{m}");
    // A cloud keeps NaN and infinite points (the map skips and counts them)...
    let r = cloud::parse_ply(format!("{head}1 2 3\nnan nan nan\n1 inf 1\n").as_bytes()).unwrap();
    assert_eq!(r.points.len(), 3);
    assert!(r.points[1].iter().all(|x| x.is_nan()) && r.points[2][1].is_infinite());
    // ...a mesh refuses them, naming where.
    let (l, c, m) = syntax_at(crate::io::mesh::parse_ply(
        format!("{head}1 2 3\nnan nan nan\n1 1 1\n").as_bytes(),
    ));
    assert_eq!((l, c), (9, 1), "{m}");
}

#[test]
fn ascii_ply_elements_take_one_line_each() {
    let head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    // A short line is reported where it ends, not where the file does.
    let (l, c, m) = syntax_at(cloud::parse_ply(
        format!("{head}1.5 2.5 3.5\n4 5\n7 8 9\n").as_bytes(),
    ));
    assert_eq!((l, c), (9, 4), "{m}");
    assert!(m.contains("line ends inside an element"), "{m}");
    // A long one at its first value too many.
    let (l, c, m) = syntax_at(cloud::parse_ply(
        format!("{head}1 2 3\n4 5 6 7\n8 9 10\n").as_bytes(),
    ));
    assert_eq!((l, c), (9, 7), "{m}");
    assert!(m.contains("more values"), "{m}");
    // Spaces, tabs and CRLF after the last value, blank lines between elements, and
    // no newline at the end are all fine.
    let r = cloud::parse_ply(format!("{head}1 2 3 \t\r\n\n4 5 6\r\n  7 8 9").as_bytes()).unwrap();
    assert_eq!(
        r.points,
        vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.0]]
    );
    // The same for a mesh's faces: a face's list may not run onto the next line.
    let mesh = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
    let (l, c, m) = syntax_at(crate::io::mesh::parse_ply(
        format!("{mesh}3 0 1\n2\n").as_bytes(),
    ));
    assert_eq!((l, c), (13, 6), "{m}");
    assert!(crate::io::mesh::parse_ply(format!("{mesh}3 0 1 2\n").as_bytes()).is_ok());
}

#[test]
fn pcl_binary_compressed_file_reads_as_its_ascii_source() {
    // `tests/fixtures/pcl-binary-compressed.pcd` was written by PCL 1.13's
    // `pcl_convert_pcd_ascii_binary pcl-ascii.pcd out.pcd 2` (x y z rgb, 12 × 10
    // organised, NaN rows), from the ASCII fixture beside it.
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    let ascii = pcd::parse(&std::fs::read(dir.join("pcl-ascii.pcd")).unwrap()).unwrap();
    let packed =
        pcd::parse(&std::fs::read(dir.join("pcl-binary-compressed.pcd")).unwrap()).unwrap();
    assert_eq!(ascii.points.len(), 120);
    assert_eq!(packed.points.len(), 120);
    assert_eq!(packed.translation, [0.5, 0.25, 0.1]);
    let nan = packed.points.iter().filter(|p| p[0].is_nan()).count();
    assert_eq!(nan, 11);
    for (a, b) in ascii.points.iter().zip(&packed.points) {
        for k in 0..3 {
            assert!(
                a[k] == b[k] || (a[k].is_nan() && b[k].is_nan()),
                "{a:?} {b:?}"
            );
        }
    }
}
