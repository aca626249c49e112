//! `tesseral convert IN -o DIR --parts K`: a partitioned dataset (the layout and
//! manifest of `build --parts`) of K parts with about equal leaf counts.
//!
//! From a `.tess` file (either version) or a dataset it streams
//! (`partition::leaf_ranges` from the chunk index, then `partition::stream_dataset`
//! a chunk at a time); any other input is read whole and cut in memory
//! (`partition::balanced_ranges_of`, `partition::split_model`). Either way the
//! dataset is written into a new hidden directory beside DIR (`.DIR.…tmp`) and
//! renamed into place at the end; an old dataset at DIR is renamed aside first and
//! removed after, so a reader sees the old dataset or the new one, never a mix.
//! Staged directories of killed writers of DIR are removed first
//! (`streamed::stage_dataset`).

use std::path::Path;

use anyhow::{bail, Context, Result};
use tesseral::io::ReadOptions;
use tesseral::partition::{self, ManifestPart};

use super::super::{octree, output};
use super::Args;

/// Refuses an output directory that is an input, holds an input, or holds
/// anything but a dataset's files.
fn guard(dir: &Path, input: &Path) -> Result<()> {
    if output::is_stdio(dir) {
        bail!("--parts writes a dataset directory, not standard output (-o -)");
    }
    if output::same_file(dir, input) {
        bail!(
            "--output {}: this is the input {}; refusing to overwrite an input (write to another name)",
            dir.display(),
            input.display()
        );
    }
    if let (Ok(d), Ok(i)) = (dir.canonicalize(), input.canonicalize()) {
        if i.starts_with(&d) {
            bail!(
                "--output {}: holds the input {}; refusing to overwrite an input (write to another name)",
                dir.display(),
                input.display()
            );
        }
    }
    if dir.exists() && !partition::is_dataset(dir) {
        let empty = dir.is_dir() && std::fs::read_dir(dir)?.next().is_none();
        if !empty {
            bail!(
                "--output {}: exists and is not a dataset directory (no manifest.json); give a new or empty directory",
                dir.display()
            );
        }
    }
    Ok(())
}

/// Writes `args.input` as a dataset of `k` parts in `dir`.
pub fn run(args: &Args, dir: &Path, k: usize, read: &ReadOptions) -> Result<()> {
    if k == 0 {
        bail!("--parts 0: give at least one part");
    }
    guard(dir, &args.input)?;
    let streamed = super::stream::open(args)?;
    // The staging directory is made once the input is read and the budgets are
    // checked.
    let (parts, space, frame) = match &streamed {
        Some((op, _)) => {
            // The parts hold the same leaves and colours: about the input's size,
            // plus a header, a frame and a trailer a part.
            let estimate = op.bytes.saturating_add(k as u64 * 256);
            output::check_size(dir, estimate, args.limits.limits.max_output)?;
            let ranges = partition::leaf_ranges(&op.files, k)?;
            let staged = super::super::streamed::stage_dataset(dir)?;
            let parts =
                super::super::streamed::with_leaf_progress("cutting", &[&op.files[..]], || {
                    partition::stream_dataset(&op.files, op.frame, &ranges, staged.path())
                })
                .with_context(|| format!("writing {}", dir.display()))?;
            staged.commit(dir)?;
            (parts, op.space(), op.frame)
        }
        None => {
            super::stream::check_in_memory(args, &args.budget)?;
            let model = octree::read_model(&args.input, &args.budget, read)?;
            let tree = &model.tree;
            let tess = tesseral::io::estimate_output_bytes(tree, "tess").unwrap_or(0);
            output::check_size(dir, tess.saturating_mul(2), args.limits.limits.max_output)?;
            let ranges = partition::balanced_ranges_of(tree, k);
            let cut = partition::split_model(&model, &ranges)
                .with_context(|| format!("cutting {} into parts", args.input.display()))?;
            let staged = super::super::streamed::stage_dataset(dir)?;
            let mut parts = Vec::with_capacity(ranges.len());
            for (i, (p, m)) in ranges.iter().zip(&cut).enumerate() {
                parts.push(partition::write_model_part(staged.path(), i, *p, m)?);
            }
            partition::write_manifest(
                staged.path(),
                tree.depth(),
                tree.origin(),
                model.frame,
                &parts,
            )?;
            staged.commit(dir)?;
            (parts, (tree.depth(), tree.origin()), model.frame)
        }
    };
    if args.json {
        report(args, dir, &parts, space, frame, streamed.is_some())?;
    }
    Ok(())
}

fn report(
    args: &Args,
    dir: &Path,
    parts: &[ManifestPart],
    (depth, origin): (u8, [i64; 3]),
    frame: tesseral::model::Frame,
    streamed: bool,
) -> Result<()> {
    let v = serde_json::json!({
        "input": args.input,
        "output": dir,
        "parts": parts.len(),
        "leaves": parts.iter().map(|p| p.leaves).sum::<u64>(),
        "voxels": parts.iter().map(|p| p.voxels).sum::<u64>(),
        "part_leaves": parts.iter().map(|p| p.leaves).collect::<Vec<_>>(),
        "depth": depth,
        "origin": origin,
        "voxel_size": frame.voxel_size,
        "translate": frame.translate,
        "streamed": streamed,
    });
    crate::outln!("{v}")?;
    Ok(())
}
