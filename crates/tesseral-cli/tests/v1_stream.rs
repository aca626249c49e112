//! Version-1 `.tess` files read by `info`, `render`, `op` and `translate` as
//! streams (`TessFile::open_streaming`: the payload indexed in stretches), as
//! `convert` reads them: each streamed result against the in-memory one (taken
//! for standard input, or `--in-memory`) and against the same model written as
//! version 2, byte for byte, colours, empty and full trees included; a legacy
//! colour list (flag bit 1), which does not stream, takes the in-memory path with
//! the same results; and a depth-12 file that streams within an address space
//! where the in-memory path fails (issue 15).

mod common;

use std::fs;
use std::path::Path;
use std::process::Command;

use common::{build_scene, json, ok, render_both, run, run_capped, run_stdin, stdout_of};
use rand::{Rng, SeedableRng};
use serde_json::Value;
use tesseral::linear::LinearOctree;
use tesseral::model::{Frame, Layer, Model};

/// A seeded random model in the space (`depth`, `origin`) with `frame`:
/// scattered voxels, sometimes a big block, sometimes nothing (`kind` 0), the
/// whole space (`kind` 1); colours on some voxels (or none).
fn random_model(
    rng: &mut rand_pcg::Pcg64,
    (depth, origin): (u8, [i64; 3]),
    frame: Frame,
    kind: usize,
) -> Model {
    let side = 1i64 << depth;
    let n = if kind == 0 {
        0
    } else {
        rng.random_range(1..1500)
    };
    let voxels: Vec<[i64; 3]> = (0..n)
        .map(|_| [0, 1, 2].map(|a| origin[a] + rng.random_range(0..side)))
        .collect();
    let mut tree = LinearOctree::from_voxels(depth, origin, voxels.iter().copied()).unwrap();
    if kind == 1 {
        tree = LinearOctree::full(depth, origin).unwrap();
    } else if n > 0 && rng.random_bool(0.5) {
        tree = tree
            .union(&LinearOctree::full(depth - 1, origin).unwrap())
            .unwrap();
    }
    let mut model = Model::new(tree.clone()).with_frame(frame);
    if rng.random_bool(0.7) && n > 0 {
        let palette = [[255, 0, 0, 255], [0, 0, 255, 255], [7, 8, 9, 100]];
        let mut sets = vec![Vec::new(); 3];
        for v in &voxels {
            sets[rng.random_range(0..3)].push(*v);
        }
        // A voxel drawn twice keeps its first colour.
        let mut seen = std::collections::HashSet::new();
        let sets = sets.into_iter().map(|vs| {
            vs.into_iter()
                .filter(|v| seen.insert(*v))
                .collect::<Vec<_>>()
        });
        let regions: Vec<_> = palette
            .iter()
            .zip(sets.collect::<Vec<_>>())
            .map(|(c, vs)| {
                let t = LinearOctree::from_voxels(depth, origin, vs).unwrap();
                (*c, t.intersection(&tree).unwrap())
            })
            .collect();
        let layer = Layer::from_regions(depth, origin, regions).unwrap();
        model = model.with_colors(layer).unwrap();
    } else if kind == 1 {
        // A full tree with an empty colour layer: the layer is kept.
        let layer =
            Layer::from_regions(depth, origin, std::iter::empty::<([u8; 4], LinearOctree)>())
                .unwrap();
        model = model.with_colors(layer).unwrap();
    }
    model.tree.assert_valid();
    model
}

fn v1_bytes(model: &Model) -> Vec<u8> {
    let mut out = Vec::new();
    tesseral::io::native::write_v1(&mut out, model).unwrap();
    out
}

fn v2_bytes(model: &Model) -> Vec<u8> {
    let mut out = Vec::new();
    tesseral::io::native::write(&mut out, model).unwrap();
    out
}

