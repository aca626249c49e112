//! `convert` from `.tess` files (both versions) and datasets, streamed: into
//! `.xyz` voxel lists and, with `--parts K`, into datasets; against the in-memory
//! paths (taken for standard input) through the real binary (issue 15).

mod common;

use std::fs;
use std::path::Path;
use std::process::Command;

use common::{build_scene, fails, json, ok, run, run_capped, run_stdin, scenes, stdout_of};
use rand::{Rng, SeedableRng};
use tesseral::linear::LinearOctree;
use tesseral::model::{Frame, Layer, Model};

/// A seeded random model: scattered voxels at a random origin, sometimes a big
/// block, sometimes nothing; colours on some voxels (or none); a frame.
fn random_model(rng: &mut rand_pcg::Pcg64, i: usize) -> Model {
    let depth = rng.random_range(2..=6u8);
    let side = 1i64 << depth;
    let origin = [0, 1, 2].map(|_| rng.random_range(-50i64..50));
    let n = if i % 5 == 4 {
        0
    } else {
        rng.random_range(1..2000)
    };
    let voxels: Vec<[i64; 3]> = (0..n)
        .map(|_| [0, 1, 2].map(|a| origin[a] + rng.random_range(0..side)))
        .collect();
    let mut tree = LinearOctree::from_voxels(depth, origin, voxels.iter().copied()).unwrap();
    if n > 0 && rng.random_bool(0.5) {
        tree = tree
            .union(&LinearOctree::full(depth - 1, origin).unwrap())
            .unwrap();
    }
    let mut model =
        Model::new(tree.clone()).with_frame(Frame::new(0.5, [1.0, -2.0, 0.25 * i as f64]));
    if i % 3 != 2 && n > 0 {
        let palette = [[255, 0, 0, 255], [0, 0, 255, 255], [7, 8, 9, 100]];
        let mut sets = vec![Vec::new(); 3];
        let mut uniq = voxels.clone();
        uniq.sort_unstable();
        uniq.dedup();
        for v in &uniq {
            sets[rng.random_range(0..3)].push(*v);
        }
        let regions = palette.iter().zip(sets).map(|(c, vs)| {
            let t = LinearOctree::from_voxels(depth, origin, vs).unwrap();
            (*c, t.intersection(&tree).unwrap())
        });
        let layer = Layer::from_regions(depth, origin, regions).unwrap();
        model = model.with_colors(layer).unwrap();
    }
    model.tree.assert_valid();
    model
}

