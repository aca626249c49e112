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

mod cut;
mod normal;
mod shade;
mod trace;

#[cfg(test)]
mod tests;

pub use cut::crop_to_clip;
pub use trace::{Hit, Ray, RayTree, TraversalStack};

use cut::Cut;
use normal::NormalCache;
use shade::Shade;

use std::io::Write;
use std::path::Path;

use rayon::prelude::*;

use crate::io::{write_atomic, FormatError};
use crate::linear::LinearOctree;

/// An RGB image, rows from the top.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Image {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// The pixels, row-major from the top-left.
    pub pixels: Vec<[u8; 3]>,
}

impl Image {
    /// A `width × height` image filled with `colour`.
    #[must_use]
    pub fn new(width: usize, height: usize, colour: [u8; 3]) -> Self {
        Self {
            width,
            height,
            pixels: vec![colour; width * height],
        }
    }

    /// The pixel at column `x`, row `y`.
    #[must_use]
    pub fn get(&self, x: usize, y: usize) -> [u8; 3] {
        self.pixels[y * self.width + x]
    }

    /// Copies `other` into this image with its top-left corner at `(x, y)`, clipped.
    pub fn blit(&mut self, other: &Image, x: usize, y: usize) {
        for row in 0..other.height {
            let ty = y + row;
            if ty >= self.height {
                break;
            }
            for col in 0..other.width {
                let tx = x + col;
                if tx >= self.width {
                    break;
                }
                self.pixels[ty * self.width + tx] = other.pixels[row * other.width + col];
            }
        }
    }

    /// Encodes the image as PNG (8-bit RGB).
    ///
    /// # Errors
    /// The writer's I/O errors.
    pub fn encode_png(&self, w: &mut dyn Write) -> std::io::Result<()> {
        let mut enc = png::Encoder::new(w, self.width as u32, self.height as u32);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::Best);
        let mut writer = enc.write_header().map_err(std::io::Error::other)?;
        let data: Vec<u8> = self.pixels.iter().flatten().copied().collect();
        writer
            .write_image_data(&data)
            .map_err(std::io::Error::other)?;
        writer.finish().map_err(std::io::Error::other)
    }

    /// Writes the image as a PNG file, atomically (temporary name, then rename).
    ///
    /// # Errors
    /// [`FormatError::Io`] naming the file.
    pub fn write_png(&self, path: &Path) -> Result<(), FormatError> {
        write_atomic(path, |w| self.encode_png(w))
    }
}

/// Orthographic or perspective projection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Projection {
    /// Parallel rays: sizes do not shrink with distance.
    Orthographic,
    /// Rays from an eye point, with the given vertical field of view in degrees.
    Perspective {
        /// The vertical field of view, degrees.
        fov_deg: f64,
    },
}

/// The named views.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum View {
    /// From the front-right-top, azimuth −45°, elevation 35.26° (isometric).
    Iso,
    /// From the front (−y), looking north.
    Front,
    /// From above, looking down, north up.
    Top,
    /// From the east (+x), looking west.
    Side,
}

impl View {
    /// Every named view, in contact-sheet order.
    pub const ALL: [View; 4] = [View::Iso, View::Front, View::Top, View::Side];

    /// The view's azimuth and elevation in degrees.
    #[must_use]
    pub fn angles(self) -> (f64, f64) {
        match self {
            View::Iso => (-45.0, 35.264_389_682_754_654),
            View::Front => (-90.0, 0.0),
            View::Top => (-90.0, 90.0),
            View::Side => (0.0, 0.0),
        }
    }

    /// Parses `iso`, `front`, `top` or `side`.
    #[must_use]
    pub fn parse(s: &str) -> Option<View> {
        match s {
            "iso" => Some(View::Iso),
            "front" => Some(View::Front),
            "top" => Some(View::Top),
            "side" => Some(View::Side),
            _ => None,
        }
    }
}

