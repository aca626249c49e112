//! Random models with random frames and colours through pairs of commands
//! (build, convert, translate, rotate, mirror, scale, op), run by the real binary, checked
//! against the same operations on the library's `Model` (whose operations are tested
//! against a map of world cubes in `model::tests`).

mod common;

use std::path::Path;

use common::ok;
use rand::{Rng, SeedableRng};
use tesseral::csg::Scene;
use tesseral::io::{read_model, write_model};
use tesseral::linear::{Axis, LinearOctree, SetOp};
use tesseral::model::{Frame, Layer, Model};

fn random_model(rng: &mut rand_pcg::Pcg64, frame: Frame) -> Model {
    let origin: [i64; 3] = std::array::from_fn(|_| rng.random_range(-8..8));
    let voxels: Vec<[i64; 3]> = (0..rng.random_range(1..80))
        .map(|_| std::array::from_fn(|a| origin[a] + rng.random_range(0..8)))
        .collect();
    let tree = LinearOctree::from_voxels(
        4,
        [origin[0] - 4, origin[1] - 4, origin[2] - 4],
        voxels.iter().copied(),
    )
    .unwrap();
    let palette = [[255, 0, 0, 255], [0, 255, 0, 255], [0, 0, 255, 255]];
    let colors = Layer::from_voxels(
        tree.depth(),
        tree.origin(),
        voxels.iter().map(|&v| (v, palette[rng.random_range(0..3)])),
    )
    .unwrap();
    Model::new(tree)
        .with_frame(frame)
        .with_colors(colors)
        .unwrap()
}

/// One command on a file, and the same operation on the library model.
type Step = (Vec<String>, Box<dyn Fn(&Model) -> Model>);

fn steps(rng: &mut rand_pcg::Pcg64, other: &Model) -> Vec<Step> {
    let by: [i64; 3] = std::array::from_fn(|_| rng.random_range(-9..9));
    let axis = [Axis::X, Axis::Y, Axis::Z][rng.random_range(0..3)];
    let name = ["x", "y", "z"][axis.index()];
    let turns = rng.random_range(-1..3);
    let other = other.clone();
    let s = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    vec![
        (
            s(&[
                "translate",
                "IN",
                "--by",
                &format!("{},{},{}", by[0], by[1], by[2]),
                "-o",
                "OUT",
            ]),
            Box::new(move |m: &Model| m.translate(by).unwrap()),
        ),
        (
            s(&[
                "rotate",
                "IN",
                "--axis",
                name,
                "--turns",
                &turns.to_string(),
                "-o",
                "OUT",
            ]),
            Box::new(move |m: &Model| m.rotate_in_space(axis, turns).unwrap()),
        ),
        (
            s(&["mirror", "IN", "--axis", name, "-o", "OUT"]),
            Box::new(move |m: &Model| m.mirror_in_space(axis).unwrap()),
        ),
        (
            s(&["scale", "IN", "--by", "2", "-o", "OUT"]),
            Box::new(|m: &Model| m.scale_up(1).unwrap()),
        ),
        (
            s(&["op", "union", "IN", "other.tess", "-o", "OUT"]),
            Box::new(move |m: &Model| m.set_op(&other, SetOp::Union).unwrap()),
        ),
        (
            s(&["convert", "IN", "OUT"]),
            Box::new(|m: &Model| m.clone()),
        ),
    ]
}

fn run_step(dir: &Path, step: &[String], input: &str, output: &str) {
    let args: Vec<&str> = step
        .iter()
        .map(|a| match a.as_str() {
            "IN" => input,
            "OUT" => output,
            other => other,
        })
        .collect();
    ok(dir, &args);
}

fn same_world(got: &Model, want: &Model, what: &str) {
    got.assert_valid();
    assert_eq!(got.frame, want.frame, "{what}: frame");
    assert!(got.tree.same_voxels(&want.tree).unwrap(), "{what}: voxels");
    let colours = |m: &Model| -> Vec<([i64; 3], u64)> {
        m.colors
            .as_ref()
            .map(|c| c.to_voxels().into_iter().map(|(v, k, _)| (v, k)).collect())
            .unwrap_or_default()
    };
    assert_eq!(colours(got), colours(want), "{what}: colours");
}

