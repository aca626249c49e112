//! The six face directions and sets of them.

use super::Axis;
use crate::Voxel;

/// One of the six face directions of a voxel, numbered `2·axis + positive`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(u8)]
pub enum Direction {
    /// −x, west.
    NegX = 0,
    /// +x, east.
    PosX = 1,
    /// −y, south.
    NegY = 2,
    /// +y, north.
    PosY = 3,
    /// −z, down.
    NegZ = 4,
    /// +z, up.
    PosZ = 5,
}

impl Direction {
    /// The six directions in order −x, +x, −y, +y, −z, +z.
    pub const ALL: [Direction; 6] = [
        Direction::NegX,
        Direction::PosX,
        Direction::NegY,
        Direction::PosY,
        Direction::NegZ,
        Direction::PosZ,
    ];

    /// The direction numbered `i` (0..6), or `None`.
    ///
    /// ```
    /// use tesseral::lattice::Direction;
    /// assert_eq!(Direction::from_index(3), Some(Direction::PosY));
    /// assert_eq!(Direction::from_index(6), None);
    /// ```
    #[inline]
    #[must_use]
    pub const fn from_index(i: u8) -> Option<Direction> {
        if i < 6 {
            Some(Direction::ALL[i as usize])
        } else {
            None
        }
    }

    /// The direction along `axis`, positive or negative.
    #[inline]
    #[must_use]
    pub const fn along(axis: Axis, positive: bool) -> Direction {
        Direction::ALL[2 * axis as usize + positive as usize]
    }

    /// Its number, 0..6.
    #[inline]
    #[must_use]
    pub const fn index(self) -> usize {
        self as usize
    }

    /// The axis it runs along.
    #[inline]
    #[must_use]
    pub const fn axis(self) -> Axis {
        Axis::ALL[self as usize >> 1]
    }

    /// Whether it points up its axis.
    #[inline]
    #[must_use]
    pub const fn is_positive(self) -> bool {
        self as u8 & 1 == 1
    }

    /// The opposite direction: −x ↔ +x and so on.
    #[inline]
    #[must_use]
    pub const fn opposite(self) -> Direction {
        Direction::ALL[(self as usize) ^ 1]
    }

    /// The unit step, e.g. `[0, -1, 0]` for −y.
    #[inline]
    #[must_use]
    pub const fn unit(self) -> [i64; 3] {
        let mut u = [0; 3];
        u[self as usize >> 1] = if self.is_positive() { 1 } else { -1 };
        u
    }

    /// The neighbour of `v` in this direction. Coordinates wrap at ±2^63.
    ///
    /// ```
    /// use tesseral::lattice::Direction;
    /// assert_eq!(Direction::NegY.step([1, 2, 3]), [1, 1, 3]);
    /// ```
    #[inline]
    #[must_use]
    pub const fn step(self, v: Voxel) -> Voxel {
        let mut n = v;
        let a = self as usize >> 1;
        n[a] = if self.is_positive() {
            n[a].wrapping_add(1)
        } else {
            n[a].wrapping_sub(1)
        };
        n
    }
}

/// A set of directions: bit `d` for [`Direction`] number `d`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Directions(u8);

impl Directions {
    /// No direction.
    pub const EMPTY: Directions = Directions(0);
    /// All six.
    pub const ALL: Directions = Directions(0b11_1111);

    /// The set with bits `bits` (bit `d` for direction `d`); bits above 5 are dropped.
    #[inline]
    #[must_use]
    pub const fn from_bits(bits: u8) -> Directions {
        Directions(bits & 0b11_1111)
    }

    /// The bits: bit `d` for direction `d`.
    #[inline]
    #[must_use]
    pub const fn bits(self) -> u8 {
        self.0
    }

    /// Whether `d` is in the set.
    #[inline]
    #[must_use]
    pub const fn contains(self, d: Direction) -> bool {
        self.0 >> d as u8 & 1 == 1
    }

    /// The set with `d` added.
    #[inline]
    #[must_use]
    pub const fn with(self, d: Direction) -> Directions {
        Directions(self.0 | 1 << d as u8)
    }

    /// How many directions it holds.
    #[inline]
    #[must_use]
    pub const fn len(self) -> u32 {
        self.0.count_ones()
    }

    /// Whether it is empty.
    #[inline]
    #[must_use]
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The directions not in the set.
    #[inline]
    #[must_use]
    pub const fn complement(self) -> Directions {
        Directions(!self.0 & 0b11_1111)
    }

    /// Only the positive directions of the set (+x, +y, +z): each face-adjacent
    /// pair of voxels counted once.
    #[inline]
    #[must_use]
    pub const fn positive(self) -> Directions {
        Directions(self.0 & 0b10_1010)
    }

    /// The directions in the set, in order.
    pub fn iter(self) -> impl Iterator<Item = Direction> {
        Direction::ALL
            .into_iter()
            .filter(move |&d| self.contains(d))
    }
}
