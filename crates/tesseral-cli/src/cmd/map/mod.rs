//! `tesseral map SCANS... -o MAP`: builds an occupancy map from range scans, as
//! OctoMap's `graph2tree` does, and writes it in any format a model can be written
//! to (`.bt` maximum likelihood, `.ot` with log-odds, `.tess` with the full range).
//!
//! Scans come from OctoMap scan graphs (`.graph`) and logs (`.log`), which carry a
//! pose per scan, and from point clouds (`.xyz`, `.ply`, `.pcd`), placed with
//! `--origin` (the sensor position; the points are world coordinates) or `--pose`
//! (the points are in the sensor frame, moved by the pose). A PCD's `VIEWPOINT` is
//! its sensor origin unless either is given. Every file is read and every scan
//! checked (`--max-cells`; for `.bt` and `.ot`, OctoMap's key range; a file's
//! points against `--memory`) before any is cast. Then a file's scans go through
//! `tesseral::occupancy::OccupancyMap::insert_scans_each` (each scan cast while the
//! one before it is applied), with the store's capacity and `--memory` (the map
//! and the scans held) checked after each.
//!
//! With `--json` one object is printed with exactly the keys `scans`, `points`,
//! `rays`, `occupied`, `free`, `leaves`, `bytes`, `seconds` (the insertion time,
//! reading and writing excluded, as `graph2tree` reports it), `rays_per_second`,
//! and `skipped` (points with a NaN or infinite coordinate, or whose ray would end
//! past ±2^61 cells, not cast: `points` is
//! `rays + skipped`).

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use tesseral::io::scan::{self, Placement, ScanFormat, ScanRecord};
use tesseral::occupancy::{OccupancyMap, SensorModel};

use super::octree::{self, OutArgs};
use super::output::{human_bytes, parse_bytes, plural};

mod checks;

use checks::{check_key_range, check_work, octomap_output};

/// Arguments of `tesseral map`.
#[derive(clap::Args)]
pub struct Args {
    /// Scan files: .graph, .log (OctoMap, with poses), .xyz, .ply, .pcd (clouds).
    #[arg(required = true, value_name = "SCANS")]
    pub scans: Vec<PathBuf>,
    /// The map file: .bt, .ot, .tess or any format `convert` writes.
    #[arg(short, long, value_name = "MAP")]
    pub output: PathBuf,
    /// The side of a map cell, in the scans' units (metres).
    #[arg(long, value_name = "METRES", allow_hyphen_values = true)]
    pub resolution: f64,
    /// Rays longer than this are cut: free up to the range, no hit recorded.
    #[arg(long, value_name = "M", allow_hyphen_values = true)]
    pub max_range: Option<f64>,
    /// The probability that a measured end point is occupied (OctoMap: 0.7).
    #[arg(
        long,
        value_name = "P",
        default_value_t = 0.7,
        allow_hyphen_values = true
    )]
    pub prob_hit: f64,
    /// The probability that a cell a ray crosses is occupied (OctoMap: 0.4).
    #[arg(
        long,
        value_name = "P",
        default_value_t = 0.4,
        allow_hyphen_values = true
    )]
    pub prob_miss: f64,
    /// The probabilities log-odds are clamped to (OctoMap: 0.1192,0.971).
    #[arg(long, value_name = "LO,HI", default_value = "0.1192,0.971", value_parser = parse_clamp, allow_hyphen_values = true)]
    pub clamp: (f64, f64),
    /// A cell is occupied above this probability (OctoMap: 0.5).
    #[arg(
        long,
        value_name = "P",
        default_value_t = 0.5,
        allow_hyphen_values = true
    )]
    pub threshold: f64,
    /// The sensor position for point clouds (their points are world coordinates).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_floats::<3>, allow_hyphen_values = true, conflicts_with = "pose")]
    pub origin: Option<[f64; 3]>,
    /// The sensor pose for point clouds (their points are in the sensor frame):
    /// translation, then roll, pitch, yaw in radians (OctoMap's convention).
    #[arg(long, value_name = "X,Y,Z,ROLL,PITCH,YAW", value_parser = parse_floats::<6>, allow_hyphen_values = true)]
    pub pose: Option<[f64; 6]>,
    /// The most cells one scan's rays may cross, summed (an upper bound computed
    /// from the points before the scan is cast): a point far off, with no
    /// --max-range, is refused rather than walked for hours.
    #[arg(long, value_name = "N", default_value_t = DEFAULT_MAX_CELLS, allow_hyphen_values = true)]
    pub max_cells: u64,
    /// The most memory the map and the scans read for it may take: bytes, or a
    /// number with K, M, G or T (powers of 1024). A file's scans are refused
    /// before any is cast when they alone take more; the map is checked after
    /// each scan (how large it grows is not known before its scans are cast),
    /// and nothing is written when it is over.
    #[arg(long, value_name = "SIZE", default_value = "8G", value_parser = parse_bytes)]
    pub memory: u64,
    /// Print the report as one JSON object.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub out: OutArgs,
}