/// `model` as a version-1 file whose colours are the legacy list (flag bit 1:
/// a voxel's code delta and its RGBA, voxel after voxel), as old builds wrote.
fn legacy_v1_bytes(model: &Model) -> Vec<u8> {
    let bare = Model::new(model.tree.clone()).with_frame(model.frame);
    let mut b = v1_bytes(&bare);
    b.truncate(b.len() - 4);
    let flags = u16::from_le_bytes([b[10], b[11]]) | 2;
    b[10..12].copy_from_slice(&flags.to_le_bytes());
    let mut pairs = Vec::new();
    for (rgba, region) in model.colors.as_ref().map_or(&[][..], |l| l.regions()) {
        for l in region.leaves() {
            pairs.extend((l.code()..l.end()).map(|c| (c, *rgba)));
        }
    }
    pairs.sort_unstable();
    b.extend_from_slice(&(pairs.len() as u64).to_le_bytes());
    let mut last = 0;
    for (code, rgba) in pairs {
        let mut d = code - last;
        last = code;
        loop {
            let byte = (d & 0x7f) as u8;
            d >>= 7;
            b.push(if d == 0 { byte } else { byte | 0x80 });
            if d == 0 {
                break;
            }
        }
        b.extend_from_slice(&rgba);
    }
    let crc = crc32(&b);
    b.extend_from_slice(&crc.to_le_bytes());
    b
}

/// CRC-32 (IEEE), bit by bit: the checksum of a `.tess` file.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &byte in bytes {
        crc ^= u32::from(byte);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// `info FILE --json`, checking the path it took; the JSON without `streamed`.
fn info(d: &Path, file: &str, streamed: bool) -> Value {
    let mut v = json(d, &["info", file, "--json"]);
    assert_eq!(v["streamed"], streamed, "{file}: {v}");
    v.as_object_mut().unwrap().remove("streamed");
    v
}

/// `info -` with `file` on standard input: the in-memory path.
fn info_in_memory(d: &Path, file: &str) -> Value {
    let out = stdout_of(run_stdin(d, &["info", "-", "--json"], file), "info -");
    let mut v: Value = serde_json::from_slice(&out).unwrap();
    assert_eq!(v["streamed"], false);
    v.as_object_mut().unwrap().remove("streamed");
    v
}

/// `translate FILE --by BY` into `out`, streamed when `streamed`.
fn translate(d: &Path, file: &str, by: &str, out: &str, streamed: bool) {
    let v = json(
        d,
        &[
            "translate",
            file,
            &format!("--by={by}"),
            "-o",
            out,
            "--json",
        ],
    );
    assert_eq!(v["streamed"] == true, streamed, "{file} by {by}: {v}");
}

/// The in-memory translation (standard input) as `.tess` bytes.
fn translate_in_memory(d: &Path, file: &str, by: &str) -> Vec<u8> {
    let by = format!("--by={by}");
    let args = ["translate", "-", &by, "-o", "-", "--format", "tess"];
    stdout_of(run_stdin(d, &args, file), "in-memory translate")
}

/// `op OP A B` into `out`, checking the path it took.
fn op(d: &Path, which: &str, a: &str, b: &str, out: &str, streamed: bool) {
    let v = json(d, &["op", which, a, b, "-o", out, "--json"]);
    assert_eq!(v["streamed"] == true, streamed, "{which} {a} {b}: {v}");
}

/// The in-memory set operation (A on standard input) as `.tess` bytes.
fn op_in_memory(d: &Path, which: &str, a: &str, b: &str) -> Vec<u8> {
    let args = ["op", which, "-", b, "-o", "-", "--format", "tess"];
    stdout_of(run_stdin(d, &args, a), "in-memory op")
}

fn read(d: &Path, name: &str) -> Vec<u8> {
    fs::read(d.join(name)).unwrap()
}

