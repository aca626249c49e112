//! `tesseral plan`: a collision-free path for an object through an environment.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, Result};
use serde::Serialize;
use tesseral::model::Frame;
use tesseral::motion::{
    estimate_plan, plan, plan_with_turns, render_plan, Aabb, PlanOptions, Rotation,
};
use tesseral::render::{Camera, RenderOptions, View};
use tesseral::Voxel;

use super::budget::Budget;
use super::collide::parse_voxel;
use super::output::{self, Size};

/// Arguments of `tesseral plan`.
#[derive(clap::Args)]
pub struct Args {
    /// The environment octree file or scene (the obstacles). Offsets, waypoints and
    /// lengths are in its voxels; `--json` adds them in its frame's world units.
    env: PathBuf,
    /// The moving object's octree file or scene. It starts where its frame puts it in
    /// the environment's frame (equal voxel sizes and a whole-voxel offset, else an
    /// error naming both), and --from/--to move it from there, as in `collide`.
    obj: PathBuf,
    /// The start: the integer offset X,Y,Z of the object.
    #[arg(long, value_parser = parse_voxel, allow_hyphen_values = true)]
    from: Voxel,
    /// The goal offset X,Y,Z.
    #[arg(long, value_parser = parse_voxel, allow_hyphen_values = true)]
    to: Voxel,
    /// The object's fixed rotation, such as `z90` (see `tesseral collide --rotate`).
    #[arg(long, default_value = "", allow_hyphen_values = true)]
    rotate: Rotation,
    /// Let the region reach this many voxels beyond the bounding box of the
    /// environment and the object at both ends (room to go around the outside).
    #[arg(long, default_value_t = 0)]
    margin: u32,
    /// The box of world voxels X0,Y0,Z0,X1,Y1,Z1 (inclusive) the object must stay
    /// in; replaces the bounding box and --margin.
    #[arg(long, value_parser = parse_region, allow_hyphen_values = true)]
    region: Option<Aabb>,
    /// Let the object turn by quarter turns about x, y and z on the way (over the 24
    /// orientations of the cube, each turn checked along its sweep); --rotate gives
    /// the starting orientation. Paths are unit moves and turns, not smoothed.
    #[arg(long, conflicts_with_all = ["no_smooth", "output"])]
    rotations: bool,
    /// Keep the raw A* path (no smoothing).
    #[arg(long)]
    no_smooth: bool,
    /// Print JSON.
    #[arg(long)]
    json: bool,
    /// Render a PNG picture of the path through the scene: the environment grey,
    /// the object green at the start and blue at the goal, the path yellow.
    #[arg(short = 'o', long = "output", value_name = "PATH.png")]
    output: Option<PathBuf>,
    /// The view of the picture: top, iso, front or side.
    #[arg(long, default_value = "top", value_parser = parse_view)]
    view: View,
    /// The picture's size, WIDTHxHEIGHT (with --output). [default: 800x600]
    #[arg(long, requires = "output", value_parser = output::parse_size)]
    size: Option<Size>,
    #[command(flatten)]
    budget: Budget,
}

fn parse_view(s: &str) -> Result<View, String> {
    View::parse(s).ok_or_else(|| format!("unknown view {s:?} (known: iso, front, top, side)"))
}

fn parse_region(s: &str) -> Result<Aabb, String> {
    let v: [i64; 6] = super::octree::parse_ints(s, "X0,Y0,Z0,X1,Y1,Z1")?;
    let (min, max) = ([v[0], v[1], v[2]], [v[3], v[4], v[5]]);
    if (0..3).any(|a| max[a] < min[a]) {
        return Err(format!(
            "the region {s:?} is empty: each of X1,Y1,Z1 must be at least X0,Y0,Z0"
        ));
    }
    Ok(Aabb { min, max })
}

#[derive(Serialize)]
struct Found<'a> {
    found: bool,
    waypoints: &'a [Voxel],
    raw: &'a [Voxel],
    steps: u64,
    length: f64,
    clearance: Option<f64>,
    free_cells: usize,
    settled: usize,
    /// The environment's voxel size and the world translation of each waypoint
    /// (the object's displacement, in world units).
    voxel_size: f64,
    waypoints_world: Vec<[f64; 3]>,
    length_world: f64,
    clearance_world: Option<f64>,
}

#[derive(Serialize)]
struct NotFound {
    found: bool,
    reason: String,
}