/// `--max-cells`' default: ten billion cells a scan, several seconds of casting
/// (100 scans of 100,000 rays to 50 m at 5 cm cross about 10^8 each).
const DEFAULT_MAX_CELLS: u64 = 10_000_000_000;

/// Parses `N` comma-separated finite numbers.
fn parse_floats<const N: usize>(s: &str) -> Result<[f64; N], String> {
    let parts: Vec<&str> = s.split(',').collect();
    if parts.len() != N {
        return Err(format!("`{s}`: expected {N} comma-separated numbers"));
    }
    let mut v = [0.0; N];
    for (x, p) in v.iter_mut().zip(parts) {
        *x = p
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("`{p}` is not a finite number"))?;
    }
    Ok(v)
}

fn parse_clamp(s: &str) -> Result<(f64, f64), String> {
    parse_floats::<2>(s).map(|[a, b]| (a, b))
}

/// Totals over all scans.
#[derive(Default)]
struct Totals {
    scans: u64,
    points: u64,
    rays: u64,
    skipped: u64,
    seconds: f64,
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    let by_memory = usize::try_from(args.memory / 4 / POINT_BYTES).unwrap_or(usize::MAX);
    run_holding(args, HELD_POINTS.min(by_memory))
}

/// The bytes of a point held between its file's check and its insertion.
const POINT_BYTES: u64 = std::mem::size_of::<[f64; 3]>() as u64;

/// The bytes of the points of `scans`.
fn points_bytes(scans: &[ScanRecord]) -> u64 {
    scans.iter().map(|s| s.points.len() as u64).sum::<u64>() * POINT_BYTES
}

/// Refuses a map of `map` bytes with `held` bytes of scans read for it, over
/// `--memory`.
fn check_memory(map: usize, held: u64, memory: u64) -> Result<()> {
    let used = (map as u64).saturating_add(held);
    if used > memory {
        bail!(
            "the map ({}) and the scans read for it ({}) take more than --memory {} allows: raise --memory (nothing was written)",
            human_bytes(map as u64),
            human_bytes(held),
            human_bytes(memory)
        );
    }
    Ok(())
}

