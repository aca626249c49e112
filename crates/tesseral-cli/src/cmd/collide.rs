//! `tesseral collide`: do two octrees overlap, by how much, and how far apart are they?

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, Result};
use serde::Serialize;
use tesseral::motion::{clearance, interference, Aabb, Placement, Rotation};
use tesseral::Voxel;

/// Arguments of `tesseral collide`.
#[derive(clap::Args)]
pub struct Args {
    /// The first octree file (any octree format, or a .tss scene); it stays where it is.
    a: PathBuf,
    /// The second octree file, turned by --rotate and then moved by --offset.
    b: PathBuf,
    /// Integer offset X,Y,Z in A's voxels, added to B's voxels (after the rotation).
    /// B is first placed where its frame puts it in A's frame: the two frames must
    /// have equal voxel sizes and placements a whole number of voxels apart.
    #[arg(long, value_parser = parse_voxel, allow_hyphen_values = true, default_value = "0,0,0")]
    offset: Voxel,
    /// Rotation of B by quarter turns about the origin, applied left to right, such
    /// as `z90,x180`, or an index 0 to 23.
    #[arg(long, default_value = "", allow_hyphen_values = true)]
    rotate: Rotation,
    /// Also list the boxes where the two overlap.
    #[arg(long)]
    contacts: bool,
    /// Print JSON (keys `intersects`, `overlap_voxels`, `clearance`).
    #[arg(long)]
    json: bool,
}

/// Parses `X,Y,Z` integers.
pub fn parse_voxel(s: &str) -> Result<Voxel, String> {
    super::octree::parse_ints(s, "X,Y,Z")
}

#[derive(Serialize)]
struct Report {
    intersects: bool,
    overlap_voxels: u64,
    /// The Euclidean gap between the closed voxel cubes; `null` when a solid is empty.
    clearance: Option<f64>,
    offset: Voxel,
    rotation: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    contacts: Option<Vec<Aabb>>,
}

pub fn run(args: Args) -> Result<()> {
    let a = super::octree::read(&args.a).context("reading the first octree")?;
    let b = super::octree::read(&args.b).context("reading the second octree")?;
    // Two frames line up exactly or not at all: B's lattice origin sits at a whole
    // number of A's voxels, which is added to --offset (in A's voxels).
    let frame_offset = a
        .frame
        .offset_to(&b.frame)
        .with_context(|| format!("colliding {} and {}", args.a.display(), args.b.display()))?;
    let offset: Voxel = std::array::from_fn(|i| args.offset[i] + frame_offset[i]);
    let (a, b) = (a.tree, b.tree);
    let place = Placement {
        rotation: args.rotate,
        offset,
    };
    let hit = interference(&a, &b, place, args.contacts);
    let report = Report {
        intersects: hit.intersects,
        overlap_voxels: hit.overlap_voxels,
        clearance: clearance(&a, &b, place),
        offset: args.offset,
        rotation: args.rotate.to_string(),
        contacts: args.contacts.then_some(hit.contacts),
    };
    let mut out = std::io::stdout().lock();
    if args.json {
        serde_json::to_writer(&mut out, &report)?;
        writeln!(out)?;
    } else {
        writeln!(
            out,
            "intersects: {}",
            if report.intersects { "yes" } else { "no" }
        )?;
        writeln!(out, "overlap voxels: {}", report.overlap_voxels)?;
        match report.clearance {
            Some(c) => writeln!(out, "clearance: {c}")?,
            None => writeln!(out, "clearance: none (an octree is empty)")?,
        }
        for c in report.contacts.iter().flatten() {
            writeln!(
                out,
                "contact: ({}, {}, {})..=({}, {}, {})",
                c.min[0], c.min[1], c.min[2], c.max[0], c.max[1], c.max[2]
            )?;
        }
    }
    Ok(())
}
