//! The fragmentation table of docs/octrees.md (Ahuja & Nash Fig. 5): solids rotated
//! about z through the centre of their bounding box by θ, as `tesseral rotate
//! --degrees θ --axis z --roundtrip` does; leaves before and after, and the voxels
//! lost and gained by θ then −θ. Prints one Markdown row per solid and angle.
//!
//! `cargo run --release -p tesseral --example fragmentation -- [SCENE.tss ...]`

use tesseral::csg::scene::Scene;
use tesseral::linear::{rotation_matrix, CellClass, LinearOctree};
use tesseral::model::Model;

mod common;
use common::sphere;

/// The box of `size` voxels centred on the lattice origin.
fn cuboid(size: [i64; 3]) -> LinearOctree {
    let (lo, hi) = (size.map(|s| -s / 2), size.map(|s| s - s / 2));
    let classify = move |min: [i64; 3], k: u8| {
        let s = 1i64 << k;
        if (0..3).all(|a| min[a] >= lo[a] && min[a] + s <= hi[a]) {
            CellClass::Inside
        } else if (0..3).any(|a| min[a] >= hi[a] || min[a] + s <= lo[a]) {
            CellClass::Outside
        } else {
            CellClass::Partial
        }
    };
    let depth = (64 - size.iter().max().copied().unwrap_or(1).leading_zeros()) as u8;
    let half = 1i64 << (depth - 1);
    LinearOctree::from_classifier(depth, [-half; 3], &classify).expect("box")
}

fn main() {
    let mut solids = vec![
        ("sphere r = 100".to_owned(), Model::new(sphere(100))),
        (
            "box 160 × 100 × 60".to_owned(),
            Model::new(cuboid([160, 100, 60])),
        ),
    ];
    for path in std::env::args().skip(1) {
        let scene = Scene::read(std::path::Path::new(&path)).expect("scene");
        let tree = scene.build().expect("build");
        solids.push((format!("`{path}`"), Model::new(tree)));
    }
    println!("| solid | θ | leaves before | after | ratio | voxels | lost | gained |");
    println!("|---|---|---|---|---|---|---|---|");
    for (name, m) in &solids {
        let about = m.bbox_centre();
        for degrees in [10.0, 30.0, 45.0] {
            let z = [0.0, 0.0, 1.0];
            let out = m
                .rotate_about(rotation_matrix(z, degrees), about)
                .expect("rotate");
            let back = out
                .rotate_about(rotation_matrix(z, -degrees), about)
                .expect("rotate back");
            let lost = m.tree.difference(&back.tree).expect("lost").voxel_count();
            let gained = back.tree.difference(&m.tree).expect("gained").voxel_count();
            let (before, after) = (m.tree.leaf_count(), out.tree.leaf_count());
            println!(
                "| {name} | {degrees}° | {before} | {after} | {:.2} | {} | {lost} | {gained} |",
                after as f64 / before as f64,
                m.tree.voxel_count()
            );
        }
    }
}
