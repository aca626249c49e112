//! `tesseral info` of the `.tess` files wider than a model holds (2^21 voxels on
//! an axis): an occupancy map's own (see
//! `tesseral::occupancy::OccupancyMap::write_file`: its frame, cells and sensor
//! model, read as a map) and a dynamic octree's own (see
//! `tesseral::dynamic::DynamicOctree::write_file`, written by `tesseral replay -o`:
//! its voxels, blocks and box).

use std::io::Read;
use std::path::Path;

use anyhow::Result;
use serde::Serialize;
use tesseral::dynamic::DynamicOctree;
use tesseral::io::native::{DYN_MAGIC, MAP_MAGIC};
use tesseral::occupancy::{probability, OccupancyMap};

/// Describes `path` when it is a map's or a dynamic octree's own `.tess` (by its
/// magic number); `None` for any other file.
pub fn run_if_wide(path: &Path, json: bool) -> Option<Result<()>> {
    let mut head = [0u8; 8];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .ok()?;
    match head {
        MAP_MAGIC => Some(run_map(path, json)),
        DYN_MAGIC => Some(run_dyn(path, json)),
        _ => None,
    }
}

/// The `--json` output of a dynamic octree. Its keys are a public interface: only
/// ever add.
#[derive(Serialize)]
struct DynInfo {
    /// Always `"dynamic_octree"`.
    kind: &'static str,
    /// Voxels (as a model's `voxels`).
    voxels: u64,
    /// World-aligned 8³ blocks holding a voxel (the file's blocks).
    blocks: usize,
    /// The voxels' lowest coordinates, or null when empty.
    bbox_min: Option<[i64; 3]>,
    /// Their highest coordinates, or null.
    bbox_max: Option<[i64; 3]>,
    /// log2 of the root's side.
    root_size_log2: u32,
    /// Bytes the octree takes in memory.
    bytes: usize,
}

/// Prints a dynamic octree file's info (`json`: one object).
fn run_dyn(path: &Path, json: bool) -> Result<()> {
    let t = DynamicOctree::read_file(path)?;
    let bounds = t.bounds();
    let info = DynInfo {
        kind: "dynamic_octree",
        voxels: t.voxel_count(),
        blocks: t.world_block_count(),
        bbox_min: bounds.map(|b| b.0),
        bbox_max: bounds.map(|b| b.1),
        root_size_log2: t.root_size_log2(),
        bytes: t.bytes(),
    };
    if json {
        crate::outln!("{}", serde_json::to_string_pretty(&info)?)?;
        return Ok(());
    }
    crate::outln!("file     {}", path.display())?;
    crate::outln!(
        "kind     unbounded dynamic octree, wider than a model holds (2^21 voxels on an axis)"
    )?;
    crate::outln!("voxels   {} in {} blocks of 8^3", info.voxels, info.blocks)?;
    bbox_line(bounds, "")?;
    crate::outln!("root     2^{} voxels on a side", info.root_size_log2)?;
    crate::outln!("bytes    {} in memory", info.bytes)?;
    Ok(())
}

/// The `--json` output of a map. Its keys are a public interface: only ever add.
#[derive(Serialize)]
struct MapInfo {
    /// Always `"occupancy_map"`.
    kind: &'static str,
    /// The side of a cell in world units (as a model's `voxel_size`).
    voxel_size: f64,
    /// Occupied cells (as a model's `voxels`).
    voxels: u64,
    /// Free cells (as a model's `free_voxels`).
    free_voxels: u64,
    /// Stored entries: one per uniform block, one per known cell of another.
    leaves: u64,
    /// Stored 8³ blocks.
    blocks: usize,
    /// The box of the blocks, in cells (whole blocks), or null when empty.
    bbox_min: Option<[i64; 3]>,
    /// Its highest cell, or null.
    bbox_max: Option<[i64; 3]>,
    /// The box's lowest world corner, or null.
    world_min: Option<[f64; 3]>,
    /// Its highest world corner, or null.
    world_max: Option<[f64; 3]>,
    /// The sensor model, as probabilities.
    prob_hit: f64,
    /// A miss's probability.
    prob_miss: f64,
    /// The clamps' probabilities.
    clamp: [f64; 2],
    /// The occupancy threshold's probability.
    threshold: f64,
    /// Bytes the map takes in memory.
    bytes: usize,
}

/// Prints a map file's info (`json`: one object).
fn run_map(path: &Path, json: bool) -> Result<()> {
    let map = OccupancyMap::read_file(path)?;
    let counts = map.counts();
    let s = map.sensor();
    let res = map.resolution();
    let bounds = map.block_bounds();
    let world = |c: [i64; 3]| c.map(|k| k as f64 * res);
    let info = MapInfo {
        kind: "occupancy_map",
        voxel_size: res,
        voxels: counts.occupied,
        free_voxels: counts.free,
        leaves: counts.leaves,
        blocks: map.block_count(),
        bbox_min: bounds.map(|b| b.0),
        bbox_max: bounds.map(|b| b.1),
        world_min: bounds.map(|b| world(b.0)),
        world_max: bounds.map(|b| world(b.1.map(|k| k.saturating_add(1)))),
        prob_hit: probability(s.hit()),
        prob_miss: probability(s.miss()),
        clamp: [probability(s.clamp_min()), probability(s.clamp_max())],
        threshold: probability(s.threshold()),
        bytes: map.bytes(),
    };
    if json {
        crate::outln!("{}", serde_json::to_string_pretty(&info)?)?;
        return Ok(());
    }
    crate::outln!("file     {}", path.display())?;
    crate::outln!("kind     occupancy map, wider than a model holds (2^21 cells on an axis)")?;
    crate::outln!(
        "cells    {} occupied, {} free, in {} leaves of {} blocks",
        info.voxels,
        info.free_voxels,
        info.leaves,
        info.blocks
    )?;
    bbox_line(bounds, " (whole blocks)")?;
    crate::outln!("frame    cells of {res} from the world origin")?;
    crate::outln!(
        "sensor   hit {:.4}, miss {:.4}, clamps {:.4}..{:.4}, occupied from {:.4}",
        info.prob_hit,
        info.prob_miss,
        info.clamp[0],
        info.clamp[1],
        info.threshold
    )?;
    crate::outln!("bytes    {} in memory", info.bytes)?;
    Ok(())
}

/// The `bbox` line: the box's corners (then `note`), or `(empty)`.
fn bbox_line(bounds: Option<([i64; 3], [i64; 3])>, note: &str) -> Result<()> {
    match bounds {
        Some((lo, hi)) => crate::outln!(
            "bbox     {} to {}{note}",
            super::octree::fmt_voxel(lo),
            super::octree::fmt_voxel(hi)
        )?,
        None => crate::outln!("bbox     (empty)")?,
    }
    Ok(())
}
