//! Malformed scan files: each error names where the fault is (line and column for
//! text, the byte offset for binary), and no input panics.

use super::*;
use crate::io::FormatError;

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

fn corrupt(r: Result<impl std::fmt::Debug, FormatError>) -> String {
    match r {
        Err(FormatError::Corrupt(m)) => m,
        other => panic!("not a corrupt-data error: {other:?}"),
    }
}

/// A PCD header of 11 lines (`POINTS` on line 10, `DATA` on 11).
fn pcd_header(fields: &str, size: &str, ty: &str, count: &str, n: u64, data: &str) -> String {
    format!(
        "# .PCD v0.7\nVERSION 0.7\nFIELDS {fields}\nSIZE {size}\nTYPE {ty}\nCOUNT {count}\nWIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA {data}\n"
    )
}

fn xyz_header(n: u64, data: &str) -> String {
    pcd_header("x y z", "4 4 4", "F F F", "1 1 1", n, data)
}

/// `binary_compressed` data: the two sizes, then `packed`.
fn compressed_body(packed: &[u8], size: usize) -> Vec<u8> {
    let mut b = (packed.len() as u32).to_le_bytes().to_vec();
    b.extend_from_slice(&(size as u32).to_le_bytes());
    b.extend_from_slice(packed);
    b
}

#[test]
fn pcd_compressed_past_2_gib_is_read_without_panic() {
    // x y z, then a field of 65,536 doubles: 524,300 bytes a point, so 4,097
    // points make 2,148,057,100 bytes uncompressed, past 2^31. The data is one
    // zero byte, then back references of 264 bytes one byte back.
    let n = 4097u64;
    let size = 4097 * 524_300usize;
    assert!(size >= 1 << 31);
    let mut packed = vec![0u8, 0];
    let refs = (size - 1) / 264;
    packed.reserve(3 * refs + 3);
    for _ in 0..refs {
        packed.extend_from_slice(&[0xe0, 255, 0]);
    }
    let last = size - 1 - refs * 264;
    assert!((9..264).contains(&last));
    packed.extend_from_slice(&[0xe0, (last - 9) as u8, 0]);
    let mut b = pcd_header(
        "x y z pad",
        "4 4 4 8",
        "F F F F",
        "1 1 1 65536",
        n,
        "binary_compressed",
    )
    .into_bytes();
    b.extend_from_slice(&compressed_body(&packed, size));
    let s = pcd::parse(&b).unwrap();
    assert_eq!(s.points.len(), n as usize);
    assert!(s.points.iter().all(|p| *p == [0.0; 3]));
    // Three bytes short: an error naming the end of the data.
    let mut short = b.clone();
    let k = short.len() - 2;
    short[k] -= 3;
    let m = corrupt(pcd::parse(&short));
    assert!(m.contains(&format!("byte {}:", short.len())), "{m}");
    assert!(
        m.contains(&format!("ends after {} of {size} bytes", size - 3)),
        "{m}"
    );
}

#[test]
fn pcd_compressed_stream_faults_name_their_byte() {
    let head = xyz_header(1, "binary_compressed").into_bytes();
    let data = head.len() + 8;
    let case = |packed: &[u8]| {
        let mut b = head.clone();
        b.extend_from_slice(&compressed_body(packed, 12));
        corrupt(pcd::parse(&b))
    };
    // A back reference before any output.
    let m = case(&[0x20, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]);
    assert!(
        m.contains(&format!("byte {data}: a back reference before")),
        "{m}"
    );
    // A literal run cut short, at its control byte.
    let m = case(&[0x00, 1, 0x05, 1, 2]);
    assert!(m.contains(&format!("byte {}:", data + 2)), "{m}");
    // A back reference of length 7 + its byte, cut before the offset.
    let m = case(&[0x01, 1, 2, 0xe0, 0]);
    assert!(m.contains(&format!("byte {}:", data + 3)), "{m}");
    // Output past the declared size.
    let m = case(&[0x0b, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x20, 0]);
    assert!(m.contains(&format!("byte {}:", data + 13)), "{m}");
    assert!(m.contains("more than the declared size"), "{m}");
}

