//! `tesseral rsmc`: Monte Carlo of self-avoiding random surfaces (Libes §6).

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, ensure, Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::{Deserialize, Serialize};
use tesseral::dynamic::DynamicOctree;
use tesseral::linear::LinearOctree;
use tesseral::render::{self, RenderOptions};
use tesseral::rsmc::{
    mesh, plot, topology, Chain, Checkpoint, Counters, DenseLattice, Lattice, Params, Sample,
};
use tesseral::Voxel;

use super::view::Animation;

/// Arguments of `tesseral rsmc`.
#[derive(clap::Args)]
pub struct Args {
    /// Total attempted steps (a resumed run continues up to this count).
    #[arg(long, default_value_t = 100_000)]
    steps: u64,
    /// Cost β of one plaquette: weight exp(-β·A - μ·V). [default: 0]
    #[arg(long, allow_negative_numbers = true)]
    beta: Option<f64>,
    /// Cost μ of one enclosed voxel. [default: 0]
    #[arg(long, allow_negative_numbers = true)]
    mu: Option<f64>,
    /// Reject moves that would make the area larger than this.
    #[arg(long)]
    max_area: Option<u64>,
    /// Seed of the random generator (PCG-64, portable). [default: 1]
    #[arg(long)]
    seed: Option<u64>,
    /// Start shape: `voxel`, or `box:AxBxC` (a box of A×B×C voxels). [default: voxel]
    #[arg(long)]
    start: Option<String>,
    /// Libes's original acceptance: no Hastings factor (with β = μ = 0, every legal
    /// move is accepted). Not detailed-balanced for exp(-βA).
    #[arg(long)]
    libes: bool,
    /// Lattice implementation.
    #[arg(long, value_enum, default_value_t = Backend::Octree)]
    backend: Backend,
    /// Folder for series.csv, area.png, the mesh and checkpoint.json (also spelled
    /// --out).
    #[arg(
        short = 'o',
        long = "output",
        alias = "out",
        default_value = "rsmc-out"
    )]
    out: PathBuf,
    /// Steps between rows of series.csv.
    #[arg(long, default_value_t = 1000)]
    sample_every: u64,
    /// Steps between checkpoints (0: only at the end). A checkpoint rebuilds the
    /// lattice in canonical order, so this is part of the trajectory's definition.
    #[arg(long, default_value_t = 0)]
    checkpoint_every: u64,
    /// Steps between global topology checks (Euler characteristic, complement
    /// connected, every edge on two faces); 0: only at the end.
    #[arg(long, default_value_t = 0)]
    check_every: u64,
    /// Mesh format of the final surface.
    #[arg(long, value_enum, default_value_t = MeshFormat::Obj)]
    mesh: MeshFormat,
    /// Width in pixels of surface.png, the rendered final surface (height 3/4 of it);
    /// 0: no picture.
    #[arg(long, hide = true, conflicts_with_all = ["size", "no_picture"])]
    render_width: Option<usize>,
    /// The size of surface.png, the rendered final surface, WIDTHxHEIGHT.
    /// [default: 800x600]
    #[arg(long, value_parser = super::output::parse_size, conflicts_with = "no_picture")]
    size: Option<super::output::Size>,
    /// Draw no surface.png.
    #[arg(long)]
    no_picture: bool,
    /// Continue the run saved in OUT/checkpoint.json.
    #[arg(long)]
    resume: bool,
    /// Print one JSON summary object at the end instead of text.
    #[arg(long)]
    json: bool,
    /// Write an interactive viewer page (`.html`) that plays the surface at every
    /// row of series.csv with a time slider (see `tesseral view`).
    #[arg(long, value_name = "FILE")]
    view: Option<PathBuf>,
    #[command(flatten)]
    page: super::view::PageArgs,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
