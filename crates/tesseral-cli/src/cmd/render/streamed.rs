//! `tesseral render` of a version-2 `.tess` file or a dataset without loading it:
//! the rays read only the chunks they reach (`tesseral::render::StreamedTree`).

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result};
use tesseral::io::{FormatError, TessFile};
use tesseral::render::{self, RenderOptions, StreamedTree};

use super::super::budget::Budget;
use super::super::output;

/// The decoded chunks and colour blocks kept: a quarter of `--memory`, between
/// 16 MiB and 1 GiB (the rest of a streamed render is the image and the index).
fn cache_bytes(budget: &Budget) -> u64 {
    (budget.memory / 4).clamp(16 << 20, 1 << 30)
}

/// The input opened for a streamed render, or `None` when it is not a version-2
/// `.tess` file or a dataset, or carries layers other than colours (then it is
/// loaded whole).
pub(super) fn open(input: &Path, budget: &Budget) -> Result<Option<StreamedTree>> {
    if output::is_stdio(input) {
        return Ok(None);
    }
    let cache = cache_bytes(budget);
    let opened = if tesseral::partition::is_dataset(input) {
        let m = tesseral::partition::read_manifest(input).map_err(|e| anyhow::anyhow!("{e}"))?;
        let mut files = Vec::with_capacity(m.parts.len());
        for i in 0..m.parts.len() {
            files.push(
                tesseral::partition::open_part(input, &m, i).map_err(|e| anyhow::anyhow!("{e}"))?,
            );
        }
        if files.is_empty() || files.iter().any(|f| !f.is_streamed()) {
            return Ok(None);
        }
        let ranges = m.parts.iter().map(|p| (p.lo, p.hi)).collect();
        StreamedTree::from_parts(files, ranges, cache)
    } else if tesseral::io::extension(input) == "tess" {
        if !TessFile::open(input)
            .map_err(|e| anyhow::anyhow!("{e}"))?
            .is_streamed()
        {
            return Ok(None);
        }
        StreamedTree::open(input, cache)
    } else {
        return Ok(None);
    };
    match opened {
        Ok(t) => Ok(Some(t)),
        Err(e) if matches!(e.kind(), FormatError::Unsupported(_)) => Ok(None),
        Err(e) => Err(anyhow::anyhow!("{e}")),
    }
}

/// Draws `tree` with its stored colours (`solid` where it has none) and writes the
/// picture.
pub(super) fn draw(
    input: &Path,
    out: &Path,
    json: bool,
    tree: &StreamedTree,
    opts: &RenderOptions,
    solid: [u8; 3],
    started: Instant,
) -> Result<()> {
    let load_ms = started.elapsed().as_secs_f64() * 1e3;
    let shader = |p: [f64; 3]| {
        tree.colour(p.map(|c| c.floor() as i64))
            .map_or(solid, |c| [c[0], c[1], c[2]])
    };
    let surface = render::Surface {
        colour: Some(&shader),
        normal: None,
    };
    let start = Instant::now();
    let image = render::render_streamed(tree, surface, opts).map_err(|e| anyhow::anyhow!("{e}"))?;
    let render_ms = start.elapsed().as_secs_f64() * 1e3;
    if output::is_stdio(out) {
        super::super::stdio::to_stdout("png", |p| {
            image.write_png(p).map_err(|e| anyhow::anyhow!("{e}"))
        })?;
    } else {
        image
            .write_png(out)
            .with_context(|| format!("writing {}", out.display()))?;
    }
    if json {
        let s = tree.stats();
        // Counting the voxels reads every chunk once, after the picture.
        let voxels = tree.voxel_count().map_err(|e| anyhow::anyhow!("{e}"))?;
        let j = serde_json::json!({
            "input": input,
            "output": out,
            "width": image.width,
            "height": image.height,
            "depth": tree.depth(),
            "leaves": tree.leaf_count(),
            "voxels": voxels,
            "rebuilt_from_scene": false,
            "streamed": true,
            "chunks": s.chunks,
            "chunks_decoded": s.chunks_decoded,
            "colour_blocks_decoded": s.colour_blocks_decoded,
            "load_ms": load_ms,
            "render_ms": render_ms,
        });
        crate::outln!("{j}")?;
    }
    Ok(())
}