/// The files of a dataset directory, sorted, with their bytes.
fn dataset_bytes(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<_> = fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().to_string_lossy().into_owned(),
                fs::read(e.path()).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// On seeded random models (colours, frames, empty ones), from a version-2 file,
/// a version-1 file and a dataset: the streamed `.xyz` (to a file and to standard
/// output) is the in-memory one byte for byte with the same report; into a
/// `.tess` it streams and writes the model's own file; `--parts K`
/// streams, and from one file writes the in-memory cut's dataset byte for byte;
/// the dataset joined again is the original file, and `info` of it is `info` of
/// the original.
#[test]
fn streamed_conversions_equal_the_in_memory_ones() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(1515);
    for i in 0..10 {
        let model = random_model(&mut rng, i);
        tesseral::io::write_model(&d.join("m.tess"), &model).unwrap();
        let mut v1 = Vec::new();
        tesseral::io::native::write_v1(&mut v1, &model).unwrap();
        fs::write(d.join("m1.tess"), v1).unwrap();
        let _ = fs::remove_dir_all(d.join("ds"));
        ok(d, &["convert", "m.tess", "-o", "ds", "--parts", "3"]);
        // The in-memory paths read standard input.
        let xyz = stdout_of(
            run_stdin(d, &["convert", "-", "-o", "-", "--format", "xyz"], "m.tess"),
            "in-memory xyz",
        );
        let mem = json(d, &["convert", "m.tess", "-o", "mem.tess", "--json"]);
        let info = json(d, &["info", "m.tess", "--json"]);
        for input in ["m.tess", "m1.tess", "ds"] {
            let what = format!("model {i}, {input}");
            let v = json(d, &["convert", input, "-o", "s.xyz", "--json"]);
            assert_eq!(v["streamed"], true, "{what}");
            assert_eq!(fs::read(d.join("s.xyz")).unwrap(), xyz, "{what}");
            for key in [
                "voxels",
                "leaves",
                "depth",
                "origin",
                "voxel_size",
                "translate",
            ] {
                assert_eq!(v[key], mem[key], "{what}: {key}");
            }
            let bbox = model.tree.bbox();
            assert_eq!(v["bbox_min"], serde_json::json!(bbox.map(|b| b.0)));
            assert_eq!(v["bbox_max"], serde_json::json!(bbox.map(|b| b.1)));
            assert_eq!(mem["bbox_min"], v["bbox_min"], "{what}");
            assert_eq!(mem["bbox_max"], v["bbox_max"], "{what}");
            assert_eq!(mem["colored_voxels"], v["colored_voxels"], "{what}");
            // `colors` counts the distinct colours, as `info` and `build` do;
            // `colored_voxels` the voxels they cover.
            assert_eq!(
                v["colors"],
                serde_json::json!(model.colors.as_ref().map(|c| c.region_count())),
                "{what}"
            );
            assert_eq!(
                v["colored_voxels"],
                serde_json::json!(model.colors.as_ref().map(|c| c.voxel_count())),
                "{what}"
            );
            assert_eq!(v["colors"], mem["colors"], "{what}");
            // Into a .tess (a version-1 file too): the model's own file.
            let v = json(d, &["convert", input, "-o", "t.tess", "--json"]);
            assert_eq!(v["streamed"], true, "{what}");
            assert_eq!(
                fs::read(d.join("t.tess")).unwrap(),
                fs::read(d.join("m.tess")).unwrap(),
                "{what}"
            );
            let out = run(d, &["convert", input, "-o", "-", "--format", "xyz"]);
            assert_eq!(stdout_of(out, &what), xyz, "{what}");

            let k = rng.random_range(1..6).to_string();
            let _ = fs::remove_dir_all(d.join("p"));
            let v = json(d, &["convert", input, "-o", "p", "--parts", &k, "--json"]);
            assert_eq!(v["streamed"], true, "{what}");
            assert_eq!(v["voxels"], model.tree.voxel_count(), "{what}");
            if input != "ds" {
                let _ = fs::remove_dir_all(d.join("q"));
                let out = run_stdin(
                    d,
                    &["convert", "-", "-o", "q", "--parts", &k, "--json"],
                    input,
                );
                let q: serde_json::Value = serde_json::from_slice(&stdout_of(out, &what)).unwrap();
                assert_eq!(q["streamed"], false, "{what}");
                assert_eq!(
                    dataset_bytes(&d.join("p")),
                    dataset_bytes(&d.join("q")),
                    "{what}"
                );
            }
            ok(d, &["convert", "p", "-o", "back.tess"]);
            assert_eq!(
                fs::read(d.join("back.tess")).unwrap(),
                fs::read(d.join("m.tess")).unwrap(),
                "{what}"
            );
            assert_eq!(json(d, &["info", "p", "--json"]), info, "{what}");
        }
        assert_eq!(names(d).iter().filter(|n| n.starts_with('.')).count(), 0);
    }
}

/// `--parts` replaces an older dataset whole (no part of it stays) and refuses
/// outputs that are, or hold, an input, that hold other files, or standard output.
#[test]
fn convert_parts_replaces_datasets_and_guards_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    build_scene(d, "showcase.tss", "a.tess", 6);
    ok(d, &["convert", "a.tess", "-o", "ds", "--parts", "6"]);
    assert_eq!(names(&d.join("ds")).len(), 7);
    ok(d, &["convert", "a.tess", "-o", "ds", "--parts", "2"]);
    assert_eq!(
        names(&d.join("ds")),
        ["manifest.json", "part-00000.tess", "part-00001.tess"]
    );
    fs::create_dir(d.join("empty")).unwrap();
    ok(d, &["convert", "ds", "-o", "empty", "--parts", "3"]);
    assert_eq!(names(&d.join("empty")).len(), 4);
    fails(
        d,
        &["convert", "ds", "-o", "ds", "--parts", "2"],
        "the input",
    );
    fails(
        d,
        &["convert", "ds/part-00000.tess", "-o", "ds", "--parts", "2"],
        "holds the input",
    );
    fs::create_dir(d.join("other")).unwrap();
    fs::write(d.join("other/notes.txt"), "mine").unwrap();
    fails(
        d,
        &["convert", "a.tess", "-o", "other", "--parts", "2"],
        "not a dataset",
    );
    assert_eq!(names(&d.join("other")), ["notes.txt"]);
    fails(
        d,
        &["convert", "a.tess", "-o", "-", "--parts", "2"],
        "standard output",
    );
    fails(
        d,
        &["convert", "a.tess", "-o", "z", "--parts", "0"],
        "from 1 to 65536",
    );
    assert_eq!(
        names(d),
        ["a.tess", "ds", "empty", "other"],
        "nothing else written, no staging directory left"
    );
}

