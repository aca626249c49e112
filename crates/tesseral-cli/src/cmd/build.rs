//! `tesseral build SCENE -o OUT.<ext>`: builds a scene's octree and writes it.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use tesseral::csg::Scene;

use super::budget::Budget;
use super::octree;

/// Arguments of `tesseral build`.
#[derive(clap::Args)]
pub struct Args {
    /// The scene file (`.tss`, see docs/scenes.md).
    scene: PathBuf,
    /// The octree file to write; its extension picks the format (see `tesseral::io`).
    #[arg(short, long)]
    output: PathBuf,
    /// Print the size and timing as JSON on stdout.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    limits: octree::OutArgs,
    #[command(flatten)]
    budget: Budget,
}

pub fn run(args: Args) -> Result<()> {
    octree::guard(&args.output, &[&args.scene], &args.limits)?;
    if super::output::is_stdio(&args.output) && args.json {
        anyhow::bail!("--json: standard output already holds the octree (-o -)");
    }
    let scene = Scene::read(&args.scene)?;
    let start = Instant::now();
    let model = args.budget.build_scene_model(&args.scene)?;
    let build_ms = start.elapsed().as_secs_f64() * 1e3;
    octree::save(&args.output, &model, &args.limits, &Default::default())
        .with_context(|| format!("writing {}", args.output.display()))?;
    let tree = &model.tree;
    if args.json {
        let out = serde_json::json!({
            "scene": args.scene,
            "output": args.output,
            "depth": tree.depth(),
            "voxel_size": scene.voxel,
            "bounds_min": scene.bounds_min,
            "objects": scene.objects,
            "leaves": tree.leaf_count(),
            "voxels": tree.voxel_count(),
            "leaves_by_depth": tree.leaves_by_depth(),
            "build_ms": build_ms,
            "colors": model.colors.as_ref().map(|c| c.region_count()),
        });
        crate::outln!("{out}")?;
    }
    Ok(())
}
