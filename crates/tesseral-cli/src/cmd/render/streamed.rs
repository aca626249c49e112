//! `tesseral render` of a `.tess` file (either version) or a dataset without loading it:
//! the rays (of a view, a cut or a contact sheet) or the layer (of a slice) read
//! only the chunks they reach (`tesseral::render::StreamedTree`).

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result};
use tesseral::io::{FormatError, TessFile};
use tesseral::render::{self, Clip, RenderOptions, StreamedTree, View};

use super::super::budget::Budget;
use super::super::output;
use super::memory::{check_drawing, picture_pixels, slice_pixels, PIXEL_BYTES, PROCESS_BYTES};

/// The decoded chunks and colour blocks kept: a quarter of `--memory`, between
/// 16 MiB and 1 GiB (the rest of a streamed render is the image and the index).
fn cache_bytes(budget: &Budget) -> u64 {
    (budget.memory / 4).clamp(16 << 20, 1 << 30)
}

/// What to draw.
pub(super) enum Mode {
    /// One view (with a cross-section when the options carry a clip).
    View,
    /// The four named views.
    Sheet,
    /// The layer `at` on `axis`, `scale` pixels per voxel.
    Slice { axis: usize, at: i64, scale: usize },
}

/// Where the picture goes.
pub(super) struct Out<'a> {
    pub(super) input: &'a Path,
    pub(super) output: &'a Path,
    pub(super) json: bool,
}

/// The world units of the input: (the side of a voxel, the corner of voxel 0).
type Units = (f64, [f64; 3]);

/// The cache's bytes a leaf when the whole tree is kept (measured: about 7 for the
/// depth-12 spheroid, colours included).
const KEPT_BYTES_PER_LEAF: u64 = 8;

/// Refuses, before any drawing, a streamed render of `tree` in `mode` whose memory
/// (the program, the cache as far as the tree fills it, the picture) is over
/// `--memory`. The cache keeps at least 16 MiB when the tree has that much, so a
/// budget below about 30M is refused for a large file.
pub(super) fn check_memory(
    input: &Path,
    tree: &StreamedTree,
    mode: &Mode,
    opts: &RenderOptions,
    budget: &Budget,
) -> Result<()> {
    let pixels = match *mode {
        Mode::View => picture_pixels(opts, false),
        Mode::Sheet => picture_pixels(opts, true),
        Mode::Slice { scale, .. } => slice_pixels(1 << tree.depth(), scale),
    };
    let kept = cache_bytes(budget).min(tree.leaf_count().saturating_mul(KEPT_BYTES_PER_LEAF));
    check_drawing(
        input,
        budget,
        kept,
        pixels,
        " (a streamed render keeps 16 MiB of decoded chunks when the file has that many)",
    )
}

/// What glibc's arenas may keep of a rendering thread's freed buffers beyond the
/// cache (measured: 12 MB for two threads rendering the depth-12 spheroid).
const ARENA_BYTES_PER_THREAD: u64 = 8 << 20;

/// Makes the allocator give freed blocks over 128 KiB back to the system at once,
/// when what it would otherwise keep could take a render of `pixels` pixels over
/// `--memory`.
///
/// glibc raises its mmap threshold to the largest block freed (up to 32 MiB), after
/// which each thread's arena keeps the decoding's freed buffers: 12 MB more resident
/// memory than the cache in a two-thread render of the depth-12 spheroid (26 MB
/// against 38 MB at `--memory 32M`). Fixing the thresholds turns that off, for about
/// a tenth more time under a small cache (munmap and page faults for each decoded
/// chunk), so it is done only when the budget is tight. Other allocators do not
/// need it.
fn return_freed_memory(budget: &Budget, pixels: u64) {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get() as u64);
    let loose = PROCESS_BYTES
        .saturating_add(cache_bytes(budget))
        .saturating_add(pixels.saturating_mul(PIXEL_BYTES))
        .saturating_add(threads.saturating_mul(ARENA_BYTES_PER_THREAD));
    if loose <= budget.memory {
        return;
    }
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: `mallopt` only sets allocator parameters; glibc allows it at any time.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 128 << 10);
        libc::mallopt(libc::M_TRIM_THRESHOLD, 128 << 10);
    }
}

