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
    /// The working memory a version-1 `.tess` operand may take when it is decoded
    /// whole (at most 24 bytes a byte of the file; only when it cannot stream: a
    /// legacy colour list, free space or log-odds, operands in different spaces,
    /// or an output that is not .tess), checked before it is read: bytes, or a
    /// number with K, M, G or T (powers of 1024).
    #[arg(long, value_name = "SIZE", default_value = "8G", value_parser = super::output::parse_bytes)]
    memory: u64,
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
    // The operands' leaves, each with its share of the result (at most their sum)
    // and of the writing of the output: both files' headers before either is read,
    // each file as it is read, then the two read.
    let ext = args.limits.format_of(&args.output);
    let budget = super::budget::Budget {
        max_leaves: None,
        memory: args.memory,
        ..Default::default()
    }
    .for_work(super::budget::MODEL_BYTES_PER_LEAF + super::budget::write_bytes_per_leaf(&ext));
    for input in [&args.a, &args.b] {
        super::streamed::check_version_1_in_memory(input, &budget)?;
    }
    let together = format!(
        "{} and {} together (read whole)",
        args.a.display(),
        args.b.display()
    );
    let on_disk =
        |p: &std::path::Path| super::streamed::leaves_on_disk(p).map(Option::unwrap_or_default);
    budget.check_leaves(
        &together,
        on_disk(&args.a)?.saturating_add(on_disk(&args.b)?),
    )?;
    let a = octree::read_model(&args.a, &budget, &Default::default())?;
    let b = octree::read_model(&args.b, &budget, &Default::default())?;
    budget.check_leaves(
        &together,
        (a.tree.leaf_count() + b.tree.leaf_count()) as u64,
    )?;
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

/// Two operands of one space and frame, each a `.tess` file or a dataset
/// directory, with no layers but colours, into a `.tess` file: a merge of the two
/// sorted streams (a dataset's parts read in order as one stream, colour regions
/// included), one chunk of each held at a time. A version-1 file streams too, its
/// payload indexed in one pass (`TessFile::open_streaming`). The output
/// size (estimated as the inputs' sizes together) is checked against
/// `--max-output` before the work. `None` when the inputs need the in-memory
/// path.
fn streamed(args: &Args, op: SetOp) -> Result<Option<Result<()>>> {
    use super::streamed::{is_tess_output, open_operand, spool_dir};
    if !is_tess_output(&args.output) {
        return Ok(None);
    }
    let Some(a) = open_operand(&args.a)? else {
        return Ok(None);
    };
    let Some(b) = open_operand(&args.b)? else {
        return Ok(None);
    };
    let same_space = (a.space(), a.frame) == (b.space(), b.frame);
    if !(same_space && a.colours_only()? && b.colours_only()?) {
        return Ok(None);
    }
    super::output::check_size(
        &args.output,
        a.bytes.saturating_add(b.bytes),
        args.limits.limits.max_output,
    )?;
    let mut summary = tesseral::partition::StreamSummary::default();
    let spool = spool_dir(&args.output);
    super::streamed::with_leaf_progress("combining", &[&a.files, &b.files], || {
        tesseral::io::write_atomic(&args.output, |w| {
            summary = tesseral::partition::stream_set_op_files(
                &a.files, &b.files, op, a.frame, w, &spool,
            )
            .map_err(std::io::Error::other)?;
            Ok(())
        })
    })
    .with_context(|| format!("writing {}", args.output.display()))?;
    let (depth, origin) = a.space();
    if args.json {
        let out = serde_json::json!({
            "output": args.output,
            "voxels": summary.voxels,
            "leaves": summary.leaves,
            "depth": depth,
            "origin": origin,
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
    } else {
        crate::outln!(
            "{}",
            octree::wrote_line(
                &args.output,
                summary.voxels,
                summary.leaves,
                depth,
                origin,
                &a.frame
            )
        )?;
    }
    Ok(Some(Ok(())))
}