/// `--max-output` and `--memory` are checked before the work: an error naming the
/// flag, nothing written; the same commands pass without them.
#[test]
fn streamed_conversions_check_budgets_before_the_work() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    build_scene(d, "showcase.tss", "a.tess", 6);
    ok(d, &["convert", "a.tess", "-o", "ds", "--parts", "2"]);
    for (args, flag) in [
        (
            &["convert", "a.tess", "-o", "o.xyz", "--max-output", "2K"][..],
            "--max-output",
        ),
        (
            &["convert", "ds", "-o", "o.xyz", "--max-output", "2K"][..],
            "--max-output",
        ),
        (
            &[
                "convert",
                "a.tess",
                "-o",
                "o",
                "--parts",
                "3",
                "--max-output",
                "2K",
            ][..],
            "--max-output",
        ),
        (
            &[
                "convert",
                "ds",
                "-o",
                "o",
                "--parts",
                "3",
                "--max-output",
                "2K",
            ][..],
            "--max-output",
        ),
        (
            &["convert", "a.tess", "-o", "o.xyz", "--memory", "1M"][..],
            "--memory",
        ),
        (
            &["convert", "ds", "-o", "o", "--parts", "3", "--memory", "1M"][..],
            "--memory",
        ),
        // The in-memory path reads the file whole: its leaves against --memory.
        (
            &["convert", "a.tess", "-o", "o.binvox", "--memory", "20K"][..],
            "--memory",
        ),
        (
            &["convert", "ds", "-o", "o.stl", "--memory", "20K"][..],
            "--memory",
        ),
    ] {
        fails(d, args, flag);
        assert_eq!(names(d), ["a.tess", "ds"], "{args:?}");
        let bare: Vec<&str> = args[..args.len() - 2].to_vec();
        ok(d, &bare);
        let out = d.join(bare[3]);
        if out.is_dir() {
            fs::remove_dir_all(out).unwrap();
        } else {
            fs::remove_file(out).unwrap();
        }
    }
}

/// A depth-12 spheroid (14.5 M leaves) is cut into a dataset, and the dataset
/// joined again into the same file, within 200 MiB of address space; the
/// in-memory cut of the same file cannot.
#[test]
fn a_streamed_cut_fits_in_a_small_address_space() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = scenes().join("fig4c-spheroid.tss");
    let s = scene.to_str().unwrap();
    ok(d, &["build", s, "-o", "s.tess", "--depth", "12"]);
    let out = run_capped(
        d,
        &["convert", "s.tess", "-o", "ds", "--parts", "4", "--json"],
        200,
    );
    let v: serde_json::Value = serde_json::from_slice(&stdout_of(out, "streamed cut")).unwrap();
    assert_eq!(v["streamed"], true);
    assert_eq!(v["leaves"], 14_520_164);
    let out = run_capped(d, &["convert", "ds", "-o", "back.tess"], 200);
    stdout_of(out, "streamed join");
    assert_eq!(
        fs::read(d.join("back.tess")).unwrap(),
        fs::read(d.join("s.tess")).unwrap()
    );
    // The in-memory cut (standard input is read whole) runs out of memory.
    let out = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v {}; exec \"$0\" convert - -o mem --parts 4 < s.tess",
            200 * 1024
        ))
        .arg(env!("CARGO_BIN_EXE_tesseral"))
        .env("RAYON_NUM_THREADS", "2")
        .env("MALLOC_ARENA_MAX", "2")
        .current_dir(d)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(!d.join("mem").exists());
}