/// The input opened for a streamed render, with its units, or `None` when it is
/// not a `.tess` file (either version) or a dataset, or carries layers other than
/// colours (a version-1 legacy colour list, free space, log-odds: then it is
/// loaded whole).
///
/// `pixels` is the picture's size, or `u64::MAX` when it is not known before the
/// file is opened (a slice): it decides whether the allocator is told to give freed
/// memory back ([`return_freed_memory`]).
pub(super) fn open(
    input: &Path,
    budget: &Budget,
    pixels: u64,
) -> Result<Option<(StreamedTree, Units)>> {
    if output::is_stdio(input) {
        return Ok(None);
    }
    return_freed_memory(budget, pixels);
    let cache = cache_bytes(budget);
    let units;
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
        units = (m.frame.voxel_size, m.frame.translate);
        StreamedTree::from_parts(files, ranges, cache)
    } else if tesseral::io::extension(input) == "tess" {
        // Either version: a version-1 payload is indexed in one pass and then read
        // stretch by stretch as a version-2 file's chunks are.
        let f = TessFile::open_streaming(input).map_err(|e| anyhow::anyhow!("{e}"))?;
        if !f.is_streamed() {
            return Ok(None);
        }
        units = (f.frame().voxel_size, f.frame().translate);
        let end = 1u64 << (3 * u32::from(f.depth()));
        StreamedTree::from_parts(vec![f], vec![(0, end)], cache)
    } else {
        return Ok(None);
    };
    match opened {
        Ok(t) => Ok(Some((t, units))),
        Err(e) if matches!(e.kind(), FormatError::Unsupported(_)) => Ok(None),
        Err(e) => Err(anyhow::anyhow!("{e}")),
    }
}

/// Says on standard error when the cut `clip` keeps none or all of the solid (an
/// empty picture alone looks like a failure), from the bounding box alone.
pub(super) fn note_cut(tree: &StreamedTree, clip: Clip, spec: &str) {
    let Some((lo, hi)) = tree.bbox() else { return };
    let a = clip.axis;
    // The bounding box is tight: voxels lie on both of its faces.
    let (none, all) = if clip.keep_above {
        (hi[a] < clip.boundary(), lo[a] >= clip.boundary())
    } else {
        (lo[a] >= clip.boundary(), hi[a] < clip.boundary())
    };
    if none {
        eprintln!("note: --cut '{spec}' keeps nothing of the solid; the picture is empty");
    } else if all {
        eprintln!("note: --cut '{spec}' keeps all of the solid (the plane does not cross it)");
    }
}

/// Draws `tree` with its stored colours (`solid` where it has none) and writes the
/// picture.
pub(super) fn draw(
    out: &Out<'_>,
    tree: &StreamedTree,
    mode: Mode,
    opts: &RenderOptions,
    solid: [u8; 3],
    started: Instant,
) -> Result<()> {
    let (input, out, json) = (out.input, out.output, out.json);
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
    let image = match mode {
        Mode::View => render::render_streamed(tree, surface, opts),
        Mode::Sheet => render::contact_sheet_streamed(tree, surface, opts, &View::ALL, 2),
        Mode::Slice { axis, at, scale } => render::section_streamed(tree, surface, axis, at, scale),
    }
    .map_err(|e| anyhow::anyhow!("{e}"))?;
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
            "threads": tree.threads(),
            "colour_blocks_decoded": s.colour_blocks_decoded,
            "load_ms": load_ms,
            "render_ms": render_ms,
        });
        crate::outln!("{j}")?;
    }
    Ok(())
}
