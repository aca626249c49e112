//! `tesseral simulate`: run a world of moving objects and report every contact.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, Result};
use serde::Serialize;
use tesseral::motion::{read_world, Aabb, Body, Frame, Placed, Placement, TopView};

/// Arguments of `tesseral simulate`.
#[derive(clap::Args)]
pub struct Args {
    /// The world file (JSON: environment, time_step, steps, objects with
    /// trajectories; see docs/motion.md).
    world: PathBuf,
    /// Print JSON: every contact and every step.
    #[arg(long)]
    json: bool,
    /// Write a top-down PNG picture of every step into this folder (created if
    /// missing), contacts marked in red.
    #[arg(long, value_name = "DIR")]
    frames: Option<PathBuf>,
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

const PALETTE: [[u8; 3]; 6] = [
    [40, 110, 230],
    [30, 170, 80],
    [230, 150, 20],
    [150, 60, 200],
    [20, 170, 180],
    [200, 80, 130],
];

pub fn run(args: Args) -> Result<()> {
    let wf = read_world(&args.world).context("reading the world file")?;
    let world = &wf.world;
    let sim = world
        .simulate(wf.time_step, wf.steps)
        .context("keeping the objects' octrees current")?;
    if let Some(dir) = &args.frames {
        write_frames(dir, world, &sim)?;
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
            "{} contacts in {} steps of {} ({} objects)",
            contacts.len(),
            wf.steps,
            wf.time_step,
            world.objects.len()
        )?;
    }
    Ok(())
}

fn write_frames(
    dir: &std::path::Path,
    world: &tesseral::motion::World,
    sim: &tesseral::motion::Simulation,
) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    // One view for the whole run: the box around everything at every step.
    let mut lo = [i64::MAX; 3];
    let mut hi = [i64::MIN; 3];
    let mut grow = |b: Option<(tesseral::Voxel, tesseral::Voxel)>| {
        if let Some((l, h)) = b {
            for a in 0..3 {
                lo[a] = lo[a].min(l[a]);
                hi[a] = hi[a].max(h[a]);
            }
        }
    };
    grow(world.environment.bbox());
    let object_boxes: Vec<_> = world
        .objects
        .iter()
        .map(|o| tesseral::motion::rotated(&o.tree, o.rotation).bbox())
        .collect();
    for f in &sim.frames {
        for (b, off) in object_boxes.iter().zip(&f.offsets) {
            grow(b.map(|(l, h)| {
                (
                    [0, 1, 2].map(|a| l[a] + off[a]),
                    [0, 1, 2].map(|a| h[a] + off[a]),
                )
            }));
        }
    }
    if lo[0] > hi[0] {
        lo = [0; 3];
        hi = [0; 3];
    }
    let bounds = Aabb { min: lo, max: hi };
    let show = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let bar = if show {
        indicatif::ProgressBar::new(sim.frames.len() as u64)
    } else {
        indicatif::ProgressBar::hidden()
    };
    for f in &sim.frames {
        let mut view = TopView::new(bounds);
        view.draw_tree(Placed::fixed(&world.environment), [150, 150, 150]);
        for (k, o) in world.objects.iter().enumerate() {
            let place = Placement {
                rotation: o.rotation,
                offset: f.offsets[k],
            };
            view.draw_tree(Placed::new(&o.tree, place), PALETTE[k % PALETTE.len()]);
        }
        view.mark_boxes(&f.contact_boxes, [230, 20, 20]);
        // Contacts that begin during the move out of this step, where they happen.
        let swept: Vec<Aabb> = sim
            .contacts
            .iter()
            .filter(|c| c.step == f.step && c.between_steps)
            .map(|c| c.a_block)
            .collect();
        view.mark_boxes(&swept, [255, 0, 255]);
        let path = dir.join(format!("frame_{:05}.png", f.step));
        view.write_png(&path)
            .with_context(|| format!("writing {}", path.display()))?;
        bar.inc(1);
    }
    bar.finish_and_clear();
    Ok(())
}
