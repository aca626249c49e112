//! `tesseral translate`: in memory (any input and output, `--clip`, `--method
//! labels`), or streamed output cell by output cell for a `.tess` file of either
//! version into a `.tess` file (docs/stream-translate.md).

use std::path::PathBuf;

use anyhow::{Context, Result};
use tesseral::model::Model;
use tesseral::pointer::PointerOctree;

use crate::cmd::octree;
/// How `translate` moves the tree.
#[derive(Clone, Copy, Default, clap::ValueEnum)]
pub enum Method {
    /// Top-down on the linear octree's codes; time follows the leaves.
    #[default]
    Linear,
    /// Ahuja & Nash §3.2 on a pointer octree, by label arithmetic with the Table 2
    /// carries; prints the §3.3 node counts.
    Labels,
}

/// Arguments of `tesseral translate`.
#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("displacement").required(true).args(["by", "by_world"])))]
pub struct TranslateArgs {
    /// The input octree file.
    input: PathBuf,
    /// The displacement `DX,DY,DZ` in voxels (negative allowed: `--by=-4,-50,0` or
    /// `--by -4,-50,0`). The frame is kept, so the world moves by DX·voxel size.
    #[arg(long, value_parser = octree::parse_vector, allow_hyphen_values = true)]
    by: Option<[i64; 3]>,
    /// The displacement `X,Y,Z` in world units (metres for an OctoMap map); it must be
    /// a whole number of voxels.
    #[arg(long, value_name = "X,Y,Z", value_parser = crate::cmd::affine::parse_world_vector, allow_hyphen_values = true)]
    by_world: Option<[f64; 3]>,
    /// The output octree file.
    #[arg(short, long)]
    output: PathBuf,
    /// Print JSON: output, voxels, leaves, depth, origin, bbox_min, bbox_max, by, method, dropped (with --clip), nodes_visited and root_expansions (with --method labels).
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    limits: octree::OutArgs,
    /// The algorithm.
    #[arg(long, value_enum, default_value_t)]
    method: Method,
    /// Keep the input's space and drop (and count) the voxels that leave it, instead
    /// of growing the space. Only with `--method linear`.
    #[arg(long)]
    clip: bool,
    /// Require the streamed translation (a `.tess` file whose only layer is
    /// colours, into a `.tess` file, with `--method linear` and without
    /// `--clip`): an error when the input or output cannot stream. Without it, such
    /// a translation streams anyway (flat memory, about the in-memory time), and
    /// anything else is translated in memory.
    #[arg(long)]
    stream: bool,
    /// The working memory of a translation that does not stream, estimated before
    /// the work for a `.tess` input (about 48 bytes a leaf, colours
    /// included): bytes, or a number with K, M, G or T (powers of 1024).
    #[arg(long, value_name = "SIZE", default_value = "8G", value_parser = crate::cmd::output::parse_bytes)]
    memory: u64,
}

/// Memory per input leaf of an in-memory translation: the input (leaves and
/// colour regions), the moved copy and the resampler's index (measured: 2.80 GB
/// for the 58 M-leaf depth-13 spheroid with its colours).
const TRANSLATE_BYTES_PER_LEAF: u64 = 48;

pub fn translate(args: TranslateArgs) -> Result<()> {
    octree::guard(&args.output, &[&args.input], &args.limits)?;
    if streamed(&args)? {
        return Ok(());
    }
    if tesseral::io::extension(&args.input) == "tess" && args.input.is_file() {
        // Either version: a version-1 file's leaves are counted by indexing it.
        let f = tesseral::io::TessFile::open_streaming(&args.input)?;
        if f.is_streamed() {
            crate::cmd::budget::Budget {
                max_leaves: None,
                memory: args.memory,
                ..Default::default()
            }
            .check_memory(
                &format!("translating {} in memory", args.input.display()),
                f.leaf_count().saturating_mul(TRANSLATE_BYTES_PER_LEAF),
                " (or translate into a .tess file, which streams)",
            )?;
        }
    }
    let model = octree::read(&args.input)?;
    let by = match (args.by, args.by_world) {
        (Some(by), _) => by,
        (None, Some(w)) => model
            .frame
            .world_to_voxels(w)
            .map_err(|e| anyhow::anyhow!("--by-world: {e}"))?,
        (None, None) => anyhow::bail!("give --by or --by-world"),
    };
    let tree = &model.tree;
    let mut extra = serde_json::json!({
        "by": by,
        "method": match args.method {
            Method::Linear => "linear",
            Method::Labels => "labels",
        },
    });
    let moved = match (args.method, args.clip) {
        (Method::Linear, false) => model.translate(by).with_context(|| {
            format!(
                "translating {} by {}",
                args.input.display(),
                octree::fmt_voxel(by)
            )
        })?,
        (Method::Linear, true) => {
            // Moved, then put back in the input's space: what leaves it is dropped.
            let moved = model
                .translate(by)
                .and_then(|m| Ok(m.in_space(tree.depth(), tree.origin())?))
                .with_context(|| format!("translating {}", args.input.display()))?;
            let dropped = tree.voxel_count() - moved.tree.voxel_count();
            if args.json {
                extra["dropped"] = dropped.into();
            } else {
                crate::outln!("clipped: {dropped} voxels left the space and were dropped")?;
            }
            moved
        }
        (Method::Labels, true) => {
            anyhow::bail!("--clip works only with --method linear")
        }
        (Method::Labels, false) => {
            let mut p = PointerOctree::from_linear(tree);
            let stats = p
                .translate(by)
                .with_context(|| format!("translating {}", args.input.display()))?;
            extra["nodes_visited"] = stats.nodes_visited().into();
            extra["root_expansions"] = stats.root_expansions.into();
            for (name, s) in ["x", "y", "z"].iter().zip(stats.axes.iter()) {
                if s.displacement != 0 && !args.json {
                    crate::outln!(
                        "axis {name}: by {}, nodes of side 2^{} moved: {}, traversed {}, path steps {}, compaction {}, split {}",
                        s.displacement, s.moved_size_log2, s.moved, s.traversed, s.path_steps, s.compacted, s.split_created
                    )?;
                }
            }
            if !args.json {
                crate::outln!(
                    "nodes visited: {} (root expansions: {})",
                    stats.nodes_visited(),
                    stats.root_expansions
                )?;
            }
            // The labels move the voxels; the colours and free space follow them.
            let rest = model.translate(by)?;
            Model::from_parts(
                p.to_linear(),
                model.frame,
                rest.colors,
                rest.free,
                rest.log_odds,
            )?
        }
    };
    let report = octree::Report {
        json: args.json,
        extra,
    };
    octree::write(&args.output, &moved, &args.limits, report)
}

