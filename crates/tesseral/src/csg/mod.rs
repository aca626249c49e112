//! Solids from primitives and set operations (constructive solid geometry), turned into
//! linear octrees (Harakal & Chmúrny §4, Figs. 4-6).
//!
//! - [`Shape`]: the primitives in their local frame: the paper's four (prism/box,
//!   spheroid/ellipsoid, elliptic cylinder, truncated elliptic cone) and torus,
//!   capsule, half-space and convex polyhedron.
//! - [`Solid`]: a tree of shapes, set operations (union, intersection, difference,
//!   negation, nested to any depth), transforms (rotations α, β, γ in degrees about x,
//!   y and z applied in that order, a uniform scale, then a position) and colours.
//! - [`Csg`]: a solid compiled for evaluation: a flat list of primitives, each with its
//!   world-to-local map, and the operation tree over them. It classifies octree cells
//!   conservatively ([`crate::linear::Classifier`]) and builds the octree ([`Csg::build`]).
//! - [`scene`]: the `.tss` scene text format and its parser.
//!
//! # Exactness
//! A voxel is black exactly when its centre satisfies the point predicate
//! ([`Csg::contains`]). A cell is decided `Inside`/`Outside` only when the ball around
//! its voxel centres lies wholly on one side of every surface that matters: each
//! primitive has a 1-Lipschitz bound on the distance to its surface
//! ([`Shape::bound`]), so one evaluation at the cell centre decides the whole cell.
//! Cells the test cannot decide are split; single voxels are decided by the exact
//! predicate. The build therefore equals a dense per-voxel evaluation, voxel for voxel,
//! and its cost follows the surface: only cells the surface may cross are split.

mod budget;
mod build;
mod colours;
mod compile;
mod index;
mod prim;
pub mod scene;
mod shape;
mod stream;
mod stream_colours;

#[cfg(test)]
pub(crate) mod tests;
#[cfg(test)]
mod tests_index;

pub use colours::colour_parts;
pub use compile::{Csg, DEFAULT_MAX_LEAVES};
pub use scene::{Scene, SceneError};
pub use shape::Shape;
pub(crate) use stream::clip_leaf;
pub use stream::{StreamPlan, StreamProgress, STREAM_CELL_LOG2};
pub use stream_colours::ColouredSink;

use crate::linear::OctreeError;

/// An RGB colour, 8 bits per channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Colour(pub [u8; 3]);

impl Colour {
    /// The named colours a scene may use, with their values.
    pub const NAMED: &'static [(&'static str, [u8; 3])] = &[
        ("red", [200, 60, 50]),
        ("green", [80, 160, 70]),
        ("blue", [60, 100, 200]),
        ("yellow", [230, 200, 60]),
        ("orange", [235, 140, 50]),
        ("purple", [140, 80, 170]),
        ("cyan", [70, 180, 200]),
        ("magenta", [200, 70, 160]),
        ("white", [235, 235, 235]),
        ("grey", [150, 150, 150]),
        ("gray", [150, 150, 150]),
        ("black", [40, 40, 40]),
        ("brown", [140, 95, 60]),
        ("olive", [110, 120, 60]),
        ("khaki", [180, 170, 110]),
        ("navy", [40, 50, 110]),
        ("teal", [50, 130, 130]),
        ("pink", [230, 150, 170]),
        ("silver", [190, 195, 200]),
        ("gold", [210, 170, 60]),
        ("steel", [120, 135, 150]),
        ("sand", [210, 190, 140]),
    ];

    /// The colours given, in turn, to top-level objects that name none.
    pub const PALETTE: [Colour; 8] = [
        Colour([200, 120, 70]),
        Colour([80, 140, 200]),
        Colour([120, 180, 90]),
        Colour([210, 180, 80]),
        Colour([170, 110, 180]),
        Colour([90, 180, 180]),
        Colour([200, 90, 110]),
        Colour([160, 160, 160]),
    ];

    /// Looks up a colour by name (see [`Colour::NAMED`]) or as `#rrggbb`.
    ///
    /// ```
    /// use tesseral::csg::Colour;
    /// assert_eq!(Colour::parse("#ff8000"), Some(Colour([255, 128, 0])));
    /// assert!(Colour::parse("red").is_some() && Colour::parse("nope").is_none());
    /// ```
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        if let Some(hex) = s.strip_prefix('#') {
            if hex.len() != 6 || !hex.bytes().all(|b| b.is_ascii_hexdigit()) {
                return None;
            }
            let v = u32::from_str_radix(hex, 16).ok()?;
            return Some(Colour([(v >> 16) as u8, (v >> 8) as u8, v as u8]));
        }
        let lower = s.to_ascii_lowercase();
        Self::NAMED
            .iter()
            .find(|(n, _)| *n == lower)
            .map(|(_, c)| Colour(*c))
    }
}

