//! A plain top-down orthographic picture (looking down the z axis) of placed octrees,
//! with contact boxes and paths drawn over them: what `tesseral simulate --frames`
//! and `tesseral plan -o` write. Each pixel shows the highest block above it,
//! shaded by height.

use std::path::Path;

use super::interfere::{Aabb, Placed};
use crate::io::{write_atomic, FormatError};
use crate::Voxel;

/// The largest picture side, in pixels.
const MAX_SIDE: i64 = 1024;
/// The picture side we aim for when the scene is small.
const MIN_SIDE: i64 = 320;

/// An RGB colour.
pub type Rgb = [u8; 3];

/// A top-down picture being drawn.
#[derive(Debug, Clone)]
pub struct TopView {
    x0: i64,
    y0: i64,
    /// Pixels per voxel when ≥ 1 (`zoom`), or voxels per pixel (`shrink`).
    zoom: i64,
    shrink: i64,
    width: usize,
    height: usize,
    z_range: (i64, i64),
    top: Vec<i64>,
    rgb: Vec<Rgb>,
}

impl TopView {
    /// A picture of the columns `min.x..=max.x` × `min.y..=max.y`, with heights
    /// shaded over `min.z..=max.z`.
    #[must_use]
    pub fn new(bounds: Aabb) -> TopView {
        let w = (bounds.max[0] - bounds.min[0] + 1).max(1);
        let h = (bounds.max[1] - bounds.min[1] + 1).max(1);
        let extent = w.max(h);
        let (zoom, shrink) = if extent >= MAX_SIDE {
            (1, (extent + MAX_SIDE - 1) / MAX_SIDE)
        } else {
            ((MIN_SIDE / extent).clamp(1, 32), 1)
        };
        let width = ((w + shrink - 1) / shrink * zoom) as usize;
        let height = ((h + shrink - 1) / shrink * zoom) as usize;
        TopView {
            x0: bounds.min[0],
            y0: bounds.min[1],
            zoom,
            shrink,
            width,
            height,
            z_range: (bounds.min[2], bounds.max[2]),
            top: vec![i64::MIN; width * height],
            rgb: vec![[255, 255, 255]; width * height],
        }
    }

    /// The width and height in pixels.
    #[must_use]
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// The pixel range covering world columns `lo..hi` on one axis.
    fn span(&self, lo: i64, hi: i64, origin: i64, len: usize) -> (usize, usize) {
        let a = ((lo - origin).div_euclid(self.shrink) * self.zoom).clamp(0, len as i64);
        let b = (((hi - origin) + self.shrink - 1).div_euclid(self.shrink) * self.zoom)
            .clamp(0, len as i64);
        (a as usize, b as usize)
    }

    fn shade(&self, color: Rgb, z: i64) -> Rgb {
        let (lo, hi) = self.z_range;
        let f = if hi > lo {
            0.45 + 0.55 * ((z - lo) as f64 / (hi - lo) as f64).clamp(0.0, 1.0)
        } else {
            1.0
        };
        color.map(|c| (f64::from(c) * f) as u8)
    }

    /// Draws every block of a placed tree in `color`, where it is the highest thing
    /// seen from above.
    pub fn draw_tree(&mut self, tree: Placed<'_>, color: Rgb) {
        for b in tree.tree.blocks() {
            let cell = tree.place.cell(b.min, b.size());
            self.fill(cell.lo, cell.hi, color, false);
        }
    }

    /// Paints boxes (such as contacts) in `color` over everything.
    pub fn mark_boxes(&mut self, boxes: &[Aabb], color: Rgb) {
        for b in boxes {
            self.fill(b.min, b.max.map(|c| c + 1), color, true);
        }
    }

    fn fill(&mut self, lo: Voxel, hi: Voxel, color: Rgb, over: bool) {
        let (x0, x1) = self.span(lo[0], hi[0], self.x0, self.width);
        let (y0, y1) = self.span(lo[1], hi[1], self.y0, self.height);
        let z = hi[2] - 1;
        let c = self.shade(color, z);
        for py in y0..y1 {
            // North (larger y) at the top of the image.
            let row = self.height - 1 - py;
            for px in x0..x1 {
                let i = row * self.width + px;
                if over || z >= self.top[i] {
                    self.top[i] = if over { i64::MAX } else { z };
                    self.rgb[i] = c;
                }
            }
        }
    }

    /// Draws a polyline through world points (x, y used), two pixels wide.
    pub fn draw_polyline(&mut self, points: &[[f64; 3]], color: Rgb) {
        let to_px = |p: &[f64; 3]| {
            let s = self.zoom as f64 / self.shrink as f64;
            (
                (p[0] - self.x0 as f64) * s,
                (self.height as f64) - (p[1] - self.y0 as f64) * s,
            )
        };
        for w in points.windows(2) {
            let (a, b) = (to_px(&w[0]), to_px(&w[1]));
            let n = ((b.0 - a.0).abs().max((b.1 - a.1).abs()) * 2.0)
                .ceil()
                .max(1.0) as usize;
            for k in 0..=n {
                let t = k as f64 / n as f64;
                let (x, y) = (a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t);
                for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
                    let (px, py) = ((x - 0.5 + dx).floor(), (y - 0.5 + dy).floor());
                    if px >= 0.0
                        && py >= 0.0
                        && (px as usize) < self.width
                        && (py as usize) < self.height
                    {
                        let i = py as usize * self.width + px as usize;
                        self.rgb[i] = color;
                        self.top[i] = i64::MAX;
                    }
                }
            }
        }
    }

    /// The colour of the pixel at column `x`, row `y` (row 0 at the top).
    #[must_use]
    pub fn pixel(&self, x: usize, y: usize) -> Rgb {
        self.rgb[y * self.width + x]
    }

    /// Writes the picture as an 8-bit RGB PNG, atomically.
    ///
    /// # Errors
    /// [`FormatError::Io`] naming the file.
    pub fn write_png(&self, path: &Path) -> Result<(), FormatError> {
        write_atomic(path, |w| {
            let mut enc = png::Encoder::new(w, self.width as u32, self.height as u32);
            enc.set_color(png::ColorType::Rgb);
            enc.set_depth(png::BitDepth::Eight);
            let mut writer = enc.write_header().map_err(std::io::Error::other)?;
            let data: Vec<u8> = self.rgb.iter().flatten().copied().collect();
            writer
                .write_image_data(&data)
                .map_err(std::io::Error::other)?;
            writer.finish().map_err(std::io::Error::other)
        })
    }
}
