//! `tesseral rotate --degrees` and `tesseral transform`: any rotation or affine map of
//! an octree, by point sampling, with the fragmentation it causes reported
//! (Ahuja & Nash Fig. 5).

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use tesseral::linear::{invert_matrix, rotation_matrix};
use tesseral::model::Model;

use super::octree;

/// An axis of rotation: `x`, `y`, `z` or a vector `X,Y,Z`.
pub fn parse_axis(text: &str) -> Result<[f64; 3], String> {
    match text.trim() {
        "x" | "X" => return Ok([1.0, 0.0, 0.0]),
        "y" | "Y" => return Ok([0.0, 1.0, 0.0]),
        "z" | "Z" => return Ok([0.0, 0.0, 1.0]),
        _ => {}
    }
    let v =
        parse_world_vector(text).map_err(|e| format!("expected x, y, z or a vector X,Y,Z: {e}"))?;
    if v.iter().all(|&c| c == 0.0) {
        return Err("the zero vector has no direction".into());
    }
    Ok(v)
}

/// Three finite numbers `X,Y,Z`.
pub fn parse_world_vector(text: &str) -> Result<[f64; 3], String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(format!("expected three numbers `X,Y,Z`, got `{text}`"));
    }
    let mut v = [0.0; 3];
    for (a, p) in parts.iter().enumerate() {
        v[a] = p
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("`{p}` is not a finite number (in `{text}`)"))?;
    }
    Ok(v)
}

/// A 3 × 3 matrix written by rows: `"a b c; d e f; g h i"`.
fn parse_matrix(text: &str) -> Result<[[f64; 3]; 3], String> {
    let rows: Vec<&str> = text.split(';').collect();
    if rows.len() != 3 {
        return Err(format!(
            "expected three rows separated by `;`, got {} in `{text}`",
            rows.len()
        ));
    }
    let mut m = [[0.0; 3]; 3];
    for (i, row) in rows.iter().enumerate() {
        let cells: Vec<&str> = row
            .split([' ', ',', '\t'])
            .filter(|c| !c.is_empty())
            .collect();
        if cells.len() != 3 {
            return Err(format!(
                "row {} `{}` does not hold three numbers",
                i + 1,
                row.trim()
            ));
        }
        for (j, c) in cells.iter().enumerate() {
            m[i][j] = c
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("row {}: `{c}` is not a finite number", i + 1))?;
        }
    }
    Ok(m)
}

/// The fragmentation report: leaves before and after, and with `roundtrip` the
/// voxels lost and gained by the inverse map.
fn fragmentation(before: &Model, after: &Model, back: Option<Model>) -> Result<serde_json::Value> {
    let mut v = serde_json::json!({
        "leaves_before": before.tree.leaf_count(),
        "leaves_after": after.tree.leaf_count(),
        "voxels_before": before.tree.voxel_count(),
    });
    if let Some(back) = back {
        let lost = before.tree.difference(&back.tree)?.voxel_count();
        let gained = back.tree.difference(&before.tree)?.voxel_count();
        v["roundtrip_lost"] = lost.into();
        v["roundtrip_gained"] = gained.into();
    }
    Ok(v)
}

fn note(extra: &serde_json::Value) {
    let mut line = format!(
        "fragmentation: {} leaves before, {} after",
        extra["leaves_before"], extra["leaves_after"]
    );
    if !extra["roundtrip_lost"].is_null() {
        line += &format!(
            "; mapped back: {} voxels lost, {} gained (of {})",
            extra["roundtrip_lost"], extra["roundtrip_gained"], extra["voxels_before"]
        );
    }
    eprintln!("{line}");
}

/// `rotate --degrees`: any angle about any axis through `about` (world units).
pub fn rotate_degrees(
    model: &Model,
    axis: [f64; 3],
    degrees: f64,
    about: Option<[f64; 3]>,
    roundtrip: bool,
) -> Result<(Model, serde_json::Value)> {
    let about = about.unwrap_or_else(|| model.bbox_centre());
    let m = rotation_matrix(axis, degrees);
    let out = model
        .rotate_about(m, about)
        .with_context(|| format!("rotating by {degrees}°"))?;
    let back = roundtrip
        .then(|| out.rotate_about(rotation_matrix(axis, -degrees), about))
        .transpose()?;
    let mut extra = fragmentation(model, &out, back)?;
    extra["degrees"] = degrees.into();
    extra["axis_vector"] = serde_json::json!(axis);
    extra["about"] = serde_json::json!(about);
    Ok((out, extra))
}

/// Prints the fragmentation note on stderr (text mode), for `rotate --degrees`.
pub fn report_fragmentation(extra: &serde_json::Value, json: bool) {
    if !json {
        note(extra);
    }
}

/// Arguments of `tesseral transform`.
#[derive(clap::Args)]
pub struct TransformArgs {
    /// The input octree file or scene.
    input: PathBuf,
    /// The matrix M of the world map x ↦ M·x + offset, by rows: "a b c; d e f; g h i".
    #[arg(long, value_parser = parse_matrix, allow_hyphen_values = true)]
    matrix: [[f64; 3]; 3],
    /// The offset X,Y,Z in world units.
    #[arg(long, value_parser = parse_world_vector, allow_hyphen_values = true, default_value = "0,0,0")]
    offset: [f64; 3],
    /// Also map the result back by the inverse and report the voxels lost and gained.
    #[arg(long)]
    roundtrip: bool,
    /// The output octree file.
    #[arg(short, long)]
    output: PathBuf,
    /// Print JSON: output, voxels, leaves, depth, origin, bbox_min, bbox_max,
    /// leaves_before, leaves_after, voxels_before, roundtrip_lost and roundtrip_gained
    /// (with --roundtrip), matrix, offset.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    limits: octree::OutArgs,
}

/// The inverse of an affine world map, for `--roundtrip`.
fn inverse_map(m: [[f64; 3]; 3], offset: [f64; 3]) -> Result<([[f64; 3]; 3], [f64; 3])> {
    let Some(inv) = invert_matrix(m) else {
        bail!("--matrix is singular or not finite");
    };
    let t = std::array::from_fn(|i| -(0..3).map(|j| inv[i][j] * offset[j]).sum::<f64>());
    Ok((inv, t))
}

pub fn transform(args: TransformArgs) -> Result<()> {
    octree::guard(&args.output, &[&args.input], &args.limits)?;
    let model = octree::read(&args.input)?;
    let (inv, inv_offset) = inverse_map(args.matrix, args.offset)?;
    let out = model
        .affine_world(args.matrix, args.offset)
        .context("transforming")?;
    let back = args
        .roundtrip
        .then(|| out.affine_world(inv, inv_offset))
        .transpose()?;
    let mut extra = fragmentation(&model, &out, back)?;
    extra["matrix"] = serde_json::json!(args.matrix);
    extra["offset"] = serde_json::json!(args.offset);
    report_fragmentation(&extra, args.json);
    octree::write(
        &args.output,
        &out,
        &args.limits,
        octree::Report {
            json: args.json,
            extra,
        },
    )
}