/// Where the camera looks from. The target is the centre of the solid's bounding box;
/// the camera sits in the direction given by azimuth (degrees from +x towards +y) and
/// elevation (degrees above the xy plane), far enough to frame the whole solid, and
/// `zoom` magnifies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Degrees from +x towards +y of the direction to the camera.
    pub azimuth_deg: f64,
    /// Degrees above the horizontal of the direction to the camera.
    pub elevation_deg: f64,
    /// Magnification (1 frames the bounding sphere).
    pub zoom: f64,
    /// The projection.
    pub projection: Projection,
}

impl Camera {
    /// An orthographic camera for a named view, zoom 1.
    #[must_use]
    pub fn view(view: View) -> Self {
        let (azimuth_deg, elevation_deg) = view.angles();
        Self {
            azimuth_deg,
            elevation_deg,
            zoom: 1.0,
            projection: Projection::Orthographic,
        }
    }
}

impl Default for Camera {
    fn default() -> Self {
        Self::view(View::Iso)
    }
}

/// An axis-aligned clipping plane for cross-sections: the voxels with coordinate on
/// `axis` at or above `at` are removed (or below it, when `keep_above`). The removed
/// voxels are gone for every ray, shadows included (see [`crop_to_clip`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clip {
    /// 0 for x, 1 for y, 2 for z.
    pub axis: usize,
    /// The plane's coordinate, in voxels.
    pub at: f64,
    /// Keep the part above the plane instead of below.
    pub keep_above: bool,
}

/// Everything that decides how an image looks.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderOptions {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// The camera.
    pub camera: Camera,
    /// Draw the outlines of the octree's black blocks.
    pub outline: bool,
    /// Draw a ground plane under the solid, with the solid's shadow (and shadows on
    /// the solid itself).
    pub shadows: bool,
    /// Ambient-occlusion rays per pixel (0: none).
    pub ao_samples: u32,
    /// A cross-section plane.
    pub clip: Option<Clip>,
    /// The background colour.
    pub background: [u8; 3],
    /// How surfaces are shaded.
    pub normals: Normals,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            width: 800,
            height: 600,
            camera: Camera::default(),
            outline: false,
            shadows: true,
            ao_samples: 0,
            clip: None,
            background: [250, 250, 252],
            normals: Normals::Auto,
        }
    }
}

/// The colour of the solid at a point (voxel coordinates), e.g. a scene's
/// per-object colours.
pub type Shader<'a> = &'a (dyn Fn([f64; 3]) -> [u8; 3] + Sync);

/// An outward unit normal of the solid near a point (voxel coordinates), when known:
/// e.g. [`crate::csg::Csg::normal_at`].
pub type NormalFn<'a> = &'a (dyn Fn([f64; 3]) -> Option<[f64; 3]> + Sync);

/// What the renderer may ask about the solid beyond its octree: colours and normals.
/// Both are optional; an octree file alone is drawn in [`DEFAULT_COLOUR`] with normals
/// estimated from the octree.
#[derive(Clone, Copy, Default)]
pub struct Surface<'a> {
    /// The colour at a point inside the solid.
    pub colour: Option<Shader<'a>>,
    /// The normal at a point on the surface.
    pub normal: Option<NormalFn<'a>>,
}

/// How surfaces are shaded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Normals {
    /// Smooth where voxels are smaller than two pixels, block faces otherwise.
    #[default]
    Auto,
    /// The faces of the blocks: the octree as it is.
    Faces,
    /// Smooth: the surface's own normal when given, else the gradient of the octree's
    /// occupancy around the hit.
    Smooth,
}

/// The colour used when no shader is given.
pub const DEFAULT_COLOUR: [u8; 3] = [150, 165, 185];

const TILE: usize = 32;

