//! The camera's frame: where the eye is, the primary rays, the light, and the beams
//! of 8 × 8 pixel tiles.

use super::beam::beam_start;
use super::nodes::Trace;
use super::{Projection, Ray, RenderOptions};

pub(super) struct Frame {
    pub(super) centre: [f64; 3],
    pub(super) radius: f64,
    pub(super) forward: [f64; 3],
    pub(super) right: [f64; 3],
    pub(super) up: [f64; 3],
    pub(super) half_w: f64,
    pub(super) half_h: f64,
    pub(super) eye: [f64; 3],
    pub(super) perspective: bool,
    pub(super) light: [f64; 3],
    pub(super) ground_z: f64,
}

pub(super) fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
pub(super) fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}
pub(super) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
pub(super) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
pub(super) fn normalize(a: [f64; 3]) -> [f64; 3] {
    scale(a, 1.0 / dot(a, a).sqrt())
}

impl Frame {
    pub(super) fn new<T: Trace + ?Sized>(rt: &T, opts: &RenderOptions) -> Frame {
        let (lo, hi) = match rt.bbox() {
            Some((lo, hi)) => (lo.map(|v| v as f64), hi.map(|v| v as f64 + 1.0)),
            None => {
                let (depth, origin) = rt.space();
                let o = origin.map(|v| v as f64);
                (o, o.map(|v| v + f64::from(1u32 << depth)))
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
    pub(super) fn ray(&self, sx: f64, sy: f64) -> Ray {
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
    pub(super) fn pixel_size(&self, t: f64, height: usize) -> f64 {
        let h = 2.0 * self.half_h / height.max(1) as f64;
        if self.perspective {
            h * t
        } else {
            h
        }
    }
}

/// The side of a beam tile, in pixels.
pub(super) const BEAM: usize = 8;

impl Frame {
    /// A lower bound on the first hit of every primary ray of pixels
    /// `[x0, x1) × [y0, y1)` (see [`super::RayTree::beam_start`]).
    pub(super) fn beam<T: Trace + ?Sized>(
        &self,
        rt: &T,
        w: usize,
        h: usize,
        x: [usize; 2],
        y: [usize; 2],
    ) -> f64 {
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
            return beam_start(rt, stop, &near);
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
        beam_start(rt, stop, &near)
    }
}
