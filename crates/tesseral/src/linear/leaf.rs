//! One black leaf of a linear octree, packed into 8 bytes.

use crate::Voxel;

/// A black leaf: an aligned cube of `2^size_log2` voxels per axis, named by the
/// tesseral code of its lowest voxel, relative to the tree's origin.
///
/// Packing: a code has at most 63 bits and a block of size `2^k` has its low `3k`
/// code bits zero, so the leaf stores `code << 1` with its low `3k` bits set as a size
/// marker: `k = trailing_ones / 3`, and bit `3k` is always zero. Packed values sort
/// exactly as the codes do, so a sorted `Vec<Leaf>` is in tesseral order.
///
/// ```
/// use tesseral::linear::Leaf;
/// let leaf = Leaf::new(0o70, 1); // the 2x2x2 block at octal path 7
/// assert_eq!((leaf.code(), leaf.size_log2(), leaf.voxel_count()), (0o70, 1, 8));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[repr(transparent)]
pub struct Leaf(u64);

impl Leaf {
    /// The leaf of size `2^size_log2` whose lowest voxel has code `code`.
    ///
    /// It is a logic error for `code` not to be a multiple of `8^size_log2`, or for
    /// `size_log2` to exceed 21.
    #[inline]
    #[must_use]
    pub fn new(code: u64, size_log2: u8) -> Self {
        debug_assert!(size_log2 <= 21);
        debug_assert_eq!(code & low_mask(size_log2), 0, "unaligned leaf");
        Self((code << 1) | low_mask(size_log2))
    }

    /// The packed 8-byte representation.
    #[inline]
    #[must_use]
    pub fn packed(self) -> u64 {
        self.0
    }

    /// Rebuilds a leaf from [`Leaf::packed`].
    #[inline]
    #[must_use]
    pub fn from_packed(packed: u64) -> Self {
        Self(packed)
    }

    /// The side of the block as a power of two.
    #[inline]
    #[must_use]
    pub fn size_log2(self) -> u8 {
        (self.0.trailing_ones() / 3) as u8
    }

    /// The code of the block's lowest voxel.
    #[inline]
    #[must_use]
    pub fn code(self) -> u64 {
        (self.0 >> 1) & !low_mask(self.size_log2())
    }

    /// One past the code of the block's last voxel: the block covers `code()..end()`.
    #[inline]
    #[must_use]
    pub fn end(self) -> u64 {
        self.code() + self.voxel_count()
    }

    /// The number of voxels in the block, `8^size_log2`.
    #[inline]
    #[must_use]
    pub fn voxel_count(self) -> u64 {
        1 << (3 * u32::from(self.size_log2()))
    }

    /// Whether the voxel with code `code` lies in the block.
    #[inline]
    #[must_use]
    pub fn contains_code(self, code: u64) -> bool {
        code & !low_mask(self.size_log2()) == self.code()
    }
}

#[inline]
fn low_mask(size_log2: u8) -> u64 {
    (1u64 << (3 * u32::from(size_log2))) - 1
}

/// A black block in world coordinates: the cube `[min, min + 2^size_log2)` per axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Block {
    /// The lowest voxel of the block.
    pub min: Voxel,
    /// The side as a power of two.
    pub size_log2: u8,
}

impl Block {
    /// The side in voxels.
    #[must_use]
    pub fn size(&self) -> i64 {
        1 << self.size_log2
    }

    /// The highest voxel of the block (inclusive).
    #[must_use]
    pub fn max(&self) -> Voxel {
        let s = self.size() - 1;
        [self.min[0] + s, self.min[1] + s, self.min[2] + s]
    }
}
