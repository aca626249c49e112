//! The world model: an octree with everything a user's data says about it.
//!
//! A [`Model`] is what every command reads and writes. Beside the black voxels (a
//! [`LinearOctree`]) it keeps:
//!
//! - a [`Frame`]: the voxel size and where voxel `(0, 0, 0)` sits in the world (an
//!   OctoMap resolution, binvox's translate and scale, a scene's units);
//! - optional colours, a [`Layer`] of [`Rgba`] over black voxels (MagicaVoxel
//!   palettes, OctoMap `ColorOcTree`, a scene's object colours);
//! - optional known-free space, a [`LinearOctree`] disjoint from the black voxels
//!   (OctoMap's free cells); without it, only the black voxels are known;
//! - optional occupancy log-odds, a [`Layer`] of `f32` over black and free voxels
//!   (OctoMap `.ot` files), kept bit for bit.
//!
//! All parts share one space (the tree's depth and origin). Operations move them
//! together and follow these rules, each tested against a map of world cubes:
//!
//! - **Frames.** Two models combine only when their voxel sizes are equal and their
//!   placements differ by a whole number of voxels ([`Frame::offset_to`]); the
//!   result has the first operand's frame. Anything else is a [`ModelError::Frame`]
//!   naming both frames.
//! - **Values.** Colours and log-odds follow their voxels. Where both operands give a
//!   voxel a value, the first operand's wins.
//! - **Free space.** A voxel known in either operand (black, or free when it has a
//!   free layer) and not black in the result is free. The result has a free layer
//!   only when an operand has one. Intersection and difference keep the first
//!   operand's space, so knowledge outside it is dropped.
//! - **Geometry.** Rotations, mirrors and scales act about the *world* origin, and
//!   the frame's placement moves with them, so a point's world position follows the
//!   same rigid motion whatever the frame. Translation by voxels keeps the frame.

mod affine;
mod frame;
mod layer;
mod ops;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_affine;

pub use frame::{Frame, FrameMismatch, FRAME_TOLERANCE};
pub use layer::{Layer, LayerValue, Rgba};
use ops::first_wins;

use crate::linear::{grow, Axis, LinearOctree, OctreeError, SetOp};
use crate::Voxel;

/// What can go wrong combining or moving models.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ModelError {
    /// The two models' lattices do not line up.
    #[error(transparent)]
    Frame(#[from] FrameMismatch),
    /// A world-unit vector is not a whole number of voxels.
    #[error("{0}")]
    NotWhole(String),
    /// The octree operation failed (too deep, overflow).
    #[error(transparent)]
    Octree(#[from] OctreeError),
}

/// An octree with its frame, and optionally colours, known-free space and
/// occupancy log-odds. See the [module docs](self) for the rules.
///
/// ```
/// use tesseral::linear::LinearOctree;
/// use tesseral::model::{Frame, Model};
/// let a = Model::new(LinearOctree::from_voxels(2, [0, 0, 0], [[0, 0, 0]]).unwrap())
///     .with_frame(Frame::new(0.05, [1.0, 2.0, 3.0]));
/// let b = a.translate([1, 0, 0]).unwrap();
/// assert_eq!(b.frame, a.frame);
/// let u = a.union(&b).unwrap();
/// assert_eq!(u.tree.voxel_count(), 2);
/// assert_eq!(u.frame.voxel_size, 0.05);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    /// The black (occupied) voxels.
    pub tree: LinearOctree,
    /// Voxel size and placement in the world.
    pub frame: Frame,
    /// Colours of black voxels.
    pub colors: Option<Layer<Rgba>>,
    /// Voxels known to be free (disjoint from `tree`).
    pub free: Option<LinearOctree>,
    /// Occupancy log-odds of known voxels (black or free).
    pub log_odds: Option<Layer<f32>>,
}

/// Parts of a model on their way into one space.
struct Parts {
    tree: LinearOctree,
    colors: Option<Vec<(Rgba, LinearOctree)>>,
    free: Option<LinearOctree>,
    log_odds: Option<Vec<(f32, LinearOctree)>>,
}

fn regions<T: layer::LayerValue>(l: &Option<Layer<T>>) -> Option<Vec<(T, LinearOctree)>> {
    l.as_ref().map(|l| l.regions().to_vec())
}

impl Model {
    /// A model of `tree` alone, in the unit frame.
    #[must_use]
    pub fn new(tree: LinearOctree) -> Self {
        Self {
            tree,
            frame: Frame::default(),
            colors: None,
            free: None,
            log_odds: None,
        }
    }

