//! Where a tree stands in the world: [`Placement`] and [`Placed`].

use super::IBox;
use crate::linear::LinearOctree;
use crate::motion::orient::Rotation;
use crate::motion::view::Traversable;
use crate::Voxel;

/// Where a tree is put in the world: a voxel `v` of the tree lands on
/// `rotation.apply_voxel(v) + offset`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Placement {
    /// Applied first, about the lattice point (0, 0, 0) of the tree's coordinates.
    pub rotation: Rotation,
    /// Added after the rotation.
    pub offset: Voxel,
}

impl Placement {
    /// A pure translation by `offset`.
    #[must_use]
    pub fn at(offset: Voxel) -> Placement {
        Placement {
            rotation: Rotation::IDENTITY,
            offset,
        }
    }

    /// Where voxel `v` of the tree lands.
    #[must_use]
    pub fn apply_voxel(&self, v: Voxel) -> Voxel {
        let r = self.rotation.apply_voxel(v);
        [
            r[0] + self.offset[0],
            r[1] + self.offset[1],
            r[2] + self.offset[2],
        ]
    }

    /// The world box `w` seen in the placed tree's own coordinates (the inverse map).
    #[inline]
    pub(crate) fn unplace_box(&self, w: &IBox) -> IBox {
        let lo = [0, 1, 2].map(|a| w.lo[a] - i128::from(self.offset[a]));
        let hi = [0, 1, 2].map(|a| w.hi[a] - i128::from(self.offset[a]));
        if self.rotation.is_identity() {
            return IBox { lo, hi };
        }
        let (lo, hi) = self.rotation.inverse().apply_box(lo, hi);
        IBox { lo, hi }
    }

    /// The half-open box `b` (in the tree's coordinates) placed in the world.
    #[inline]
    pub(crate) fn place_box(&self, b: &IBox) -> IBox {
        if self.rotation.is_identity() {
            return IBox {
                lo: [0, 1, 2].map(|a| b.lo[a] + i128::from(self.offset[a])),
                hi: [0, 1, 2].map(|a| b.hi[a] + i128::from(self.offset[a])),
            };
        }
        let (lo, hi) = self.rotation.apply_box(b.lo, b.hi);
        IBox {
            lo: [0, 1, 2].map(|a| lo[a] + i128::from(self.offset[a])),
            hi: [0, 1, 2].map(|a| hi[a] + i128::from(self.offset[a])),
        }
    }
}

/// A tree with its placement in the world: a [`LinearOctree`] or a prepared
/// [`BoxTree`](crate::motion::BoxTree).
#[derive(Debug)]
pub struct Placed<'t, T: Traversable + ?Sized = LinearOctree> {
    /// The tree, in its own coordinates.
    pub tree: &'t T,
    /// Where it is put.
    pub place: Placement,
}

impl<T: Traversable + ?Sized> Clone for Placed<'_, T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T: Traversable + ?Sized> Copy for Placed<'_, T> {}

impl<'t, T: Traversable + ?Sized> Placed<'t, T> {
    /// `tree` where it stands (identity placement).
    #[must_use]
    pub fn fixed(tree: &'t T) -> Self {
        Placed {
            tree,
            place: Placement::default(),
        }
    }

    /// `tree` placed by `place`.
    #[must_use]
    pub fn new(tree: &'t T, place: Placement) -> Self {
        Placed { tree, place }
    }

    #[inline]
    pub(crate) fn world_box(&self, n: &T::Node) -> IBox {
        self.place.place_box(&self.tree.node_box(n))
    }
}
