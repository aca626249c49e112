//! The 3×3×3 neighbourhood of a voxel as 27 bits.

use super::{Direction, Directions};

/// The occupancy of the 3×3×3 cells around a voxel: the cell at offset
/// `(dx, dy, dz)` (each in −1..=1) is bit `(dx+1) + 3(dy+1) + 9(dz+1)`, so bit 13 is
/// the voxel itself. Bits 27..32 are always clear.
///
/// ```
/// use tesseral::lattice::{Direction, Neighbourhood};
/// let n = Neighbourhood::from_bits(1 << 13 | 1 << 22);
/// assert!(n.has_face(Direction::PosZ));
/// assert_eq!(n.complement().len(), 25);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[repr(transparent)]
pub struct Neighbourhood(u32);

/// The bit of each direction's face neighbour.
const FACE_BIT: [u32; 6] = [12, 14, 10, 16, 4, 22];

impl Neighbourhood {
    /// No cell.
    pub const EMPTY: Neighbourhood = Neighbourhood(0);
    /// All 27 cells.
    pub const FULL: Neighbourhood = Neighbourhood((1 << 27) - 1);
    /// The bit of the centre cell.
    pub const CENTRE_BIT: u32 = 13;
    /// The 20 cells that share only an edge or a corner with the centre.
    pub const EDGES_AND_CORNERS: Neighbourhood = {
        let mut m = 0u32;
        let mut b = 0;
        while b < 27 {
            let d = [b % 3, (b / 3) % 3, b / 9];
            let off_centre = (d[0] != 1) as u32 + (d[1] != 1) as u32 + (d[2] != 1) as u32;
            if off_centre >= 2 {
                m |= 1 << b;
            }
            b += 1;
        }
        Neighbourhood(m)
    };

    /// The neighbourhood with bits `bits`; bits 27 and above are dropped.
    #[inline]
    #[must_use]
    pub const fn from_bits(bits: u32) -> Neighbourhood {
        Neighbourhood(bits & Self::FULL.0)
    }

    /// The 27 bits.
    #[inline]
    #[must_use]
    pub const fn bits(self) -> u32 {
        self.0
    }

    /// The bit of the cell at `offset` (each component in −1..=1).
    #[inline]
    #[must_use]
    pub const fn bit(offset: [i64; 3]) -> u32 {
        ((offset[0] + 1) + 3 * (offset[1] + 1) + 9 * (offset[2] + 1)) as u32
    }

    /// The bit of the face neighbour in direction `d`.
    #[inline]
    #[must_use]
    pub const fn face_bit(d: Direction) -> u32 {
        FACE_BIT[d as usize]
    }

    /// Whether the cell at `offset` (each component in −1..=1) is set.
    #[inline]
    #[must_use]
    pub const fn contains(self, offset: [i64; 3]) -> bool {
        self.0 >> Self::bit(offset) & 1 == 1
    }

    /// The neighbourhood with the cell at `offset` set.
    #[inline]
    #[must_use]
    pub const fn with(self, offset: [i64; 3]) -> Neighbourhood {
        Neighbourhood(self.0 | 1 << Self::bit(offset))
    }

    /// Whether the centre cell is set.
    #[inline]
    #[must_use]
    pub const fn has_centre(self) -> bool {
        self.0 >> Self::CENTRE_BIT & 1 == 1
    }

    /// Whether the face neighbour in direction `d` is set.
    #[inline]
    #[must_use]
    pub const fn has_face(self, d: Direction) -> bool {
        self.0 >> FACE_BIT[d as usize] & 1 == 1
    }

    /// The directions whose face neighbour is set.
    #[inline]
    #[must_use]
    pub const fn faces(self) -> Directions {
        let x = self.0;
        Directions::from_bits(
            ((x >> 12) & 1
                | ((x >> 14) & 1) << 1
                | ((x >> 10) & 1) << 2
                | ((x >> 16) & 1) << 3
                | ((x >> 4) & 1) << 4
                | ((x >> 22) & 1) << 5) as u8,
        )
    }

    /// The cells not set (of the 27).
    #[inline]
    #[must_use]
    pub const fn complement(self) -> Neighbourhood {
        Neighbourhood(!self.0 & Self::FULL.0)
    }

    /// The cells set in both.
    #[inline]
    #[must_use]
    pub const fn and(self, other: Neighbourhood) -> Neighbourhood {
        Neighbourhood(self.0 & other.0)
    }

    /// How many cells are set.
    #[inline]
    #[must_use]
    pub const fn len(self) -> u32 {
        self.0.count_ones()
    }

    /// Whether no cell is set.
    #[inline]
    #[must_use]
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The offsets of the set cells, in bit order.
    pub fn offsets(self) -> impl Iterator<Item = [i64; 3]> {
        (0..27i64)
            .filter(move |&b| self.0 >> b & 1 == 1)
            .map(|b| [b % 3 - 1, (b / 3) % 3 - 1, b / 9 - 1])
    }
}