    /// The same model in another frame.
    #[must_use]
    pub fn with_frame(mut self, frame: Frame) -> Self {
        self.frame = frame;
        self
    }

    /// The same model with colours, restricted to its black voxels.
    ///
    /// # Errors
    /// As [`Layer::restrict`].
    pub fn with_colors(mut self, colors: Layer<Rgba>) -> Result<Self, OctreeError> {
        self.colors = Some(colors.restrict(&self.tree)?);
        Ok(self)
    }

    /// A model from parts in any spaces: they are re-expressed in the tree's space,
    /// grown by root expansion to hold the others; colours are cut to the tree, free
    /// space cut away from it, and log-odds cut to the known voxels.
    ///
    /// # Errors
    /// As [`LinearOctree::resample`].
    pub fn from_parts(
        tree: LinearOctree,
        frame: Frame,
        colors: Option<Layer<Rgba>>,
        free: Option<LinearOctree>,
        log_odds: Option<Layer<f32>>,
    ) -> Result<Self, OctreeError> {
        Self::assemble(
            Parts {
                tree,
                colors: regions(&colors),
                free,
                log_odds: regions(&log_odds),
            },
            frame,
        )
    }

    fn assemble(p: Parts, frame: Frame) -> Result<Self, OctreeError> {
        let (mut depth, mut origin) = (p.tree.depth(), p.tree.origin());
        let mut boxes: Vec<(Voxel, Voxel)> = Vec::new();
        boxes.extend(p.free.as_ref().and_then(LinearOctree::bbox));
        for r in [&p.log_odds].into_iter().flatten() {
            boxes.extend(r.iter().filter_map(|(_, t)| t.bbox()));
        }
        for (lo, hi) in boxes {
            (depth, origin) = grow::grown_space(depth, origin, lo, hi)?;
        }
        let put = |t: LinearOctree| -> Result<LinearOctree, OctreeError> {
            if (t.depth(), t.origin()) == (depth, origin) {
                Ok(t)
            } else {
                Ok(t.resample(depth, origin)?.0)
            }
        };
        let tree = put(p.tree)?;
        let free = match p.free {
            Some(f) => Some(put(f)?.set_op_same_space(&tree, SetOp::Difference)),
            None => None,
        };
        let colors = match p.colors {
            Some(r) => Some(Layer::from_regions(depth, origin, r)?.restrict(&tree)?),
            None => None,
        };
        let log_odds = match p.log_odds {
            Some(r) => {
                let known = match &free {
                    Some(f) => tree.set_op_same_space(f, SetOp::Union),
                    None => tree.clone(),
                };
                Some(Layer::from_regions(depth, origin, r)?.restrict(&known)?)
            }
            None => None,
        };
        Ok(Self {
            tree,
            frame,
            colors,
            free,
            log_odds,
        })
    }

    /// Applies a tree operation to every part, keeping the frame given.
    fn map(
        &self,
        frame: Frame,
        f: impl Fn(&LinearOctree) -> Result<LinearOctree, OctreeError>,
    ) -> Result<Self, OctreeError> {
        let map_regions = |r: Option<Vec<(Rgba, LinearOctree)>>| -> Result<_, OctreeError> {
            r.map(|r| {
                r.iter()
                    .map(|(x, t)| Ok((*x, f(t)?)))
                    .collect::<Result<Vec<_>, _>>()
            })
            .transpose()
        };
        let log_odds = regions(&self.log_odds)
            .map(|r| {
                r.iter()
                    .map(|(x, t)| Ok((*x, f(t)?)))
                    .collect::<Result<Vec<_>, OctreeError>>()
            })
            .transpose()?;
        Self::assemble(
            Parts {
                tree: f(&self.tree)?,
                colors: map_regions(regions(&self.colors))?,
                free: self.free.as_ref().map(&f).transpose()?,
                log_odds,
            },
            frame,
        )
    }

    /// The model moved by `by` voxels; the frame is kept, so the world moves by
    /// `by × voxel_size`.
    ///
    /// # Errors
    /// As [`LinearOctree::translate`].
    pub fn translate(&self, by: [i64; 3]) -> Result<Self, ModelError> {
        Ok(self.map(self.frame, |t| t.translate(by))?)
    }