/// On seeded random models (colours or none, frames, empty and full trees), a
/// version-1 file streams through `info`, `translate`, `op` and `render`, and
/// each gives what the in-memory path gives for the same file and what the
/// streamed path gives for the model written as version 2, byte for byte.
#[test]
fn version_1_files_stream_with_the_in_memory_results() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(0x7e55_0001);
    let ops = ["union", "intersection", "difference", "xor"];
    for i in 0..10 {
        let depth = rng.random_range(2..=5u8);
        let space = (depth, [0, 1, 2].map(|_| rng.random_range(-40i64..40)));
        let frame = Frame::new(0.25 * (1 + i % 3) as f64, [1.0, -2.0, 0.5 * i as f64]);
        let a = random_model(&mut rng, space, frame, i % 5);
        let b = random_model(&mut rng, space, frame, 2 + i % 3);
        fs::write(d.join("a1.tess"), v1_bytes(&a)).unwrap();
        fs::write(d.join("a2.tess"), v2_bytes(&a)).unwrap();
        fs::write(d.join("b1.tess"), v1_bytes(&b)).unwrap();
        fs::write(d.join("b2.tess"), v2_bytes(&b)).unwrap();
        let what = format!("model {i}");
        // info: streamed from either version, as the in-memory reader says.
        let want = info_in_memory(d, "a1.tess");
        assert_eq!(info(d, "a1.tess", true), want, "{what}");
        assert_eq!(info(d, "a2.tess", true), want, "{what}");
        // translate: unaligned, aligned, growing the space, none.
        let side = 1i64 << depth;
        for by in [
            "3,-5,7",
            &format!("{side},0,-{side}"),
            &format!("{},1,0", 2 * side),
            "0,0,0",
        ] {
            translate(d, "a1.tess", by, "t1.tess", true);
            translate(d, "a2.tess", by, "t2.tess", true);
            let mem = translate_in_memory(d, "a1.tess", by);
            assert!(read(d, "t1.tess") == mem, "{what} by {by}: v1 streamed");
            assert!(read(d, "t2.tess") == mem, "{what} by {by}: v2 streamed");
        }
        // op: both operands version 1, mixed, and both version 2.
        for which in ops {
            let mem = op_in_memory(d, which, "a1.tess", "b1.tess");
            for (x, y) in [("a1", "b1"), ("a1", "b2"), ("a2", "b1"), ("a2", "b2")] {
                op(
                    d,
                    which,
                    &format!("{x}.tess"),
                    &format!("{y}.tess"),
                    "o.tess",
                    true,
                );
                assert!(read(d, "o.tess") == mem, "{what}: {which} {x} {y}");
            }
        }
        // render: streamed against --in-memory, and against version 2.
        let size = ["--size", "48x36"];
        let views: [&[&str]; 3] = [
            &size,
            &[&size[..], &["--outline"]].concat(),
            &[&size[..], &["--sheet"]].concat(),
        ];
        for extra in views {
            render_both(d, "a2.tess", extra);
            let v2 = read(d, "s.png");
            let (v, _) = render_both(d, "a1.tess", extra);
            assert!(
                read(d, "s.png") == v2,
                "{what} {extra:?}: v1 and v2 pictures differ"
            );
            assert_eq!(
                v["chunks"],
                json(
                    d,
                    &[&["render", "a2.tess", "-o", "x.png", "--json"][..], extra].concat()
                )["chunks"]
            );
        }
    }
    let stray: Vec<_> = fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(stray.is_empty(), "{stray:?}");
}

/// A version-1 file whose colours are the legacy per-voxel list (flag bit 1)
/// does not stream (its colours are per voxel, not regions: see
/// docs/stream-translate.md): `info`, `translate`, `op` and `render` take the
/// in-memory path with the results the model gives written as version 2, and
/// `translate --stream` names why.
#[test]
fn a_legacy_colour_list_is_read_whole_with_the_same_results() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(0x7e55_0002);
    for i in 0..4 {
        let space = (rng.random_range(2..=4u8), [5, -3, 0]);
        let frame = Frame::new(0.5, [0.0, 1.0, 2.0]);
        let a = loop {
            let m = random_model(&mut rng, space, frame, 2);
            if m.colors.as_ref().is_some_and(|l| l.voxel_count() > 0) {
                break m;
            }
        };
        fs::write(d.join("l.tess"), legacy_v1_bytes(&a)).unwrap();
        fs::write(d.join("a2.tess"), v2_bytes(&a)).unwrap();
        let what = format!("model {i}");
        assert_eq!(info(d, "l.tess", false), info(d, "a2.tess", true), "{what}");
        translate(d, "l.tess", "1,2,3", "t1.tess", false);
        translate(d, "a2.tess", "1,2,3", "t2.tess", true);
        assert!(
            read(d, "t1.tess") == read(d, "t2.tess"),
            "{what}: translate"
        );
        let out = run(
            d,
            &[
                "translate",
                "l.tess",
                "--by=1,2,3",
                "-o",
                "t3.tess",
                "--stream",
            ],
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("--stream") && err.contains("legacy colour list"),
            "{err}"
        );
        assert!(!d.join("t3.tess").exists());
        op(d, "union", "l.tess", "a2.tess", "o1.tess", false);
        op(d, "union", "a2.tess", "a2.tess", "o2.tess", true);
        assert!(read(d, "o1.tess") == read(d, "o2.tess"), "{what}: op");
        let v = json(
            d,
            &[
                "render", "l.tess", "-o", "l.png", "--json", "--size", "40x30",
            ],
        );
        assert_eq!(v["streamed"], false);
        render_both(d, "a2.tess", &["--size", "40x30"]);
        assert!(read(d, "l.png") == read(d, "s.png"), "{what}: render");
    }
}

