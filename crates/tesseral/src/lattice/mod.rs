//! The lattice's vocabulary, defined once and shared by every module: an [`Axis`],
//! one of the six face [`Direction`]s, a set of them ([`Directions`]), an exposed
//! [`Face`] of a voxel, and the 27-cell [`Neighbourhood`] of a voxel.
//!
//! Directions are numbered `2·axis + positive`: 0 = −x, 1 = +x, 2 = −y, 3 = +y,
//! 4 = −z, 5 = +z, so the opposite of a direction flips its low bit. A neighbourhood
//! holds the cell at offset `(dx, dy, dz)` (each in −1..=1) at bit
//! `(dx+1) + 3(dy+1) + 9(dz+1)`; bit 13 is the centre.
//!
//! ```
//! use tesseral::lattice::{Direction, Neighbourhood};
//! let n = Neighbourhood::EMPTY.with([0, 0, 0]).with([1, 0, 0]);
//! assert!(n.has_centre());
//! assert!(n.has_face(Direction::PosX));
//! assert_eq!(n.faces().len(), 1);
//! assert_eq!(Direction::PosX.opposite(), Direction::NegX);
//! ```

mod direction;
mod neighbourhood;

pub use crate::code::Axis;
pub use direction::{Direction, Directions};
pub use neighbourhood::Neighbourhood;

use crate::Voxel;

/// One exposed face (a plaquette of the surface): the face of the black voxel `voxel`
/// that points in direction `dir` towards a white voxel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Face {
    /// The black voxel that owns the face.
    pub voxel: Voxel,
    /// The direction the face points in.
    pub dir: Direction,
}

impl Face {
    /// The white voxel on the other side of the face.
    ///
    /// ```
    /// use tesseral::lattice::{Direction, Face};
    /// let f = Face { voxel: [1, 2, 3], dir: Direction::PosZ };
    /// assert_eq!(f.outside(), [1, 2, 4]);
    /// ```
    #[inline]
    #[must_use]
    pub fn outside(&self) -> Voxel {
        self.dir.step(self.voxel)
    }
}

#[cfg(test)]
mod tests;