    /// The model moved by a world vector, which must be a whole number of voxels.
    ///
    /// # Errors
    /// [`ModelError::NotWhole`] giving the nearest whole vector; as
    /// [`Model::translate`].
    pub fn translate_world(&self, by: [f64; 3]) -> Result<Self, ModelError> {
        let v = self
            .frame
            .world_to_voxels(by)
            .map_err(ModelError::NotWhole)?;
        self.translate(v)
    }

    /// The model turned by `turns` quarter turns about `axis` through the world
    /// origin (right-handed: about z, +x goes to +y). The frame's placement turns
    /// with it.
    ///
    /// # Errors
    /// As [`LinearOctree::translate`] (the lattice is re-centred).
    pub fn rotate(&self, axis: Axis, turns: i32) -> Result<Self, ModelError> {
        let frame = Frame::new(
            self.frame.voxel_size,
            turn_point(self.frame.translate, axis, turns),
        );
        Ok(self.map(frame, |t| {
            // `LinearOctree::rotate` turns about the centre c of the tree's space;
            // about the lattice origin is that, then a shift by R(c) − c. With
            // doubled coordinates c is integral, and the shift is even.
            let c2: [i64; 3] =
                std::array::from_fn(|a| 2 * t.origin()[a] + (1i64 << t.depth().min(62)));
            let r = turn_point(c2.map(|c| c as f64), axis, turns).map(|c| c as i64);
            let shift: [i64; 3] = std::array::from_fn(|a| (r[a] - c2[a]) / 2);
            t.rotate(axis, turns).translate(shift)
        })?)
    }

    /// The model turned within its space about the space's centre, as
    /// [`LinearOctree::rotate`]: every part turns with the tree and the frame is kept,
    /// so in world terms the model turns about the centre of its space.
    ///
    /// # Errors
    /// As [`LinearOctree::resample`] (never, as every part shares the space).
    pub fn rotate_in_space(&self, axis: Axis, turns: i32) -> Result<Self, ModelError> {
        Ok(self.map(self.frame, |t| Ok(t.rotate(axis, turns)))?)
    }

    /// The model mirrored within its space, as [`LinearOctree::mirror`]; the frame is
    /// kept, so in world terms the mirror plane passes through the space's centre.
    ///
    /// # Errors
    /// As [`Model::rotate_in_space`].
    pub fn mirror_in_space(&self, axis: Axis) -> Result<Self, ModelError> {
        Ok(self.map(self.frame, |t| Ok(t.mirror(axis)))?)
    }

    /// The model mirrored in the plane `axis = 0` of the world; the frame's
    /// placement is mirrored too.
    ///
    /// # Errors
    /// As [`LinearOctree::translate`].
    pub fn mirror(&self, axis: Axis) -> Result<Self, ModelError> {
        let a = axis.index();
        let mut frame = self.frame;
        frame.translate[a] = -frame.translate[a];
        Ok(self.map(frame, |t| {
            // Within its space the mirror is x ↦ 2o + s − x; about 0 it is x ↦ −x.
            let mut shift = [0i64; 3];
            shift[a] = -(2 * t.origin()[a] + (1i64 << t.depth().min(62)));
            t.mirror(axis).translate(shift)
        })?)
    }

    /// The model scaled up by `2^s` about the world origin: each voxel becomes a
    /// block of `2^s` voxels per axis of the same size, and the frame's placement
    /// scales with it.
    ///
    /// # Errors
    /// As [`LinearOctree::scale_up`].
    pub fn scale_up(&self, s: u8) -> Result<Self, ModelError> {
        let k = f64::from(1u32 << s.min(31));
        let frame = Frame::new(self.frame.voxel_size, self.frame.translate.map(|c| c * k));
        Ok(self.map(frame, |t| t.scale_up(s))?)
    }

    /// The model scaled down by `2^s` about the world origin, conservatively (a coarse
    /// voxel is black when any of its fine voxels is). A coarse voxel whose fine
    /// voxels carry several values keeps the one with the lowest key; it is free
    /// when some fine voxel was free and none black.
    ///
    /// # Errors
    /// As [`LinearOctree::scale_down`].
    pub fn scale_down(&self, s: u8) -> Result<Self, ModelError> {
        let k = f64::from(1u32 << s.min(31));
        let frame = Frame::new(self.frame.voxel_size, self.frame.translate.map(|c| c / k));
        let tree = self.tree.scale_down(s)?;
        let down = |r: Option<Vec<(f32, LinearOctree)>>| -> Result<_, OctreeError> {
            r.map(|r| first_wins(r.iter().map(|(x, t)| Ok((*x, t.scale_down(s)?)))))
                .transpose()
        };
        let colors = regions(&self.colors)
            .map(|r| first_wins(r.iter().map(|(x, t)| Ok((*x, t.scale_down(s)?)))))
            .transpose()?;
        Ok(Self::assemble(
            Parts {
                tree,
                colors,
                free: self.free.as_ref().map(|f| f.scale_down(s)).transpose()?,
                log_odds: down(regions(&self.log_odds))?,
            },
            frame,
        )?)
    }

