//! Coordinates that wrapped silently (issue 19, item 7): a `.tess` whose space runs
//! past `i64`, and `collide` clearance between voxels at opposite ends of `i64`.

mod hostile;
use hostile::{fails_naming, run_capped};

/// The fuzzer's minimized file: depth 1 from origin x = i64::MAX, with a correct CRC.
const WRAPPING_TESS: &str =
    "iVRFU1NSTAoBAAIAAQAAAP////////9/AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAABAAAAAAAAAAH/AAD/sWGZwg==";

fn base64(s: &str) -> Vec<u8> {
    let val = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        _ => 63,
    };
    let digits: Vec<u8> = s.bytes().filter(|&c| c != b'=').map(val).collect();
    let mut out = Vec::new();
    for chunk in digits.chunks(4) {
        let mut n = 0u32;
        for (i, &d) in chunk.iter().enumerate() {
            n |= u32::from(d) << (18 - 6 * i);
        }
        out.extend_from_slice(&n.to_be_bytes()[1..chunk.len()]);
    }
    out
}

#[test]
fn a_tess_whose_space_runs_past_i64_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = base64(WRAPPING_TESS);
    assert_eq!(&bytes[1..6], b"TESSR");
    std::fs::write(dir.path().join("wrap.tess"), bytes).unwrap();
    for args in [
        &["info", "wrap.tess"][..],
        &["convert", "wrap.tess", "out.xyz"],
    ] {
        let out = run_capped(dir.path(), args, 1024, 20);
        fails_naming(&out, &["wrap.tess", "origin", "9223372036854775807"]);
    }
    assert!(!dir.path().join("out.xyz").exists());
}

/// The clearance between the closed unit cubes of two voxels, by brute force in f64
/// over exact i128 gaps (obviously right).
fn brute_clearance(a: [i64; 3], b: [i64; 3]) -> f64 {
    (0..3)
        .map(|k| {
            let (p, q) = (i128::from(a[k]), i128::from(b[k]));
            let g = (q - p - 1).max(p - q - 1).max(0) as f64;
            g * g
        })
        .sum::<f64>()
        .sqrt()
}

#[test]
fn collide_clearance_between_the_ends_of_i64_is_right() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (lo, hi) = (i64::MIN, i64::MAX);
    let cases = [
        ([lo, lo, lo], [hi, hi, hi]),
        ([lo, 0, 0], [hi, 0, 0]),
        ([0, lo, 5], [0, hi, 5]),
        ([hi, hi, hi], [hi - 3, hi, hi]),
        ([lo, lo, lo], [lo + 1, lo, lo]),
    ];
    for (a, b) in cases {
        std::fs::write(d.join("a.xyz"), format!("{} {} {}\n", a[0], a[1], a[2])).unwrap();
        std::fs::write(d.join("b.xyz"), format!("{} {} {}\n", b[0], b[1], b[2])).unwrap();
        let out = run_capped(d, &["collide", "a.xyz", "b.xyz", "--json"], 1024, 20);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let got = v["clearance"].as_f64().unwrap();
        let want = brute_clearance(a, b);
        assert!(
            (got - want).abs() <= want * 1e-12,
            "{a:?} {b:?}: clearance {got}, want {want}"
        );
        assert_eq!(v["intersects"], false);
    }
}
