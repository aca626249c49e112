//! `tesseral simulate`: run a world of moving objects and report every contact.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, Result};
use serde::Serialize;
use tesseral::motion::{read_world, render_frame, Aabb, Body, Frame};
use tesseral::render::{Camera, RenderOptions, View};

use super::output::{self, Limits, Size};

/// Arguments of `tesseral simulate`.
#[derive(clap::Args)]
pub struct Args {
    /// The world file (JSON: environment, time_step, steps, objects with
    /// trajectories; see docs/motion.md).
    world: PathBuf,
    /// Print JSON: every contact and every step.
    #[arg(long)]
    json: bool,
    /// Render a PNG picture of every step into this folder (created if missing):
    /// objects in colour, overlaps and objects in contact red, blocks hit between
    /// steps magenta.
    #[arg(long, value_name = "DIR")]
    frames: Option<PathBuf>,
    /// The view of the frames: iso, front, top or side.
    #[arg(long, default_value = "iso", value_parser = parse_view)]
    view: View,
    /// The frames' size, WIDTHxHEIGHT (with --frames). [default: 480x360]
    #[arg(long, requires = "frames", value_parser = output::parse_size)]
    size: Option<Size>,
    /// The frames' width in pixels (older spelling; use --size).
    #[arg(long, hide = true, requires = "frames", conflicts_with = "size", value_parser = clap::value_parser!(u32).range(16..=4096))]
    width: Option<u32>,
    /// The frames' height in pixels (older spelling; use --size).
    #[arg(long, hide = true, requires = "frames", conflicts_with = "size", value_parser = clap::value_parser!(u32).range(16..=4096))]
    height: Option<u32>,
    #[command(flatten)]
    limits: Limits,
}

#[derive(Serialize)]
struct ContactOut {
    time: f64,
    step: u64,
    fraction: String,
    a: String,
    b: String,
    between_steps: bool,
    a_block: Aabb,
    b_block: Aabb,
}

#[derive(Serialize)]
struct Report<'a> {
    steps: u64,
    time_step: f64,
    objects: Vec<&'a str>,
    contacts: Vec<ContactOut>,
    frames: &'a [Frame],
}

fn name(b: &Body) -> String {
    match b {
        Body::Environment => "environment".to_owned(),
        Body::Object { name, .. } => name.clone(),
    }
}

/// `1 object`, `2 objects`.
fn plural(n: u64, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}

fn parse_view(s: &str) -> Result<View, String> {
    View::parse(s).ok_or_else(|| format!("unknown view {s:?} (known: iso, front, top, side)"))
}

pub fn run(args: Args) -> Result<()> {
    if let Some(dir) = &args.frames {
        if output::same_file(dir, &args.world) {
            anyhow::bail!(
                "--frames {}: this is the world file; give a folder for the pictures",
                dir.display()
            );
        }
    }
    let wf = read_world(&args.world).context("reading the world file")?;
    let world = &wf.world;
    let size = args.size.unwrap_or(Size {
        width: args.width.map_or(480, |w| w as usize),
        height: args.height.map_or(360, |h| h as usize),
    });
    if let Some(dir) = &args.frames {
        // One picture per step and one of the start, each estimated before any work.
        let each = tesseral::io::estimate_image_bytes(size.width as u64, size.height as u64);
        let total = each.saturating_mul(wf.steps.saturating_add(1));
        output::check_size(dir, total, args.limits.max_output)?;
    }
    let sim = world
        .simulate(wf.time_step, wf.steps)
        .context("keeping the objects' octrees current")?;
    if let Some(dir) = &args.frames {
        write_frames(dir, world, &sim, args.view, (size.width, size.height))?;
    }
    let contacts: Vec<ContactOut> = sim
        .contacts
        .iter()
        .map(|c| ContactOut {
            time: c.time,
            step: c.step,
            fraction: c.fraction.to_string(),
            a: name(&c.a),
            b: name(&c.b),
            between_steps: c.between_steps,
            a_block: c.a_block,
            b_block: c.b_block,
        })
        .collect();
    let mut out = std::io::stdout().lock();
    if args.json {
        let report = Report {
            steps: wf.steps,
            time_step: wf.time_step,
            objects: world.objects.iter().map(|o| o.name.as_str()).collect(),
            contacts,
            frames: &sim.frames,
        };
        serde_json::to_writer(&mut out, &report)?;
        writeln!(out)?;
    } else {
        for c in &contacts {
            let note = if c.between_steps {
                " (between steps: a per-step test misses it)"
            } else {
                ""
            };
            writeln!(
                out,
                "contact at t = {} (step {} + {} of the step): {} and {}{note}",
                c.time, c.step, c.fraction, c.a, c.b
            )?;
        }
        writeln!(
            out,
            "{} in {} of {} ({})",
            plural(contacts.len() as u64, "contact"),
            plural(wf.steps, "step"),
            wf.time_step,
            plural(world.objects.len() as u64, "object")
        )?;
    }
    Ok(())
}

fn write_frames(
    dir: &std::path::Path,
    world: &tesseral::motion::World,
    sim: &tesseral::motion::Simulation,
    view: View,
    size: (usize, usize),
) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let opts = RenderOptions {
        width: size.0,
        height: size.1,
        camera: Camera::view(view),
        ..RenderOptions::default()
    };
    let show = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let bar = if show {
        indicatif::ProgressBar::new(sim.frames.len() as u64)
    } else {
        indicatif::ProgressBar::hidden()
    };
    for f in &sim.frames {
        // Contacts that begin during the move out of this step, where they happen.
        let swept: Vec<Aabb> = sim
            .contacts
            .iter()
            .filter(|c| c.step == f.step && c.between_steps)
            .map(|c| c.a_block)
            .collect();
        let img = render_frame(world, f, &swept, &opts)
            .with_context(|| format!("drawing step {}", f.step))?;
        let path = dir.join(format!("frame_{:05}.png", f.step));
        img.write_png(&path)
            .with_context(|| format!("writing {}", path.display()))?;
        bar.inc(1);
    }
    bar.finish_and_clear();
    Ok(())
}
