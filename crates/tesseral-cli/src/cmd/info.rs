//! `tesseral info FILE [--json]`: what an octree file holds.

use std::path::PathBuf;

use anyhow::Result;
use serde::Serialize;

use super::budget::Budget;
use super::octree;

/// Arguments of `tesseral info`.
#[derive(clap::Args)]
pub struct Args {
    /// The octree file (its format is chosen by the extension), or a .tss scene,
    /// which is built.
    file: PathBuf,
    /// Print JSON (keys: voxels, leaves, depth, origin, bbox_min, bbox_max,
    /// leaves_by_depth, bytes).
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    budget: Budget,
}

/// The `--json` output. Its keys are a public interface: only ever add to them.
#[derive(Serialize)]
struct Info {
    /// Black voxels.
    voxels: u64,
    /// Black leaves (maximal blocks).
    leaves: usize,
    /// Depth D of the space: 2^D voxels per axis.
    depth: u8,
    /// The space's lowest corner.
    origin: [i64; 3],
    /// The lowest black voxel on each axis, or null when empty.
    bbox_min: Option<[i64; 3]>,
    /// The highest black voxel on each axis, or null when empty.
    bbox_max: Option<[i64; 3]>,
    /// Leaves per depth, index 0 being the root.
    leaves_by_depth: Vec<u64>,
    /// Memory of the linear octree's leaves: 8 bytes per leaf.
    bytes: u64,
}

pub fn run(args: Args) -> Result<()> {
    let tree = octree::read_model(&args.file, &args.budget, &Default::default())?.tree;
    let bbox = tree.bbox();
    let info = Info {
        voxels: tree.voxel_count(),
        leaves: tree.leaf_count(),
        depth: tree.depth(),
        origin: tree.origin(),
        bbox_min: bbox.map(|b| b.0),
        bbox_max: bbox.map(|b| b.1),
        leaves_by_depth: tree.leaves_by_depth(),
        bytes: 8 * tree.leaf_count() as u64,
    };
    if args.json {
        crate::outln!("{}", serde_json::to_string_pretty(&info)?)?;
        return Ok(());
    }
    crate::outln!("file     {}", args.file.display())?;
    crate::outln!("voxels   {}", info.voxels)?;
    crate::outln!("leaves   {}", info.leaves)?;
    crate::outln!(
        "space    depth {} ({} per axis) from {}",
        info.depth,
        1u64 << info.depth,
        octree::fmt_voxel(info.origin)
    )?;
    match bbox {
        Some((lo, hi)) => crate::outln!(
            "bbox     {} to {}",
            octree::fmt_voxel(lo),
            octree::fmt_voxel(hi)
        )?,
        None => crate::outln!("bbox     (empty)")?,
    }
    let by_depth: Vec<String> = info
        .leaves_by_depth
        .iter()
        .enumerate()
        .filter(|(_, &n)| n > 0)
        .map(|(d, n)| format!("{d}:{n}"))
        .collect();
    crate::outln!("by depth {}", by_depth.join(" "))?;
    let per_voxel = if info.voxels == 0 {
        0.0
    } else {
        info.bytes as f64 / info.voxels as f64
    };
    crate::outln!("bytes    {} ({per_voxel:.3} per voxel)", info.bytes)?;
    Ok(())
}
