//! `tesseral convert IN OUT`: converts an octree between file formats.

use std::path::PathBuf;

use anyhow::Result;

use super::octree;

/// Arguments of `tesseral convert`.
#[derive(clap::Args)]
pub struct Args {
    /// The input file; its format is chosen by the extension.
    input: PathBuf,
    /// The output file; its format is chosen by the extension.
    output: PathBuf,
}

pub fn run(args: Args) -> Result<()> {
    let tree = octree::read(&args.input)?;
    octree::write(&args.output, &tree)
}
