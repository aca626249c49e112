//! Images of octrees: rays cast through the linear octree itself (the parametric
//! traversal of Revelles et al., with octant mirroring, in [`RayTree`]), stopping at
//! the first black block of any size; multi-threaded over tiles with rayon.
//!
//! - Cameras: orthographic or perspective, the named views iso/front/top/side, and
//!   azimuth, elevation and zoom ([`Camera`]).
//! - Shading: a colour per object (a callback, e.g. [`crate::csg::Csg::colour_at`]),
//!   diffuse light, a ground plane with the solid's cast shadow, optional ambient
//!   occlusion.
//! - Modes: block outlines showing the octree decomposition (as the papers' figures
//!   do), cross-sections (a clipping plane whose cut faces are drawn), 2-D slices
//!   ([`section`]), and contact sheets of several views ([`contact_sheet`]).
//! - PNG output through the `png` crate ([`Image::write_png`]), written atomically.

mod beam;
mod clipped;
mod cut;
mod frame;
mod image;
mod index;
mod nodes;
mod normal;
mod options;
mod shade;
mod stream;
mod trace;

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_images;

pub use cut::crop_to_clip;
pub use image::Image;
pub use index::RayTree;
pub use options::{
    Camera, Clip, NormalFn, Normals, Projection, RenderOptions, Shader, Surface, View,
    DEFAULT_COLOUR,
};
pub use stream::{
    contact_sheet_streamed, render_streamed, section_streamed, StreamStats, StreamedTree,
};
pub use trace::{Hit, Ray, TraversalStack};

use cut::Cut;
use frame::{add, cross, dot, normalize, scale, Frame, BEAM};
use nodes::Trace;
use normal::NormalCache;
use shade::Shade;

use rayon::prelude::*;

use crate::linear::LinearOctree;

const TILE: usize = 32;

/// Renders `tree` as seen by `opts.camera`. `surface` gives colours and normals when
/// known (a scene's); by default the solid is [`DEFAULT_COLOUR`].
///
/// # Runtime
/// O(pixels × nodes visited per ray), in parallel over 32 × 32 tiles; plus
/// [`RayTree::new`] once.
///
/// ```
/// use tesseral::linear::LinearOctree;
/// use tesseral::render::{render, RenderOptions};
/// let tree = LinearOctree::full(3, [0, 0, 0]).unwrap();
/// let img = render(&tree, Default::default(), &RenderOptions { width: 64, height: 48, ..Default::default() });
/// assert_eq!((img.width, img.height), (64, 48));
/// assert_ne!(img.get(32, 24), RenderOptions::default().background);
/// ```
#[must_use]
pub fn render(tree: &LinearOctree, surface: Surface<'_>, opts: &RenderOptions) -> Image {
    match opts.clip {
        None => render_with(&RayTree::new(tree), surface, opts),
        Some(clip) => {
            let kept = crop_to_clip(tree, clip);
            let contains = |v| tree.contains(v);
            let cut = Cut {
                clip,
                original: &contains,
            };
            render_cut(&RayTree::new(&kept), surface, opts, Some(cut))
        }
    }
}

/// As [`render`], with the ray index already built (for several views of one tree).
/// It draws `rt` as it is: `opts.clip` needs the tree and is ignored here; pass a
/// tree cropped by [`crop_to_clip`], or use [`render`] or [`contact_sheet`], which
/// also mark the cut faces.
#[must_use]
pub fn render_with(rt: &RayTree, surface: Surface<'_>, opts: &RenderOptions) -> Image {
    render_cut(rt, surface, opts, None)
}