/// A similarity transform: `p ↦ R (s p) + at`, with `R = Rz(γ) Ry(β) Rx(α)`: the
/// rotations about x, y and z applied in that order (Harakal & Chmúrny §4), after a
/// uniform scale `s` and before the translation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transform {
    /// The rotation matrix, row-major.
    pub rot: [[f64; 3]; 3],
    /// The uniform scale factor (positive).
    pub scale: f64,
    /// The translation, applied last.
    pub at: [f64; 3],
}

impl Default for Transform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Transform {
    /// The identity.
    pub const IDENTITY: Self = Self {
        rot: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        scale: 1.0,
        at: [0.0; 3],
    };

    /// The rotation by `α, β, γ` degrees about x, then y, then z. A multiple of 90°
    /// turns exactly (its sine and cosine are 0 and ±1, as OpenSCAD's are), so a
    /// quarter-turned box's faces stay where they were, not 10⁻¹⁶ off.
    ///
    /// ```
    /// use tesseral::csg::Transform;
    /// let t = Transform::rotation([0.0, 0.0, 90.0]);
    /// assert_eq!(t.apply([1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]);
    /// let t = Transform::rotation([0.0, 0.0, 30.0]);
    /// let p = t.apply([1.0, 0.0, 0.0]);
    /// assert!((p[0] - 0.75f64.sqrt()).abs() < 1e-12 && (p[1] - 0.5).abs() < 1e-12);
    /// ```
    #[must_use]
    pub fn rotation(deg: [f64; 3]) -> Self {
        let [(sa, ca), (sb, cb), (sg, cg)] = deg.map(crate::linear::sin_cos_degrees);
        let rx = [[1.0, 0.0, 0.0], [0.0, ca, -sa], [0.0, sa, ca]];
        let ry = [[cb, 0.0, sb], [0.0, 1.0, 0.0], [-sb, 0.0, cb]];
        let rz = [[cg, -sg, 0.0], [sg, cg, 0.0], [0.0, 0.0, 1.0]];
        Self {
            rot: matmul(rz, matmul(ry, rx)),
            ..Self::IDENTITY
        }
    }

    /// The translation by `at`.
    #[must_use]
    pub fn translation(at: [f64; 3]) -> Self {
        Self {
            at,
            ..Self::IDENTITY
        }
    }

    /// The uniform scale by `s`.
    #[must_use]
    pub fn scaling(s: f64) -> Self {
        Self {
            scale: s,
            ..Self::IDENTITY
        }
    }

    /// `self ∘ inner`: first `inner`, then `self`.
    #[must_use]
    pub fn then_inner(&self, inner: &Transform) -> Transform {
        let moved = self.apply(inner.at);
        let rot = matmul(self.rot, inner.rot);
        Transform {
            rot,
            scale: self.scale * inner.scale,
            at: moved,
        }
    }

    /// Applies the transform to a point.
    #[must_use]
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        let r = &self.rot;
        let s = self.scale;
        [
            s * (r[0][0] * p[0] + r[0][1] * p[1] + r[0][2] * p[2]) + self.at[0],
            s * (r[1][0] * p[0] + r[1][1] * p[1] + r[1][2] * p[2]) + self.at[1],
            s * (r[2][0] * p[0] + r[2][1] * p[1] + r[2][2] * p[2]) + self.at[2],
        ]
    }
}

pub(crate) fn matmul(a: [[f64; 3]; 3], b: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut m = [[0.0; 3]; 3];
    for (i, row) in m.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    m
}

