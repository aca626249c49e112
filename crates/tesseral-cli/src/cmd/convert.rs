//! `tesseral convert IN OUT`: converts between formats, chosen by extension.
//!
//! Meshes coming in (`.stl`, `.obj`, `.ply`) are voxelized at `--depth` (voxels along
//! the longest side) or `--voxel-size` (in mesh units); `--surface-only` keeps the
//! voxels the surface touches, for meshes that are not watertight. Meshes going out
//! (`.stl`, `.obj`, `.ply`, `.glb`) are the exact boundary, or with `--smooth` a
//! surface-nets surface.

use std::path::PathBuf;

use anyhow::{bail, Result};
use tesseral::io::{self, ReadOptions, WriteOptions};
use tesseral::mesh::{MeshOptions, Resolution, VoxelizeOptions, MAX_VOXELIZE_DEPTH};

use super::budget::Budget;
use super::octree;

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
    octree::guard(&out, &[&args.input], &args.limits)?;
    if output_is_stdout(&out) && args.json {
        bail!("--json: standard output already holds the octree (-o -)");
    }
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
    let read = ReadOptions {
        mesh: VoxelizeOptions {
            resolution,
            surface_only: args.surface_only,
            // A crossing is 8 bytes, held about three times over while it is
            // sorted and indexed.
            max_crossings: usize::try_from(args.budget.memory / 24).unwrap_or(usize::MAX),
            max_leaves: args.budget.leaf_cap(),
        },
    };
    let write = WriteOptions {
        mesh: MeshOptions {
            smooth: args.smooth,
        },
    };
    if streamed(&args, &out)? {
        return Ok(());
    }
    let model = octree::read_model(&args.input, &args.budget, &read)?;
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
            "colors": model.colors.as_ref().map(|c| c.voxel_count()),
            "free_voxels": model.free.as_ref().map(|f| f.voxel_count()),
        });
        crate::outln!("{summary}")?;
    }
    Ok(())
}

/// A version-2 `.tess` file, or a dataset of them, into a `.tess` file, chunk by
/// chunk with the colour regions as streams (`partition::stream_concat`): never the
/// whole tree in memory. `false` (nothing done) for other inputs and outputs, and
/// for files with layers other than colours.
fn streamed(args: &Args, out: &std::path::Path) -> Result<bool> {
    use tesseral::io::TessFile;
    use tesseral::partition::{is_dataset, open_part, read_manifest};
    if output_is_stdout(out) || io::extension(out) != "tess" {
        return Ok(false);
    }
    let input = &args.input;
    let size = |p: &std::path::Path| std::fs::metadata(p).map_or(0, |m| m.len());
    let (files, frame, bytes) = if is_dataset(input) {
        let m = read_manifest(input)?;
        let mut files = Vec::with_capacity(m.parts.len());
        let mut bytes = 0u64;
        for (i, p) in m.parts.iter().enumerate() {
            bytes += size(&input.join(&p.file));
            files.push(open_part(input, &m, i)?);
        }
        let frame = tesseral::model::Frame::new(m.frame.voxel_size, m.frame.translate);
        (files, frame, bytes)
    } else if input.is_file() && io::extension(input) == "tess" {
        let f = TessFile::open(input)?;
        let frame = f.frame();
        (vec![f], frame, size(input))
    } else {
        return Ok(false);
    };
    for f in &files {
        if !f.is_streamed() || (f.has_layers() && f.colour_streams()?.is_none()) {
            return Ok(false);
        }
    }
    // The copy holds the same leaves and colours: about the inputs' size.
    super::output::check_size(out, bytes, args.limits.limits.max_output)?;
    let spool_dir = super::streamed::spool_dir(out);
    let mut summary = tesseral::partition::StreamSummary::default();
    io::write_atomic(out, |w| {
        summary = tesseral::partition::stream_concat(&files, frame, w, &spool_dir)
            .map_err(std::io::Error::other)?;
        Ok(())
    })
    .map_err(|e| anyhow::anyhow!("writing {}: {e}", out.display()))?;
    if args.json {
        let first = &files[0];
        let summary = serde_json::json!({
            "input": args.input,
            "output": out,
            "voxels": summary.voxels,
            "leaves": summary.leaves,
            "depth": first.depth(),
            "origin": first.origin(),
            "voxel_size": frame.voxel_size,
            "translate": frame.translate,
            "streamed": true,
        });
        crate::outln!("{summary}")?;
    }
    Ok(true)
}
