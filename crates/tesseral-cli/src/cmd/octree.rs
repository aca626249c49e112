//! Helpers shared by the octree commands: reading and writing through
//! `tesseral::io`, and parsing of vectors and axes.

use std::path::Path;

use anyhow::Result;
use tesseral::linear::Axis;
use tesseral::model::Model;

use super::budget::Budget;
use super::output::{self, Limits};

/// Reads a model: a `.tss` scene is built within `budget` with its frame (the
/// scene's voxel size and lower corner) and its objects' colours; any other file is
/// read in the format its extension names, with what the format carries.
pub fn read_model(
    path: &Path,
    budget: &Budget,
    options: &tesseral::io::ReadOptions,
) -> Result<Model> {
    if tesseral::io::extension(path) == "tss" {
        return budget.build_scene_model(path);
    }
    // The library's message already names the file and its cause; keep it as one
    // line rather than repeating the cause from the error chain.
    tesseral::io::read_model_with(path, options).map_err(|e| anyhow::anyhow!("{e}"))
}

/// Reads a model from an octree file (any format `tesseral::io` knows by the
/// extension) or a `.tss` scene, with the default budget.
pub fn read(path: &Path) -> Result<Model> {
    read_model(path, &Budget::default(), &Default::default())
}

/// Checks an octree output before any work: a format we write, and not an input.
pub fn guard(output: &Path, inputs: &[&Path]) -> Result<()> {
    output::guard("--output", output, &output::octree_formats(), inputs)
}

/// How a command that writes an octree reports: a line of text, or with `--json` an
/// object with the keys `output`, `voxels`, `leaves`, `depth`, `origin`, `bbox_min`,
/// `bbox_max` (null when empty), plus the command's own keys in `extra`.
pub struct Report {
    /// Print JSON instead of text.
    pub json: bool,
    /// The command's own keys (a JSON object), added to the JSON output.
    pub extra: serde_json::Value,
}

/// Writes a model atomically, in the format named by the extension, and reports it
/// (see [`Report`]; JSON also has `voxel_size` and `translate`, the frame). Refuses,
/// before writing, an output estimated above `--max-output`.
pub fn write(path: &Path, model: &Model, limits: &Limits, report: Report) -> Result<()> {
    let tree = &model.tree;
    let ext = tesseral::io::extension(path);
    if let Some(bytes) = tesseral::io::estimate_output_bytes(tree, &ext) {
        output::check_size(path, bytes, limits.max_output)?;
    }
    tesseral::io::write_model(path, model).map_err(|e| anyhow::anyhow!("{e}"))?;
    if report.json {
        let bbox = tree.bbox();
        let mut v = serde_json::json!({
            "output": path,
            "voxels": tree.voxel_count(),
            "leaves": tree.leaf_count(),
            "depth": tree.depth(),
            "origin": tree.origin(),
            "bbox_min": bbox.map(|b| b.0),
            "bbox_max": bbox.map(|b| b.1),
            "voxel_size": model.frame.voxel_size,
            "translate": model.frame.translate,
        });
        if let (Some(map), serde_json::Value::Object(extra)) = (v.as_object_mut(), report.extra) {
            map.extend(extra);
        }
        crate::outln!("{v}")?;
        return Ok(());
    }
    let frame = if model.frame.is_unit() {
        String::new()
    } else {
        format!(", {}", model.frame)
    };
    crate::outln!(
        "wrote {}: {} voxels, {} leaves, depth {}, origin {}{frame}",
        path.display(),
        tree.voxel_count(),
        tree.leaf_count(),
        tree.depth(),
        fmt_voxel(tree.origin())
    )?;
    Ok(())
}

/// `(x, y, z)`.
pub fn fmt_voxel(v: [i64; 3]) -> String {
    format!("({}, {}, {})", v[0], v[1], v[2])
}

/// Parses `DX,DY,DZ` (integers, negative allowed).
pub fn parse_vector(text: &str) -> Result<[i64; 3], String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(format!("expected three integers `DX,DY,DZ`, got `{text}`"));
    }
    let mut v = [0i64; 3];
    for (a, p) in parts.iter().enumerate() {
        v[a] = p
            .parse()
            .map_err(|_| format!("`{p}` is not an integer (in `{text}`)"))?;
    }
    Ok(v)
}

/// An axis on the command line.
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum AxisArg {
    /// x, east.
    X,
    /// y, north.
    Y,
    /// z, up.
    Z,
}

impl From<AxisArg> for Axis {
    fn from(a: AxisArg) -> Self {
        match a {
            AxisArg::X => Axis::X,
            AxisArg::Y => Axis::Y,
            AxisArg::Z => Axis::Z,
        }
    }
}

/// Parses a scale factor `2^K` (K may be negative) into K.
pub fn parse_power_of_two(text: &str) -> Result<i32, String> {
    let t = text.trim();
    if let Some(k) = t.strip_prefix("2^") {
        let k: i32 = k
            .trim_start_matches(['(', ' '])
            .trim_end_matches([')', ' '])
            .parse()
            .map_err(|_| format!("`{t}`: the exponent is not an integer"))?;
        if k.unsigned_abs() > 21 {
            return Err(format!("`{t}`: the exponent must lie in -21..=21"));
        }
        return Ok(k);
    }
    match t.parse::<u64>() {
        Ok(n) if n.is_power_of_two() && n.trailing_zeros() <= 21 => Ok(n.trailing_zeros() as i32),
        _ => Err(format!(
            "`{t}` is not a power of two; write `2^K` (for example 2^3 or 2^-1)"
        )),
    }
}
