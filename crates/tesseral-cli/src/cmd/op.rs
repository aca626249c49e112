//! `tesseral op union|intersection|difference|xor A B -o OUT`.

use std::path::PathBuf;

use anyhow::{Context, Result};
use tesseral::linear::SetOp;

use super::octree;

/// A set operation on the command line.
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum OpArg {
    /// Voxels in A or B.
    Union,
    /// Voxels in A and B.
    Intersection,
    /// Voxels in A and not in B.
    Difference,
    /// Voxels in exactly one of A and B.
    Xor,
}

/// Arguments of `tesseral op`.
#[derive(clap::Args)]
pub struct Args {
    /// The operation.
    #[arg(value_enum)]
    op: OpArg,
    /// The first operand.
    a: PathBuf,
    /// The second operand; it is aligned to A's space when the two differ.
    b: PathBuf,
    /// The output octree file.
    #[arg(short, long)]
    output: PathBuf,
    /// Print JSON: output, voxels, leaves, depth, origin, bbox_min, bbox_max, op.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    limits: octree::OutArgs,
}

pub fn run(args: Args) -> Result<()> {
    octree::guard(&args.output, &[&args.a, &args.b], &args.limits)?;
    let a = octree::read(&args.a)?;
    let b = octree::read(&args.b)?;
    let op = match args.op {
        OpArg::Union => SetOp::Union,
        OpArg::Intersection => SetOp::Intersection,
        OpArg::Difference => SetOp::Difference,
        OpArg::Xor => SetOp::SymmetricDifference,
    };
    let r = a.set_op(&b, op).with_context(|| {
        format!(
            "combining {} ({}) and {} ({})",
            args.a.display(),
            a.frame,
            args.b.display(),
            b.frame
        )
    })?;
    let name = match args.op {
        OpArg::Union => "union",
        OpArg::Intersection => "intersection",
        OpArg::Difference => "difference",
        OpArg::Xor => "xor",
    };
    let report = octree::Report {
        json: args.json,
        extra: serde_json::json!({ "op": name }),
    };
    octree::write(&args.output, &r, &args.limits, report)
}