/// Draws `rt`, marking the faces `cut` made (hatched, darker).
fn render_cut<T: Trace + ?Sized>(
    rt: &T,
    surface: Surface<'_>,
    opts: &RenderOptions,
    cut: Option<Cut<'_>>,
) -> Image {
    let frame = Frame::new(rt, opts);
    let (w, h) = (opts.width, opts.height);
    let tiles_x = w.div_ceil(TILE);
    let tiles_y = h.div_ceil(TILE);
    let tiles: Vec<(usize, Vec<[u8; 3]>)> = (0..tiles_x * tiles_y)
        .into_par_iter()
        .map(|ti| {
            let (tx, ty) = (ti % tiles_x, ti / tiles_x);
            let xr = [tx * TILE, ((tx + 1) * TILE).min(w)];
            let yr = [ty * TILE, ((ty + 1) * TILE).min(h)];
            let tw = xr[1] - xr[0];
            let mut buf = vec![opts.background; tw * (yr[1] - yr[0])];
            let mut stack = TraversalStack::default();
            let mut cache = NormalCache::new();
            let shade = Shade {
                rt,
                frame: &frame,
                surface,
                opts,
                cut,
            };
            trace_block(rt, &frame, opts, xr, yr, &mut stack, |x, y, ray, hit| {
                buf[(y - yr[0]) * tw + (x - xr[0])] = shade.pixel(&mut cache, ray, hit);
            });
            (ti, buf)
        })
        .collect();
    let mut img = Image::new(w, h, opts.background);
    for (ti, buf) in tiles {
        let (tx, ty) = (ti % tiles_x, ti / tiles_x);
        let tw = ((tx + 1) * TILE).min(w) - tx * TILE;
        for (i, px) in buf.into_iter().enumerate() {
            let (x, y) = (tx * TILE + i % tw, ty * TILE + i / tw);
            img.pixels[y * w + x] = px;
        }
    }
    img
}

/// Casts the primary rays of the pixels `xr × yr`, beam tile by beam tile: each
/// 8 × 8 tile first finds a lower bound on its rays' first hits
/// ([`RayTree::beam_start`]), so its rays skip the empty space in front, and a tile
/// whose beam meets nothing casts no ray at all.
fn trace_block<T: Trace + ?Sized>(
    rt: &T,
    frame: &Frame,
    opts: &RenderOptions,
    xr: [usize; 2],
    yr: [usize; 2],
    stack: &mut TraversalStack,
    mut each: impl FnMut(usize, usize, &Ray, Option<Hit>),
) {
    let (w, h) = (opts.width, opts.height);
    for by in (yr[0]..yr[1]).step_by(BEAM) {
        for bx in (xr[0]..xr[1]).step_by(BEAM) {
            let (bx1, by1) = ((bx + BEAM).min(xr[1]), (by + BEAM).min(yr[1]));
            let start = frame.beam(rt, w, h, [bx, bx1], [by, by1]);
            let margin = 1e-6 * (1.0 + start.abs());
            for y in by..by1 {
                for x in bx..bx1 {
                    let ray = pixel_ray(frame, w, h, x, y);
                    let from = (start - margin).max(0.0);
                    let mut hit = if start.is_finite() {
                        trace::cast(rt, &ray, from, f64::INFINITY, stack)
                    } else {
                        None
                    };
                    if hit.is_some_and(|h| h.at_start) && from > 0.0 {
                        // Only rounding can put a hit at the beam's start: cast again.
                        hit = trace::cast(rt, &ray, 0.0, f64::INFINITY, stack);
                    }
                    each(x, y, &ray, hit);
                }
            }
        }
    }
}

/// Casts the primary rays of every pixel and returns how many hit the solid: the
/// traversal alone, without shading (for benchmarks and coverage tests).
#[must_use]
pub fn primary_hits(rt: &RayTree, opts: &RenderOptions) -> usize {
    let frame = Frame::new(rt, opts);
    let (w, h) = (opts.width, opts.height);
    let tiles_x = w.div_ceil(TILE);
    (0..tiles_x * h.div_ceil(TILE))
        .into_par_iter()
        .map(|ti| {
            let (tx, ty) = (ti % tiles_x, ti / tiles_x);
            let xr = [tx * TILE, ((tx + 1) * TILE).min(w)];
            let yr = [ty * TILE, ((ty + 1) * TILE).min(h)];
            let mut stack = TraversalStack::default();
            let mut n = 0;
            trace_block(rt, &frame, opts, xr, yr, &mut stack, |_, _, _, hit| {
                n += usize::from(hit.is_some());
            });
            n
        })
        .sum()
}

fn pixel_ray(frame: &Frame, w: usize, h: usize, x: usize, y: usize) -> Ray {
    let sx = (x as f64 + 0.5) / w as f64 * 2.0 - 1.0;
    let sy = 1.0 - (y as f64 + 0.5) / h as f64 * 2.0;
    frame.ray(sx, sy)
}