struct Frame {
    centre: [f64; 3],
    radius: f64,
    forward: [f64; 3],
    right: [f64; 3],
    up: [f64; 3],
    half_w: f64,
    half_h: f64,
    eye: [f64; 3],
    perspective: bool,
    light: [f64; 3],
    ground_z: f64,
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn normalize(a: [f64; 3]) -> [f64; 3] {
    scale(a, 1.0 / dot(a, a).sqrt())
}

impl Frame {
    fn new(rt: &RayTree, opts: &RenderOptions) -> Frame {
        let (lo, hi) = match rt.bbox() {
            Some((lo, hi)) => (lo.map(|v| v as f64), hi.map(|v| v as f64 + 1.0)),
            None => {
                let o = rt.origin().map(|v| v as f64);
                (o, o.map(|v| v + f64::from(1u32 << rt.depth())))
            }
        };
        let centre = [
            (lo[0] + hi[0]) / 2.0,
            (lo[1] + hi[1]) / 2.0,
            (lo[2] + hi[2]) / 2.0,
        ];
        let radius = (0..3).map(|a| (hi[a] - lo[a]).powi(2)).sum::<f64>().sqrt() / 2.0;
        let cam = &opts.camera;
        let (az, el) = (cam.azimuth_deg.to_radians(), cam.elevation_deg.to_radians());
        let to_cam = [el.cos() * az.cos(), el.cos() * az.sin(), el.sin()];
        let forward = scale(to_cam, -1.0);
        let world_up = if el.cos().abs() < 1e-6 {
            // Straight down or up: north (or south) is up in the image.
            [
                -az.cos() * el.sin().signum(),
                -az.sin() * el.sin().signum(),
                0.0,
            ]
        } else {
            [0.0, 0.0, 1.0]
        };
        let right = normalize(cross(forward, world_up));
        let up = cross(right, forward);
        let aspect = opts.width as f64 / opts.height.max(1) as f64;
        let zoom = if cam.zoom > 0.0 { cam.zoom } else { 1.0 };
        let (half_h, eye, perspective) = match cam.projection {
            Projection::Orthographic => {
                let h = radius * 1.05 / zoom / aspect.min(1.0);
                (h, add(centre, scale(to_cam, radius * 3.0)), false)
            }
            Projection::Perspective { fov_deg } => {
                let fov = fov_deg.clamp(1.0, 170.0).to_radians();
                let tan = (fov / 2.0).tan();
                let fit = (radius * 1.05) / (fov / 2.0).sin().min((tan * aspect).atan().sin());
                (tan, add(centre, scale(to_cam, fit / zoom)), true)
            }
        };
        // The light comes from over the viewer's left shoulder.
        let light = normalize(add(
            add(scale(to_cam, 0.6), scale(right, -0.45)),
            [0.0, 0.0, 0.9],
        ));
        Frame {
            centre,
            radius,
            forward,
            right,
            up,
            half_w: half_h * aspect,
            half_h,
            eye,
            perspective,
            light,
            ground_z: lo[2],
        }
    }

    /// The primary ray through image coordinates `(sx, sy)` in [−1, 1].
    fn ray(&self, sx: f64, sy: f64) -> Ray {
        if self.perspective {
            let d = add(
                self.forward,
                add(
                    scale(self.right, sx * self.half_w),
                    scale(self.up, sy * self.half_h),
                ),
            );
            Ray::new(self.eye, normalize(d))
        } else {
            let o = add(
                self.eye,
                add(
                    scale(self.right, sx * self.half_w),
                    scale(self.up, sy * self.half_h),
                ),
            );
            Ray::new(o, self.forward)
        }
    }

