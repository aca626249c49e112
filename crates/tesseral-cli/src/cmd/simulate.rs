//! `tesseral simulate`: run a world of moving objects and report every contact.

use std::io::Write;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use serde::Serialize;
use tesseral::motion::{read_world_limited, render_frame, Aabb, Body, Contact, Step, WorldError};
use tesseral::render::{Camera, RenderOptions, View};

use super::budget::Budget;
use super::output::{self, Limits, Size};
use super::stdio::Detachable;

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
    /// The view of the frames: iso, front, top or side; or a page `FILE.html` to
    /// write, an interactive viewer that plays the steps with a time slider (see
    /// `tesseral view`). Give it twice for both.
    #[arg(long, default_value = "iso", value_parser = parse_view_arg, action = clap::ArgAction::Append)]
    view: Vec<ViewArg>,
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
    page: super::view::PageArgs,
    #[command(flatten)]
    limits: Limits,
    #[command(flatten)]
    budget: Budget,
    /// Let the world file name octree files outside its own folder (absolute paths
    /// or `..`); without it such a path is an error, so that a world file from
    /// elsewhere cannot make simulate read any file of the machine.
    #[arg(long)]
    allow_outside: bool,
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

/// The head of the `--json` report; `frames` and `contacts` follow it, streamed.
#[derive(Serialize)]
struct ReportHead<'a> {
    steps: u64,
    time_step: f64,
    objects: Vec<&'a str>,
    /// The environment's frame: positions and contact boxes are in its voxels.
    voxel_size: f64,
    translate: [f64; 3],
}

fn name(b: &Body) -> String {
    match b {
        Body::Environment => "environment".to_owned(),
        Body::Object { name, .. } => name.clone(),
    }
}

/// A `--view` value: a named view for the pictures, or a page to write.
#[derive(Clone, Debug)]
enum ViewArg {
    Named(View),
    Page(PathBuf),
}

fn parse_view_arg(s: &str) -> Result<ViewArg, String> {
    if tesseral::io::extension(Path::new(s)) == "html" {
        return Ok(ViewArg::Page(PathBuf::from(s)));
    }
    parse_view(s).map(ViewArg::Named)
}

fn parse_view(s: &str) -> Result<View, String> {
    View::parse(s).ok_or_else(|| format!("unknown view {s:?} (known: iso, front, top, side)"))
}

pub fn run(args: Args) -> Result<()> {
    if let Some(dir) = &args.frames {
        if output::same_file(dir, &args.world) {
            bail!(
                "--frames {}: this is the world file; give a folder for the pictures",
                dir.display()
            );
        }
    }
    let mut named = None;
    let mut view_page = None;
    for v in &args.view {
        match v {
            ViewArg::Named(n) if named.is_none() => named = Some(*n),
            ViewArg::Page(p) if view_page.is_none() => view_page = Some(p.clone()),
            _ => bail!("--view: give at most one named view and one page (.html)"),
        }
    }
    if let Some(page) = &view_page {
        output::guard("--view", page, &["html"], &[&args.world])?;
    }
    let cap = args.budget.world_leaf_cap();
    let wf = match read_world_limited(&args.world, cap as u64, args.allow_outside) {
        Err(WorldError::TooManyLeaves { path, leaves, .. }) => {
            return Err(args
                .budget
                .refuse_at(&path.display().to_string(), leaves, cap))
        }
        r => r.context("reading the world file")?,
    };
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
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let opts = RenderOptions {
        width: size.width,
        height: size.height,
        camera: Camera::view(named.unwrap_or(View::Iso)),
        ..RenderOptions::default()
    };
    let show = args.frames.is_some() && std::io::IsTerminal::is_terminal(&std::io::stderr());
    let bar = if show {
        indicatif::ProgressBar::new(wf.steps.saturating_add(1))
    } else {
        indicatif::ProgressBar::hidden()
    };
    // Each step is reported and dropped as it comes: a long run keeps one step in
    // memory (the review's depth-10 sphere resting in itself kept them all).
    // A reader that leaves early (`| head`) ends the report, not the frames and
    // the page still to write.
    let stdout = Detachable::new(std::io::BufWriter::new(std::io::stdout().lock()));
    let mut report = Reporter {
        out: Budgeted::new(stdout, args.limits.max_output),
        json: args.json,
        contacts_json: Vec::new(),
        contacts: 0,
    };
    if args.json {
        let head = ReportHead {
            steps: wf.steps,
            time_step: wf.time_step,
            objects: world.objects.iter().map(|o| o.name.as_str()).collect(),
            voxel_size: wf.frame.voxel_size,
            translate: wf.frame.translate,
        };
        let mut text = serde_json::to_vec(&head)?;
        text.pop(); // the closing brace: frames and contacts follow
        report.out.write_all(&text)?;
        report.out.write_all(b",\"frames\":[")?;
    }
    let mut failure = None;
    let boxes = args.json || args.frames.is_some();
    let count = wf.steps.saturating_add(1);
    let mut anim = (view_page.as_ref())
        .map(|p| super::view::Animation::for_file(p, wf.frame, args.page, count));
    world
        .simulate_each(wf.time_step, wf.steps, boxes, |step| {
            let done = report
                .step(&step)
                .and_then(|()| match &args.frames {
                    Some(dir) => write_frame(dir, world, &step, &opts),
                    None => Ok(()),
                })
                .and_then(|()| match anim.as_mut() {
                    Some(a) if a.wants(step.frame.step) => view_frame(a, world, &step),
                    _ => Ok(()),
                });
            bar.inc(1);
            let files = args.frames.is_some() || anim.is_some();
            match done {
                Ok(()) if report.out.inner.closed() && !files => ControlFlow::Break(()),
                Ok(()) => ControlFlow::Continue(()),
                Err(e) => {
                    failure = Some(e);
                    ControlFlow::Break(())
                }
            }
        })
        .context("keeping the objects' octrees current")?;
    bar.finish_and_clear();
    if let Some(e) = failure {
        return Err(e);
    }
    if let (Some(a), Some(path)) = (anim, &view_page) {
        a.finish(path)?;
    }
    if args.json {
        let contacts = std::mem::take(&mut report.contacts_json);
        report.out.write_all(b"],\"contacts\":[")?;
        report.out.write_all(&contacts)?;
        report.out.write_all(b"]}\n")?;
    } else {
        let line = format!(
            "{} in {} of {} ({})\n",
            output::plural(report.contacts, "contact", "contacts"),
            output::plural(wf.steps, "step", "steps"),
            wf.time_step,
            output::plural(world.objects.len() as u64, "object", "objects")
        );
        report.out.write_all(line.as_bytes())?;
    }
    report.out.flush()?;
    Ok(())
}

