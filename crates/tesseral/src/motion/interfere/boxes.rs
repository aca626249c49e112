//! Boxes in world coordinates: [`Aabb`] (inclusive voxels, the public answer) and
//! [`IBox`] (half-open, 128-bit, what the traversals compute with), and exact
//! squared gaps between them ([`Gap2`]).

use serde::Serialize;

use crate::Voxel;

/// A box of voxels `min..=max` per axis (both inclusive), in world coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub struct Aabb {
    /// The lowest voxel.
    pub min: Voxel,
    /// The highest voxel (inclusive).
    pub max: Voxel,
}

impl Aabb {
    /// The number of voxels in the box.
    #[must_use]
    pub fn voxel_count(&self) -> u64 {
        (0..3)
            .map(|a| (self.max[a] - self.min[a] + 1) as u64)
            .product()
    }
}

/// A half-open integer box `[lo, hi)` per axis (internal).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[doc(hidden)]
pub struct IBox {
    pub lo: Wide,
    pub hi: Wide,
}

/// A point of a box in 128-bit coordinates: a box of `i64` voxels ends one past
/// `i64::MAX`, and the gap between boxes at opposite ends of `i64` is 2^64.
#[doc(hidden)]
pub type Wide = [i128; 3];

/// `v` widened to [`Wide`].
#[doc(hidden)]
#[inline]
#[must_use]
pub fn wide(v: Voxel) -> Wide {
    v.map(i128::from)
}

/// `v` clamped into `i64`: for coordinates known to lie in a tree's space.
#[doc(hidden)]
#[inline]
#[must_use]
pub fn narrow(v: i128) -> i64 {
    v.clamp(i128::from(i64::MIN), i128::from(i64::MAX)) as i64
}

impl IBox {
    /// The cube of side `side` from `min`.
    #[inline]
    #[must_use]
    pub fn cube(min: Voxel, side: i64) -> IBox {
        let lo = wide(min);
        IBox {
            lo,
            hi: lo.map(|c| c + i128::from(side)),
        }
    }

    #[inline]
    pub fn overlaps(&self, o: &IBox) -> bool {
        (0..3).all(|a| self.lo[a] < o.hi[a] && o.lo[a] < self.hi[a])
    }

    #[inline]
    pub fn inside(&self, o: &IBox) -> bool {
        (0..3).all(|a| o.lo[a] <= self.lo[a] && self.hi[a] <= o.hi[a])
    }

    #[inline]
    pub fn intersection(&self, o: &IBox) -> IBox {
        let mut r = *self;
        for a in 0..3 {
            r.lo[a] = r.lo[a].max(o.lo[a]);
            r.hi[a] = r.hi[a].min(o.hi[a]);
        }
        r
    }

    #[inline]
    pub fn volume(&self) -> u64 {
        (0..3)
            .map(|a| u64::try_from((self.hi[a] - self.lo[a]).max(0)).unwrap_or(u64::MAX))
            .fold(1u64, u64::saturating_mul)
    }

    /// The squared Euclidean gap between the two closed boxes, exactly: each axis's
    /// gap is below 2^64, so the sum of three squares needs a little over 128 bits.
    #[inline]
    pub fn gap2(&self, o: &IBox) -> Gap2 {
        let mut d = Gap2::default();
        for a in 0..3 {
            let g = (o.lo[a] - self.hi[a]).max(self.lo[a] - o.hi[a]).max(0) as u128;
            d = d.plus(g * g);
        }
        d
    }

    /// The box's voxels; only for boxes inside a tree's space, which fits `i64`.
    pub fn aabb(&self) -> Aabb {
        Aabb {
            min: self.lo.map(narrow),
            max: self.hi.map(|c| narrow(c - 1)),
        }
    }
}

/// A squared distance between boxes: `carry · 2^128 + low`, ordered as the number.
#[doc(hidden)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, PartialOrd, Ord)]
pub struct Gap2 {
    carry: u8,
    low: u128,
}

impl Gap2 {
    /// The largest value, above every real gap.
    pub const MAX: Gap2 = Gap2 {
        carry: u8::MAX,
        low: u128::MAX,
    };

    #[inline]
    fn plus(self, x: u128) -> Gap2 {
        let (low, over) = self.low.overflowing_add(x);
        Gap2 {
            carry: self.carry + u8::from(over),
            low,
        }
    }

    /// The value, saturated at `u128::MAX` (reached only by gaps beyond 1.8·10^19).
    #[must_use]
    pub fn saturated(self) -> u128 {
        if self.carry > 0 {
            u128::MAX
        } else {
            self.low
        }
    }

    /// The square root of the value, as `f64`.
    #[must_use]
    pub fn sqrt(self) -> f64 {
        (f64::from(self.carry) * 2f64.powi(128) + self.low as f64).sqrt()
    }
}
