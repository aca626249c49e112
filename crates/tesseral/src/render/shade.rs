//! Shading one pixel: the surface hit (its colour, its normal, given or estimated from
//! the voxels, diffuse light, the shadow ray, ambient occlusion, block outlines, cut
//! faces) or the ground plane.

use super::cut::Cut;
use super::nodes::Trace;
use super::normal::NormalCache;
use super::{
    add, cross, dot, normalize, scale, Frame, Hit, Normals, Ray, RenderOptions, Surface,
    DEFAULT_COLOUR,
};

/// What shading a pixel needs besides its ray: the tree, the camera, the surface's
/// colours and normals, the options and the cut.
pub(super) struct Shade<'a, T: ?Sized> {
    pub(super) rt: &'a T,
    pub(super) frame: &'a Frame,
    pub(super) surface: Surface<'a>,
    pub(super) opts: &'a RenderOptions,
    pub(super) cut: Option<Cut<'a>>,
}

impl<T: Trace + ?Sized> Shade<'_, T> {
    pub(super) fn pixel(&self, cache: &mut NormalCache, ray: &Ray, hit: Option<Hit>) -> [u8; 3] {
        let (rt, frame, opts) = (self.rt, self.frame, self.opts);
        let ground_t = if opts.shadows && ray.dir[2] < -1e-9 {
            let t = (frame.ground_z - ray.origin[2]) / ray.dir[2];
            (t > 0.0).then_some(t)
        } else {
            None
        };
        match hit {
            Some(h) if ground_t.is_none_or(|g| h.t <= g) => self.hit(cache, ray, &h),
            _ => match ground_t {
                Some(g) => shade_ground(rt, frame, opts, ray, g),
                None => opts.background,
            },
        }
    }

    fn hit(&self, cache: &mut NormalCache, ray: &Ray, h: &Hit) -> [u8; 3] {
        let (rt, frame, surface, opts, cut_by) =
            (self.rt, self.frame, self.surface, self.opts, self.cut);
        let p = ray.at(h.t);
        let mut n = [0.0; 3];
        n[h.axis] = -ray.dir[h.axis].signum();
        // Sample the colour half a voxel inside the surface.
        let inside = add(p, scale(n, -0.5));
        let cut = cut_by.is_some_and(|c| c.is_cut_face(inside.map(|v| v.floor() as i64), n));
        let face = n;
        let smooth = match opts.normals {
            Normals::Faces => false,
            Normals::Smooth => true,
            Normals::Auto => frame.pixel_size(h.t, opts.height) > 0.5,
        };
        if smooth && !opts.outline && !cut {
            let given = surface
                .normal
                .and_then(|f| f(p))
                .filter(|m| dot(*m, face) > 0.05);
            n = given.unwrap_or_else(|| cache.normal(rt, inside.map(|c| c.floor() as i64), face));
        }
        // The centre of the voxel hit: the solid's predicate holds there exactly.
        let centre = inside.map(|c| c.floor() + 0.5);
        let base = surface.colour.map_or(DEFAULT_COLOUR, |f| f(centre));
        let base = if cut {
            // Cut faces: the object's colour, darker, hatched, so the section reads.
            let stripe = ((p[0] + p[1] + p[2]) / 3.0).rem_euclid(6.0) < 3.0;
            let k = if stripe { 0.55 } else { 0.7 };
            base.map(|c| (f64::from(c) * k) as u8)
        } else {
            base
        };
        let mut light = dot(n, frame.light).max(0.0);
        if opts.shadows && light > 0.0 {
            // From a smooth surface, start the shadow ray clear of the voxel staircase.
            let lift = if smooth { 1.5 } else { 0.0 };
            let from = add(add(p, scale(face, 1e-3)), scale(n, lift));
            if rt
                .cast(&Ray::new(from, frame.light), 0.0, f64::INFINITY)
                .is_some()
            {
                light = 0.0;
            }
        }
        let mut ambient = 0.42;
        if opts.ao_samples > 0 {
            ambient *= ambient_occlusion(rt, frame, p, n, opts.ao_samples, h.t);
        }
        // A little light from below the horizon side keeps shadowed faces readable.
        let fill = 0.12 * dot(n, scale(frame.forward, -1.0)).max(0.0);
        let k = (ambient + 0.62 * light + fill).min(1.15);
        let mut rgb = base.map(|c| (f64::from(c) * k).min(255.0));
        if opts.outline {
            let size = (1i64 << h.size_log2) as f64;
            let mut edge = f64::INFINITY;
            for (ax, (&pa, &ba)) in p.iter().zip(&h.block_min).enumerate() {
                if ax == h.axis && !cut {
                    continue;
                }
                if cut && ax == cut_by.map_or(3, |c| c.clip.axis) {
                    continue;
                }
                let u = pa - ba as f64;
                edge = edge.min(u.abs()).min((size - u).abs());
            }
            let width = frame.pixel_size(h.t, opts.height) * 0.75;
            if edge < width {
                rgb = rgb.map(|c| c * 0.25);
            }
        }
        rgb.map(|c| c.round() as u8)
    }
}