    /// Whether the model has colours, free space or log-odds.
    fn has_layers(&self) -> bool {
        self.colors.is_some() || self.free.is_some() || self.log_odds.is_some()
    }

    /// The complement within the space: the white voxels become black. Colours,
    /// free space and log-odds do not carry over (they describe the old voxels).
    #[must_use]
    pub fn complement(&self) -> Self {
        Self::new(self.tree.complement()).with_frame(self.frame)
    }

    /// The voxels whose state is known: black, plus free when there is a free layer.
    #[must_use]
    pub fn known(&self) -> LinearOctree {
        match &self.free {
            Some(f) => self.tree.set_op_same_space(f, SetOp::Union),
            None => self.tree.clone(),
        }
    }

    /// The model with every part re-expressed in the space `(depth, origin)`
    /// (voxels outside it are dropped).
    ///
    /// # Errors
    /// As [`LinearOctree::resample`].
    pub fn in_space(&self, depth: u8, origin: Voxel) -> Result<Self, OctreeError> {
        if (self.tree.depth(), self.tree.origin()) == (depth, origin) {
            return Ok(self.clone());
        }
        let put = |t: &LinearOctree| t.resample(depth, origin).map(|r| r.0);
        let relayer = |l: &Option<Layer<Rgba>>| {
            l.as_ref()
                .map(|l| l.map_regions(depth, origin, put))
                .transpose()
        };
        Ok(Self {
            tree: put(&self.tree)?,
            frame: self.frame,
            colors: relayer(&self.colors)?,
            free: self.free.as_ref().map(put).transpose()?,
            log_odds: self
                .log_odds
                .as_ref()
                .map(|l| l.map_regions(depth, origin, put))
                .transpose()?,
        })
    }

    /// Panics with the first broken invariant: each tree and layer valid, all in the
    /// tree's space, colours on black voxels, free space disjoint from them, log-odds
    /// on known voxels, and a positive, finite voxel size.
    pub fn assert_valid(&self) {
        self.tree.assert_valid();
        let space = (self.tree.depth(), self.tree.origin());
        assert!(
            self.frame.voxel_size.is_finite() && self.frame.voxel_size > 0.0,
            "voxel size {}",
            self.frame.voxel_size
        );
        assert!(
            self.frame.translate.iter().all(|c| c.is_finite()),
            "translate not finite"
        );
        if let Some(f) = &self.free {
            f.assert_valid();
            assert_eq!(
                (f.depth(), f.origin()),
                space,
                "free space in another space"
            );
            assert!(
                f.set_op_same_space(&self.tree, SetOp::Intersection)
                    .is_empty(),
                "free space overlaps black voxels"
            );
        }
        if let Some(c) = &self.colors {
            c.assert_valid();
            assert_eq!((c.depth(), c.origin()), space, "colours in another space");
            assert!(
                c.domain()
                    .set_op_same_space(&self.tree, SetOp::Difference)
                    .is_empty(),
                "colours on voxels that are not black"
            );
        }
        if let Some(l) = &self.log_odds {
            l.assert_valid();
            assert_eq!((l.depth(), l.origin()), space, "log-odds in another space");
            assert!(
                l.domain()
                    .set_op_same_space(&self.known(), SetOp::Difference)
                    .is_empty(),
                "log-odds on unknown voxels"
            );
        }
    }
}

/// A point turned by quarter turns about an axis through the origin, with the
/// convention of [`LinearOctree::rotate`]: about z, +x goes to +y; about x, +y to
/// +z; about y, +z to +x.
#[must_use]
pub fn turn_point(mut p: [f64; 3], axis: Axis, turns: i32) -> [f64; 3] {
    let (from, to) = match axis {
        Axis::X => (1, 2),
        Axis::Y => (2, 0),
        Axis::Z => (0, 1),
    };
    for _ in 0..turns.rem_euclid(4) {
        let (u, v) = (p[from], p[to]);
        p[from] = -v;
        p[to] = u;
    }
    p
}
