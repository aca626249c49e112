//! The checks of `tesseral map` on each scan before any is cast: the work its rays
//! may take (`--max-cells`) and, for `.bt` and `.ot`, OctoMap's key range.

use anyhow::{bail, Result};
use tesseral::io::scan::ScanRecord;
use tesseral::occupancy::OccupancyMap;

use super::Args;

/// Whether the map is written as OctoMap's `.bt` or `.ot`, whose keys reach cells
/// −32768..32767 on each axis.
pub(super) fn octomap_output(args: &Args) -> bool {
    matches!(args.out.format_of(&args.output).as_str(), "bt" | "ot")
}

/// Refuses, before it is cast, a scan whose rays would reach a cell outside
/// OctoMap's key range. Every ray lies within `longest` (its length after
/// `--max-range`) of the sensor, so a box that wide around the sensor inside the
/// range settles it without moving a point; else each ray's ends are checked (the
/// sensor, the point cut at `--max-range`: the key range is a box, so the ends
/// suffice), the points placed in the world.
pub(super) fn check_key_range(
    map: &OccupancyMap,
    s: &ScanRecord,
    args: &Args,
    longest: f64,
) -> Result<()> {
    let inside = |p: [f64; 3]| tesseral::io::octomap::in_key_range(map.cell_of(p));
    let sensor = s.translation;
    if inside(sensor.map(|c| c - longest)) && inside(sensor.map(|c| c + longest)) {
        return Ok(());
    }
    let points = s.world_points();
    let end = |p: &[f64; 3]| {
        let d = [0, 1, 2].map(|a| p[a] - sensor[a]);
        let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        match args.max_range {
            Some(r) if len > r => [0, 1, 2].map(|a| sensor[a] + d[a] * (r / len)),
            _ => *p,
        }
    };
    let finite = points.iter().filter(|p| p.iter().all(|c| c.is_finite()));
    if let Some(c) = std::iter::once(sensor)
        .chain(finite.map(end))
        .find(|&p| !inside(p))
        .map(|p| map.cell_of(p))
    {
        bail!(
            "a ray reaches cell ({}, {}, {}), outside OctoMap's key range (cells −32768..32767 on each axis, ±{:?} m at resolution {:?}): write .tess, which keeps the full range, or cut rays with --max-range",
            c[0],
            c[1],
            c[2],
            32768.0 * args.resolution,
            args.resolution
        );
    }
    Ok(())
}

/// A length for people: three decimals from a millimetre to 10,000 km, four
/// significant digits in scientific notation beyond.
fn metres(x: f64) -> String {
    if (1e-3..1e7).contains(&x) {
        format!("{x:.3}")
    } else {
        format!("{x:.3e}")
    }
}

/// Refuses a scan whose rays would cross more than `--max-cells` cells, before any
/// is cast; else gives its longest ray's length (after `--max-range`).
pub(super) fn check_work(map: &OccupancyMap, s: &ScanRecord, args: &Args) -> Result<f64> {
    let work = map.scan_work(s.sensor_in_points_frame(), &s.points, args.max_range);
    if work.cells > args.max_cells {
        let hint = if args.max_range.is_some() {
            "lower --max-range or raise --max-cells"
        } else {
            "cut long rays with --max-range M, or raise --max-cells"
        };
        let rays = match work.rays {
            1 => "its ray".to_string(),
            n => format!("its {n} rays"),
        };
        bail!(
            "{rays} may cross {} cells (the longest is {} m at resolution {:?}), past --max-cells {}: {hint}",
            work.cells,
            metres(work.longest),
            args.resolution,
            args.max_cells
        );
    }
    Ok(work.longest)
}
