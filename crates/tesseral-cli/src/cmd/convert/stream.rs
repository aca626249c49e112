//! The streamed paths of `convert` from a `.tess` file or a dataset: into a `.tess`
//! file (`partition::stream_concat`) and into an `.xyz` voxel list
//! (`partition::write_xyz`, after a counting pass), a chunk at a time; and the
//! `--memory` check of the in-memory path for those inputs.

use std::path::Path;

use anyhow::Result;
use tesseral::io;

use super::super::budget::Budget;
use super::super::output;
use super::super::streamed::{self, Operand};
use super::Args;

/// Memory a streamed `convert` holds whatever the input's size: the program, two
/// decoded chunks and the writer's, and a spool buffer per colour.
pub fn stream_memory(colours: usize) -> u64 {
    let chunk = io::DEFAULT_CHUNK_LEAVES as u64 * 8;
    let spool = (1 << 14) * 8 + (8 << 10);
    (48 << 20) + 4 * chunk + colours as u64 * spool
}

/// The colour regions of an operand (each file's, counted once per colour).
fn colour_count(op: &Operand) -> Result<usize> {
    let mut seen = Vec::new();
    for f in &op.files {
        for (c, _) in f.colour_leaves()?.unwrap_or_default() {
            if !seen.contains(&c) {
                seen.push(c);
            }
        }
    }
    Ok(seen.len())
}

/// The voxels of the input's colour regions.
fn colour_voxels(op: &Operand) -> Result<u64> {
    let mut n = 0u64;
    for f in &op.files {
        for (_, region) in f.colour_leaves()?.unwrap_or_default() {
            for l in region {
                n += l?.voxel_count();
            }
        }
    }
    Ok(n)
}

/// Opens the input for streaming when it is a `.tess` file or a dataset whose
/// only layer is colours, after checking the streamed memory against `--memory`;
/// `None` (read it in memory) otherwise.
pub fn open(args: &Args) -> Result<Option<(Operand, usize)>> {
    let input = &args.input;
    // A version-1 file streams too: its payload is indexed in one pass.
    let Some(op) = streamed::open_operand(input)? else {
        return Ok(None);
    };
    if !op.colours_only()? {
        return Ok(None);
    }
    let colours = colour_count(&op)?;
    args.budget.check_memory(
        &format!("converting {} streamed", args.input.display()),
        stream_memory(colours),
        "",
    )?;
    Ok(Some((op, colours)))
}

/// A `.tess` file (either version) or a dataset into a `.tess` file, chunk by
/// chunk with the colour regions as streams (`partition::stream_concat`): never
/// the whole tree in memory. `false` (nothing done) for other inputs and
/// outputs, and for files with layers other than colours.
pub fn to_tess(args: &Args, out: &Path) -> Result<bool> {
    if output::is_stdio(out) || io::extension(out) != "tess" {
        return Ok(false);
    }
    let input = &args.input;
    let is_tess = input.is_file() && io::extension(input) == "tess";
    if !(tesseral::partition::is_dataset(input) || is_tess) {
        return Ok(false);
    }
    let Some((op, _)) = open(args)? else {
        return Ok(false);
    };
    if op.files.iter().any(|f| !f.is_streamed()) {
        return Ok(false);
    }
    // The copy holds the same leaves and colours: about the inputs' size.
    output::check_size(out, op.bytes, args.limits.limits.max_output)?;
    let spool_dir = streamed::spool_dir(out);
    let mut summary = tesseral::partition::StreamSummary::default();
    streamed::with_leaf_progress("converting", &[&op.files[..]], || {
        io::write_atomic(out, |w| {
            summary = tesseral::partition::stream_concat(&op.files, op.frame, w, &spool_dir)
                .map_err(std::io::Error::other)?;
            Ok(())
        })
    })
    .map_err(|e| anyhow::anyhow!("writing {}: {e}", out.display()))?;
    if args.json {
        let (depth, origin) = op.space();
        // The report's bounding box and coloured voxels: one more pass over the
        // input, only when asked.
        let facts = tesseral::partition::leaf_facts(&op.files)?;
        let colours = summary.colours;
        let summary = serde_json::json!({
            "input": args.input,
            "output": out,
            "voxels": summary.voxels,
            "leaves": summary.leaves,
            "depth": depth,
            "origin": origin,
            "bbox_min": facts.bbox.map(|b| b.0),
            "bbox_max": facts.bbox.map(|b| b.1),
            "voxel_size": op.frame.voxel_size,
            "translate": op.frame.translate,
            "colors": (colours > 0).then_some(colours),
            "colored_voxels": if colours > 0 { Some(colour_voxels(&op)?) } else { None },
            "streamed": true,
        });
        crate::outln!("{summary}")?;
    }
    Ok(true)
}