fn ambient_occlusion<T: Trace + ?Sized>(
    rt: &T,
    frame: &Frame,
    p: [f64; 3],
    n: [f64; 3],
    samples: u32,
    t: f64,
) -> f64 {
    // A fixed cosine-weighted pattern, rotated per pixel by a hash of the position.
    let reach = frame.radius * 0.15;
    let seed = ((p[0] * 73.0 + p[1] * 151.0 + p[2] * 283.0 + t) as i64 as u64)
        .wrapping_mul(0x9e37_79b9_7f4a_7c15);
    let (t1, t2) = if n[2].abs() < 0.9 {
        let a = normalize(cross(n, [0.0, 0.0, 1.0]));
        (a, cross(n, a))
    } else {
        let a = normalize(cross(n, [1.0, 0.0, 0.0]));
        (a, cross(n, a))
    };
    let from = add(p, scale(n, 1e-3));
    let mut open = 0u32;
    for i in 0..samples {
        let u1 = (f64::from(i) + 0.5) / f64::from(samples);
        let u2 =
            ((seed >> 11) as f64 / (1u64 << 53) as f64 + f64::from(i) * 0.618_033_988_75).fract();
        let r = u1.sqrt();
        let phi = 2.0 * std::f64::consts::PI * u2;
        let d = add(
            add(scale(t1, r * phi.cos()), scale(t2, r * phi.sin())),
            scale(n, (1.0 - u1).sqrt()),
        );
        if rt.cast(&Ray::new(from, d), 0.0, reach).is_none() {
            open += 1;
        }
    }
    0.35 + 0.65 * f64::from(open) / f64::from(samples)
}

fn shade_ground<T: Trace + ?Sized>(
    rt: &T,
    frame: &Frame,
    opts: &RenderOptions,
    ray: &Ray,
    t: f64,
) -> [u8; 3] {
    let p = ray.at(t);
    let dx = p[0] - frame.centre[0];
    let dy = p[1] - frame.centre[1];
    let r = (dx * dx + dy * dy).sqrt() / (frame.radius * 2.2);
    if r > 1.0 {
        return opts.background;
    }
    // A soft-edged disc with a faint grid, 16 cells across the solid.
    let cell = (frame.radius / 6.0).max(1.0);
    let grid = ((p[0] / cell).floor() + (p[1] / cell).floor()).rem_euclid(2.0) == 0.0;
    let mut k = if grid { 0.955 } else { 0.98 };
    let from = [p[0], p[1], p[2] + 1e-3];
    if rt
        .cast(&Ray::new(from, frame.light), 0.0, f64::INFINITY)
        .is_some()
    {
        k *= 0.62;
    }
    let fade = (r * r).min(1.0);
    let bg = opts.background.map(f64::from);
    let ground = [232.0, 230.0, 225.0].map(|c: f64| c * k);
    [0, 1, 2].map(|i| (ground[i] * (1.0 - fade) + bg[i] * fade).round() as u8)
}
