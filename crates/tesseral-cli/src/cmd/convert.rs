//! `tesseral convert IN OUT`: converts between formats, chosen by extension.
//!
//! Meshes coming in (`.stl`, `.obj`, `.ply`) are voxelized at `--depth` (voxels along
//! the longest side) or `--voxel-size` (in mesh units); `--surface-only` keeps the
//! voxels the surface touches, for meshes that are not watertight. Meshes going out
//! (`.stl`, `.obj`, `.ply`, `.glb`) are the exact boundary, or with `--smooth` a
//! surface-nets surface.
//!
//! From a `.tess` file or a dataset, a `.tess` or `.xyz` output streams (a chunk at
//! a time, [`stream`]), and `--parts K` writes a dataset of K parts ([`parts`]).

use std::path::PathBuf;

use anyhow::{bail, Result};
use tesseral::io::{self, ReadOptions, WriteOptions};
use tesseral::mesh::{MeshOptions, Resolution, VoxelizeOptions, MAX_VOXELIZE_DEPTH};

use super::budget::Budget;
use super::octree;

mod parts;
mod stream;

fn output_is_stdout(path: &std::path::Path) -> bool {
    super::output::is_stdio(path)
}

/// The mesh formats read (voxelized) and written (meshed).
const MESH_IN: [&str; 3] = ["stl", "obj", "ply"];
const MESH_OUT: [&str; 4] = ["stl", "obj", "ply", "glb"];

/// Arguments of `tesseral convert`.
#[derive(clap::Args)]
pub struct Args {
    /// The input file: .tess, .xyz, .binvox, .vox, .bt, .ot, a mesh .stl, .obj, .ply,
    /// or a .tss scene (built as `build` does).
    pub input: PathBuf,
    /// The output file: .tess, .xyz, .binvox, .vox, .bt, .ot, or a mesh .stl, .obj,
    /// .ply, .glb (or give it with -o).
    #[arg(value_name = "OUTPUT", required_unless_present = "output")]
    pub output_positional: Option<PathBuf>,
    /// The output file, as the second argument.
    #[arg(short, long, conflicts_with = "output_positional")]
    pub output: Option<PathBuf>,
    /// Voxelize an input mesh with 2^DEPTH voxels along its longest side (default 8).
    #[arg(long, conflicts_with = "voxel_size")]
    pub depth: Option<u8>,
    /// Voxelize an input mesh with voxels of this side, in the mesh's units.
    #[arg(long)]
    pub voxel_size: Option<f64>,
    /// Keep only the voxels an input mesh's surface touches (no inside test, so the
    /// mesh need not be watertight).
    #[arg(long)]
    pub surface_only: bool,
    /// Write an output mesh as a smooth surface (surface nets) instead of the exact
    /// blocky boundary.
    #[arg(long)]
    pub smooth: bool,
    /// Write a partitioned dataset of K parts of about equal leaf counts: OUTPUT is
    /// a directory of `.tess` parts and a `manifest.json` (as `build --parts`). From
    /// a `.tess` file or a dataset it streams.
    #[arg(long, value_name = "K", value_parser = super::build::parse_parts, conflicts_with_all = ["smooth", "format"])]
    pub parts: Option<usize>,
    /// Print a summary as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub limits: octree::OutArgs,
    #[command(flatten)]
    pub budget: Budget,
}

/// Runs the command.
pub fn run(mut args: Args) -> Result<()> {
    let Some(out) = args.output.take().or(args.output_positional.take()) else {
        bail!("convert: give the output file, as `convert IN OUT` or `convert IN -o OUT`");
    };
    // Flags that do not apply are errors, not silently ignored.
    let mesh_in = MESH_IN.contains(&io::extension(&args.input).as_str());
    let mesh_out = MESH_OUT.contains(&args.limits.format_of(&out).as_str());
    if !mesh_in {
        for (flag, given) in [
            ("--depth", args.depth.is_some()),
            ("--voxel-size", args.voxel_size.is_some()),
            ("--surface-only", args.surface_only),
        ] {
            if given {
                bail!(
                    "{flag} voxelizes a mesh input (.stl, .obj, .ply); {} is not a mesh",
                    args.input.display()
                );
            }
        }
    }
    if args.smooth && !mesh_out {
        bail!(
            "--smooth shapes a mesh output (.stl, .obj, .ply, .glb); {} is not a mesh",
            out.display()
        );
    }
    let read = read_options(&args)?;
    if let Some(k) = args.parts {
        return parts::run(&args, &out, k, &read);
    }
    octree::guard(&out, &[&args.input], &args.limits)?;
    if output_is_stdout(&out) && args.json {
        bail!("--json: standard output already holds the octree (-o -)");
    }
    let write = WriteOptions {
        mesh: MeshOptions {
            smooth: args.smooth,
        },
    };
    if stream::to_tess(&args, &out)? || stream::to_xyz(&args, &out)? {
        return Ok(());
    }
    // The model, and the writing of its output (a mesh's vertex maps, ...).
    let budget = args.budget.for_work(super::budget::write_bytes_per_leaf(
        &args.limits.format_of(&out),
    ));
    stream::check_in_memory(&args, &budget)?;
    let model = octree::read_model(&args.input, &budget, &read)?;
    octree::save(&out, &model, &args.limits, &write)?;
    if args.json {
        let bbox = model.tree.bbox();
        let summary = serde_json::json!({
            "input": args.input,
            "output": out,
            "voxels": model.tree.voxel_count(),
            "leaves": model.tree.leaf_count(),
            "depth": model.tree.depth(),
            "origin": model.tree.origin(),
            "bbox_min": bbox.map(|b| b.0),
            "bbox_max": bbox.map(|b| b.1),
            "voxel_size": model.frame.voxel_size,
            "translate": model.frame.translate,
            "colors": model.colors.as_ref().map(|c| c.region_count()),
            "colored_voxels": model.colors.as_ref().map(|c| c.voxel_count()),
            "free_voxels": model.free.as_ref().map(|f| f.voxel_count()),
        });
        crate::outln!("{summary}")?;
    }
    Ok(())
}

/// How the input is read: a mesh voxelized at `--depth` or `--voxel-size`, within
/// `--memory`.
fn read_options(args: &Args) -> Result<ReadOptions> {
    let resolution = match (args.depth, args.voxel_size) {
        (Some(d), _) => {
            if d > MAX_VOXELIZE_DEPTH {
                bail!("--depth {d}: at most {MAX_VOXELIZE_DEPTH}");
            }
            Resolution::Depth(d)
        }
        (None, Some(h)) => {
            if !(h.is_finite() && h > 0.0) {
                bail!("--voxel-size {h}: must be a positive number");
            }
            Resolution::VoxelSize(h)
        }
        (None, None) => Resolution::Depth(8),
    };
    Ok(ReadOptions {
        mesh: VoxelizeOptions {
            resolution,
            surface_only: args.surface_only,
            // A crossing is 8 bytes, held about three times over while it is
            // sorted and indexed.
            max_crossings: usize::try_from(args.budget.memory / 24).unwrap_or(usize::MAX),
            max_leaves: args.budget.leaf_cap(),
        },
    })
}
