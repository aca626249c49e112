//! Runs the real `tesseral view`: the page is written, self-contained, within its
//! size budget (shown coarser, or refused under --exact), and bad input is refused.
//! The page's drawing is tested in a browser by scripts/view-browser-test.

use std::path::{Path, PathBuf};

use base64::Engine as _;
use serde_json::Value;

mod common;
use common::{fails, json, ok};

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

/// The page's data block, parsed.
fn page_data(path: &Path) -> Value {
    let html = std::fs::read_to_string(path).expect("page written");
    assert!(html.starts_with("<!DOCTYPE html>"));
    let start = html.find("id=\"tesseral-data\">").expect("data block") + 19;
    let end = start + html[start..].find("</script>").expect("end of data");
    serde_json::from_str(&html[start..end]).expect("data is JSON")
}

fn self_contained(path: &Path) {
    let html = std::fs::read_to_string(path).unwrap();
    assert!(!html.contains("http://") && !html.contains("https://"));
    assert!(!html.contains("src=\"") && !html.contains("<link"));
    assert!(html.contains("webgl2"));
}

#[test]
fn a_scene_makes_a_page_with_its_voxels_and_colours() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let tank = scenes_dir().join("tank.tss");
    let tank = tank.to_str().unwrap();
    let out = json(d, &["view", tank, "-o", "tank.html", "--json"]);
    let page = d.join("tank.html");
    self_contained(&page);
    let size = std::fs::metadata(&page).unwrap().len();
    assert_eq!(out["page_bytes"].as_u64(), Some(size));
    assert_eq!(out["shown_depth"], out["depth"]);
    assert_eq!(out["colors"], out["colours"]);
    let render = json(
        d,
        &["render", tank, "-o", "t.png", "--size", "32x32", "--json"],
    );
    assert_eq!(out["voxels"], render["voxels"]);
    assert_eq!(out["leaves"], render["leaves"]);
    let data = page_data(&page);
    assert_eq!(data["frames"][0]["voxels"], render["voxels"]);
    assert_eq!(data["frames"][0]["levels"], render["depth"]);
    assert!(data["notes"].as_array().unwrap().is_empty());
    // The entries are what the data says, and the palette holds the scene's colours.
    let b64 = base64::engine::general_purpose::STANDARD;
    let entries = b64.decode(data["entries"].as_str().unwrap()).unwrap();
    assert_eq!(Some(entries.len() as u64 / 4), data["entry_count"].as_u64());
    let palette = b64.decode(data["palette"].as_str().unwrap()).unwrap();
    assert!(
        palette.len() >= 6 && palette.len() % 3 == 0,
        "{}",
        palette.len()
    );
}

#[test]
fn an_octree_file_without_colours_gets_the_colour_flag() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("pts.xyz"), "0 0 0\n1 0 0\n3 3 3\n").unwrap();
    ok(
        d,
        &["view", "pts.xyz", "-o", "pts.html", "--colour", "#102030"],
    );
    let data = page_data(&d.join("pts.html"));
    let palette = base64::engine::general_purpose::STANDARD
        .decode(data["palette"].as_str().unwrap())
        .unwrap();
    assert_eq!(palette, vec![0x10, 0x20, 0x30]);
    assert_eq!(data["frames"][0]["voxels"], 3);
}

#[test]
fn a_tree_over_the_page_budget_is_shown_coarser_or_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let tank = scenes_dir().join("tank.tss");
    let tank = tank.to_str().unwrap();
    let out = json(
        d,
        &[
            "view",
            tank,
            "-o",
            "small.html",
            "--max-page",
            "80K",
            "--json",
        ],
    );
    assert!(out["page_bytes"].as_u64().unwrap() <= 80 * 1024);
    let shown = out["shown_depth"].as_u64().unwrap();
    assert!(shown < out["depth"].as_u64().unwrap(), "{out}");
    let data = page_data(&d.join("small.html"));
    let note = data["notes"][0].as_str().unwrap();
    assert!(
        note.contains(&format!("Shown at depth {shown} of 7")),
        "{note}"
    );
    assert!(note.contains("--max-page"), "{note}");
    fails(
        d,
        &[
            "view",
            tank,
            "-o",
            "exact.html",
            "--max-page",
            "80K",
            "--exact",
        ],
        "--max-page",
    );
    assert!(!d.join("exact.html").exists());
    // Smaller than the page's own code: nothing fits.
    fails(
        d,
        &["view", tank, "-o", "tiny.html", "--max-page", "1K"],
        "--max-page",
    );
    assert!(!d.join("tiny.html").exists());
}

