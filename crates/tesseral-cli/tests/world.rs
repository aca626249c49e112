//! Issue "one world through every command", items 1–3: the frame, the colours and
//! the free space a user's file carries survive every command. Each test runs the
//! real binary; the files are made and checked with the library.

mod common;

use std::path::Path;

use common::{fails, json, ok};
use tesseral::io::{read_model, write_model};
use tesseral::linear::LinearOctree;
use tesseral::model::{Frame, Layer, Model};

/// A 0.05 m map: a block of occupied cells, free cells in front of it.
fn map(dir: &Path, name: &str, voxel_size: f64) -> Model {
    let occupied = LinearOctree::from_voxels(
        16,
        [-32768; 3],
        (0..6).flat_map(|x| (0..5).flat_map(move |y| (0..4).map(move |z| [x + 10, y, z]))),
    )
    .unwrap();
    let free = LinearOctree::from_voxels(
        16,
        [-32768; 3],
        (0..10).flat_map(|x| (0..5).flat_map(move |y| (0..4).map(move |z| [x, y, z]))),
    )
    .unwrap();
    let m = Model::from_parts(
        occupied,
        Frame::new(voxel_size, [0.0; 3]),
        None,
        Some(free),
        None,
    )
    .unwrap();
    write_model(&dir.join(name), &m).unwrap();
    m
}

#[test]
fn item_1_a_map_keeps_its_resolution_through_translate_and_op() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    map(d, "scan.bt", 0.05);
    ok(
        d,
        &["translate", "scan.bt", "--by", "1,0,0", "-o", "out.bt"],
    );
    let out = read_model(&d.join("out.bt")).unwrap();
    out.assert_valid();
    assert_eq!(out.frame.voxel_size, 0.05);
    assert_eq!(out.tree.bbox().unwrap().0, [11, 0, 0]);
    // In world units: 0.05 m is one voxel; 0.07 m is not a whole number of voxels.
    ok(
        d,
        &[
            "translate",
            "scan.bt",
            "--by-world",
            "0.1,0,0",
            "-o",
            "w.bt",
        ],
    );
    assert_eq!(
        read_model(&d.join("w.bt")).unwrap().tree.bbox().unwrap().0,
        [12, 0, 0]
    );
    fails(
        d,
        &[
            "translate",
            "scan.bt",
            "--by-world",
            "0.07,0,0",
            "-o",
            "x.bt",
        ],
        "not a whole number of voxels",
    );
    ok(d, &["op", "union", "scan.bt", "out.bt", "-o", "u.bt"]);
    assert_eq!(read_model(&d.join("u.bt")).unwrap().frame.voxel_size, 0.05);
    // A 0.05 m map and a 0.1 m map are not merged silently.
    map(d, "coarse.bt", 0.1);
    fails(
        d,
        &["op", "union", "scan.bt", "coarse.bt", "-o", "bad.bt"],
        "voxel sizes differ",
    );
    let err = String::from_utf8(
        common::run(d, &["op", "union", "scan.bt", "coarse.bt", "-o", "bad.bt"]).stderr,
    )
    .unwrap();
    assert!(err.contains("0.05") && err.contains("0.1"), "{err}");
    assert!(!d.join("bad.bt").exists());
}

/// An ASCII STL octahedron of the given radius around `c`.
fn octahedron(c: [f64; 3], r: f64) -> String {
    let v = |a: usize, s: f64| {
        let mut p = c;
        p[a] += s * r;
        p
    };
    let mut s = String::from("solid o\n");
    for sx in [1.0, -1.0] {
        for sy in [1.0, -1.0] {
            for sz in [1.0, -1.0] {
                let (a, b, cc) = (v(0, sx), v(1, sy), v(2, sz));
                // Outward orientation: flip when the octant is mirrored an odd number of times.
                let tri = if sx * sy * sz > 0.0 {
                    [a, b, cc]
                } else {
                    [a, cc, b]
                };
                s += "facet normal 0 0 0\nouter loop\n";
                for p in tri {
                    s += &format!("vertex {} {} {}\n", p[0], p[1], p[2]);
                }
                s += "endloop\nendfacet\n";
            }
        }
    }
    s + "endsolid o\n"
}

fn obj_bounds(path: &Path) -> ([f64; 3], [f64; 3]) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lo = [f64::MAX; 3];
    let mut hi = [f64::MIN; 3];
    for line in text.lines().filter_map(|l| l.trim().strip_prefix("v ")) {
        let p: Vec<f64> = line
            .split_whitespace()
            .map(|w| w.parse().unwrap())
            .collect();
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    (lo, hi)
}

