//! The drawings of a [`StreamedTree`]: a view (with or without a cross-section), a
//! contact sheet and a slice, each the in-memory drawing's image byte for byte,
//! reading only the chunks its rays or its layer reach. A cross-section crops the
//! tree node by node as the rays reach it ([`Clipped`]), so the chunks wholly on
//! the removed side are never read.

use super::super::clipped::Clipped;
use super::super::cut::Cut;
use super::super::trace::contains;
use super::super::{render_cut, section_of, sheet_of, Image, RenderOptions, Surface, View};
use super::StreamedTree;
use crate::io::FormatError;

/// Renders a [`StreamedTree`] as [`super::super::render`] renders the whole tree,
/// cross-section (`opts.clip`) included, reading only the chunks the rays reach.
/// The image equals the in-memory render's.
///
/// # Errors
/// The first damaged chunk or colour block met, naming the file and the chunk.
///
/// # Runtime
/// As [`super::super::render`], plus decoding the chunks reached (again when
/// evicted).
pub fn render_streamed(
    tree: &StreamedTree,
    surface: Surface<'_>,
    opts: &RenderOptions,
) -> Result<Image, FormatError> {
    let img = tree.on_threads(|| match opts.clip {
        None => render_cut(tree, surface, opts, None),
        Some(clip) => {
            let kept = Clipped::new(tree, clip);
            let original = |v| contains(tree, v);
            let cut = Cut {
                clip,
                original: &original,
            };
            render_cut(&kept, surface, opts, Some(cut))
        }
    });
    tree.take_error().map_or(Ok(img), Err)
}

/// [`super::super::contact_sheet`] of a [`StreamedTree`], cross-section
/// (`opts.clip`) included; the image equals the in-memory sheet's.
///
/// # Errors
/// As [`render_streamed`].
pub fn contact_sheet_streamed(
    tree: &StreamedTree,
    surface: Surface<'_>,
    opts: &RenderOptions,
    views: &[View],
    columns: usize,
) -> Result<Image, FormatError> {
    let img = tree.on_threads(|| match opts.clip {
        None => sheet_of(tree, None, surface, opts, views, columns),
        Some(clip) => {
            let kept = Clipped::new(tree, clip);
            let original = |v| contains(tree, v);
            let cut = Cut {
                clip,
                original: &original,
            };
            sheet_of(&kept, Some(cut), surface, opts, views, columns)
        }
    });
    tree.take_error().map_or(Ok(img), Err)
}

/// [`super::super::section`] of a [`StreamedTree`]: reads only the chunks the layer
/// crosses; the image equals the in-memory slice's.
///
/// # Errors
/// As [`render_streamed`].
///
/// # Runtime
/// O(side² × pixels²) for the image, plus the blocks the layer crosses.
pub fn section_streamed(
    tree: &StreamedTree,
    surface: Surface<'_>,
    axis: usize,
    at: i64,
    pixels: usize,
) -> Result<Image, FormatError> {
    let img = tree.on_threads(|| section_of(tree, surface, axis, at, pixels));
    tree.take_error().map_or(Ok(img), Err)
}