#[test]
fn the_depth_10_showcase_fits_20_mib() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let showcase = scenes_dir().join("showcase.tss");
    let out = json(
        d,
        &["view", showcase.to_str().unwrap(), "-o", "s.html", "--json"],
    );
    assert_eq!(out["depth"], 10);
    assert_eq!(out["shown_depth"], 10, "{out}");
    assert!(out["leaves"].as_u64().unwrap() > 1_500_000);
    assert!(out["page_bytes"].as_u64().unwrap() <= 20 << 20, "{out}");
}

#[test]
fn bad_input_is_refused_with_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("pts.xyz"), "0 0 0\n").unwrap();
    fails(d, &["view", "pts.xyz", "-o", "page.png"], ".png");
    fails(d, &["view", "pts.xyz", "-o", "noext"], "no extension");
    fails(d, &["view", "missing.xyz", "-o", "p.html"], "missing.xyz");
    fails(
        d,
        &["view", "pts.xyz", "-o", "p.html", "--colour", "nope"],
        "--colour",
    );
    fails(d, &["view", "pts.xyz", "-o", "-"], "--output");
    std::fs::write(d.join("bad.tss"), "depth 4\nsphere(r = )\n").unwrap();
    fails(d, &["view", "bad.tss", "-o", "p.html"], "bad.tss");
    // An input is never overwritten, whatever its name.
    std::fs::copy(d.join("pts.xyz"), d.join("in.html")).unwrap();
    let before = std::fs::read(d.join("in.html")).unwrap();
    let out = common::run(d, &["view", "in.html", "-o", "in.html"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(std::fs::read(d.join("in.html")).unwrap(), before);
}

fn write_xyz(dir: &Path, name: &str, voxels: impl IntoIterator<Item = [i64; 3]>) {
    let text: String = voxels
        .into_iter()
        .map(|v| format!("{} {} {}\n", v[0], v[1], v[2]))
        .collect();
    std::fs::write(dir.join(name), text).unwrap();
}

fn cube(n: i64) -> Vec<[i64; 3]> {
    (0..n)
        .flat_map(|x| (0..n).flat_map(move |y| (0..n).map(move |z| [x, y, z])))
        .collect()
}

#[test]
fn simulate_view_plays_every_step() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_xyz(
        d,
        "wall.xyz",
        (0..16).flat_map(|y| (0..16).map(move |z| [30, y, z])),
    );
    write_xyz(d, "box.xyz", cube(3));
    let world = r#"{
      "environment": "wall.xyz", "time_step": 1, "steps": 3,
      "objects": [ { "name": "crate", "octree": "box.xyz", "start": [20, 4, 4], "velocity": [4, 0, 0] } ]
    }"#;
    std::fs::write(d.join("world.json"), world).unwrap();
    ok(d, &["simulate", "world.json", "--view", "sim.html"]);
    let data = page_data(&d.join("sim.html"));
    self_contained(&d.join("sim.html"));
    let frames = data["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 4);
    assert_eq!(frames[2]["label"], "step 2, t = 2");
    // The wall and the crate: 256 + 27 voxels (they do not overlap until step 3).
    assert_eq!(frames[0]["voxels"], 256 + 27);
    // Two colours: the environment's and the crate's (red once in contact).
    let palette = base64::engine::general_purpose::STANDARD
        .decode(data["palette"].as_str().unwrap())
        .unwrap();
    assert!(palette.len() >= 6);
    // A named view and a page together; two pages are refused; the world is never
    // overwritten.
    ok(
        d,
        &[
            "simulate",
            "world.json",
            "--view",
            "top",
            "--view",
            "b.html",
        ],
    );
    fails(
        d,
        &[
            "simulate",
            "world.json",
            "--view",
            "a.html",
            "--view",
            "b.html",
        ],
        "--view",
    );
    fails(d, &["simulate", "world.json", "--view", "nope"], "nope");
}

#[test]
fn rsmc_view_plays_the_samples() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let args = [
        "rsmc",
        "--steps",
        "3000",
        "--sample-every",
        "1000",
        "-o",
        "run",
        "--view",
        "r.html",
        "--no-picture",
    ];
    ok(d, &args);
    let data = page_data(&d.join("r.html"));
    let frames = data["frames"].as_array().unwrap();
    let labels: Vec<&str> = frames
        .iter()
        .map(|f| f["label"].as_str().unwrap())
        .collect();
    assert_eq!(labels.len(), 4, "{labels:?}");
    assert!(
        labels[0].starts_with("step 0, area 6, volume 1"),
        "{labels:?}"
    );
    assert!(labels[3].starts_with("step 3000,"), "{labels:?}");
    assert_eq!(frames[0]["voxels"], 1);
    fails(
        d,
        &["rsmc", "--steps", "10", "-o", "run2", "--view", "r.png"],
        "--view",
    );
}