    /// The size of a pixel, in voxels, at ray parameter `t`.
    fn pixel_size(&self, t: f64, height: usize) -> f64 {
        let h = 2.0 * self.half_h / height.max(1) as f64;
        if self.perspective {
            h * t
        } else {
            h
        }
    }
}

/// The side of a beam tile, in pixels.
const BEAM: usize = 8;

impl Frame {
    /// A lower bound on the first hit of every primary ray of pixels
    /// `[x0, x1) × [y0, y1)` (see [`RayTree::beam_start`]).
    fn beam(&self, rt: &RayTree, w: usize, h: usize, x: [usize; 2], y: [usize; 2]) -> f64 {
        let sx = |px: usize| px as f64 / w as f64 * 2.0 - 1.0;
        let sy = |py: usize| 1.0 - py as f64 / h as f64 * 2.0;
        let (sx0, sx1, sy0, sy1) = (sx(x[0]), sx(x[1]), sy(y[1]), sy(y[0]));
        let footprint = (sx1 - sx0).max(sy1 - sy0) * self.half_w.max(self.half_h);
        if !self.perspective {
            // Parallel rays: t = (p − eye) · forward for every ray; the tile is a
            // rectangle of the image plane.
            let (rx0, rx1) = (sx0 * self.half_w, sx1 * self.half_w);
            let (ry0, ry1) = (sy0 * self.half_h, sy1 * self.half_h);
            let stop = footprint.max(1.0).log2().floor() as u8;
            let (eye, f, r, u) = (self.eye, self.forward, self.right, self.up);
            let near = move |lo: [f64; 3], hi: [f64; 3]| {
                let c = [0, 1, 2].map(|i| 0.5 * (lo[i] + hi[i]) - eye[i]);
                let e = [0, 1, 2].map(|i| 0.5 * (hi[i] - lo[i]));
                let spread =
                    |v: [f64; 3]| v[0].abs() * e[0] + v[1].abs() * e[1] + v[2].abs() * e[2];
                let (cx, hx) = (dot(c, r), spread(r));
                let (cy, hy) = (dot(c, u), spread(u));
                if cx + hx < rx0 || cx - hx > rx1 || cy + hy < ry0 || cy - hy > ry1 {
                    return None;
                }
                Some(dot(c, f) - spread(f))
            };
            return rt.beam_start(stop, &near);
        }
        // Rays from the eye: the tile is a cone around its centre ray.
        let axis = self.ray(0.5 * (sx0 + sx1), 0.5 * (sy0 + sy1)).dir;
        let half_angle = [(sx0, sy0), (sx0, sy1), (sx1, sy0), (sx1, sy1)]
            .iter()
            .map(|&(a, b)| dot(self.ray(a, b).dir, axis).clamp(-1.0, 1.0).acos())
            .fold(0.0f64, f64::max);
        let eye = self.eye;
        let stop = 0u8;
        let near = move |lo: [f64; 3], hi: [f64; 3]| {
            let v = [0, 1, 2].map(|i| 0.5 * (lo[i] + hi[i]) - eye[i]);
            let rn = 0.5 * (hi[0] - lo[0]) * 3f64.sqrt();
            let dist = dot(v, v).sqrt();
            if dist <= rn {
                return Some(0.0);
            }
            let angle = (dot(v, axis) / dist).clamp(-1.0, 1.0).acos();
            if angle > half_angle + (rn / dist).asin() + 1e-9 {
                return None;
            }
            Some(dist - rn)
        };
        rt.beam_start(stop, &near)
    }
}

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
            let cut = Cut {
                clip,
                original: tree,
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
fn render_cut(
    rt: &RayTree,
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
fn trace_block(
    rt: &RayTree,
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
                        rt.cast_with(&ray, from, f64::INFINITY, stack)
                    } else {
                        None
                    };
                    if hit.is_some_and(|h| h.at_start) && from > 0.0 {
                        // Only rounding can put a hit at the beam's start: cast again.
                        hit = rt.cast_with(&ray, 0.0, f64::INFINITY, stack);
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
    let cut = opts.clip.map(|clip| Cut {
        clip,
        original: tree,
    });
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
        let img = render_cut(&rt, surface, &o, cut);
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
    let side = tree.side() as usize;
    let (u_ax, v_ax) = ((axis + 1) % 3, (axis + 2) % 3);
    let px = pixels.max(1);
    let size = side * px;
    let mut img = Image::new(size, size, [255, 255, 255]);
    let origin = tree.origin();
    let rt = RayTree::new(tree);
    for vy in 0..side {
        for ux in 0..side {
            let mut v = origin;
            v[axis] = at;
            v[u_ax] += ux as i64;
            v[v_ax] += vy as i64;
            if rt.contains(v) {
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
    }
    // Block outlines, where the layer crosses a block.
    for b in tree.blocks() {
        if at < b.min[axis] || at > b.max()[axis] {
            continue;
        }
        let s = b.size() as usize * px;
        let x0 = (b.min[u_ax] - origin[u_ax]) as usize * px;
        let y0 = (b.min[v_ax] - origin[v_ax]) as usize * px;
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
    }
    img
}