/// A solid: primitives combined by set operations, with transforms and colours on any
/// node. Build it with the constructors and the chaining methods, then
/// [`Solid::compile`] it.
///
/// Each chaining method wraps what is there already, so it applies *after* it:
/// `.rotate(..).at(..)` rotates about the local origin, then moves.
///
/// ```
/// use tesseral::csg::{Shape, Solid};
/// let solid = Solid::shape(Shape::cuboid([8.0, 8.0, 8.0]))
///     .difference([Solid::shape(Shape::sphere(5.0))])
///     .at([8.0, 8.0, 8.0]);
/// let tree = solid.compile().unwrap().build(4, [0, 0, 0]).unwrap();
/// assert!(tree.contains([4, 4, 4]) && !tree.contains([8, 8, 8]));
/// ```
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Solid {
    /// A primitive in its local frame.
    Primitive(Shape),
    /// The points in any of the solids (empty for none).
    Union(Vec<Solid>),
    /// The points in all of the solids (all space for none).
    Intersection(Vec<Solid>),
    /// The points of the first solid in none of the others.
    Difference(Vec<Solid>),
    /// The complement.
    Not(Box<Solid>),
    /// A solid moved by a transform.
    Transformed(Box<Solid>, Transform),
    /// A solid with a colour (inner colours override it).
    Coloured(Box<Solid>, Colour),
}

impl Solid {
    /// A primitive.
    #[must_use]
    pub fn shape(shape: Shape) -> Self {
        Solid::Primitive(shape)
    }

    /// The union of solids.
    #[must_use]
    pub fn union(parts: impl IntoIterator<Item = Solid>) -> Self {
        Solid::Union(parts.into_iter().collect())
    }

    /// The intersection of solids.
    #[must_use]
    pub fn intersection(parts: impl IntoIterator<Item = Solid>) -> Self {
        Solid::Intersection(parts.into_iter().collect())
    }

    /// `self` minus each of `cutters`.
    #[must_use]
    pub fn difference(self, cutters: impl IntoIterator<Item = Solid>) -> Self {
        let mut v = vec![self];
        v.extend(cutters);
        Solid::Difference(v)
    }

    /// The complement of `self`.
    #[must_use]
    pub fn negate(self) -> Self {
        Solid::Not(Box::new(self))
    }

    /// Applies `t` after what is there.
    #[must_use]
    pub fn transform(self, t: Transform) -> Self {
        Solid::Transformed(Box::new(self), t)
    }

    /// Rotates by `[α, β, γ]` degrees about x, then y, then z.
    #[must_use]
    pub fn rotate(self, deg: [f64; 3]) -> Self {
        self.transform(Transform::rotation(deg))
    }

    /// Moves by `at`.
    #[must_use]
    pub fn at(self, at: [f64; 3]) -> Self {
        self.transform(Transform::translation(at))
    }

    /// Scales uniformly by `s` about the origin.
    #[must_use]
    pub fn scaled(self, s: f64) -> Self {
        self.transform(Transform::scaling(s))
    }

    /// Gives the solid a colour.
    #[must_use]
    pub fn colour(self, c: Colour) -> Self {
        Solid::Coloured(Box::new(self), c)
    }

    /// Compiles the solid for evaluation: transforms are folded into each primitive.
    ///
    /// # Runtime
    /// O(nodes).
    ///
    /// # Errors
    /// [`CsgError::Invalid`] for a bad primitive parameter, a non-positive scale, or a
    /// difference of nothing.
    pub fn compile(&self) -> Result<Csg, CsgError> {
        Csg::compile(self)
    }
}

/// What can go wrong compiling or building a solid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CsgError {
    /// A primitive parameter, scale or operation is invalid.
    #[error("invalid solid: {0}")]
    Invalid(String),
    /// The octree space is invalid (too deep).
    #[error(transparent)]
    Octree(#[from] OctreeError),
    /// The octree would need more leaves than the limit allows.
    #[error("the octree would exceed {limit} leaves; lower the depth or raise the limit")]
    TooManyLeaves {
        /// The limit that was hit.
        limit: usize,
    },
}
