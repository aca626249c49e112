//! Streamed builds (every build to a `.tess` file): the scene's leaves and colours
//! go straight to the file, a few work cells at a time, so memory stays flat
//! whatever the depth.

use std::path::Path;

use anyhow::{Context, Result};
use tesseral::csg::{Scene, StreamPlan, StreamProgress};

use super::super::budget::Budget;
use super::super::output;

/// Memory the program takes before any leaf: code, stacks, the scene.
const BASE_BYTES: u64 = 48 << 20;
/// A cell may hold this many times the average leaves per cell.
const CELL_SKEW: u64 = 8;
/// Bytes a leaf takes while its cell is built (the leaf and vector growth).
const BYTES_PER_CELL_LEAF: u64 = 16;
/// File bytes per ten leaves of a streamed `.tess`, per stream of leaves (the
/// shape, and each colour region's leaves again): a varint delta each, about 1.07
/// bytes a leaf measured on the showcase and the spheroid at depths 12 to 15.
const FILE_BYTES_PER_TEN_LEAVES: u64 = 11;

/// The estimated size of a streamed `.tess` of `leaves` leaves, `colours` colours:
/// the leaves, as many again for the colour regions (which hold the coloured
/// leaves, about all of them), the index.
pub fn file_estimate(leaves: u64, colours: usize) -> u64 {
    let streams = if colours == 0 { 1 } else { 2 };
    let chunks = leaves / tesseral::io::DEFAULT_CHUNK_LEAVES as u64 + 1;
    4096 + (leaves / 10).saturating_mul(FILE_BYTES_PER_TEN_LEAVES * streams)
        + chunks * 80
        + colours as u64 * 12
}

/// The memory a streaming build holds: a window of cells, each with up to
/// `CELL_SKEW` × the average leaves (twice that with colours: the colour parts'
/// leaves of the cell), plus the plan, the writer's chunk, one spool buffer per
/// colour and the base.
pub fn stream_memory(estimate_leaves: u64, cells: u64, window: usize, colours: usize) -> u64 {
    let per_cell = estimate_leaves / cells.max(1) + 1;
    let copies = if colours == 0 { 1 } else { 2 };
    // The window cannot hold more than every leaf.
    let window_leaves = (window as u64)
        .saturating_mul(per_cell.saturating_mul(CELL_SKEW))
        .min(estimate_leaves.saturating_add(1));
    let window_bytes = window_leaves
        .saturating_mul(copies)
        .saturating_mul(BYTES_PER_CELL_LEAF);
    let writer = (tesseral::io::DEFAULT_CHUNK_LEAVES as u64 + 200) * 8 * 3;
    let spools = colours as u64 * ((1 << 14) * 8 + (8 << 10));
    BASE_BYTES
        .saturating_add(window_bytes)
        .saturating_add(cells.saturating_mul(40))
        .saturating_add(writer)
        .saturating_add(spools)
}

/// The most work cells built at once, at most [`StreamPlan::default_window`] (two
/// a thread), whose `memory` fits `--memory`; at least one. A build on many cores
/// under a tight budget builds fewer cells at once (on fewer threads) rather than
/// being refused: the depth-12 spheroid at `--memory 96M` needs about 90 MiB on
/// two threads and 368 MiB on sixteen.
fn window_within(budget: &Budget, memory: impl Fn(usize) -> u64) -> usize {
    let mut window = StreamPlan::default_window().max(1);
    while window > 1 && memory(window) > budget.memory {
        window -= 1;
    }
    window
}

/// Refuses a streamed build of `leaves` leaves (estimated, or counted once built)
/// over `--max-leaves`, when given: a stream's memory does not grow with its leaves,
/// so only the flag bounds them.
fn check_max_leaves(budget: &Budget, what: &str, leaves: u64, counted: bool) -> Result<()> {
    match budget.max_leaves {
        Some(max) if leaves > max as u64 => {
            let (about, after) = if counted {
                ("", " (nothing was written)")
            } else {
                ("about ", "")
            };
            anyhow::bail!(
                "{what}: the octree would have {about}{leaves} leaves, more than --max-leaves {max} allows{after}; raise --max-leaves or lower the depth"
            )
        }
        _ => Ok(()),
    }
}

/// What a streamed build reports.
pub struct Streamed {
    pub leaves: u64,
    pub voxels: u64,
    pub estimate: u64,
    pub memory_estimate: u64,
    pub cells: u64,
    pub colours: u64,
}