/// Writes each step as it comes: a contact line, or (with `--json`) the frame, with
/// the contacts kept as JSON text until the frames are out.
struct Reporter<W: Write> {
    out: Budgeted<W>,
    json: bool,
    contacts_json: Vec<u8>,
    contacts: u64,
}

impl<W: Write> Reporter<W> {
    fn step(&mut self, step: &Step) -> Result<()> {
        if self.json {
            if step.frame.step > 0 {
                self.out.write_all(b",")?;
            }
            serde_json::to_writer(&mut self.out, &step.frame)?;
            for c in &step.contacts {
                if self.contacts > 0 {
                    self.contacts_json.push(b',');
                }
                serde_json::to_writer(&mut self.contacts_json, &contact_out(c))?;
                self.contacts += 1;
            }
            // The contacts held back count against the output budget too.
            self.out.reserve(self.contacts_json.len() as u64)?;
        } else {
            for c in step.contacts.iter().map(contact_out) {
                let note = if c.between_steps {
                    " (between steps: a per-step test misses it)"
                } else {
                    ""
                };
                let line = format!(
                    "contact at t = {} (step {} + {} of the step): {} and {}{note}\n",
                    c.time, c.step, c.fraction, c.a, c.b
                );
                self.out.write_all(line.as_bytes())?;
                self.contacts += 1;
            }
        }
        Ok(())
    }
}

/// A writer that refuses to write more than `limit` bytes (`--max-output`).
struct Budgeted<W: Write> {
    inner: W,
    written: u64,
    reserved: u64,
    limit: u64,
}

impl<W: Write> Budgeted<W> {
    fn new(inner: W, limit: u64) -> Self {
        Self {
            inner,
            written: 0,
            reserved: 0,
            limit,
        }
    }

    /// Sets aside `bytes` still to be written; fails when they would not fit.
    fn reserve(&mut self, bytes: u64) -> std::io::Result<()> {
        self.reserved = bytes;
        self.check(0)
    }

    fn check(&self, more: u64) -> std::io::Result<()> {
        let total = self
            .written
            .saturating_add(self.reserved)
            .saturating_add(more);
        if total > self.limit {
            return Err(std::io::Error::other(format!(
                "the report would exceed the output limit of {} bytes; raise it with --max-output",
                self.limit
            )));
        }
        Ok(())
    }
}

impl<W: Write> Write for Budgeted<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.check(buf.len() as u64)?;
        let n = self.inner.write(buf)?;
        self.written += n as u64;
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

fn contact_out(c: &Contact) -> ContactOut {
    ContactOut {
        time: c.time,
        step: c.step,
        fraction: c.fraction.to_string(),
        a: name(&c.a),
        b: name(&c.b),
        between_steps: c.between_steps,
        a_block: c.a_block,
        b_block: c.b_block,
    }
}

/// Draws one step: objects in colour, overlaps red, and the blocks hit during the
/// move out of this step magenta.
fn write_frame(
    dir: &Path,
    world: &tesseral::motion::World,
    step: &Step,
    opts: &RenderOptions,
) -> Result<()> {
    let f = &step.frame;
    let swept: Vec<Aabb> = step
        .contacts
        .iter()
        .filter(|c| c.step == f.step && c.between_steps)
        .map(|c| c.a_block)
        .collect();
    let img =
        render_frame(world, f, &swept, opts).with_context(|| format!("drawing step {}", f.step))?;
    let path = dir.join(format!("frame_{:05}.png", f.step));
    img.write_png(&path)
        .with_context(|| format!("writing {}", path.display()))
}

/// Adds one step to the viewer page: objects in their colours, the environment grey.
fn view_frame(
    anim: &mut super::view::Animation,
    world: &tesseral::motion::World,
    step: &Step,
) -> Result<()> {
    let f = &step.frame;
    let (all, regions) = tesseral::motion::frame_regions(world, f)
        .with_context(|| format!("joining step {}", f.step))?;
    let layer = tesseral::model::Layer::from_regions(
        all.depth(),
        all.origin(),
        regions
            .into_iter()
            .map(|(c, t)| ([c[0], c[1], c[2], 255], t)),
    )?;
    let colouring = tesseral::view::Colouring::Layer(&layer, tesseral::motion::ENVIRONMENT_COLOUR);
    anim.add(&all, colouring, &format!("step {}, t = {}", f.step, f.time))
}
