//! `tesseral info FILE [--json] [--tree | --codes]`: what an octree file holds, or
//! the octree in the papers' notations.

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
    /// leaves_by_depth, bytes, voxel_size, translate, world_min, world_max, colors,
    /// colored_voxels, free_voxels, free_leaves, log_odds, streamed).
    #[arg(long)]
    json: bool,
    /// Print the octree as the indented node list of Ahuja & Nash Fig. 4 instead:
    /// each gray and black node's label path from the root `r` (such as `r05`),
    /// indented by depth; white nodes are not listed. With --json: `{"nodes":
    /// [{"label", "depth", "colour"}]}`.
    #[arg(long, conflicts_with = "codes")]
    tree: bool,
    /// Print the leaves as locational codes with Harakal & Chmúrny's "X" postfix
    /// instead, one per line in tesseral order (`05XX`: a block two levels above a
    /// voxel). With --json: `{"codes": [...]}`.
    #[arg(long)]
    codes: bool,
    #[command(flatten)]
    budget: Budget,
}

/// `--tree` and `--codes`: the papers' notations, streamed line by line.
fn notation(args: &Args, tree: &tesseral::linear::LinearOctree) -> Result<()> {
    if args.json {
        // Streamed as it is made: a large tree never sits in memory as JSON.
        let items: Box<dyn Iterator<Item = serde_json::Value>> = if args.tree {
            Box::new(tree.node_list().map(
                |n| serde_json::json!({"label": n.label(), "depth": n.depth(), "colour": n.colour}),
            ))
        } else {
            Box::new(tree.locational_codes().map(serde_json::Value::from))
        };
        crate::out!("{{\"{}\":[", if args.tree { "nodes" } else { "codes" })?;
        for (i, item) in items.enumerate() {
            crate::out!("{}{item}", if i == 0 { "" } else { "," })?;
        }
        crate::outln!("]}}")?;
    } else if args.tree {
        for node in tree.node_list() {
            crate::outln!("{node}")?;
        }
    } else {
        for code in tree.locational_codes() {
            crate::outln!("{code}")?;
        }
    }
    Ok(())
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
    /// The side of a voxel in world units.
    voxel_size: f64,
    /// The world position of voxel (0, 0, 0)'s lowest corner.
    translate: [f64; 3],
    /// The world box of the black voxels (lowest corner), or null when empty.
    world_min: Option<[f64; 3]>,
    /// The world box of the black voxels (highest corner), or null when empty.
    world_max: Option<[f64; 3]>,
    /// Distinct colours, or null when the file has no colours.
    colors: Option<usize>,
    /// Black voxels with a colour.
    colored_voxels: u64,
    /// Voxels known to be free, or null when the file has no free space.
    free_voxels: Option<u64>,
    /// Leaves of the free space, or null.
    free_leaves: Option<usize>,
    /// Whether per-voxel occupancy log-odds are stored.
    log_odds: bool,
    /// Whether the file was read chunk by chunk (a `.tess` file of either version
    /// or a dataset, with no layers but colours) rather than loaded whole.
    streamed: bool,
}

/// An inclusive box of voxels.
type BBox = ([i64; 3], [i64; 3]);

/// The info of a `.tess` file (either version: a version-1 payload is indexed in
/// one pass, `TessFile::open_streaming`) with no layers but colours, or of a
/// dataset of them, read chunk by chunk from the maps (the leaves never all held),
/// part after part, the colour regions as streams. `None` for other files (a
/// legacy colour list, free space or log-odds: read whole).
fn streamed(path: &std::path::Path) -> Result<Option<(Info, Option<BBox>)>> {
    use tesseral::io::TessFile;
    use tesseral::partition::{is_dataset, open_part, read_manifest};
    if super::output::is_stdio(path) {
        return Ok(None);
    }
    let dataset = is_dataset(path);
    let (files, frame) = if dataset {
        let m = read_manifest(path)?;
        let mut files = Vec::with_capacity(m.parts.len());
        for i in 0..m.parts.len() {
            files.push(open_part(path, &m, i)?);
        }
        let frame = tesseral::model::Frame::new(m.frame.voxel_size, m.frame.translate);
        (files, frame)
    } else if path.is_file() && tesseral::io::extension(path) == "tess" {
        let f = TessFile::open_streaming(path)?;
        let frame = f.frame();
        (vec![f], frame)
    } else {
        return Ok(None);
    };
    let mut colours = Vec::new();
    for f in &files {
        let streams = if f.has_layers() {
            f.colour_streams()?
        } else {
            Some(Vec::new())
        };
        let (true, Some(streams)) = (f.is_streamed(), streams) else {
            return Ok(None);
        };
        colours.extend(streams);
    }
    let Some(f) = files.first() else {
        return Ok(None);
    };
    let (depth, origin) = (f.depth(), f.origin());
    let space = tesseral::linear::LinearOctree::empty(depth, origin)?;
    let mut by_depth = vec![0u64; usize::from(depth) + 1];
    let (mut voxels, mut leaves) = (0u64, 0usize);
    let mut bbox: Option<BBox> = None;
    for l in files.iter().flat_map(|f| f.leaves()) {
        let l = l?;
        leaves += 1;
        voxels += l.voxel_count();
        by_depth[usize::from(depth - l.size_log2())] += 1;
        let lo = space.voxel_of(l.code());
        let hi = lo.map(|c| c + (1i64 << l.size_log2()) - 1);
        bbox = Some(match bbox {
            None => (lo, hi),
            Some((a, b)) => (
                [0, 1, 2].map(|i| a[i].min(lo[i])),
                [0, 1, 2].map(|i| b[i].max(hi[i])),
            ),
        });
    }
    let mut distinct: Vec<tesseral::model::Rgba> = colours.iter().map(|(c, _)| *c).collect();
    distinct.sort_unstable();
    distinct.dedup();
    let n_colours = distinct.len();
    let mut colored_voxels = 0u64;
    for (_, region) in colours {
        for l in region {
            colored_voxels += l?.voxel_count();
        }
    }
    let info = Info {
        voxels,
        leaves,
        depth,
        origin,
        bbox_min: bbox.map(|b| b.0),
        bbox_max: bbox.map(|b| b.1),
        leaves_by_depth: by_depth,
        bytes: 8 * leaves as u64,
        voxel_size: frame.voxel_size,
        translate: frame.translate,
        world_min: bbox.map(|b| frame.voxel_corner(b.0)),
        world_max: bbox.map(|b| frame.voxel_corner(b.1.map(|c| c + 1))),
        // As the in-memory model says: a file's colour layer even when empty, a
        // dataset's joined layer only when some part has a colour.
        colors: (n_colours > 0 || (!dataset && files[0].has_layers())).then_some(n_colours),
        colored_voxels,
        free_voxels: None,
        free_leaves: None,
        log_odds: false,
        streamed: true,
    };
    Ok(Some((info, bbox)))
}