/// [`run`], keeping at most `budget` points of the files read before the insertion.
fn run_holding(args: Args, budget: usize) -> Result<()> {
    let inputs: Vec<&Path> = args.scans.iter().map(PathBuf::as_path).collect();
    octree::guard(&args.output, &inputs, &args.out)?;
    if super::output::is_stdio(&args.output) && args.json {
        bail!("--json: standard output already holds the map (-o -)");
    }
    // clap refuses --origin with --pose.
    let placement = Placement::of(args.origin, args.pose).context("--origin with --pose")?;
    for path in &args.scans {
        let Some(f) = ScanFormat::from_extension(&tesseral::io::extension(path)) else {
            bail!(
                "{}: not a scan file (scan formats: {})",
                path.display(),
                scan::SCAN_EXTENSIONS
            );
        };
        if f.has_poses() && placement.overrides() {
            let flag = if args.origin.is_some() {
                "--origin"
            } else {
                "--pose"
            };
            bail!(
                "{flag} places point clouds (.xyz, .ply, .pcd); {} carries a pose for each scan",
                path.display()
            );
        }
    }
    if !(args.resolution.is_finite() && args.resolution > 0.0) {
        bail!(
            "--resolution {:?}: must be a positive number",
            args.resolution
        );
    }
    if let Some(m) = args.max_range {
        if !(m.is_finite() && m > 0.0) {
            bail!("--max-range {m:?}: must be a positive number");
        }
    }
    let sensor =
        SensorModel::from_probabilities(args.prob_hit, args.prob_miss, args.clamp, args.threshold)
            .context("--prob-hit, --prob-miss, --clamp, --threshold")?;
    let mut map = OccupancyMap::new(args.resolution, sensor)?;

    let bar = if std::io::stderr().is_terminal() {
        let b = indicatif::ProgressBar::new(0);
        b.set_style(
            indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} scans {msg}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b
    } else {
        indicatif::ProgressBar::hidden()
    };
    let octomap = octomap_output(&args);
    let mut t = Totals::default();
    // Every file is read and checked before any scan is cast, so that a bad file or
    // scan late in the list is refused at once, not after the work on those before
    // it. Files are kept for the insertion while they hold at most HELD_POINTS
    // points together, and the last one read whatever its size (so one file is
    // read once); the others are read (and checked) again then.
    let mut held = Vec::with_capacity(args.scans.len());
    let mut kept = 0;
    for (k, path) in args.scans.iter().enumerate() {
        bar.set_message(format!("reading {}", path.display()));
        let scans = read_checked(&map, path, placement, &args, octomap)?;
        let bytes = points_bytes(&scans);
        if bytes > args.memory {
            bail!(
                "{}: its points take {}, more than --memory {} allows: raise --memory, or split the file",
                path.display(),
                human_bytes(bytes),
                human_bytes(args.memory)
            );
        }
        bar.inc_length(scans.len() as u64);
        let points: usize = scans.iter().map(|s| s.points.len()).sum();
        let last = k + 1 == args.scans.len();
        held.push((last || kept + points <= budget).then(|| {
            kept += points;
            scans
        }));
    }
    // The bytes of the scans held now: the files kept and the one being inserted.
    let mut held_bytes: u64 = held.iter().flatten().map(|s| points_bytes(s)).sum();
    for (path, held) in args.scans.iter().zip(held) {
        let (scans, read_again) = match held {
            Some(scans) => (scans, false),
            None => (read_checked(&map, path, placement, &args, octomap)?, true),
        };
        let file_bytes = points_bytes(&scans);
        if read_again {
            held_bytes += file_bytes;
        }
        let at = |i: usize| format!("{}: scan {} of {}", path.display(), i + 1, scans.len());
        bar.set_message(path.display().to_string());
        // Each scan is cast while the one before it is applied (insert_scans).
        let start = Instant::now();
        let mut i = 0;
        let placed = scans.iter().map(|s| (s.translation, s.world_points()));
        map.insert_scans_each(placed, args.max_range, |map, stats| {
            t.scans += 1;
            t.points += stats.points;
            t.rays += stats.rays;
            t.skipped += stats.skipped;
            map.check_capacity().with_context(|| at(i))?;
            check_memory(map.bytes(), held_bytes, args.memory).with_context(|| at(i))?;
            i += 1;
            bar.inc(1);
            anyhow::Ok(())
        })?;
        t.seconds += start.elapsed().as_secs_f64();
        held_bytes -= file_bytes;
    }
    bar.finish_and_clear();
    if t.points == 0 {
        eprintln!(
            "warning: the scans hold no points: the map is empty (of {} file{})",
            args.scans.len(),
            if args.scans.len() == 1 { "" } else { "s" }
        );
    }

    write_map(&map, &args.output, &args.out)?;
    if args.out.format_of(&args.output) == "ot" && (args.threshold - 0.5).abs() > 1e-12 {
        eprintln!(
            "warning: {}: an .ot keeps every cell's log-odds but not the threshold; \
             OctoMap (and tesseral) read it as occupied from probability 0.5, where this \
             map used {} (.bt and .tess keep the states as mapped)",
            args.output.display(),
            args.threshold
        );
    }
    let rate = if t.seconds > 0.0 {
        t.rays as f64 / t.seconds
    } else {
        0.0
    };
    let counts = map.counts();
    if args.json {
        let v = serde_json::json!({
            "scans": t.scans,
            "points": t.points,
            "rays": t.rays,
            "occupied": counts.occupied,
            "free": counts.free,
            "leaves": counts.leaves,
            "bytes": map.bytes(),
            "seconds": t.seconds,
            "rays_per_second": rate,
            "skipped": t.skipped,
        });
        crate::outln!("{v}")?;
    } else {
        let skipped = if t.skipped > 0 {
            format!(
                " ({} skipped: NaN, infinite, or past ±2^61 cells)",
                t.skipped
            )
        } else {
            String::new()
        };
        let line = format!(
            "wrote {}: {}, {}{skipped}, {} in {:.3} s ({:.3} M rays/s); {} occupied and {} free cells in {}, {} in memory",
            if super::output::is_stdio(&args.output) {
                "<stdout>".to_string()
            } else {
                args.output.display().to_string()
            },
            plural(t.scans, "scan", "scans"),
            plural(t.points, "point", "points"),
            plural(t.rays, "ray", "rays"),
            t.seconds,
            rate / 1e6,
            counts.occupied,
            counts.free,
            plural(counts.leaves, "leaf", "leaves"),
            human_bytes(map.bytes() as u64)
        );
        if super::output::is_stdio(&args.output) {
            eprintln!("{line}");
        } else {
            crate::outln!("{line}")?;
        }
    }
    Ok(())
}