pub fn run(args: Args) -> Result<()> {
    if let Some(path) = &args.output {
        if output::is_stdio(path) {
            anyhow::bail!(
                "--output -: standard output holds the path; give the picture a file name"
            );
        }
        output::guard("--output", path, &["png"], &[&args.env, &args.obj])?;
    }
    let env = super::octree::read(&args.env).context("reading the environment")?;
    let obj = super::octree::read(&args.obj).context("reading the object")?;
    // The frame rule of `collide`: the object sits where its frame puts it in the
    // environment's lattice, and the offsets move it from there.
    let placed = env.frame.offset_to(&obj.frame).with_context(|| {
        format!(
            "planning {} through {}",
            args.obj.display(),
            args.env.display()
        )
    })?;
    let frame = env.frame;
    let env = env.tree;
    let obj = obj
        .tree
        .translate(placed)
        .context("placing the object in the environment's frame")?;
    let options = PlanOptions {
        rotation: args.rotate,
        smooth: !args.no_smooth,
        margin: i64::from(args.margin),
        region: args.region,
        ..PlanOptions::default()
    };
    // Refuse a region too large for memory before the search grows into it; a
    // region the object cannot use at all is left to `plan` to explain.
    if let Ok(e) = estimate_plan(&env, &obj, args.from, args.to, &options) {
        let hint = if args.region.is_some() {
            ", or give a smaller --region"
        } else {
            ", or lower --margin (or give --region)"
        };
        args.budget.check_memory(
            &format!("the planning region ({} free cells)", e.free_cells),
            e.bytes,
            hint,
        )?;
    }
    if args.rotations {
        return plan_turning(&args, &env, &obj, &frame, &options);
    }
    let result = plan(&env, &obj, args.from, args.to, &options);
    if let Some(path) = &args.output {
        picture(
            path,
            &env,
            &obj,
            &args,
            result.as_ref().ok().map(|p| p.waypoints.as_slice()),
        )?;
    }
    let mut out = std::io::stdout().lock();
    match result {
        Ok(p) => {
            if args.json {
                let f = Found {
                    found: true,
                    waypoints: &p.waypoints,
                    raw: &p.raw,
                    steps: p.steps,
                    length: p.length,
                    clearance: p.clearance,
                    free_cells: p.free_cells,
                    settled: p.settled,
                    voxel_size: frame.voxel_size,
                    waypoints_world: p.waypoints.iter().map(|&w| world(&frame, w)).collect(),
                    length_world: p.length * frame.voxel_size,
                    clearance_world: p.clearance.map(|c| c * frame.voxel_size),
                };
                serde_json::to_writer(&mut out, &f)?;
                writeln!(out)?;
            } else {
                writeln!(
                    out,
                    "path: {} waypoints, length {:.3} voxels ({} unit moves before smoothing)",
                    p.waypoints.len(),
                    p.length,
                    p.steps
                )?;
                match p.clearance {
                    Some(c) => writeln!(out, "clearance: {c:.3}")?,
                    None => writeln!(out, "clearance: unbounded (empty environment)")?,
                }
                if !frame.is_unit() {
                    writeln!(
                        out,
                        "voxel size {}: length {:.3} in world units",
                        frame.voxel_size,
                        p.length * frame.voxel_size
                    )?;
                }
                for w in &p.waypoints {
                    writeln!(out, "{},{},{}", w[0], w[1], w[2])?;
                }
            }
            Ok(())
        }
        Err(why) => {
            if args.json {
                serde_json::to_writer(
                    &mut out,
                    &NotFound {
                        found: false,
                        reason: why.to_string(),
                    },
                )?;
                writeln!(out)?;
            } else {
                writeln!(out, "{why}")?;
            }
            out.flush()?;
            // No path is an answer, not a failure of the command: exit status 1.
            std::process::exit(1);
        }
    }
}

/// `plan --rotations`: A* over (offset, orientation), moves and quarter turns.
fn plan_turning(
    args: &Args,
    env: &tesseral::linear::LinearOctree,
    obj: &tesseral::linear::LinearOctree,
    frame: &Frame,
    options: &PlanOptions,
) -> Result<()> {
    let mut out = std::io::stdout().lock();
    match plan_with_turns(env, obj, args.from, args.to, args.rotate, options) {
        Ok(p) => {
            let waypoints = p.waypoints();
            if args.json {
                let v = serde_json::json!({
                    "found": true,
                    "waypoints": waypoints.iter().map(|w| w.0).collect::<Vec<_>>(),
                    "orientations": waypoints.iter().map(|w| w.1.to_string()).collect::<Vec<_>>(),
                    "moves": p.moves,
                    "turns": p.turns,
                    "settled": p.settled,
                    "voxel_size": frame.voxel_size,
                    "waypoints_world": waypoints.iter().map(|w| world(frame, w.0)).collect::<Vec<_>>(),
                });
                writeln!(out, "{v}")?;
            } else {
                writeln!(
                    out,
                    "path: {} waypoints, {} unit moves and {} quarter turns",
                    waypoints.len(),
                    p.moves,
                    p.turns
                )?;
                for (w, r) in &waypoints {
                    writeln!(out, "{},{},{} {r}", w[0], w[1], w[2])?;
                }
            }
            Ok(())
        }
        Err(why) => {
            if args.json {
                writeln!(
                    out,
                    "{}",
                    serde_json::json!({"found": false, "reason": why.to_string()})
                )?;
            } else {
                writeln!(out, "{why}")?;
            }
            out.flush()?;
            std::process::exit(1);
        }
    }
}

/// A waypoint (an offset in voxels) as a displacement in world units.
fn world(frame: &Frame, w: Voxel) -> [f64; 3] {
    w.map(|c| c as f64 * frame.voxel_size)
}

fn picture(
    path: &std::path::Path,
    env: &tesseral::linear::LinearOctree,
    obj: &tesseral::linear::LinearOctree,
    args: &Args,
    waypoints: Option<&[Voxel]>,
) -> Result<()> {
    let size = args.size.unwrap_or(Size {
        width: 800,
        height: 600,
    });
    let opts = RenderOptions {
        width: size.width,
        height: size.height,
        camera: Camera::view(args.view),
        ..RenderOptions::default()
    };
    let img = render_plan(env, obj, args.rotate, args.from, args.to, waypoints, &opts)
        .context("drawing the path")?;
    img.write_png(path)
        .with_context(|| format!("writing {}", path.display()))
}