/// Builds `scene` straight into the `.tess` file `out`, after checking the memory
/// estimate against `--memory` and the file's estimated size against `max_output`.
pub fn build_streamed(
    path: &Path,
    scene: &Scene,
    out: &Path,
    budget: &Budget,
    max_output: u64,
) -> Result<Streamed> {
    let what = format!("{} at depth {}", path.display(), scene.depth);
    let estimate = scene.estimate_leaves_streamed()?;
    check_max_leaves(budget, &what, estimate, false)?;
    let (csg, plan) = scene.stream_plan(0..u64::MAX)?;
    let colours = scene.colour_csgs()?;
    let memory = |w| stream_memory(estimate, plan.cell_count(), w, colours.len());
    let window = window_within(budget, memory);
    let memory_estimate = memory(window);
    budget.check_memory(&what, memory_estimate, " or lower the depth")?;
    output::check_size(out, file_estimate(estimate, colours.len()), max_output)?;
    // The colour spools' temporary files go next to the output, on its disk.
    let spool_dir = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_owned(),
        _ => std::path::PathBuf::from("."),
    };
    let bar = progress_bar(plan.cell_count(), estimate);
    let mut summary = tesseral::partition::StreamSummary::default();
    let mut over = None;
    let written = tesseral::io::write_atomic(out, |w| {
        summary = tesseral::partition::write_plan_tess_coloured(
            &plan,
            &csg,
            &colours,
            scene.frame(),
            w,
            window,
            &spool_dir,
            &mut |p: StreamProgress| {
                if let Some(b) = &bar {
                    b.set_position(p.cells_done);
                    b.set_message(format!("{} leaves", p.leaves));
                }
            },
        )?;
        // The estimate can be low: the leaves counted are checked before the
        // file is committed (an error here leaves no file).
        if let Err(e) = check_max_leaves(budget, &what, summary.leaves, true) {
            over = Some(e);
            return Err(std::io::Error::other("over --max-leaves"));
        }
        Ok(())
    });
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    if let Some(e) = over {
        return Err(e);
    }
    written.with_context(|| format!("writing {}", out.display()))?;
    Ok(Streamed {
        leaves: summary.leaves,
        voxels: summary.voxels,
        estimate,
        memory_estimate,
        cells: plan.cell_count(),
        colours: summary.colours,
    })
}

/// A bar of work cells with the leaves so far and the time left, on a terminal only.
fn progress_bar(cells: u64, estimate: u64) -> Option<indicatif::ProgressBar> {
    use std::io::IsTerminal;
    if !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = indicatif::ProgressBar::new(cells);
    bar.set_style(
        indicatif::ProgressStyle::with_template(&format!(
            "building {{bar:40}} {{pos}}/{{len}} cells, {{msg}} (~{estimate} expected), eta {{eta}}"
        ))
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    Some(bar)
}

/// A bar of leaves against the estimate, with the part in progress and the time
/// left, on a terminal only.
fn leaves_bar(estimate: u64) -> Option<indicatif::ProgressBar> {
    use std::io::IsTerminal;
    if !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = indicatif::ProgressBar::new(estimate.max(1));
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "building {bar:40} {pos}/~{len} leaves, {msg}, eta {eta}",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    Some(bar)
}

/// Builds `scene` into the dataset directory `dir` as `k` parts (each streamed),
/// after the same memory check as a streamed build; a reader of `dir` sees the old
/// dataset or the new one, never a mixture.
pub fn build_parts(
    path: &Path,
    scene: &Scene,
    dir: &Path,
    k: usize,
    budget: &Budget,
) -> Result<Vec<tesseral::partition::ManifestPart>> {
    let what = format!("{} at depth {}", path.display(), scene.depth);
    if k == 0 {
        anyhow::bail!("--parts 0: give at least one part");
    }
    if dir.exists() && !tesseral::partition::is_dataset(dir) {
        let empty = dir.is_dir() && std::fs::read_dir(dir)?.next().is_none();
        if !empty {
            anyhow::bail!(
                "--output {}: exists and is not a dataset directory (no manifest.json); give a new or empty directory",
                dir.display()
            );
        }
    }
    let estimate = scene.estimate_leaves_streamed()?;
    check_max_leaves(budget, &what, estimate, false)?;
    let (_, plan) = scene.stream_plan(0..u64::MAX)?;
    let colours = scene.colour_csgs()?.len();
    let memory = |w| stream_memory(estimate, plan.cell_count(), w, colours);
    let window = window_within(budget, memory);
    budget.check_memory(&what, memory(window), " or lower the depth")?;
    drop(plan);
    // Written into a hidden directory beside DIR and renamed into place at the end
    // (an old dataset there moved aside, then removed); Ctrl-C removes it, and the
    // next writer removes it after a SIGKILL.
    let staged = super::super::streamed::stage_dataset(dir)?;
    // The bar counts the leaves of the parts written so far and of the part in
    // progress, against the scene's estimate.
    let bar = leaves_bar(estimate);
    let (mut before, mut current, mut part) = (0u64, 0u64, 0usize);
    let built = tesseral::partition::build_scene_dataset(
        scene,
        staged.path(),
        k,
        window,
        &mut |i, p: StreamProgress| {
            if i != part {
                (before, part) = (before + current, i);
            }
            current = p.leaves;
            if let Some(b) = &bar {
                b.set_position(before + current);
                b.set_message(format!("part {} of {k}", i + 1));
            }
        },
    );
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let parts = built?;
    let leaves = parts.iter().map(|p| p.leaves).sum();
    check_max_leaves(budget, &what, leaves, true)?;
    staged.commit(dir)?;
    Ok(parts)
}