/// The depth-12 spheroid (14.5 M leaves) written as a version-1 file streams
/// through `info`, `render`, `translate` and `op` within 256 MiB of address space
/// (`ulimit -v`), with the results of the version-2 file; the in-memory paths of
/// the same file cannot.
#[test]
fn a_version_1_file_streams_in_a_small_address_space() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    build_scene(d, "fig4c-spheroid.tss", "s.tess", 12);
    {
        let model = tesseral::io::read_model(&d.join("s.tess")).unwrap();
        let mut f = std::io::BufWriter::new(fs::File::create(d.join("s1.tess")).unwrap());
        tesseral::io::native::write_v1(&mut f, &model).unwrap();
        std::io::Write::flush(&mut f).unwrap();
    }
    let capped = |args: &[&str]| -> Value {
        let out = run_capped(d, args, 256);
        serde_json::from_slice(&stdout_of(out, &format!("{args:?}"))).unwrap()
    };
    let v = capped(&["info", "s1.tess", "--json"]);
    assert_eq!(
        (v["streamed"].clone(), v["leaves"].clone()),
        (true.into(), 14_520_164.into())
    );
    let v = capped(&[
        "translate",
        "s1.tess",
        "--by=3,-5,7",
        "-o",
        "t1.tess",
        "--json",
    ]);
    assert_eq!(v["streamed"], true);
    ok(d, &["translate", "s.tess", "--by=3,-5,7", "-o", "t2.tess"]);
    assert!(read(d, "t1.tess") == read(d, "t2.tess"), "translate");
    let v = capped(&["op", "xor", "s1.tess", "t2.tess", "-o", "x1.tess", "--json"]);
    assert_eq!(v["streamed"], true);
    ok(d, &["op", "xor", "s.tess", "t2.tess", "-o", "x2.tess"]);
    assert!(read(d, "x1.tess") == read(d, "x2.tess"), "op");
    let v = capped(&[
        "render", "s1.tess", "-o", "r1.png", "--json", "--memory", "64M", "--size", "320x240",
    ]);
    assert_eq!(v["streamed"], true);
    ok(
        d,
        &[
            "render", "s.tess", "-o", "r2.png", "--memory", "64M", "--size", "320x240",
        ],
    );
    assert!(read(d, "r1.png") == read(d, "r2.png"), "render");
    // The in-memory paths of the same file, under the same cap, fail.
    for args in [
        &["info", "-", "--json"][..],
        &["translate", "-", "--by=3,-5,7", "-o", "m.tess"],
        &[
            "render",
            "s1.tess",
            "--in-memory",
            "-o",
            "m.png",
            "--size",
            "320x240",
        ],
    ] {
        let out = Command::new("sh")
            .arg("-c")
            .arg(format!(
                "ulimit -v {}; exec \"$0\" \"$@\" < s1.tess",
                256 * 1024
            ))
            .arg(env!("CARGO_BIN_EXE_tesseral"))
            .args(args)
            .env("RAYON_NUM_THREADS", "2")
            .env("MALLOC_ARENA_MAX", "2")
            .current_dir(d)
            .output()
            .unwrap();
        assert!(
            !out.status.success(),
            "{args:?} passed in memory under the cap"
        );
    }
    assert!(!d.join("m.tess").exists() && !d.join("m.png").exists());
}
