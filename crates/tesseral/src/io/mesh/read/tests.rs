use super::*;

fn cube_obj() -> String {
    let mut s = String::from("# unit cube\n");
    for z in 0..2 {
        for y in 0..2 {
            for x in 0..2 {
                s += &format!("v {x} {y} {z}\n");
            }
        }
    }
    // Quads, counter-clockwise from outside (1-based, x + 2y + 4z + 1).
    s += "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
    s
}

#[test]
fn garbage_and_binary_stl_are_not_obj() {
    // Seeded random bytes: never an empty mesh, always an error with a place.
    let mut x = 0x9e37_79b9_7f4a_7c15u64;
    for seed in 0..200 {
        let bytes: Vec<u8> = (0..64 + seed)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                x as u8
            })
            .collect();
        if let Ok(m) = parse_obj(&bytes) {
            // Only text made of OBJ statements may parse.
            assert!(std::str::from_utf8(&bytes).is_ok(), "seed {seed}: {m:?}");
        }
    }
    let mut stl = vec![0u8; 84];
    stl[..10].copy_from_slice(b"binary stl");
    stl[80] = 1;
    stl.extend(std::iter::repeat_n(0x41u8, 50));
    let e = parse_obj(&stl).unwrap_err().with_path("m.obj").to_string();
    assert!(e.starts_with("m.obj:1:1:"), "{e}");
    let e = parse_obj(b"v 0 0 0\nhello world\n")
        .unwrap_err()
        .to_string();
    assert_eq!(e, "2:1: `hello` is not an OBJ statement");
    // The statements of the format that we do not use are read past.
    let ok = "mtllib a.mtl\no cube\ng side\nusemtl red\ns off\nvt 0 0\nvn 0 0 1\n";
    assert_eq!(
        parse_obj(format!("{ok}{}", cube_obj()).as_bytes())
            .unwrap()
            .triangles
            .len(),
        12
    );
}

#[test]
fn obj_quads_become_a_closed_cube() {
    let m = parse_obj(cube_obj().as_bytes()).unwrap();
    assert_eq!((m.positions.len(), m.triangles.len()), (8, 12));
    assert_eq!(m.edge_defects(), 0);
    assert!((m.volume() - 1.0).abs() < 1e-12);
}

#[test]
fn written_meshes_parse_back() {
    let m = parse_obj(cube_obj().as_bytes()).unwrap();
    for (ext, f) in [
        (
            "stl",
            super::super::write::write_stl
                as fn(&mut dyn std::io::Write, &TriMesh) -> std::io::Result<()>,
        ),
        ("obj", super::super::write::write_obj),
        ("ply", super::super::write::write_ply),
    ] {
        let mut bytes = Vec::new();
        f(&mut bytes, &m).unwrap();
        let back = parse(&bytes, ext).unwrap();
        assert_eq!(back.triangles.len(), 12, "{ext}");
        assert!((back.volume() - 1.0).abs() < 1e-6, "{ext}");
    }
}

#[test]
fn ascii_stl_and_ply_parse() {
    let stl = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
    let m = parse_stl(stl.as_bytes()).unwrap();
    assert_eq!(m.triangles.len(), 1);
    let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    let m = parse_ply(ply.as_bytes()).unwrap();
    assert_eq!((m.positions.len(), m.triangles.len()), (3, 1));
}

#[test]
fn a_cut_ascii_stl_is_an_error() {
    // Only the header, or facets without the closing `endsolid`: the tail is lost.
    for text in [
        "solid x\n",
        "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n",
    ] {
        let e = parse_stl(text.as_bytes()).unwrap_err();
        assert!(e.to_string().contains("without `endsolid`"), "{e}");
    }
    // An empty but closed solid is a valid, empty mesh.
    let m = parse_stl(b"solid x\nendsolid x\n").unwrap();
    assert!(m.triangles.is_empty());
}

#[test]
fn a_short_point_names_its_keyword() {
    let e = parse_obj(b"v 1 2\n").unwrap_err().with_path("a.obj");
    assert_eq!(e.to_string(), "a.obj:1:6: `v` needs three numbers");
    let e = parse_stl(b"solid x\nvertex 1 2\n")
        .unwrap_err()
        .with_path("a.stl");
    assert_eq!(e.to_string(), "a.stl:2:11: `vertex` needs three numbers");
}

#[test]
fn errors_name_line_and_column() {
    let e = parse_obj(b"v 0 0 0\nv 1 x 0\n")
        .unwrap_err()
        .with_path("a.obj");
    assert_eq!(e.to_string(), "a.obj:2:5: `x` is not a finite number");
    let e = parse_obj(b"v 0 0 0\nf 1 2 3\n")
        .unwrap_err()
        .with_path("a.obj");
    assert!(e.to_string().starts_with("a.obj:2:5:"), "{e}");
    let e = parse_stl(b"solid x\nvertex 1 2\n")
        .unwrap_err()
        .with_path("a.stl");
    assert!(e.to_string().starts_with("a.stl:2:"), "{e}");
    // A hostile PLY header.
    let ply = b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    assert!(parse_ply(ply).is_err());
    // A binary STL claiming more triangles than it holds.
    let mut stl = vec![0u8; 84 + 50];
    stl[80..84].copy_from_slice(&1000u32.to_le_bytes());
    assert!(parse_stl(&stl).is_err());
}

/// A UTF-8 byte order mark (editors on Windows write one) is skipped, and columns
/// are counted after it.
#[test]
fn a_byte_order_mark_is_skipped() {
    const BOM: &str = "\u{feff}";
    let stl = format!("{BOM}solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n");
    assert_eq!(parse_stl(stl.as_bytes()).unwrap().triangles.len(), 1);
    let obj = format!("{BOM}{}", cube_obj());
    assert_eq!(parse_obj(obj.as_bytes()).unwrap().triangles.len(), 12);
    let e = parse_obj(format!("{BOM}v 1 x 0\n").as_bytes())
        .unwrap_err()
        .with_path("a.obj");
    assert_eq!(e.to_string(), "a.obj:1:5: `x` is not a finite number");
}

/// UTF-16 and UTF-32 text is refused at 1:1 naming its encoding, not read as
/// bytes that fail further on (a binary STL's triangle count, a NUL in a number).
#[test]
fn wide_text_is_named() {
    let utf16le: Vec<u8> = "\u{feff}solid t\nendsolid t\n"
        .encode_utf16()
        .flat_map(u16::to_le_bytes)
        .collect();
    let e = parse_stl(&utf16le).unwrap_err().with_path("a.stl");
    assert_eq!(
        e.to_string(),
        "a.stl:1:1: the text is UTF-16 little-endian (byte order mark FF FE): save it as UTF-8"
    );
    let utf16be: Vec<u8> = "\u{feff}v 0 0 0\n"
        .encode_utf16()
        .flat_map(u16::to_be_bytes)
        .collect();
    let e = parse_obj(&utf16be).unwrap_err().to_string();
    assert!(e.contains("UTF-16 big-endian"), "{e}");
    let e = parse_ply(b"\xff\xfe\x00\x00p\x00\x00\x00")
        .unwrap_err()
        .to_string();
    assert!(e.contains("UTF-32 little-endian"), "{e}");
}