#[test]
fn pcd_compressed_values_cut_between_pieces_read_whole() {
    // 40,000 points of 19 bytes (760,000 bytes): the decompressor hands on pieces
    // of 256 KiB, so values straddle the cuts. Fields in another order, an
    // unsigned field with three values.
    let n = 40_000usize;
    let pts: Vec<[f64; 3]> = (0..n)
        .map(|i| [(i % 100) as f64 * 0.25, (i / 100) as f64, -((i % 7) as f64)])
        .collect();
    let mut cols: Vec<u8> = (0..3 * n).map(|i| (i % 11) as u8).collect();
    cols.extend(pts.iter().flat_map(|p| p[1].to_le_bytes()));
    cols.extend(pts.iter().flat_map(|p| (p[0] as f32).to_le_bytes()));
    cols.extend(pts.iter().flat_map(|p| (p[2] as f32).to_le_bytes()));
    let packed = ::lzf::compress(&cols).unwrap();
    let mut b = pcd_header(
        "i y x z",
        "1 8 4 4",
        "U F F F",
        "3 1 1 1",
        n as u64,
        "binary_compressed",
    )
    .into_bytes();
    b.extend_from_slice(&compressed_body(&packed, cols.len()));
    let s = pcd::parse(&b).unwrap();
    assert_eq!(s.points, pts);
}

#[test]
fn lzf_decompresses_what_the_lzf_crate_compresses() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_pcg::Pcg64::seed_from_u64(21);
    for case in 0..60 {
        // Words from a small vocabulary: runs, repeats near and far, literals.
        let len = rng.random_range(1..(if case < 50 { 4000 } else { 600_000 }));
        let vocab: Vec<Vec<u8>> = (0..rng.random_range(1..40))
            .map(|_| (0..rng.random_range(1..12)).map(|_| rng.random()).collect())
            .collect();
        let mut raw = Vec::with_capacity(len + 12);
        while raw.len() < len {
            if rng.random_bool(0.2) {
                raw.push(rng.random());
            } else {
                raw.extend_from_slice(&vocab[rng.random_range(0..vocab.len())]);
            }
        }
        let Ok(packed) = ::lzf::compress(&raw) else {
            continue; // incompressible
        };
        let mut out = Vec::new();
        lzf_decode::decompress(&packed, 0, raw.len(), |start, b, new| {
            assert_eq!(out.len(), new, "case {case}: pieces in order");
            out.extend_from_slice(&b[new - start..]);
        })
        .unwrap();
        assert!(out == raw, "case {case}");
        if case < 50 {
            // Cut anywhere or a byte changed: an error or the declared size.
            for k in 0..packed.len() {
                let cut = lzf_decode::decompress(&packed[..k], 0, raw.len(), |_, _, _| {});
                assert!(cut.is_err(), "case {case}: cut at {k}");
                let mut c = packed.clone();
                c[k] ^= 0xa5;
                let _ = lzf_decode::decompress(&c, 0, raw.len(), |_, _, _| {});
            }
        }
    }
}

#[test]
fn ply_element_counts_past_the_data_say_where_it_ends() {
    let head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    let (l, c, m) = syntax_at(cloud::parse_ply(format!("{head}1 2 3\n").as_bytes()));
    assert_eq!((l, c), (9, 1), "{m}");
    assert!(m.contains("3 `vertex` elements"), "{m}");
    let mut b = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n".to_vec();
    let body = b.len();
    b.extend_from_slice(&[0; 24]);
    let m = corrupt(cloud::parse_ply(&b));
    assert!(m.starts_with(&format!("byte {body}:")), "{m}");
    assert!(m.contains(&format!("ends at byte {}", b.len())), "{m}");
}

const FACES: &str = "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n";

#[test]
fn ply_list_lengths_and_vertex_indices_name_their_place() {
    let mut b = FACES.as_bytes().to_vec();
    b.extend_from_slice(&[0; 24]);
    let at = b.len();
    b.extend_from_slice(&u32::MAX.to_le_bytes());
    let m = corrupt(cloud::parse_ply(&b));
    assert!(m.contains(&format!("byte {at}:")), "{m}");
    assert!(m.contains("bad list length 4294967295"), "{m}");
    let mut b = FACES.as_bytes().to_vec();
    b.extend_from_slice(&[0; 24]);
    b.extend_from_slice(&3u32.to_le_bytes());
    for i in [0i32, 1, 2] {
        b.extend_from_slice(&i.to_le_bytes());
    }
    let m = corrupt(cloud::parse_ply(&b));
    assert!(m.contains(&format!("byte {}:", b.len() - 4)), "{m}");
    assert!(m.contains("face 0") && m.contains("the 2 there are"), "{m}");
    // ASCII: the line and column of the value.
    let ascii = FACES
        .replace("binary_little_endian", "ascii")
        .replace("uint", "int");
    let (l, c, m) = syntax_at(cloud::parse_ply(
        format!("{ascii}0 0 0\n1 1 1\n3 0 1 2\n").as_bytes(),
    ));
    assert_eq!((l, c), (12, 7), "{m}");
    assert!(m.contains("the 2 there are"), "{m}");
    let (l, c, m) = syntax_at(cloud::parse_ply(
        format!("{ascii}0 0 0\n1 1 1\n-1 0 1 2\n").as_bytes(),
    ));
    assert_eq!((l, c), (12, 1), "{m}");
    assert!(m.contains("bad list length -1"), "{m}");
}