#[test]
fn item_1_a_small_mesh_keeps_its_world_bounds_through_convert_translate_convert() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("ico.stl"), octahedron([1.0, 2.0, 3.0], 0.05)).unwrap();
    ok(d, &["convert", "ico.stl", "ico.tess", "--depth", "6"]);
    ok(
        d,
        &["translate", "ico.tess", "--by", "0,0,0", "-o", "t.tess"],
    );
    ok(d, &["convert", "t.tess", "back.obj"]);
    let (lo, hi) = obj_bounds(&d.join("back.obj"));
    for a in 0..3 {
        let c = [1.0, 2.0, 3.0][a];
        assert!(
            (lo[a] - (c - 0.05)).abs() < 0.01 && (hi[a] - (c + 0.05)).abs() < 0.01,
            "axis {a}: {lo:?}..{hi:?}"
        );
    }
}

#[test]
fn item_2_colours_survive_commands_and_formats() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A ColorOcTree with two colours stays a ColorOcTree with both.
    let tree = LinearOctree::from_voxels(16, [-32768; 3], (0..8).map(|x| [x, 0, 0])).unwrap();
    let colors = Layer::from_voxels(
        16,
        [-32768; 3],
        (0..8).map(|x| {
            (
                [x, 0, 0],
                if x < 4 {
                    [255, 0, 0, 255]
                } else {
                    [0, 0, 255, 255]
                },
            )
        }),
    )
    .unwrap();
    let m = Model::new(tree.clone())
        .with_frame(Frame::new(0.05, [0.0; 3]))
        .with_colors(colors)
        .unwrap();
    write_model(&d.join("c.ot"), &m).unwrap();
    ok(d, &["translate", "c.ot", "--by", "0,1,0", "-o", "c2.ot"]);
    let text = std::fs::read(d.join("c2.ot")).unwrap();
    assert!(String::from_utf8_lossy(&text[..200]).contains("id ColorOcTree"));
    let back = read_model(&d.join("c2.ot")).unwrap();
    let c = back.colors.as_ref().unwrap();
    assert_eq!(
        (c.get([0, 1, 0]), c.get([7, 1, 0])),
        (Some([255, 0, 0, 255]), Some([0, 0, 255, 255]))
    );
    // A two-colour .vox keeps both palette colours through rotate and op.
    ok(d, &["convert", "c.ot", "c.vox"]);
    ok(
        d,
        &[
            "rotate", "c.vox", "--axis", "z", "--turns", "1", "-o", "r.vox",
        ],
    );
    ok(d, &["op", "union", "r.vox", "r.vox", "-o", "u.vox"]);
    let u = read_model(&d.join("u.vox")).unwrap();
    assert_eq!(u.colors.as_ref().unwrap().region_count(), 2);
    // build writes the scene's frame and colours; meshes come out in scene units.
    let scene = "depth 6\nbounds [-10, -10, 0] [10, 10, 20]\nbox(size = [8, 8, 8]) at [0, 0, 4] colour \"red\"\nsphere(r = 4) at [0, 0, 12] colour \"blue\"\n";
    std::fs::write(d.join("s.tss"), scene).unwrap();
    ok(d, &["build", "s.tss", "-o", "s.tess"]);
    let info = json(d, &["info", "s.tess", "--json"]);
    assert_eq!(info["colors"], 2, "{info}");
    assert!(
        (info["voxel_size"].as_f64().unwrap() - 20.0 / 64.0).abs() < 1e-12,
        "{info}"
    );
    ok(d, &["build", "s.tss", "-o", "s.obj"]);
    let (lo, hi) = obj_bounds(&d.join("s.obj"));
    assert!(
        (lo[0] + 4.0).abs() < 0.4 && (hi[2] - 16.0).abs() < 0.4,
        "{lo:?} {hi:?}"
    );
    // render uses the stored colours: the red box and the blue sphere both show.
    ok(d, &["render", "s.tess", "-o", "s.png", "--size", "160x120"]);
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(d.join("s.png")).unwrap(),
    ));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let frame = reader.next_frame(&mut buf).unwrap();
    let px = &buf[..frame.buffer_size()];
    let step = px.len() / (160 * 120);
    let (mut reds, mut blues) = (0, 0);
    for p in px.chunks(step) {
        let (r, g, b) = (i32::from(p[0]), i32::from(p[1]), i32::from(p[2]));
        reds += usize::from(r > g + 60 && r > b + 60);
        blues += usize::from(b > r + 60 && b > g + 30);
    }
    assert!(reds > 100 && blues > 100, "reds {reds}, blues {blues}");
}

#[test]
fn item_3_free_space_survives_convert_translate_and_op() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let m = map(d, "scan.bt", 0.05);
    let free = m.free.as_ref().unwrap().voxel_count();
    let info = json(d, &["info", "scan.bt", "--json"]);
    assert_eq!(
        (info["voxels"].as_u64(), info["free_voxels"].as_u64()),
        (Some(120), Some(free))
    );
    ok(
        d,
        &["translate", "scan.bt", "--by", "0,0,0", "-o", "same.bt"],
    );
    assert_eq!(
        std::fs::read(d.join("same.bt")).unwrap(),
        std::fs::read(d.join("scan.bt")).unwrap()
    );
    ok(d, &["convert", "scan.bt", "scan.ot"]);
    ok(d, &["convert", "scan.ot", "scan.tess"]);
    ok(d, &["convert", "scan.tess", "again.bt"]);
    let again = read_model(&d.join("again.bt")).unwrap();
    again.assert_valid();
    assert_eq!(again.free.as_ref().unwrap().voxel_count(), free);
    // A difference carves: the removed voxels become known free.
    ok(
        d,
        &["op", "difference", "scan.bt", "same.bt", "-o", "carved.bt"],
    );
    let carved = read_model(&d.join("carved.bt")).unwrap();
    assert_eq!(carved.tree.voxel_count(), 0);
    assert_eq!(carved.free.as_ref().unwrap().voxel_count(), free + 120);
}

