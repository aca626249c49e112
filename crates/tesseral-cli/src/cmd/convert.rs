//! `tesseral convert IN OUT`: converts between formats, chosen by extension.

use std::path::PathBuf;

use anyhow::{Context, Result};
use tesseral::io::{self, ReadOptions, WriteOptions};

/// Arguments of `tesseral convert`.
#[derive(clap::Args)]
pub struct Args {
    /// The input file (.tess, .xyz, .binvox, .vox, .bt, .ot).
    pub input: PathBuf,
    /// The output file (.tess, .xyz, .binvox, .vox, .bt, .ot).
    pub output: PathBuf,
    /// Print a summary as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    let read = ReadOptions::default();
    let write = WriteOptions::default();
    let model = io::read_model_with(&args.input, &read)
        .with_context(|| format!("reading {}", args.input.display()))?;
    io::write_model_with(&args.output, &model, &write)
        .with_context(|| format!("writing {}", args.output.display()))?;
    if args.json {
        let summary = serde_json::json!({
            "input": args.input,
            "output": args.output,
            "voxels": model.tree.voxel_count(),
            "leaves": model.tree.leaf_count(),
            "depth": model.tree.depth(),
            "origin": model.tree.origin(),
            "voxel_size": model.frame.map(|f| f.voxel_size),
            "colors": model.colors.as_ref().map(|c| c.len()),
        });
        println!("{summary}");
    }
    Ok(())
}
