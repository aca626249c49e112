//! `tesseral translate` (in `transform/translate.rs`), `rotate`, `mirror`, `scale`
//! and `complement`.

use std::path::PathBuf;

use anyhow::{Context, Result};
use tesseral::model::Model;

use super::octree::{self, AxisArg};

mod translate;

pub use translate::{translate, TranslateArgs};

/// Arguments of `tesseral rotate`.
#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("angle").required(true).args(["turns", "degrees"])))]
pub struct RotateArgs {
    /// The input octree file.
    input: PathBuf,
    /// The axis of rotation: x, y, z, or (with --degrees) a vector X,Y,Z.
    #[arg(long, value_parser = super::affine::parse_axis, allow_hyphen_values = true)]
    axis: [f64; 3],
    /// Quarter turns, right-handed (about z, +x goes to +y); negative allowed. Exact,
    /// within the space.
    #[arg(long, allow_hyphen_values = true)]
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
    // clap lets `requires = "degrees"` pass when --turns, which conflicts with
    // --degrees, is given.
    if args.degrees.is_none() {
        if let Some(flag) = [
            (args.about.is_some(), "--about"),
            (args.roundtrip, "--roundtrip"),
        ]
        .into_iter()
        .find_map(|(given, flag)| given.then_some(flag))
        {
            anyhow::bail!("{flag} applies only with --degrees, not with --turns");
        }
    }
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
