//! `tesseral build SCENE -o OUT.<ext>`: builds a scene's octree and writes it.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use tesseral::csg::Scene;

use super::budget::Budget;
use super::octree;

mod stream;

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
    /// Stream the leaves and colours straight to the output, a few cells at a time,
    /// with memory flat in the depth (checked against `--memory` before the work).
    /// A build to a `.tess` file always streams, so this flag only asks for it: it is
    /// an error with another format.
    #[arg(long)]
    stream: bool,
    /// Build into a partitioned dataset of K parts of about equal work: OUTPUT is a
    /// directory of `.tess` parts and a `manifest.json` (see docs/scale.md), each
    /// part streamed as with --stream.
    #[arg(long, value_name = "K", value_parser = parse_parts)]
    parts: Option<usize>,
    /// Build at this depth (1 to 16) instead of the scene's: the same space, voxels
    /// 2^k times smaller or larger.
    #[arg(long, value_name = "D", value_parser = clap::value_parser!(u8).range(1..=16))]
    depth: Option<u8>,
    #[command(flatten)]
    limits: octree::OutArgs,
    #[command(flatten)]
    budget: Budget,
}

/// The most parts of a dataset (`--parts`): each is a file.
pub const MAX_PARTS: usize = 1 << 16;

/// Parses `--parts K`: 1 to [`MAX_PARTS`].
pub fn parse_parts(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(k) if (1..=MAX_PARTS).contains(&k) => Ok(k),
        _ => Err(format!(
            "`{s}`: give a number of parts from 1 to {MAX_PARTS}"
        )),
    }
}

pub fn run(args: Args) -> Result<()> {
    if let Some(k) = args.parts {
        return run_parts(&args, k);
    }
    octree::guard(&args.output, &[&args.scene], &args.limits)?;
    if super::output::is_stdio(&args.output) && args.json {
        anyhow::bail!("--json: standard output already holds the octree (-o -)");
    }
    let mut scene = Scene::read(&args.scene)?;
    if let Some(d) = args.depth {
        scene = scene.with_depth(d)?;
    }
    let is_tess =
        !super::output::is_stdio(&args.output) && args.limits.format_of(&args.output) == "tess";
    if args.stream && !is_tess {
        anyhow::bail!(
            "--stream: only a .tess file can be written while building (not {})",
            args.output.display()
        );
    }
    if is_tess {
        return run_streamed(&args, &scene);
    }
    let start = Instant::now();
    // The model, and the writing of its output (a mesh's vertex maps, ...).
    let budget = args.budget.for_work(super::budget::write_bytes_per_leaf(
        &args.limits.format_of(&args.output),
    ));
    let tree = budget.build_scene(&args.scene, &scene).map_err(|e| {
        // A .tess build streams within --memory; --max-leaves binds it too.
        if budget.memory_binds() {
            anyhow::anyhow!("{e}; or build to a .tess file, which streams")
        } else {
            e
        }
    })?;
    let colors = scene.colour_layer(&tree, budget.leaf_cap())?;
    let model = tesseral::model::Model {
        colors,
        ..tesseral::model::Model::new(tree).with_frame(scene.frame())
    };
    let build_ms = start.elapsed().as_secs_f64() * 1e3;
    octree::save(&args.output, &model, &args.limits, &Default::default())
        .with_context(|| format!("writing {}", args.output.display()))?;
    let tree = &model.tree;
    if args.json {
        let out = serde_json::json!({
            "scene": args.scene,
            "output": args.output,
            "depth": tree.depth(),
            "origin": tree.origin(),
            "bbox_min": tree.bbox().map(|b| b.0),
            "bbox_max": tree.bbox().map(|b| b.1),
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

fn run_streamed(args: &Args, scene: &Scene) -> Result<()> {
    let start = Instant::now();
    let s = stream::build_streamed(
        &args.scene,
        scene,
        &args.output,
        &args.budget,
        args.limits.limits.max_output,
    )?;
    let build_ms = start.elapsed().as_secs_f64() * 1e3;
    if args.json {
        let out = serde_json::json!({
            "scene": args.scene,
            "output": args.output,
            "depth": scene.depth,
            "origin": [0, 0, 0],
            "voxel_size": scene.voxel,
            "bounds_min": scene.bounds_min,
            "objects": scene.objects,
            "leaves": s.leaves,
            "voxels": s.voxels,
            "build_ms": build_ms,
            "colors": (s.colours > 0).then_some(s.colours),
            "streamed": true,
            "estimated_leaves": s.estimate,
            "memory_estimate": s.memory_estimate,
            "cells": s.cells,
        });
        crate::outln!("{out}")?;
    }
    Ok(())
}

fn run_parts(args: &Args, k: usize) -> Result<()> {
    let mut scene = Scene::read(&args.scene)?;
    if let Some(d) = args.depth {
        scene = scene.with_depth(d)?;
    }
    let start = Instant::now();
    let parts = stream::build_parts(&args.scene, &scene, &args.output, k, &args.budget)?;
    let build_ms = start.elapsed().as_secs_f64() * 1e3;
    if args.json {
        let out = serde_json::json!({
            "scene": args.scene,
            "output": args.output,
            "depth": scene.depth,
            "parts": parts.len(),
            "leaves": parts.iter().map(|p| p.leaves).sum::<u64>(),
            "voxels": parts.iter().map(|p| p.voxels).sum::<u64>(),
            "part_leaves": parts.iter().map(|p| p.leaves).collect::<Vec<_>>(),
            "build_ms": build_ms,
        });
        crate::outln!("{out}")?;
    }
    Ok(())
}
