//! The interactive viewer: one self-contained HTML page (WebGL2) that casts rays
//! through the octree itself in a fragment shader, as [`crate::render`] does on the
//! CPU.
//!
//! - [`pack`]: the tree as a pointer-less array of `u32` entries (child mask and
//!   first-child index, or a palette index for a black leaf), breadth first, cut
//!   short to a coarser depth when a page budget asks for it.
//! - [`trace`]: the traversal the shader runs, in Rust, so that tests check the
//!   packing against the tree ([`crate::linear::LinearOctree::contains`] and
//!   [`crate::render::RayTree::cast`]).
//! - [`Page`]: the page itself: the entries and palette as base64 in a JSON block,
//!   the JavaScript and GLSL of `src/view/assets/` embedded at build time. Several
//!   trees make an animation, played with a time slider.
//!
//! The page's camera is the renderer's (named views, azimuth and elevation, the
//! bounding-sphere framing, orthographic or perspective), so its first frame
//! matches `tesseral render` from the same view. See `docs/view.md`.

pub mod pack;
mod page;
pub mod trace;

#[cfg(test)]
mod tests;

use std::collections::HashMap;

use crate::linear::{Leaf, LinearOctree};
use crate::model::{Layer, Rgba};

pub use pack::{PackedTree, MAX_ENTRIES};
pub use page::{Page, PageFrame, ENTRY_BYTES, PAGE_OVERHEAD};

/// What can go wrong making a page.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ViewError {
    /// Not even the tree's top level fits the entry budget.
    #[error("the packed tree needs {entries} entries, more than the budget of {limit}")]
    TooLarge {
        /// Entries needed.
        entries: usize,
        /// Entries allowed.
        limit: usize,
    },
    /// More distinct colours than a palette index holds.
    #[error("more than {limit} distinct colours")]
    Palette {
        /// The most colours.
        limit: usize,
    },
}

/// The most colours in a page's palette (a payload has 24 bits).
pub const MAX_COLOURS: usize = 1 << 24;

/// The distinct colours of a page, each with its index.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Palette {
    colours: Vec<[u8; 3]>,
    index: HashMap<[u8; 3], u32>,
}

impl Palette {
    /// The index of `rgb`, added when new.
    ///
    /// # Errors
    /// [`ViewError::Palette`] past [`MAX_COLOURS`].
    pub fn index(&mut self, rgb: [u8; 3]) -> Result<u32, ViewError> {
        if let Some(&i) = self.index.get(&rgb) {
            return Ok(i);
        }
        if self.colours.len() >= MAX_COLOURS {
            return Err(ViewError::Palette { limit: MAX_COLOURS });
        }
        let i = self.colours.len() as u32;
        self.colours.push(rgb);
        self.index.insert(rgb, i);
        Ok(i)
    }

    /// The colours, by index.
    #[must_use]
    pub fn colours(&self) -> &[[u8; 3]] {
        &self.colours
    }
}

/// How a tree's black leaves get their colours.
#[derive(Clone, Copy, Debug)]
pub enum Colouring<'a> {
    /// One colour for all.
    Fixed([u8; 3]),
    /// A file's stored colours, in the tree's space; voxels without one get the
    /// fallback colour. Leaves are split where the colours change, so every voxel
    /// shows its own colour.
    Layer(&'a Layer<Rgba>, [u8; 3]),
}

/// The tree's leaves with palette indices: split where a colour layer changes, so
/// that each piece has one colour.
///
/// # Errors
/// [`ViewError::Palette`] when the colours overflow the palette.
pub fn coloured_leaves(
    tree: &LinearOctree,
    colouring: Colouring<'_>,
    palette: &mut Palette,
) -> Result<Vec<(Leaf, u32)>, ViewError> {
    match colouring {
        Colouring::Fixed(rgb) => {
            let i = palette.index(rgb)?;
            Ok(tree.leaves().iter().map(|&l| (l, i)).collect())
        }
        Colouring::Layer(layer, fallback) => {
            let stored = layer.leaves();
            let mut out = Vec::with_capacity(tree.leaf_count());
            let mut j = 0;
            let mut push = |lo: u64, hi: u64, rgb: [u8; 3]| -> Result<(), ViewError> {
                let i = palette.index(rgb)?;
                aligned_blocks(lo, hi, |l| out.push((l, i)));
                Ok(())
            };
            for leaf in tree.leaves() {
                let (mut at, end) = (leaf.code(), leaf.end());
                while j < stored.len() && stored[j].0.end() <= at {
                    j += 1;
                }
                let mut k = j;
                while at < end {
                    match stored.get(k) {
                        Some((s, c)) if s.code() < end => {
                            if s.code() > at {
                                push(at, s.code(), fallback)?;
                                at = s.code();
                            }
                            let stop = s.end().min(end);
                            push(at, stop, [c[0], c[1], c[2]])?;
                            at = stop;
                            k += 1;
                        }
                        _ => {
                            push(at, end, fallback)?;
                            at = end;
                        }
                    }
                }
            }
            Ok(out)
        }
    }
}

/// Calls `each` with the largest aligned blocks covering the codes `[lo, hi)`.
fn aligned_blocks(mut lo: u64, hi: u64, mut each: impl FnMut(Leaf)) {
    while lo < hi {
        let mut s = 0u8;
        while s < 21 {
            let span = 1u64 << (3 * (u32::from(s) + 1));
            if lo % span != 0 || lo + span > hi {
                break;
            }
            s += 1;
        }
        each(Leaf::new(lo, s));
        lo += 1u64 << (3 * u32::from(s));
    }
}