/// A contact sheet: the tree seen from each of `views`, tiled `columns` across, each
/// cell `opts.width × opts.height`, separated by a 4-pixel gutter.
#[must_use]
pub fn contact_sheet(
    tree: &LinearOctree,
    surface: Surface<'_>,
    opts: &RenderOptions,
    views: &[View],
    columns: usize,
) -> Image {
    let kept = opts.clip.map(|c| crop_to_clip(tree, c));
    let rt = RayTree::new(kept.as_ref().unwrap_or(tree));
    let contains = |v| tree.contains(v);
    let cut = opts.clip.map(|clip| Cut {
        clip,
        original: &contains,
    });
    sheet_of(&rt, cut, surface, opts, views, columns)
}

/// [`contact_sheet`] of `rt`, already cropped when `cut` is given.
fn sheet_of<T: Trace + ?Sized>(
    rt: &T,
    cut: Option<Cut<'_>>,
    surface: Surface<'_>,
    opts: &RenderOptions,
    views: &[View],
    columns: usize,
) -> Image {
    let columns = columns.clamp(1, views.len().max(1));
    let rows = views.len().div_ceil(columns);
    let gap = 4;
    let mut sheet = Image::new(
        columns * opts.width + (columns + 1) * gap,
        rows * opts.height + (rows + 1) * gap,
        [210, 210, 215],
    );
    for (i, v) in views.iter().enumerate() {
        let mut o = opts.clone();
        let (az, el) = v.angles();
        o.camera.azimuth_deg = az;
        o.camera.elevation_deg = el;
        let img = render_cut(rt, surface, &o, cut);
        let (c, r) = (i % columns, i / columns);
        sheet.blit(
            &img,
            gap + c * (opts.width + gap),
            gap + r * (opts.height + gap),
        );
    }
    sheet
}

/// A 2-D slice of the tree: the layer of voxels with coordinate `at` on `axis`, one
/// square of `pixels` pixels per voxel, black voxels coloured by `surface`, and the
/// outlines of the octree blocks the layer crosses drawn in dark grey.
///
/// The image's horizontal axis is the next axis after `axis` (cyclically) and its
/// vertical axis the one after that, growing upwards.
///
/// # Runtime
/// O(side² × pixels² + leaves).
#[must_use]
pub fn section(
    tree: &LinearOctree,
    surface: Surface<'_>,
    axis: usize,
    at: i64,
    pixels: usize,
) -> Image {
    section_of(&RayTree::new(tree), surface, axis, at, pixels)
}

/// [`section`] of any tree rays can be cast through: the black blocks the layer
/// crosses are found by a descent along it, so only they are read.
fn section_of<T: Trace + ?Sized>(
    t: &T,
    surface: Surface<'_>,
    axis: usize,
    at: i64,
    pixels: usize,
) -> Image {
    let (depth, origin) = t.space();
    let side = 1usize << depth;
    let (u_ax, v_ax) = ((axis + 1) % 3, (axis + 2) % 3);
    let px = pixels.max(1);
    let size = side * px;
    let mut img = Image::new(size, size, [255, 255, 255]);
    // The voxels of the layer, block by block.
    nodes::layer_blocks(t, axis, at, &mut |bmin, s| {
        for j in 0..s {
            for i in 0..s {
                let mut v = bmin;
                v[axis] = at;
                v[u_ax] += i;
                v[v_ax] += j;
                let (ux, vy) = (
                    (v[u_ax] - origin[u_ax]) as usize,
                    (v[v_ax] - origin[v_ax]) as usize,
                );
                let centre = v.map(|c| c as f64 + 0.5);
                let colour = surface.colour.map_or(DEFAULT_COLOUR, |f| f(centre));
                for dy in 0..px {
                    for dx in 0..px {
                        let (x, y) = (ux * px + dx, size - 1 - (vy * px + dy));
                        img.pixels[y * size + x] = colour;
                    }
                }
            }
        }
    });
    // Block outlines, where the layer crosses a block.
    nodes::layer_blocks(t, axis, at, &mut |bmin, s| {
        let s = s as usize * px;
        let x0 = (bmin[u_ax] - origin[u_ax]) as usize * px;
        let y0 = (bmin[v_ax] - origin[v_ax]) as usize * px;
        for i in 0..s {
            for (x, y) in [
                (x0 + i, y0),
                (x0 + i, y0 + s - 1),
                (x0, y0 + i),
                (x0 + s - 1, y0 + i),
            ] {
                if x < size && y < size {
                    img.pixels[(size - 1 - y) * size + x] = [60, 60, 70];
                }
            }
        }
    });
    img
}