/// Writes the map: `.bt` and `.ot` straight from its blocks (no model in between;
/// the same bytes), `.tess` as the map's own file when it is wider than a model
/// holds (2^21 cells on an axis), any other format through its model.
fn write_map(map: &OccupancyMap, path: &Path, out: &OutArgs) -> Result<()> {
    let context = || format!("{}: the map cannot be written", path.display());
    let ext = out.format_of(path);
    match map.encode_direct(&ext) {
        Some(bytes) => octree::save_encoded(path, &ext, &bytes.with_context(context)?, out),
        None => {
            let model = map.to_model().with_context(context)?;
            octree::save(path, &model, out, &Default::default())
        }
    }
}

/// The most points that the files read before the insertion keep for it (100 MB,
/// or a quarter of `--memory` when that is less), besides the last file; the rest
/// are read again (see [`run`]).
const HELD_POINTS: usize = 1 << 22;

/// A scan file's scans, placed, each checked against `--max-cells` and, when the
/// map is written as `.bt` or `.ot` (`octomap`), OctoMap's key range.
fn read_checked(
    map: &OccupancyMap,
    path: &Path,
    placement: Placement,
    args: &Args,
    octomap: bool,
) -> Result<Vec<ScanRecord>> {
    let mut scans = scan::read(path).map_err(|e| anyhow::anyhow!("{e}"))?;
    let n = scans.len();
    for (i, s) in scans.iter_mut().enumerate() {
        let at = || format!("{}: scan {} of {n}", path.display(), i + 1);
        s.place(placement);
        let longest = check_work(map, s, args).with_context(at)?;
        if octomap {
            check_key_range(map, s, args, longest).with_context(at)?;
        }
    }
    Ok(scans)
}

#[cfg(test)]
mod tests;