/// A `.tess` file (either version) or a dataset into an `.xyz` voxel list (or `-o - --format
/// xyz`): one pass counts the voxels and the bounding box (for the header and the
/// `--max-output` check, before anything is written), a second writes the voxels
/// a chunk at a time. The bytes of the in-memory path. `false` for other inputs
/// and outputs.
pub fn to_xyz(args: &Args, out: &Path) -> Result<bool> {
    if args.limits.format_of(out) != "xyz" {
        return Ok(false);
    }
    let Some((op, colours)) = open(args)? else {
        return Ok(false);
    };
    let facts = tesseral::partition::leaf_facts(&op.files)?;
    let estimate = io::estimate_xyz_bytes(facts.voxels, facts.bbox);
    output::check_size(out, estimate, args.limits.limits.max_output)?;
    let write =
        |w: &mut dyn std::io::Write| tesseral::partition::write_xyz(&op.files, facts.voxels, w);
    if output::is_stdio(out) {
        let mut w = std::io::BufWriter::new(std::io::stdout().lock());
        write(&mut w).map_err(|e| anyhow::Error::new(e).context("writing <stdout>"))?;
        std::io::Write::flush(&mut w)?;
        return Ok(true);
    }
    let mut failure = None;
    let written = output::with_progress(estimate, || {
        io::write_atomic(out, |w| {
            write(w).map_err(|e| {
                failure = Some(e);
                std::io::Error::other("stopped")
            })
        })
    });
    if let Some(e) = failure {
        anyhow::bail!(
            "converting {} into {}: {e}",
            args.input.display(),
            out.display()
        );
    }
    written.map_err(|e| anyhow::anyhow!("{e}"))?;
    if args.json {
        let (depth, origin) = op.space();
        let summary = serde_json::json!({
            "input": args.input,
            "output": out,
            "voxels": facts.voxels,
            "leaves": facts.leaves,
            "depth": depth,
            "origin": origin,
            "bbox_min": facts.bbox.map(|b| b.0),
            "bbox_max": facts.bbox.map(|b| b.1),
            "voxel_size": op.frame.voxel_size,
            "translate": op.frame.translate,
            "colors": (colours > 0).then_some(colours),
            "colored_voxels": if colours > 0 { Some(colour_voxels(&op)?) } else { None },
            "free_voxels": null,
            "streamed": true,
        });
        crate::outln!("{summary}")?;
    }
    Ok(true)
}

/// Before an in-memory conversion of a `.tess` file or a dataset: its leaves
/// against `budget` (the model and the writing of the output; a version-1 file by
/// its size, as the streamed paths count it), with the outputs that stream named.
pub fn check_in_memory(args: &Args, budget: &Budget) -> Result<()> {
    let input = &args.input;
    let Some(leaves) = streamed::leaves_on_disk(input)? else {
        return Ok(());
    };
    budget
        .check_leaves(&format!("reading {} whole", input.display()), leaves)
        .map_err(|e| {
            anyhow::anyhow!(
                "{e} (or convert it into a .tess, .xyz or a dataset with --parts, which stream)"
            )
        })
}
