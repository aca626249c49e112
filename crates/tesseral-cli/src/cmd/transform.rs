//! `tesseral translate`, `rotate`, `mirror`, `scale` and `complement`.

use std::path::PathBuf;

use anyhow::{Context, Result};
use tesseral::model::Model;
use tesseral::pointer::PointerOctree;

use super::octree::{self, AxisArg};

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
pub struct TranslateArgs {
    /// The input octree file.
    input: PathBuf,
    /// The displacement `DX,DY,DZ` in voxels (negative allowed: `--by=-4,-50,0` or
    /// `--by -4,-50,0`). The frame is kept, so the world moves by DX·voxel size.
    #[arg(long, value_parser = octree::parse_vector, allow_hyphen_values = true,
          required_unless_present = "by_world", conflicts_with = "by_world")]
    by: Option<[i64; 3]>,
    /// The displacement `X,Y,Z` in world units (metres for an OctoMap map); it must be
    /// a whole number of voxels.
    #[arg(long, value_name = "X,Y,Z", value_parser = super::affine::parse_world_vector, allow_hyphen_values = true)]
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
    /// Require the streamed translation (a version-2 `.tess` file whose only layer
    /// is colours, into a `.tess` file, with `--method linear` and without
    /// `--clip`): an error when the input or output cannot stream. Without it, such
    /// a translation streams anyway (flat memory, about the in-memory time), and
    /// anything else is translated in memory.
    #[arg(long)]
    stream: bool,
    /// The working memory of a translation that does not stream, estimated before
    /// the work for a version-2 `.tess` input (about 48 bytes a leaf, colours
    /// included): bytes, or a number with K, M, G or T (powers of 1024).
    #[arg(long, value_name = "SIZE", default_value = "8G", value_parser = super::output::parse_bytes)]
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
        let f = tesseral::io::TessFile::open(&args.input)?;
        if f.is_streamed() {
            super::budget::Budget {
                max_leaves: None,
                memory: args.memory,
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

/// A version-2 `.tess` file with no layers but colours, translated into a `.tess`
/// file output cell by output cell (`partition::stream_translate`): never the
/// whole tree in memory. `false` (nothing done) for other inputs, outputs and methods.
fn streamed(args: &TranslateArgs) -> Result<bool> {
    use tesseral::io::TessFile;
    let tess =
        |p: &std::path::Path| !super::output::is_stdio(p) && tesseral::io::extension(p) == "tess";
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
    let f = TessFile::open(&args.input)?;
    if !f.is_streamed() || (f.has_layers() && f.colour_streams()?.is_none()) {
        return refuse(&format!(
            "{} is not a version-2 .tess file with only colours beside its shape (convert it to .tess first)",
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
    super::output::check_size(
        &args.output,
        len.saturating_add(len / 4),
        args.limits.limits.max_output,
    )?;
    // The colour spools' temporary files go next to the output.
    let spool_dir = super::streamed::spool_dir(&args.output);
    let mut done = None;
    tesseral::io::write_atomic(&args.output, |w| {
        done = Some(
            tesseral::partition::stream_translate(&f, by, w, &spool_dir)
                .map_err(std::io::Error::other)?,
        );
        Ok(())
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
        let fr = if frame.is_unit() {
            String::new()
        } else {
            format!(", {frame}")
        };
        crate::outln!(
            "wrote {}: {} voxels, {} leaves, depth {}, origin {}{fr}",
            args.output.display(),
            t.summary.voxels,
            t.summary.leaves,
            t.depth,
            octree::fmt_voxel(t.origin)
        )?;
    }
    Ok(true)
}

/// Arguments of `tesseral rotate`.
#[derive(clap::Args)]
pub struct RotateArgs {
    /// The input octree file.
    input: PathBuf,
    /// The axis of rotation: x, y, z, or (with --degrees) a vector X,Y,Z.
    #[arg(long, value_parser = super::affine::parse_axis, allow_hyphen_values = true)]
    axis: [f64; 3],
    /// Quarter turns, right-handed (about z, +x goes to +y); negative allowed. Exact,
    /// within the space.
    #[arg(
        long,
        allow_hyphen_values = true,
        required_unless_present = "degrees",
        conflicts_with = "degrees"
    )]
    turns: Option<i32>,
    /// Any angle in degrees, right-handed, by point sampling at voxel centres (see
    /// docs/octrees.md); reports the fragmentation (leaves before and after) on stderr.
    #[arg(long, allow_hyphen_values = true)]
    degrees: Option<f64>,
    /// With --degrees: the point X,Y,Z (world units) the axis passes through; the
    /// centre of the bounding box by default.
    #[arg(long, value_parser = super::affine::parse_world_vector, allow_hyphen_values = true, requires = "degrees")]
    about: Option<[f64; 3]>,
    /// With --degrees: also rotate the result back and report the voxels lost and
    /// gained.
    #[arg(long, requires = "degrees")]
    roundtrip: bool,
    /// The output octree file.
    #[arg(short, long)]
    output: PathBuf,
    /// Print JSON: output, voxels, leaves, depth, origin, bbox_min, bbox_max, axis,
    /// turns; with --degrees: degrees, axis_vector, about, leaves_before,
    /// leaves_after, voxels_before, roundtrip_lost, roundtrip_gained.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    limits: octree::OutArgs,
}

pub fn rotate(args: RotateArgs) -> Result<()> {
    octree::guard(&args.output, &[&args.input], &args.limits)?;
    let model = octree::read(&args.input)?;
    if let Some(degrees) = args.degrees {
        if !degrees.is_finite() {
            anyhow::bail!("--degrees `{degrees}`: not a finite angle");
        }
        let (out, extra) =
            super::affine::rotate_degrees(&model, args.axis, degrees, args.about, args.roundtrip)?;
        super::affine::report_fragmentation(&extra, args.json);
        return octree::write(
            &args.output,
            &out,
            &args.limits,
            octree::Report {
                json: args.json,
                extra,
            },
        );
    }
    let turns = args.turns.unwrap_or(0);
    let axis = match args.axis {
        [1.0, 0.0, 0.0] => AxisArg::X,
        [0.0, 1.0, 0.0] => AxisArg::Y,
        [0.0, 0.0, 1.0] => AxisArg::Z,
        _ => anyhow::bail!("--turns needs --axis x, y or z; a vector axis takes --degrees"),
    };
    let args = RotateQuarter { axis, turns, args };
    rotate_quarter(args, model)
}

struct RotateQuarter {
    axis: AxisArg,
    turns: i32,
    args: RotateArgs,
}

fn rotate_quarter(q: RotateQuarter, model: Model) -> Result<()> {
    let RotateQuarter { axis, turns, args } = q;
    octree::write(
        &args.output,
        &model.rotate_in_space(axis.into(), turns)?,
        &args.limits,
        octree::Report {
            json: args.json,
            extra: serde_json::json!({ "axis": axis_name(axis), "turns": turns }),
        },
    )
}

/// Arguments of `tesseral mirror`.
#[derive(clap::Args)]
pub struct MirrorArgs {
    /// The input octree file.
    input: PathBuf,
    /// The axis whose coordinate is reversed within the space.
    #[arg(long, value_enum)]
    axis: AxisArg,
    /// The output octree file.
    #[arg(short, long)]
    output: PathBuf,
    /// Print JSON: output, voxels, leaves, depth, origin, bbox_min, bbox_max, axis.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    limits: octree::OutArgs,
}

pub fn mirror(args: MirrorArgs) -> Result<()> {
    octree::guard(&args.output, &[&args.input], &args.limits)?;
    let model = octree::read(&args.input)?;
    octree::write(
        &args.output,
        &model.mirror_in_space(args.axis.into())?,
        &args.limits,
        octree::Report {
            json: args.json,
            extra: serde_json::json!({ "axis": axis_name(args.axis) }),
        },
    )
}

/// Arguments of `tesseral scale`.
#[derive(clap::Args)]
pub struct ScaleArgs {
    /// The input octree file.
    input: PathBuf,
    /// The factor: `2^K` (K > 0 scales up exactly, K < 0 scales down conservatively:
    /// a block with any black voxel becomes black), a whole number N, or one integer
    /// per axis `KX,KY,KZ` (each voxel becomes a KX × KY × KZ block; a negative factor
    /// mirrors). Exact; the frame's placement scales with it.
    #[arg(long, value_parser = parse_scale, allow_hyphen_values = true)]
    by: ScaleBy,
    /// The output octree file.
    #[arg(short, long)]
    output: PathBuf,
    /// Print JSON: output, voxels, leaves, depth, origin, bbox_min, bbox_max, and
    /// scale_log2 (for 2^K) or scale (per axis).
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    limits: octree::OutArgs,
}

/// What `scale --by` asks for.
#[derive(Clone, Copy)]
pub enum ScaleBy {
    /// `2^K`.
    PowerOfTwo(i32),
    /// An integer per axis.
    Axes([i64; 3]),
}

fn parse_scale(text: &str) -> Result<ScaleBy, String> {
    if text.contains(',') {
        let k = octree::parse_vector(text)?;
        if let Some(a) = k.iter().position(|&c| c == 0) {
            return Err(format!(
                "`{text}`: the factor along {} is 0, which collapses the solid",
                ["x", "y", "z"][a]
            ));
        }
        if k.iter().any(|c| c.unsigned_abs() > 1 << 20) {
            return Err(format!("`{text}`: factors must lie within ±2^20"));
        }
        return Ok(ScaleBy::Axes(k));
    }
    if let Ok(k) = octree::parse_power_of_two(text) {
        return Ok(ScaleBy::PowerOfTwo(k));
    }
    match text.trim().parse::<i64>() {
        Ok(0) => Err(format!("`{text}`: a factor of 0 collapses the solid")),
        Ok(n) if n.unsigned_abs() <= 1 << 20 => Ok(ScaleBy::Axes([n; 3])),
        _ => Err(format!(
            "`{text}`: expected 2^K, a whole number, or KX,KY,KZ (such as 3,1,2)"
        )),
    }
}

pub fn scale(args: ScaleArgs) -> Result<()> {
    octree::guard(&args.output, &[&args.input], &args.limits)?;
    let model = octree::read(&args.input)?;
    let k = match args.by {
        ScaleBy::PowerOfTwo(k) => k,
        ScaleBy::Axes(k) => {
            let scaled = model
                .scale_axes(k)
                .with_context(|| format!("scaling {} by {k:?}", args.input.display()))?;
            return octree::write(
                &args.output,
                &scaled,
                &args.limits,
                octree::Report {
                    json: args.json,
                    extra: serde_json::json!({ "scale": k }),
                },
            );
        }
    };
    let scaled = if k >= 0 {
        model.scale_up(k as u8)
    } else {
        model.scale_down(k.unsigned_abs() as u8)
    }
    .with_context(|| format!("scaling {} by 2^{k}", args.input.display()))?;
    octree::write(
        &args.output,
        &scaled,
        &args.limits,
        octree::Report {
            json: args.json,
            extra: serde_json::json!({ "scale_log2": k }),
        },
    )
}

/// Arguments of `tesseral complement`.
#[derive(clap::Args)]
pub struct ComplementArgs {
    /// The input octree file.
    input: PathBuf,
    /// The output octree file.
    #[arg(short, long)]
    output: PathBuf,
    /// Print JSON: output, voxels, leaves, depth, origin, bbox_min, bbox_max.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    limits: octree::OutArgs,
}

pub fn complement(args: ComplementArgs) -> Result<()> {
    octree::guard(&args.output, &[&args.input], &args.limits)?;
    let model = octree::read(&args.input)?;
    octree::write(
        &args.output,
        &model.complement(),
        &args.limits,
        octree::Report {
            json: args.json,
            extra: serde_json::json!({}),
        },
    )
}

/// The axis's name in JSON output.
fn axis_name(a: AxisArg) -> &'static str {
    match a {
        AxisArg::X => "x",
        AxisArg::Y => "y",
        AxisArg::Z => "z",
    }
}