pub fn run(args: Args) -> Result<()> {
    if !(args.tree || args.codes) {
        if let Some(done) = super::info_wide::run_if_wide(&args.file, args.json) {
            return done;
        }
    }
    if !(args.tree || args.codes) {
        if let Some((info, bbox)) = streamed(&args.file)? {
            return print(&args, &info, bbox);
        }
    }
    super::streamed::check_version_1_in_memory(&args.file, &args.budget)?;
    let model = octree::read_model(&args.file, &args.budget, &Default::default())?;
    let tree = &model.tree;
    if args.tree || args.codes {
        return notation(&args, tree);
    }
    let bbox = tree.bbox();
    let frame = model.frame;
    let info = Info {
        voxels: tree.voxel_count(),
        leaves: tree.leaf_count(),
        depth: tree.depth(),
        origin: tree.origin(),
        bbox_min: bbox.map(|b| b.0),
        bbox_max: bbox.map(|b| b.1),
        leaves_by_depth: tree.leaves_by_depth(),
        bytes: 8 * tree.leaf_count() as u64,
        voxel_size: frame.voxel_size,
        translate: frame.translate,
        world_min: bbox.map(|b| frame.voxel_corner(b.0)),
        world_max: bbox.map(|b| frame.voxel_corner(b.1.map(|c| c + 1))),
        colors: model.colors.as_ref().map(|c| c.region_count()),
        colored_voxels: model.colors.as_ref().map_or(0, |c| c.voxel_count()),
        free_voxels: model.free.as_ref().map(|f| f.voxel_count()),
        free_leaves: model.free.as_ref().map(|f| f.leaf_count()),
        log_odds: model.log_odds.is_some(),
        streamed: false,
    };
    print(&args, &info, bbox)
}

/// A world coordinate for people: rounded to 12 significant digits, so that a
/// product such as 14 × 0.1 prints as 1.4, not 1.4000000000000001 (`--json` keeps
/// the exact value).
fn short(x: f64) -> f64 {
    format!("{x:.11e}").parse().unwrap_or(x)
}

fn print(args: &Args, info: &Info, bbox: Option<BBox>) -> Result<()> {
    let frame = tesseral::model::Frame::new(info.voxel_size, info.translate);
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
    crate::outln!("frame    {}", frame)?;
    if let (Some(lo), Some(hi)) = (info.world_min, info.world_max) {
        crate::outln!(
            "world    ({}, {}, {}) to ({}, {}, {})",
            short(lo[0]),
            short(lo[1]),
            short(lo[2]),
            short(hi[0]),
            short(hi[1]),
            short(hi[2])
        )?;
    }
    if let Some(n) = info.colors {
        crate::outln!("colours  {n} distinct on {} voxels", info.colored_voxels)?;
    }
    if let (Some(v), Some(l)) = (info.free_voxels, info.free_leaves) {
        crate::outln!("free     {v} voxels in {l} leaves")?;
    }
    if info.log_odds {
        crate::outln!("log-odds stored per known voxel")?;
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

#[cfg(test)]
mod tests {
    use super::short;

    #[test]
    fn world_coordinates_print_without_float_noise() {
        assert_eq!(short(14.0 * 0.1).to_string(), "1.4");
        assert_eq!(short(-39.0 * 0.1).to_string(), "-3.9");
        assert_eq!(short(0.7000000000000001).to_string(), "0.7");
        // Twelve significant digits kept, tiny and huge values untouched in kind.
        assert_eq!(short(1234.56789012345).to_string(), "1234.56789012");
        assert_eq!(short(2.5e-7).to_string(), "0.00000025");
        assert_eq!(short(-0.0).to_string(), "-0");
        assert!(short(f64::NAN).is_nan());
        assert_eq!(short(f64::INFINITY), f64::INFINITY);
    }
}
