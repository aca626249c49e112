//! `tesseral info` of an occupancy map's own `.tess` (a map wider than a model
//! holds: see `tesseral::occupancy::OccupancyMap::write_file`): its frame, cells
//! and sensor model, read as a map.

use std::io::Read;
use std::path::Path;

use anyhow::Result;
use serde::Serialize;
use tesseral::occupancy::{probability, OccupancyMap};

/// Whether `path` is a map's own `.tess` (by its magic number).
pub fn is_map_file(path: &Path) -> bool {
    let mut head = [0u8; 8];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok_and(|()| head == tesseral::io::native::MAP_MAGIC)
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
pub fn run(path: &Path, json: bool) -> Result<()> {
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
    match bounds {
        Some((lo, hi)) => crate::outln!(
            "bbox     {} to {} (whole blocks)",
            super::octree::fmt_voxel(lo),
            super::octree::fmt_voxel(hi)
        )?,
        None => crate::outln!("bbox     (empty)")?,
    }
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