/// A `.tess` file of either version (a version-1 payload indexed in one pass,
/// `TessFile::open_streaming`) with no layers but colours, translated into a
/// `.tess` file output cell by output cell (`partition::stream_translate`): never
/// the whole tree in memory. `false` (nothing done) for other inputs, outputs and methods.
fn streamed(args: &TranslateArgs) -> Result<bool> {
    use tesseral::io::TessFile;
    let tess = |p: &std::path::Path| {
        !crate::cmd::output::is_stdio(p) && tesseral::io::extension(p) == "tess"
    };
    let linear = matches!(args.method, Method::Linear) && !args.clip;
    let refuse = |why: &str| -> Result<bool> {
        if args.stream {
            anyhow::bail!("--stream: {why}");
        }
        Ok(false)
    };
    if !(linear && tess(&args.input) && args.input.is_file() && tess(&args.output)) {
        return refuse(
            "only a .tess file into a .tess file streams, with --method linear and without --clip",
        );
    }
    let f = TessFile::open_streaming(&args.input)?;
    if !f.is_streamed() || (f.has_layers() && f.colour_streams()?.is_none()) {
        return refuse(&format!(
            "{} has layers that do not stream (a version-1 legacy colour list, free space or log-odds; only colours stream)",
            args.input.display()
        ));
    }
    let by = match (args.by, args.by_world) {
        (Some(by), _) => by,
        (None, Some(w)) => f
            .frame()
            .world_to_voxels(w)
            .map_err(|e| anyhow::anyhow!("--by-world: {e}"))?,
        (None, None) => anyhow::bail!("give --by or --by-world"),
    };
    // The output holds the same shape, moved: about the input's size (an
    // unaligned move changes the leaf count by a fraction of a per cent on a
    // built scene; a few big blocks moved off the lattice can shatter, hence the
    // margin). Checked before the work.
    let len = std::fs::metadata(&args.input).map_or(0, |m| m.len());
    crate::cmd::output::check_size(
        &args.output,
        len.saturating_add(len / 4),
        args.limits.limits.max_output,
    )?;
    // The colour spools' temporary files go next to the output.
    let spool_dir = crate::cmd::streamed::spool_dir(&args.output);
    let mut done = None;
    let inputs = [std::slice::from_ref(&f)];
    crate::cmd::streamed::with_leaf_progress("translating", &inputs, || {
        tesseral::io::write_atomic(&args.output, |w| {
            done = Some(
                tesseral::partition::stream_translate(&f, by, w, &spool_dir)
                    .map_err(std::io::Error::other)?,
            );
            Ok(())
        })
    })
    .with_context(|| {
        format!(
            "translating {} by {} into {}",
            args.input.display(),
            octree::fmt_voxel(by),
            args.output.display()
        )
    })?;
    let Some(t) = done else {
        anyhow::bail!("writing {}: nothing was written", args.output.display());
    };
    let frame = f.frame();
    if args.json {
        let out = serde_json::json!({
            "output": args.output,
            "voxels": t.summary.voxels,
            "leaves": t.summary.leaves,
            "depth": t.depth,
            "origin": t.origin,
            "bbox_min": t.bbox.map(|b| b.0),
            "bbox_max": t.bbox.map(|b| b.1),
            "voxel_size": frame.voxel_size,
            "translate": frame.translate,
            "by": by,
            "method": "linear",
            "colors": (t.summary.colours > 0).then_some(t.summary.colours),
            "streamed": true,
        });
        crate::outln!("{out}")?;
    } else {
        crate::outln!(
            "{}",
            octree::wrote_line(
                &args.output,
                t.summary.voxels,
                t.summary.leaves,
                t.depth,
                t.origin,
                &frame
            )
        )?;
    }
    Ok(true)
}