#[test]
fn ply_without_xyz_names_the_vertex_element() {
    let ply = "ply\nformat ascii 1.0\ncomment no z\nelement vertex 1\nproperty float x\nproperty float y\nproperty float w\nend_header\n1 2 3\n";
    let (l, c, m) = syntax_at(cloud::parse_ply(ply.as_bytes()));
    assert_eq!((l, c), (4, 1), "{m}");
    assert!(m.contains("lacks `z`"), "{m}");
}

#[test]
fn pcd_ascii_counts_past_the_data_name_a_line() {
    // More points than the bytes can hold: the `POINTS` value.
    let (l, c, m) = syntax_at(pcd::parse((xyz_header(3, "ascii") + "1 2 3\n").as_bytes()));
    assert_eq!((l, c), (10, 8), "{m}");
    assert!(m.contains("declares 3 points"), "{m}");
    // Data that ends early: where it ends.
    let (l, c, m) = syntax_at(pcd::parse((xyz_header(2, "ascii") + "1 2 3\n").as_bytes()));
    assert_eq!((l, c), (13, 1), "{m}");
    assert!(m.contains("1 of 2 points") && m.contains("line 10"), "{m}");
    let (l, c, m) = syntax_at(pcd::parse(
        (xyz_header(2, "ascii") + "1 2 3\n4 5").as_bytes(),
    ));
    assert_eq!((l, c), (13, 4), "{m}");
    assert!(m.contains("found 2"), "{m}");
    // Binary data that ends early: the byte where the points start and the count.
    let mut b = xyz_header(2, "binary").into_bytes();
    let at = b.len();
    b.extend_from_slice(&[0; 20]);
    let m = corrupt(pcd::parse(&b));
    assert!(m.starts_with(&format!("byte {at}:")), "{m}");
    assert!(m.contains("line 10"), "{m}");
}

#[test]
fn pcd_header_faults_name_the_field_at_fault() {
    // A float of two bytes: the `SIZE` entry.
    let h = pcd_header("x y z", "4 2 4", "F F F", "1 1 1", 0, "ascii");
    assert_eq!(syntax_at(pcd::parse(h.as_bytes())).0, 4);
    assert_eq!(syntax_at(pcd::parse(h.as_bytes())).1, 8);
    // Too few `SIZE` / `TYPE` / `COUNT` entries: that line.
    let h = pcd_header("x y z", "4 4", "F F F", "1 1 1", 0, "ascii");
    let (l, _, m) = syntax_at(pcd::parse(h.as_bytes()));
    assert_eq!(l, 4, "{m}");
    let h = pcd_header("x y z", "4 4 4", "F F F", "1 1", 0, "ascii");
    assert_eq!(syntax_at(pcd::parse(h.as_bytes())).0, 6);
    // No `z`: the `FIELDS` line, saying which.
    let h = pcd_header("x y w", "4 4 4", "F F F", "1 1 1", 0, "ascii");
    let (l, _, m) = syntax_at(pcd::parse(h.as_bytes()));
    assert_eq!(l, 3, "{m}");
    assert!(m.contains("`z`"), "{m}");
}

#[test]
fn a_byte_order_mark_is_skipped() {
    const BOM: &str = "\u{feff}";
    let s = cloud::parse_xyz(format!("{BOM}1 2 3\n").as_bytes()).unwrap();
    assert_eq!(s.points, vec![[1.0, 2.0, 3.0]]);
    let (l, c, _) = syntax_at(cloud::parse_xyz(format!("{BOM}1 x 3\n").as_bytes()));
    assert_eq!((l, c), (1, 3));
    let s = log::parse(format!("{BOM}NODE 0 0 0 0 0 0\n1 2 3\n").as_bytes()).unwrap();
    assert_eq!(s[0].points, vec![[1.0, 2.0, 3.0]]);
    let ply = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n";
    let s = cloud::parse_ply(format!("{BOM}{ply}").as_bytes()).unwrap();
    assert_eq!(s.points, vec![[1.0, 2.0, 3.0]]);
    let s = pcd::parse(format!("{BOM}{}1 2 3\n", xyz_header(1, "ascii")).as_bytes()).unwrap();
    assert_eq!(s.points, vec![[1.0, 2.0, 3.0]]);
    // Binary data after a marked header; offsets still count from the file's start.
    let mut b = format!("{BOM}{}", xyz_header(2, "binary")).into_bytes();
    let at = b.len();
    b.extend_from_slice(&[0; 12]);
    assert!(corrupt(pcd::parse(&b)).starts_with(&format!("byte {at}:")));
    b.extend_from_slice(&[0; 12]);
    assert_eq!(pcd::parse(&b).unwrap().points.len(), 2);
    for bytes in [&b"\xff\xfe1\x00"[..], b"\xfe\xff\x001"] {
        let e = cloud::parse_xyz(bytes).unwrap_err().to_string();
        assert!(e.starts_with("1:1: the text is UTF-16"), "{e}");
        assert!(log::parse(bytes).is_err() && pcd::parse(bytes).is_err());
    }
}

