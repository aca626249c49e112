//! The 24 orientations of a cube: rotations by multiples of 90° about the axes
//! (Ahuja & Nash §5, after Jackins & Tanimoto). Each maps voxels to voxels one to one,
//! so a rotated octree has exactly as many blocks as the original.

use std::fmt;
use std::str::FromStr;

use super::interfere::Wide;
use crate::linear::Block;
use crate::Voxel;

/// A rotation by multiples of 90°: a signed permutation of the axes with determinant
/// +1. Rotations turn about the lattice point (0, 0, 0).
///
/// As a map of points, `r.apply_point(p)[a] = ±p[perm[a]]`. A voxel is the unit cube
/// at its lowest corner, so the rotated voxel is the cube whose lowest corner is the
/// rotated cube's lowest corner: a negated axis maps voxel index `i` to `-i - 1`.
///
/// ```
/// use tesseral::motion::Rotation;
/// let r: Rotation = "z90".parse().unwrap();
/// assert_eq!(r.apply_point([1, 0, 0]), [0, 1, 0]); // x turns into y
/// assert_eq!(r.apply_voxel([0, 0, 0]), [-1, 0, 0]);
/// assert_eq!(Rotation::all().len(), 24);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Rotation {
    perm: [u8; 3],
    neg: [bool; 3],
}

impl Default for Rotation {
    fn default() -> Self {
        Self::IDENTITY
    }
}

/// What can go wrong parsing a rotation such as `z90,x180`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum RotationError {
    /// A part is not an axis (`x`, `y`, `z`) followed by 0, 90, 180, 270 or a negative
    /// multiple of 90.
    #[error("bad rotation {0:?}: expected parts like x90, y-90, z180 separated by commas")]
    Syntax(String),
    /// An index outside `0..24`.
    #[error("rotation index {0} is outside 0 to 23")]
    Index(usize),
}

impl Rotation {
    /// No rotation.
    pub const IDENTITY: Rotation = Rotation {
        perm: [0, 1, 2],
        neg: [false; 3],
    };

    /// The point reflection `p -> -p` (determinant −1, so not a rotation): used
    /// internally to reflect a solid for Minkowski differences.
    pub(crate) const REFLECTION: Rotation = Rotation {
        perm: [0, 1, 2],
        neg: [true; 3],
    };

    /// All 24 rotations, identity first, in a fixed order (so an index names one).
    #[must_use]
    pub fn all() -> Vec<Rotation> {
        const PERMS: [[u8; 3]; 6] = [
            [0, 1, 2],
            [0, 2, 1],
            [1, 0, 2],
            [1, 2, 0],
            [2, 0, 1],
            [2, 1, 0],
        ];
        let mut out = Vec::with_capacity(24);
        for perm in PERMS {
            for signs in 0..8u8 {
                let neg = [signs & 1 != 0, signs & 2 != 0, signs & 4 != 0];
                let r = Rotation { perm, neg };
                if r.determinant() == 1 {
                    out.push(r);
                }
            }
        }
        out
    }

    /// The rotation with index `i` in [`Rotation::all`].
    ///
    /// # Errors
    /// [`RotationError::Index`] when `i >= 24`.
    pub fn from_index(i: usize) -> Result<Rotation, RotationError> {
        Self::all().get(i).copied().ok_or(RotationError::Index(i))
    }

    /// A quarter turn repeated `quarter_turns` times about `axis` (0 = x, 1 = y, 2 = z),
    /// counter-clockwise when seen from the positive end of the axis.
    ///
    /// # Panics
    /// When `axis > 2`.
    #[must_use]
    pub fn about_axis(axis: usize, quarter_turns: i32) -> Rotation {
        assert!(axis < 3, "axis {axis} is not 0, 1 or 2");
        let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
        // One quarter turn about `axis`: u -> w, w -> -u.
        let mut quarter = Rotation::IDENTITY;
        quarter.perm[w] = u as u8;
        quarter.perm[u] = w as u8;
        quarter.neg[u] = true;
        let mut r = Rotation::IDENTITY;
        for _ in 0..quarter_turns.rem_euclid(4) {
            r = quarter.compose(r);
        }
        r
    }

    /// `self ∘ first`: apply `first`, then `self`.
    #[must_use]
    pub fn compose(self, first: Rotation) -> Rotation {
        let mut out = Rotation::IDENTITY;
        for a in 0..3 {
            let p = usize::from(self.perm[a]);
            out.perm[a] = first.perm[p];
            out.neg[a] = self.neg[a] ^ first.neg[p];
        }
        out
    }

