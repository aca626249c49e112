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
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_world_vector, allow_hyphen_values = true)]
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
}

pub fn translate(args: TranslateArgs) -> Result<()> {
    octree::guard(&args.output, &[&args.input], &args.limits)?;
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

/// Arguments of `tesseral rotate`.
#[derive(clap::Args)]
pub struct RotateArgs {
    /// The input octree file.
    input: PathBuf,
    /// The axis of rotation.
    #[arg(long, value_enum)]
    axis: AxisArg,
    /// Quarter turns, right-handed (about z, +x goes to +y); negative allowed.
    #[arg(long, allow_hyphen_values = true)]
    turns: i32,
    /// The output octree file.
    #[arg(short, long)]
    output: PathBuf,
    /// Print JSON: output, voxels, leaves, depth, origin, bbox_min, bbox_max, axis, turns.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    limits: octree::OutArgs,
}

pub fn rotate(args: RotateArgs) -> Result<()> {
    octree::guard(&args.output, &[&args.input], &args.limits)?;
    let model = octree::read(&args.input)?;
    octree::write(
        &args.output,
        &model.rotate_in_space(args.axis.into(), args.turns)?,
        &args.limits,
        octree::Report {
            json: args.json,
            extra: serde_json::json!({ "axis": axis_name(args.axis), "turns": args.turns }),
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
    /// The factor `2^K`: K > 0 scales up exactly, K < 0 scales down conservatively
    /// (a block with any black voxel becomes black).
    #[arg(long, value_parser = octree::parse_power_of_two, allow_hyphen_values = true)]
    by: i32,
    /// The output octree file.
    #[arg(short, long)]
    output: PathBuf,
    /// Print JSON: output, voxels, leaves, depth, origin, bbox_min, bbox_max, scale_log2.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    limits: octree::OutArgs,
}

pub fn scale(args: ScaleArgs) -> Result<()> {
    octree::guard(&args.output, &[&args.input], &args.limits)?;
    let model = octree::read(&args.input)?;
    let k = args.by;
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

/// Parses `X,Y,Z` in world units.
fn parse_world_vector(text: &str) -> Result<[f64; 3], String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(format!("expected three numbers `X,Y,Z`, got `{text}`"));
    }
    let mut v = [0.0; 3];
    for (a, p) in parts.iter().enumerate() {
        v[a] = p
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("`{p}` is not a finite number (in `{text}`)"))?;
    }
    Ok(v)
}

/// The axis's name in JSON output.
fn axis_name(a: AxisArg) -> &'static str {
    match a {
        AxisArg::X => "x",
        AxisArg::Y => "y",
        AxisArg::Z => "z",
    }
}