#[test]
fn text_numbers_out_of_range_or_of_the_wrong_kind_are_errors() {
    let (l, c, m) = syntax_at(cloud::parse_xyz(b"1 2 3\n1 1e400 3\n"));
    assert_eq!((l, c), (2, 3));
    assert!(m.contains("out of range"), "{m}");
    // `inf` written as such is a missing return, kept.
    assert!(cloud::parse_xyz(b"1 -inf 3\n").unwrap().points[0][1].is_infinite());
    let (l, c, m) = syntax_at(log::parse(b"NODE 0 0 0 0 0 0\n1 1e39 3\n"));
    assert_eq!((l, c), (2, 3));
    assert!(m.contains("out of range"), "{m}");
    // PCD: a 4-byte float, an unsigned byte, a whole-number field.
    let h = pcd_header("x y z i", "4 4 4 1", "F F F U", "1 1 1 1", 1, "ascii");
    let (l, c, m) = syntax_at(pcd::parse(format!("{h}1 1e39 3 7\n").as_bytes()));
    assert_eq!((l, c), (12, 3), "{m}");
    assert!(m.contains("out of range"), "{m}");
    let (l, c, m) = syntax_at(pcd::parse(format!("{h}1 2 3 300\n").as_bytes()));
    assert_eq!((l, c), (12, 7), "{m}");
    assert!(m.contains("out of range"), "{m}");
    let (_, c, m) = syntax_at(pcd::parse(format!("{h}1 2 3 1.5\n").as_bytes()));
    assert_eq!(c, 7, "{m}");
    assert!(m.contains("not a whole number"), "{m}");
    assert!(pcd::parse(format!("{h}1 2 3 255\n").as_bytes()).is_ok());
    // PLY: an `int` property holding 1.5, a `float` past f32, a `double` past f64.
    let ply = |ty: &str, v: &str| {
        format!("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nproperty {ty} i\nend_header\n1 2 3 {v}\n")
    };
    let (l, c, m) = syntax_at(cloud::parse_ply(ply("int", "1.5").as_bytes()));
    assert_eq!((l, c), (9, 7), "{m}");
    assert!(m.contains("not a whole number"), "{m}");
    let (_, c, m) = syntax_at(cloud::parse_ply(ply("uchar", "256").as_bytes()));
    assert_eq!(c, 7, "{m}");
    assert!(m.contains("out of range"), "{m}");
    let (_, _, m) = syntax_at(cloud::parse_ply(ply("float", "1e39").as_bytes()));
    assert!(m.contains("out of range"), "{m}");
    let (_, _, m) = syntax_at(cloud::parse_ply(ply("double", "1e400").as_bytes()));
    assert!(m.contains("out of range"), "{m}");
    assert!(cloud::parse_ply(ply("uchar", "255").as_bytes()).is_ok());
    assert!(cloud::parse_ply(ply("double", "nan").as_bytes()).is_ok());
}

#[test]
fn pcd_counts_that_disagree_are_refused() {
    // POINTS 2 against WIDTH 3 × HEIGHT 1: the POINTS line (10), its number.
    let h = xyz_header(3, "ascii").replace("POINTS 3", "POINTS 2");
    let (l, c, m) = syntax_at(pcd::parse((h + "1 2 3\n4 5 6\n7 8 9\n").as_bytes()));
    assert_eq!((l, c), (10, 8), "{m}");
    assert!(m.contains("`WIDTH` × `HEIGHT` = 3 × 1"), "{m}");
    // Three points for a declared two: the third's line (15) named; blank lines
    // after the last point are fine.
    let (l, _, m) = syntax_at(pcd::parse(
        (xyz_header(2, "ascii") + "1 2 3\n4 5 6\n\n7 8 9\n").as_bytes(),
    ));
    assert_eq!(l, 15, "{m}");
    assert!(m.contains("more points than the 2"), "{m}");
    let s = pcd::parse((xyz_header(2, "ascii") + "1 2 3\n4 5 6\n\n \n").as_bytes()).unwrap();
    assert_eq!(s.points.len(), 2);
}