#[test]
fn item_8_garbage_is_not_read_as_an_obj() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut x = 12345u64;
    let garbage: Vec<u8> = (0..4096)
        .map(|_| {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 33) as u8
        })
        .collect();
    std::fs::write(d.join("noise.obj"), &garbage).unwrap();
    fails(d, &["convert", "noise.obj", "n.tess"], "noise.obj:");
    // A binary STL renamed .obj.
    std::fs::write(d.join("cube.stl"), octahedron([0.0; 3], 1.0)).unwrap();
    ok(d, &["convert", "cube.stl", "c.tess", "--depth", "4"]);
    ok(d, &["convert", "c.tess", "bin.stl"]);
    std::fs::copy(d.join("bin.stl"), d.join("bin.obj")).unwrap();
    fails(d, &["convert", "bin.obj", "b.tess"], "bin.obj:1:");
    // A text file that is not OBJ, and an OBJ with no faces.
    std::fs::write(d.join("notes.obj"), "hello world\n").unwrap();
    fails(
        d,
        &["convert", "notes.obj", "x.tess"],
        "notes.obj:1:1: `hello` is not an OBJ statement",
    );
    std::fs::write(d.join("empty.obj"), "# nothing\no thing\n").unwrap();
    fails(d, &["convert", "empty.obj", "x.tess"], "no triangles");
    assert!(!d.join("x.tess").exists() && !d.join("n.tess").exists());
}

#[test]
fn item_9_a_voxelization_over_budget_is_refused_before_the_work() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("oct.stl"), octahedron([0.0; 3], 1.0)).unwrap();
    // About 2.7e8 crossings and 4.6e8 surface leaves at depth 14: over what 1 GiB
    // allows, refused at once.
    fails(
        d,
        &[
            "convert", "oct.stl", "big.tess", "--depth", "14", "--memory", "1G",
        ],
        "--memory",
    );
    assert!(!d.join("big.tess").exists());
    // At the default budget, the leaves are estimated from the surface area first:
    // about 4.6e8 at depth 14, refused at once naming the flags.
    fails(
        d,
        &["convert", "oct.stl", "big.tess", "--depth", "14"],
        "or --memory",
    );
    // Within the budget it is built.
    ok(
        d,
        &[
            "convert",
            "oct.stl",
            "small.tess",
            "--depth",
            "8",
            "--memory",
            "1G",
        ],
    );
}

#[test]
fn item_2_coloured_meshes_carry_their_colours() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = "depth 5\nbounds [0, 0, 0] [32, 32, 32]\nbox(size = [8, 8, 8]) at [8, 8, 8] colour \"red\"\nbox(size = [8, 8, 8]) at [20, 20, 20] colour \"blue\"\n";
    std::fs::write(d.join("s.tss"), scene).unwrap();
    ok(d, &["build", "s.tss", "-o", "s.ply"]);
    let bytes = std::fs::read(d.join("s.ply")).unwrap();
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    let header = String::from_utf8_lossy(&bytes[..end]);
    assert!(header.contains("property uchar red"), "{header}");
    // Faces: count byte, three i32, then RGB; both colours appear.
    let nv: usize = header
        .lines()
        .find_map(|l| l.strip_prefix("element vertex "))
        .unwrap()
        .parse()
        .unwrap();
    let nf: usize = header
        .lines()
        .find_map(|l| l.strip_prefix("element face "))
        .unwrap()
        .parse()
        .unwrap();
    let faces = &bytes[end + 12 * nv..];
    assert_eq!(faces.len(), 16 * nf);
    let rgb: std::collections::HashSet<[u8; 3]> =
        faces.chunks(16).map(|f| [f[13], f[14], f[15]]).collect();
    assert_eq!(
        rgb,
        [[200, 60, 50], [60, 100, 200]].into_iter().collect(),
        "{rgb:?}"
    );
    // It reads back as a mesh (the colour properties are read past).
    ok(d, &["convert", "s.ply", "back.tess", "--depth", "4"]);
    ok(d, &["build", "s.tss", "-o", "s.glb"]);
    let glb = std::fs::read(d.join("s.glb")).unwrap();
    let n = u32::from_le_bytes([glb[12], glb[13], glb[14], glb[15]]) as usize;
    let json: serde_json::Value = serde_json::from_slice(&glb[20..20 + n]).unwrap();
    assert_eq!(
        json["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"],
        1
    );
}
