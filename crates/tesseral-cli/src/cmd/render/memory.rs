//! `render`'s memory, checked against `--memory` before it draws: the program, the
//! tree (streamed: the cache as far as the file fills it; in memory: the leaves and
//! their ray index) and the picture.

use std::path::Path;

use anyhow::Result;
use tesseral::render::RenderOptions;

use super::super::budget::Budget;

/// The program, its threads and a streamed file's index (measured: 7.8 MB for a
/// 5-level file).
pub(super) const PROCESS_BYTES: u64 = 12 << 20;

/// A pixel of the picture while it is drawn and written (measured: 5.9 bytes at
/// 2000 × 1500).
pub(super) const PIXEL_BYTES: u64 = 8;

/// A leaf of a tree drawn in memory, read from a file: the leaves, their colours,
/// the ray index and the reader's buffers (measured: 55 bytes for the depth-11
/// spheroid, 38 for the depth-12 one; a margin above the larger).
pub(super) const FILE_BYTES_PER_LEAF: u64 = 64;

/// A leaf of a scene built and drawn in memory (measured: 33 bytes for the
/// showcase at depth 10, 1.69 M leaves, with its colours; a margin above).
pub(super) const SCENE_BYTES_PER_LEAF: u64 = 36;

/// The pixels of a view of `opts`' size, or of a sheet of four (two by two, with
/// the gaps of `render::contact_sheet`, and one view while it is drawn).
pub(super) fn picture_pixels(opts: &RenderOptions, sheet: bool) -> u64 {
    let (w, h) = (opts.width as u64, opts.height as u64);
    if sheet {
        (2 * w + 12) * (2 * h + 12) + w * h
    } else {
        w * h
    }
}

/// The pixels of a slice of a tree `side` voxels across, `scale` pixels a voxel
/// (within `MAX_SIDE` a side, checked before).
pub(super) fn slice_pixels(side: u64, scale: usize) -> u64 {
    side.saturating_mul(scale as u64).saturating_pow(2)
}

/// Refuses a drawing of `input` holding `tree` bytes and a picture of `pixels`
/// pixels, with the program, over `--memory` (`hint` ends the message).
pub(super) fn check_drawing(
    input: &Path,
    budget: &Budget,
    tree: u64,
    pixels: u64,
    hint: &str,
) -> Result<()> {
    let bytes = PROCESS_BYTES
        .saturating_add(tree)
        .saturating_add(pixels.saturating_mul(PIXEL_BYTES));
    budget.check_memory(&format!("rendering {}", input.display()), bytes, hint)
}