    /// The inverse rotation.
    #[must_use]
    pub fn inverse(self) -> Rotation {
        let mut out = Rotation::IDENTITY;
        for a in 0..3 {
            let p = usize::from(self.perm[a]);
            out.perm[p] = a as u8;
            out.neg[p] = self.neg[a];
        }
        out
    }

    /// Whether this is the identity.
    #[must_use]
    pub fn is_identity(self) -> bool {
        self == Self::IDENTITY
    }

    fn determinant(self) -> i32 {
        // Sign of the permutation times the product of the signs.
        let [a, b, c] = self.perm;
        let inversions = u8::from(a > b) + u8::from(a > c) + u8::from(b > c);
        let mut d = if inversions % 2 == 0 { 1 } else { -1 };
        for n in self.neg {
            if n {
                d = -d;
            }
        }
        d
    }

    /// Rotates a lattice point.
    #[inline]
    #[must_use]
    pub fn apply_point(self, p: Voxel) -> Voxel {
        let mut out = [0; 3];
        for a in 0..3 {
            let v = p[usize::from(self.perm[a])];
            out[a] = if self.neg[a] { -v } else { v };
        }
        out
    }

    /// Rotates a voxel (the unit cube at its lowest corner).
    #[inline]
    #[must_use]
    pub fn apply_voxel(self, v: Voxel) -> Voxel {
        self.apply_cube(v, 1)
    }

    /// Rotates the cube `[min, min + side)` per axis; returns the new lowest corner.
    #[inline]
    #[must_use]
    pub fn apply_cube(self, min: Voxel, side: i64) -> Voxel {
        let mut out = [0; 3];
        for a in 0..3 {
            let v = min[usize::from(self.perm[a])];
            out[a] = if self.neg[a] { -(v + side) } else { v };
        }
        out
    }

    /// Maps the half-open box `[lo, hi)` of voxels (each cube mapped as by
    /// [`Rotation::apply_cube`]); returns the new `(lo, hi)`.
    #[inline]
    pub(crate) fn apply_box(self, lo: Wide, hi: Wide) -> (Wide, Wide) {
        let mut l = [0; 3];
        let mut h = [0; 3];
        for a in 0..3 {
            let p = usize::from(self.perm[a]);
            if self.neg[a] {
                l[a] = -hi[p];
                h[a] = -lo[p];
            } else {
                l[a] = lo[p];
                h[a] = hi[p];
            }
        }
        (l, h)
    }

    /// Rotates a block.
    #[must_use]
    pub fn apply_block(self, b: Block) -> Block {
        Block {
            min: self.apply_cube(b.min, b.size()),
            size_log2: b.size_log2,
        }
    }
}

impl fmt::Display for Rotation {
    /// Writes the rotation as its image of the axes, such as `+y-x+z`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for a in 0..3 {
            let sign = if self.neg[a] { '-' } else { '+' };
            let axis = ['x', 'y', 'z'][usize::from(self.perm[a])];
            write!(f, "{sign}{axis}")?;
        }
        Ok(())
    }
}

impl FromStr for Rotation {
    type Err = RotationError;

    /// Parses a comma-separated list of turns applied left to right, such as
    /// `z90,x180` (each an axis and a multiple of 90 degrees), or an index `0..24`
    /// into [`Rotation::all`]. The empty string is the identity.
    fn from_str(s: &str) -> Result<Rotation, RotationError> {
        let s = s.trim();
        if let Ok(i) = s.parse::<usize>() {
            return Self::from_index(i);
        }
        let mut r = Rotation::IDENTITY;
        for part in s.split(',').map(str::trim).filter(|p| !p.is_empty()) {
            let bad = || RotationError::Syntax(part.to_owned());
            let mut chars = part.chars();
            let axis = match chars.next().map(|c| c.to_ascii_lowercase()) {
                Some('x') => 0,
                Some('y') => 1,
                Some('z') => 2,
                _ => return Err(bad()),
            };
            let degrees: i64 = chars.as_str().parse().map_err(|_| bad())?;
            if degrees % 90 != 0 {
                return Err(bad());
            }
            let turns = i32::try_from((degrees / 90).rem_euclid(4)).map_err(|_| bad())?;
            r = Rotation::about_axis(axis, turns).compose(r);
        }
        Ok(r)
    }
}