enum Backend {
    /// The unbounded dynamic octree: O(|S|) memory.
    Octree,
    /// Dense array that follows the surface (baseline): O(box volume) memory.
    Dense,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum MeshFormat {
    Obj,
    Ply,
}

/// The checkpoint file: the chain plus what the CLI needs to continue its outputs.
#[derive(Serialize, Deserialize)]
struct CliCheckpoint {
    chain: Checkpoint,
    sample_every: u64,
    checkpoint_every: u64,
    /// Counters at the last regular row of series.csv (for the acceptance rate).
    base_steps: u64,
    base_accepted: u64,
}

/// The counters at the previous row, as the checkpoint keeps them.
fn since((steps, accepted): (u64, u64)) -> Counters {
    Counters {
        steps,
        accepted,
        ..Counters::default()
    }
}

/// The series is kept in memory (it is rewritten at each checkpoint and plotted).
const MAX_ROWS: u64 = 10_000_000;

/// Validates the fields the CLI adds to the chain's checkpoint, and the chain's own
/// ([`Checkpoint::validate`]), naming the field at fault.
fn check_checkpoint(cp: &CliCheckpoint, steps: u64) -> Result<()> {
    cp.chain.validate()?;
    ensure!(
        cp.sample_every >= 1,
        "sample_every is 0; it must be at least 1"
    );
    ensure!(
        steps / cp.sample_every <= MAX_ROWS,
        "sample_every {} with --steps {steps} gives more than {MAX_ROWS} CSV rows",
        cp.sample_every
    );
    let k = cp.chain.counters;
    ensure!(
        cp.base_steps <= k.steps,
        "base_steps {} exceeds counters.steps {}",
        cp.base_steps,
        k.steps
    );
    ensure!(
        cp.base_accepted <= k.accepted,
        "base_accepted {} exceeds counters.accepted {}",
        cp.base_accepted,
        k.accepted
    );
    ensure!(
        k.accepted - cp.base_accepted <= k.steps - cp.base_steps,
        "base_accepted {} and base_steps {} give more acceptances than steps since the last row",
        cp.base_accepted,
        cp.base_steps
    );
    Ok(())
}

fn parse_start(s: &str) -> Result<Vec<Voxel>> {
    tesseral::rsmc::parse_start(s).with_context(|| format!("--start {s:?}"))
}

fn write_file(path: &Path, body: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<()> {
    tesseral::io::write_atomic(path, body).with_context(|| format!("writing {}", path.display()))
}

fn write_csv(path: &Path, rows: &[Sample]) -> Result<()> {
    write_file(path, |w| {
        writeln!(w, "step,area,volume,radius_of_gyration,acceptance_rate")?;
        for r in rows {
            writeln!(
                w,
                "{},{},{},{:.6},{:.6}",
                r.step, r.area, r.volume, r.radius_of_gyration, r.acceptance
            )?;
        }
        Ok(())
    })
}

fn read_csv(path: &Path) -> Result<Vec<Sample>> {
    let text = fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut rows = Vec::new();
    for (n, line) in text.lines().enumerate().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let bad = || {
            format!(
                "{}:{}: expected step,area,volume,radius_of_gyration,acceptance_rate",
                path.display(),
                n + 1
            )
        };
        ensure!(f.len() == 5, bad());
        rows.push(Sample {
            step: f[0].parse().with_context(bad)?,
            area: f[1].parse().with_context(bad)?,
            volume: f[2].parse().with_context(bad)?,
            radius_of_gyration: f[3].parse().with_context(bad)?,
            acceptance: f[4].parse().with_context(bad)?,
        });
    }
    Ok(rows)
}

/// The size of surface.png: --size, or the older --render-width W (W × 3W/4; 0:
/// none); `None` draws no picture.
fn picture_size(args: &Args) -> Option<super::output::Size> {
    match (args.no_picture, args.size, args.render_width) {
        (true, _, _) | (_, _, Some(0)) => None,
        (_, Some(size), _) => Some(size),
        (_, None, Some(w)) => Some(super::output::Size {
            width: w,
            height: w * 3 / 4,
        }),
        (_, None, None) => Some(super::output::Size {
            width: 800,
            height: 600,
        }),
    }
}

/// Runs `tesseral rsmc`.
pub fn run(args: Args) -> Result<()> {
    ensure!(args.sample_every >= 1, "--sample-every must be at least 1");
    if let Some(w) = args.render_width {
        ensure!(
            w == 0 || (16..=8192).contains(&w),
            "--render-width {w} is outside 16..=8192 (or 0 for no picture)"
        );
    }
    ensure!(
        args.steps / args.sample_every <= MAX_ROWS,
        "--steps {} / --sample-every {} gives more than {MAX_ROWS} CSV rows; raise --sample-every",
        args.steps,
        args.sample_every
    );
    fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    match args.backend {
        Backend::Octree => simulate::<DynamicOctree>(args),
        Backend::Dense => simulate::<DenseLattice>(args),
    }
}

fn simulate<L: Lattice>(args: Args) -> Result<()> {
    let cp_path = args.out.join("checkpoint.json");
    let csv_path = args.out.join("series.csv");
    let (mut chain, mut rows, mut base, sample_every, checkpoint_every) = if args.resume {
        let text = fs::read_to_string(&cp_path)
            .with_context(|| format!("reading {}", cp_path.display()))?;
        let cp: CliCheckpoint = serde_json::from_str(&text)
            .with_context(|| format!("parsing {}", cp_path.display()))?;
        check_checkpoint(&cp, args.steps)
            .with_context(|| format!("bad checkpoint {}", cp_path.display()))?;
        let p = cp.chain.params;
        let same = |name: &str, given: Option<f64>, saved: f64| -> Result<()> {
            match given {
                Some(g) if g.to_bits() != saved.to_bits() => {
                    bail!("--{name} {g} differs from the checkpoint's {saved}")
                }
                _ => Ok(()),
            }
        };
        same("beta", args.beta, p.beta)?;
        same("mu", args.mu, p.mu)?;
        if let Some(s) = args.seed {
            ensure!(
                s == cp.chain.seed,
                "--seed {s} differs from the checkpoint's {}",
                cp.chain.seed
            );
        }
        ensure!(
            args.max_area.is_none() || args.max_area == p.max_area,
            "--max-area differs from the checkpoint's {:?}",
            p.max_area
        );
        ensure!(
            args.start.is_none(),
            "--start cannot be given with --resume"
        );
        ensure!(
            !(args.libes && p.hastings),
            "--libes differs from the checkpoint (it used the Hastings factor)"
        );
        let step = cp.chain.counters.steps;
        let mut rows = if csv_path.exists() {
            read_csv(&csv_path)?
        } else {
            Vec::new()
        };
        rows.retain(|r| r.step <= step && (r.step % cp.sample_every == 0));
        let chain = Chain::from_checkpoint(L::empty(), cp.chain)
            .with_context(|| format!("restoring {}", cp_path.display()))?;
        (
            chain,
            rows,
            (cp.base_steps, cp.base_accepted),
            cp.sample_every,
            cp.checkpoint_every,
        )
    } else {
        let params = Params {
            beta: args.beta.unwrap_or(0.0),
            mu: args.mu.unwrap_or(0.0),
            max_area: args.max_area,
            hastings: !args.libes,
        };
        let start = parse_start(args.start.as_deref().unwrap_or("voxel"))?;
        let chain = Chain::new(L::empty(), params, args.seed.unwrap_or(1), &start)
            .context("starting the chain")?;
        (
            chain,
            Vec::new(),
            (0, 0),
            args.sample_every,
            args.checkpoint_every,
        )
    };
    if chain.steps() == 0 {
        rows.push(chain.sample(since(base)));
    }
    let start_steps = chain.steps();
    let bar = ProgressBar::with_draw_target(
        Some(args.steps.saturating_sub(start_steps)),
        ProgressDrawTarget::stderr(),
    );
    if args.json {
        bar.set_draw_target(ProgressDrawTarget::hidden());
    }
    bar.set_style(
        ProgressStyle::with_template(
            "{bar:40} {percent:>3}% {human_pos}/{human_len} steps, {rate}, eta {eta} {msg}",
        )
        .expect("valid template")
        .with_key(
            "rate",
            |state: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
                let _ = w.write_str(&super::output::rate_text(state.per_sec()));
            },
        ),
    );
    let save = |chain: &mut Chain<L>, rows: &[Sample], base: (u64, u64)| -> Result<()> {
        let cp = CliCheckpoint {
            chain: chain.checkpoint(),
            sample_every,
            checkpoint_every,
            base_steps: base.0,
            base_accepted: base.1,
        };
        write_csv(&csv_path, rows)?;
        let json = serde_json::to_vec(&cp).context("encoding the checkpoint")?;
        write_file(&cp_path, |w| w.write_all(&json))
    };
    let next_multiple = |s: u64, every: u64| {
        s.checked_div(every)
            .map_or(u64::MAX, |q| (q + 1).saturating_mul(every))
    };
    if let Some(page) = &args.view {
        super::output::guard("--view", page, &["html"], &[&cp_path, &csv_path])?;
    }
    let count = args.steps.saturating_sub(chain.steps()) / sample_every.max(1) + 2;
    let unit = tesseral::Frame::new(1.0, [0.0; 3]);
    let mut anim = (args.view.as_ref()).map(|p| Animation::for_file(p, unit, args.page, count));
    let surface = |c: &Chain<L>| {
        let label = format!(
            "step {}, area {}, volume {}",
            c.steps(),
            c.area(),
            c.volume()
        );
        (c.voxels(), label)
    };
    if let Some(a) = anim.as_mut() {
        a.offer_voxels(false, || surface(&chain))?;
    }
    let t0 = Instant::now();
    while chain.steps() < args.steps {
        let s = chain.steps();
        let target = args
            .steps
            .min(next_multiple(s, sample_every))
            .min(next_multiple(s, checkpoint_every))
            .min(next_multiple(s, args.check_every))
            .min(s + 1_000_000);
        chain.run(target - s);
        bar.set_position(target - start_steps);
        let s = chain.steps();
        if s % sample_every == 0 {
            rows.push(chain.sample(since(base)));
            base = (s, chain.counters().accepted);
            bar.set_message(format!("area {}", chain.area()));
            if let Some(a) = anim.as_mut().filter(|_| s < args.steps) {
                a.offer_voxels(false, || surface(&chain))?;
            }
        }
        if args.check_every > 0 && s % args.check_every == 0 {
            topology::check_sphere(&chain.voxels())
                .with_context(|| format!("global topology check at step {s}"))?;
        }
        if checkpoint_every > 0 && s % checkpoint_every == 0 && s < args.steps {
            save(&mut chain, &rows, base)?;
        }
    }
    let seconds = t0.elapsed().as_secs_f64();
    bar.finish_and_clear();
    if rows.last().map(|r| r.step) != Some(chain.steps()) {
        rows.push(chain.sample(since(base)));
    }
    let report = topology::check_sphere(&chain.voxels())
        .context("global topology check of the final surface")?;
    // The last surface always, whichever samples the page keeps.
    if let (Some(mut a), Some(path)) = (anim, &args.view) {
        a.offer_voxels(true, || surface(&chain))?;
        a.finish(path)?;
    }
    save(&mut chain, &rows, base)?;
    let points: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| (r.step as f64, r.area as f64))
        .collect();
    let png = plot::line_plot_png(&points, 800, 500).context("drawing the area plot")?;
    write_file(&args.out.join("area.png"), |w| w.write_all(&png))?;
    let faces = chain.faces();
    let mesh_name = match args.mesh {
        MeshFormat::Obj => "surface.obj",
        MeshFormat::Ply => "surface.ply",
    };
    write_file(&args.out.join(mesh_name), |w| match args.mesh {
        MeshFormat::Obj => mesh::write_obj(&faces, w),
        MeshFormat::Ply => mesh::write_ply(&faces, w),
    })?;
    if let Some(size) = picture_size(&args) {
        let tree = LinearOctree::from_voxels_fitted(&chain.voxels())
            .context("building the octree to render")?;
        let opts = RenderOptions {
            width: size.width,
            height: size.height,
            ao_samples: 4,
            ..RenderOptions::default()
        };
        let image = render::render(&tree, render::Surface::default(), &opts);
        write_file(&args.out.join("surface.png"), |w| image.encode_png(w))?;
    }
    let k = chain.counters();
    let ran = k.steps - start_steps;
    let per_second = if seconds > 0.0 {
        ran as f64 / seconds
    } else {
        0.0
    };
    if args.json {
        let summary = serde_json::json!({
            "steps": k.steps,
            "accepted": k.accepted,
            "area": chain.area(),
            "volume": chain.volume(),
            "euler": report.euler(),
            "seconds": seconds,
            "steps_per_second": per_second,
            "radius_of_gyration": chain.radius_of_gyration(),
            "grown": k.grown,
            "illegal": k.illegal,
            "capped": k.capped,
            "refused": k.refused,
            "seed": chain.seed(),
            "backend": args.backend,
            "out": args.out.display().to_string(),
            // The key every other command uses for its output; `out` kept.
            "output": args.out.display().to_string(),
        });
        crate::outln!("{summary}")?;
    } else {
        crate::outln!(
            "{} steps ({} this run, {:.2} M steps/s): area {}, volume {}, Euler characteristic {}, {} accepted; wrote {}",
            k.steps,
            ran,
            per_second / 1e6,
            chain.area(),
            chain.volume(),
            report.euler(),
            k.accepted,
            args.out.display()
        )?;
    }
    Ok(())
}
