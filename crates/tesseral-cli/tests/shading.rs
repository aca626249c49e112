//! Runs the real `tesseral` binary: an octree file, whose normals are estimated from
//! its voxels, is drawn like its scene, whose normals are the solid's own.

use std::path::Path;

mod common;
use common::ok;

/// The RGB pixels of a PNG written by `render`.
fn pixels(path: &Path) -> Vec<[u8; 3]> {
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(path).expect("png written"),
    ));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let frame = reader.next_frame(&mut buf).unwrap();
    assert_eq!(frame.color_type, png::ColorType::Rgb);
    buf[..frame.buffer_size()]
        .chunks(3)
        .map(|p| [p[0], p[1], p[2]])
        .collect()
}

/// The mean difference per channel, in grey levels, between two pictures over the
/// pixels where `reference` shows the solid (not the background of its corner).
fn mean_difference(reference: &[[u8; 3]], other: &[[u8; 3]]) -> f64 {
    let background = reference[0];
    let (mut sum, mut n) = (0.0, 0usize);
    for (a, b) in reference.iter().zip(other) {
        if *a != background {
            sum += (0..3).map(|i| f64::from(a[i].abs_diff(b[i]))).sum::<f64>() / 3.0;
            n += 1;
        }
    }
    assert!(n > 1000, "the solid covers only {n} pixels");
    sum / n as f64
}

/// A sphere and a turned ellipsoid, from the front and from the iso view: the octree
/// file's picture (estimated normals) differs from the scene's (the solid's own
/// normals) by at most 2 grey levels on average. The first estimator (26 neighbours,
/// blended with the face) differed by 7 to 8, and flat block faces differ by over 20,
/// which the test also checks, so that the bound tells smooth from faceted.
#[test]
fn octree_file_shades_like_its_scene() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let solids = [
        ("sphere", "sphere(r = 50) at [64, 64, 64]"),
        (
            "ellipsoid",
            "ellipsoid(r = [55, 35, 25]) rotate [20, 30, 10] at [64, 64, 64]",
        ),
    ];
    for (name, solid) in solids {
        let tss = format!("{name}.tss");
        let tess = format!("{name}.tess");
        std::fs::write(
            d.join(&tss),
            format!("depth 7\nbounds [0, 0, 0] [128, 128, 128]\n\n{solid}\n"),
        )
        .unwrap();
        ok(d, &["build", &tss, "-o", &tess]);
        for view in ["front", "iso"] {
            let common = ["--view", view, "--size", "200x200", "--no-shadows"];
            let draw = |input: &str, out: &str, extra: &[&str]| {
                let mut args = vec!["render", input, "-o", out];
                args.extend_from_slice(&common);
                args.extend_from_slice(extra);
                ok(d, &args);
                pixels(&d.join(out))
            };
            let scene = draw(&tss, "scene.png", &[]);
            let file = draw(&tess, "file.png", &[]);
            let faces = draw(&tess, "faces.png", &["--normals", "faces"]);
            let smooth = mean_difference(&scene, &file);
            let flat = mean_difference(&scene, &faces);
            assert!(
                smooth <= 2.0,
                "{name}, {view}: the octree file's picture differs from the scene's by {smooth:.2} grey levels on average"
            );
            assert!(
                flat > 10.0,
                "{name}, {view}: flat faces differ by only {flat:.2}: the comparison cannot tell"
            );
        }
    }
}
