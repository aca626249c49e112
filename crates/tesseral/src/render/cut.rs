//! Cross-sections (`--cut`): the tree is cropped to the kept half-space before it
//! is drawn, so what was removed is gone for every ray (primary rays, shadows on
//! the solid and on the ground, occlusion) and the picture is framed on what is
//! left. A plane outside the solid keeps all of it or none of it, as the
//! inequality says. Only the marking of cut faces needs the uncropped tree.

use super::Clip;
use crate::linear::LinearOctree;
use crate::Voxel;

impl Clip {
    /// The first voxel coordinate at or above the plane: voxels below it are kept
    /// (or, with `keep_above`, those at or above it). A voxel `c` is removed when
    /// `c ≥ at`, that is `c ≥ ⌈at⌉`.
    ///
    /// # Runtime
    /// O(1).
    ///
    /// # Example
    /// ```
    /// use tesseral::render::Clip;
    /// let c = Clip { axis: 0, at: 2.5, keep_above: false };
    /// assert_eq!(c.boundary(), 3);
    /// ```
    #[must_use]
    pub fn boundary(&self) -> i64 {
        // Saturating: a plane far outside any tree keeps all or nothing.
        let k = self.at.ceil();
        if k.is_nan() {
            0
        } else {
            k.clamp(i64::MIN as f64, i64::MAX as f64) as i64
        }
    }

    /// Whether the clip keeps voxel `v`.
    ///
    /// # Runtime
    /// O(1).
    ///
    /// # Example
    /// ```
    /// use tesseral::render::Clip;
    /// let c = Clip { axis: 2, at: 4.0, keep_above: false };
    /// assert!(c.keeps([9, 9, 3]) && !c.keeps([0, 0, 4]));
    /// ```
    #[must_use]
    pub fn keeps(&self, v: Voxel) -> bool {
        (v[self.axis] >= self.boundary()) == self.keep_above
    }
}

/// The voxels of `tree` that `clip` keeps, in the same space.
///
/// # Runtime
/// O(n) plus the leaves the plane cuts, times the depth (a crop).
///
/// # Example
/// ```
/// use tesseral::linear::LinearOctree;
/// use tesseral::render::{crop_to_clip, Clip};
/// let cube = LinearOctree::full(3, [0, 0, 0]).unwrap();
/// let below = crop_to_clip(&cube, Clip { axis: 2, at: 2.5, keep_above: false });
/// assert_eq!(below.voxel_count(), 8 * 8 * 3);
/// // A plane beyond the solid keeps all of it.
/// let all = crop_to_clip(&cube, Clip { axis: 0, at: 100.0, keep_above: false });
/// assert_eq!(all, cube);
/// ```
#[must_use]
pub fn crop_to_clip(tree: &LinearOctree, clip: Clip) -> LinearOctree {
    let k = clip.boundary();
    let mut lo = [i64::MIN; 3];
    let mut hi = [i64::MAX; 3];
    if clip.keep_above {
        lo[clip.axis] = k;
    } else {
        if k == i64::MIN {
            return LinearOctree::from_parts(tree.depth(), tree.origin(), Vec::new());
        }
        hi[clip.axis] = k - 1;
    }
    tree.crop(lo, hi)
}

/// What the shader needs to know about a cross-section.
#[derive(Clone, Copy)]
pub(super) struct Cut<'a> {
    pub(super) clip: Clip,
    /// Whether the tree before cropping holds a voxel.
    pub(super) original: &'a (dyn Fn(Voxel) -> bool + Sync),
}

impl Cut<'_> {
    /// The outward normal of the cut faces: towards the removed side.
    pub(super) fn normal(&self) -> [f64; 3] {
        let mut n = [0.0; 3];
        n[self.clip.axis] = if self.clip.keep_above { -1.0 } else { 1.0 };
        n
    }

    /// Whether a face of the kept solid, seen with outward normal `n` on the face of
    /// voxel `inside`, is a cut face: on the plane, facing the removed side, with the
    /// solid continuing beyond it in the uncropped tree.
    pub(super) fn is_cut_face(&self, inside: Voxel, n: [f64; 3]) -> bool {
        let a = self.clip.axis;
        if n != self.normal() {
            return false;
        }
        let step = if self.clip.keep_above { -1 } else { 1 };
        let mut beyond = inside;
        beyond[a] = inside[a].saturating_add(step);
        self.clip.keeps(inside) && !self.clip.keeps(beyond) && (self.original)(beyond)
    }
}

#[cfg(test)]
mod tests {
    use std::collections::HashSet;

    use super::*;
    use crate::csg::tests::Rng;
    use crate::render::{render, Camera, Projection, RenderOptions, Surface, View};

    /// A solid of random blobs, so that cuts cross both full blocks and ragged
    /// surfaces.
    fn random_tree(rng: &mut Rng, origin: Voxel) -> LinearOctree {
        let mut voxels = Vec::new();
        for _ in 0..1 + rng.next() % 4 {
            let c = [0, 1, 2].map(|_| rng.range(6.0, 26.0));
            let r = rng.range(3.0, 8.0);
            for x in 0..32i64 {
                for y in 0..32i64 {
                    for z in 0..32i64 {
                        let d = [x, y, z].map(|v| v as f64 + 0.5);
                        if (0..3).map(|a| (d[a] - c[a]).powi(2)).sum::<f64>() < r * r {
                            voxels.push([origin[0] + x, origin[1] + y, origin[2] + z]);
                        }
                    }
                }
            }
        }
        LinearOctree::from_voxels(5, origin, voxels).unwrap()
    }

