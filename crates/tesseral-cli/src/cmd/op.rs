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
    let op = match args.op {
        OpArg::Union => SetOp::Union,
        OpArg::Intersection => SetOp::Intersection,
        OpArg::Difference => SetOp::Difference,
        OpArg::Xor => SetOp::SymmetricDifference,
    };
    if let Some(done) = streamed(&args, op)? {
        return done;
    }
    let a = octree::read(&args.a)?;
    let b = octree::read(&args.b)?;
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

/// Two version-2 `.tess` files of one space and frame, with no layers but colours,
/// into a `.tess` file: a merge of the two sorted streams (colour regions
/// included), one chunk of each held at a time. `None` when the inputs need the
/// in-memory path.
fn streamed(args: &Args, op: SetOp) -> Result<Option<Result<()>>> {
    use tesseral::io::TessFile;
    let tess = |p: &std::path::Path| {
        !super::output::is_stdio(p) && p.is_file() && tesseral::io::extension(p) == "tess"
    };
    let out_tess =
        !super::output::is_stdio(&args.output) && tesseral::io::extension(&args.output) == "tess";
    if !(tess(&args.a) && tess(&args.b) && out_tess) {
        return Ok(None);
    }
    let a = TessFile::open(&args.a)?;
    let b = TessFile::open(&args.b)?;
    let colours_only =
        |f: &TessFile| -> Result<bool> { Ok(!f.has_layers() || f.colour_streams()?.is_some()) };
    let same_space = (a.depth(), a.origin(), a.frame()) == (b.depth(), b.origin(), b.frame());
    let streamable =
        a.is_streamed() && b.is_streamed() && same_space && colours_only(&a)? && colours_only(&b)?;
    if !streamable {
        return Ok(None);
    }
    // The colour spools' temporary files go next to the output.
    let spool_dir = match args.output.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_owned(),
        _ => std::path::PathBuf::from("."),
    };
    let mut summary = tesseral::partition::StreamSummary::default();
    tesseral::io::write_atomic(&args.output, |w| {
        summary = tesseral::partition::stream_set_op_in(&a, &b, op, a.frame(), w, &spool_dir)
            .map_err(std::io::Error::other)?;
        Ok(())
    })
    .with_context(|| format!("writing {}", args.output.display()))?;
    if args.json {
        let out = serde_json::json!({
            "output": args.output,
            "voxels": summary.voxels,
            "leaves": summary.leaves,
            "depth": a.depth(),
            "origin": a.origin(),
            "op": match args.op {
                OpArg::Union => "union",
                OpArg::Intersection => "intersection",
                OpArg::Difference => "difference",
                OpArg::Xor => "xor",
            },
            "colors": (summary.colours > 0).then_some(summary.colours),
            "streamed": true,
        });
        crate::outln!("{out}")?;
    }
    Ok(Some(Ok(())))
}