#[test]
fn command_pairs_follow_the_model() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for seed in 0..8u64 {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let h = [0.25, 0.5, 1.0, 0.05][rng.random_range(0..4)];
        let frame = Frame::new(
            h,
            std::array::from_fn(|_| h * f64::from(rng.random_range(-20..20))),
        );
        let a = random_model(&mut rng, frame);
        let b = random_model(
            &mut rng,
            Frame::new(
                h,
                [
                    frame.translate[0] + 3.0 * h,
                    frame.translate[1],
                    frame.translate[2],
                ],
            ),
        );
        write_model(&d.join("a.tess"), &a).unwrap();
        write_model(&d.join("other.tess"), &b).unwrap();
        let all = steps(&mut rng, &b);
        for (i, first) in all.iter().enumerate() {
            for (j, second) in all.iter().enumerate() {
                run_step(d, &first.0, "a.tess", "mid.tess");
                run_step(d, &second.0, "mid.tess", "out.tess");
                let want = (second.1)(&(first.1)(&a));
                let got = read_model(&d.join("out.tess")).unwrap();
                same_world(
                    &got,
                    &want,
                    &format!("seed {seed}: {:?} then {:?}", all[i].0, all[j].0),
                );
            }
        }
    }
}

/// A random scene: a random voxel size and placement, and a few coloured (and
/// uncoloured) boxes and spheres, some overlapping.
fn random_scene(rng: &mut rand_pcg::Pcg64) -> String {
    let h = [0.25, 0.5, 1.0, 0.05][rng.random_range(0..4)];
    let min: [f64; 3] = std::array::from_fn(|_| h * f64::from(rng.random_range(-40..40)));
    let side = 16.0 * h;
    let mut text = format!(
        "depth 4\nbounds [{}, {}, {}] [{}, {}, {}]\n",
        min[0],
        min[1],
        min[2],
        min[0] + side,
        min[1] + side,
        min[2] + side
    );
    let colours = ["\"red\"", "\"green\"", "\"blue\""];
    for _ in 0..rng.random_range(1..4) {
        let at: [f64; 3] = std::array::from_fn(|a| min[a] + side * rng.random_range(0.2..0.8));
        let size = side * rng.random_range(0.1..0.5);
        let shape = if rng.random_bool(0.5) {
            format!("box(size = {size})")
        } else {
            format!("sphere(r = {})", size / 2.0)
        };
        let colour = match rng.random_range(0..4) {
            3 => String::new(),
            k => format!(" colour {}", colours[k]),
        };
        text += &format!("{shape} at [{}, {}, {}]{colour}\n", at[0], at[1], at[2]);
    }
    text
}

/// `build` followed by every other command: the scene's frame and colours come out
/// of the binary as the library's scene model, moved by the same operation, says.
#[test]
fn build_then_every_command_follows_the_model() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for seed in 0..6u64 {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(100 + seed);
        let text = random_scene(&mut rng);
        std::fs::write(d.join("s.tss"), &text).unwrap();
        let scene = Scene::parse(&text, "s.tss".as_ref()).unwrap();
        let built = scene.build_model_limited(1 << 20).unwrap();
        built.assert_valid();
        // The other operand of `op`: the same model one voxel over, in its own frame.
        let mut other = built.clone();
        other.frame.translate[1] += built.frame.voxel_size;
        write_model(&d.join("other.tess"), &other).unwrap();
        ok(d, &["build", "s.tss", "-o", "built.tess"]);
        same_world(
            &read_model(&d.join("built.tess")).unwrap(),
            &built,
            &format!("seed {seed}: build of\n{text}"),
        );
        for (args, model_op) in steps(&mut rng, &other) {
            run_step(d, &args, "built.tess", "out.tess");
            let got = read_model(&d.join("out.tess")).unwrap();
            same_world(
                &got,
                &model_op(&built),
                &format!("seed {seed}: build then {args:?} of\n{text}"),
            );
        }
    }
}