    fn random_clip(rng: &mut Rng, origin: Voxel) -> Clip {
        let axis = (rng.next() % 3) as usize;
        // Planes through the solid, on its edges, and far outside on either side.
        let at = match rng.next() % 4 {
            0 => origin[axis] as f64 - 1000.0,
            1 => origin[axis] as f64 + 1000.0,
            2 => origin[axis] as f64 + (rng.next() % 33) as f64,
            _ => origin[axis] as f64 + rng.range(-2.0, 34.0),
        };
        Clip {
            axis,
            at,
            keep_above: rng.next() % 2 == 0,
        }
    }

    /// The crop against a voxel-set model: a voxel `c` is removed when `c ≥ at` (or
    /// kept only then, with `keep_above`).
    #[test]
    fn crop_matches_the_inequality() {
        let seed = 0xc07_c07;
        println!("seed {seed:#x}");
        let mut rng = Rng(seed);
        for _ in 0..40 {
            let origin = [0, 1, 2].map(|_| (rng.next() % 200) as i64 - 100);
            let tree = random_tree(&mut rng, origin);
            let clip = random_clip(&mut rng, origin);
            let kept = crop_to_clip(&tree, clip);
            kept.assert_valid();
            let want: HashSet<Voxel> = tree
                .voxels()
                .filter(|v| {
                    let removed = (v[clip.axis] as f64) >= clip.at;
                    removed == clip.keep_above
                })
                .collect();
            let got: HashSet<Voxel> = kept.voxels().collect();
            assert_eq!(got, want, "{clip:?}");
        }
    }

    /// A cut render is the render of the cropped solid: same framing, same shadows on
    /// the ground and on the solid, pixel for pixel. The cut faces differ only in
    /// their hatching, so the voxels that can show a cut face (the kept layer next
    /// to the plane) are coloured black, where hatching and light change nothing.
    #[test]
    fn a_cut_draws_the_cropped_solid() {
        let seed = 0x5ec7_1017;
        println!("seed {seed:#x}");
        let mut rng = Rng(seed);
        let mut through = 0;
        for trial in 0..24 {
            let origin = [0, 1, 2].map(|_| (rng.next() % 64) as i64 - 32);
            let tree = random_tree(&mut rng, origin);
            let clip = random_clip(&mut rng, origin);
            let k = clip.boundary();
            let layer = if clip.keep_above { k } else { k - 1 };
            let colour = move |p: [f64; 3]| {
                if p[clip.axis].floor() as i64 == layer {
                    [0, 0, 0]
                } else {
                    [200, 60, 40]
                }
            };
            let surface = Surface {
                colour: Some(&colour),
                normal: None,
            };
            let view = View::ALL[trial % View::ALL.len()];
            let mut camera = Camera::view(view);
            if trial % 3 == 0 {
                camera.projection = Projection::Perspective { fov_deg: 40.0 };
            }
            let opts = RenderOptions {
                width: 96,
                height: 72,
                camera,
                ao_samples: if trial % 4 == 0 { 4 } else { 0 },
                clip: None,
                ..RenderOptions::default()
            };
            let kept = crop_to_clip(&tree, clip);
            let want = render(&kept, surface, &opts);
            let got = render(
                &tree,
                surface,
                &RenderOptions {
                    clip: Some(clip),
                    ..opts.clone()
                },
            );
            assert!(got == want, "seed {seed:#x} trial {trial}: {clip:?}");
            if !kept.is_empty() && kept.voxel_count() < tree.voxel_count() {
                through += 1;
            }
        }
        assert!(through >= 5, "only {through} planes cut the solid");
    }

    /// Planes beyond the solid keep all of it or none of it; a plane through it
    /// shows hatched cut faces.
    #[test]
    fn planes_outside_keep_all_or_nothing() {
        let tree = random_tree(&mut Rng(0xfeed), [0, 0, 0]);
        let (lo, hi) = tree.bbox().unwrap();
        let opts = RenderOptions {
            width: 80,
            height: 60,
            ..RenderOptions::default()
        };
        let whole = render(&tree, Surface::default(), &opts);
        let empty = render(
            &LinearOctree::empty(5, [0, 0, 0]).unwrap(),
            Surface::default(),
            &opts,
        );
        assert!(whole != empty);
        for axis in 0..3 {
            for (at, keep_above, all) in [
                (hi[axis] as f64 + 100.0, false, true),
                (lo[axis] as f64 - 1000.0, true, true),
                (hi[axis] as f64 + 100.0, true, false),
                (lo[axis] as f64, false, false),
            ] {
                let clip = Clip {
                    axis,
                    at,
                    keep_above,
                };
                let img = render(
                    &tree,
                    Surface::default(),
                    &RenderOptions {
                        clip: Some(clip),
                        ..opts.clone()
                    },
                );
                assert!(img == if all { &whole } else { &empty }.clone(), "{clip:?}");
            }
            // The camera sees one side of each axis: one of the two halves shows
            // its cut faces.
            let marked = [false, true].iter().any(|&keep_above| {
                let middle = Clip {
                    axis,
                    at: (lo[axis] + hi[axis]) as f64 / 2.0,
                    keep_above,
                };
                let cut = render(
                    &tree,
                    Surface::default(),
                    &RenderOptions {
                        clip: Some(middle),
                        ..opts.clone()
                    },
                );
                cut != render(&crop_to_clip(&tree, middle), Surface::default(), &opts)
            });
            assert!(marked, "axis {axis}: the cut faces are marked");
        }
    }
}
