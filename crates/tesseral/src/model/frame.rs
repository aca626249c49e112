//! Where a voxel lattice sits in the world.

use std::fmt;

use crate::Voxel;

/// Where the voxel lattice sits in the world: the corner of voxel `(i, j, k)` is
/// `translate + voxel_size * (i, j, k)`.
///
/// OctoMap's resolution, binvox's translate and scale, and a scene's voxel size and
/// lower bound all become a `Frame`, so a round trip through tesseral keeps them.
/// The default is unit voxels with voxel `(0, 0, 0)` at the world origin.
///
/// ```
/// use tesseral::model::Frame;
/// let f = Frame::new(0.05, [1.0, 0.0, 0.0]);
/// assert_eq!(f.voxel_corner([2, 0, 0]), [1.1, 0.0, 0.0]);
/// assert_eq!(f.voxel_of_point([1.12, 0.01, -0.01]), [2, 0, -1]);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// The side of one voxel, in world units (metres for OctoMap).
    pub voxel_size: f64,
    /// The world position of the corner of voxel `(0, 0, 0)`.
    pub translate: [f64; 3],
}

impl Default for Frame {
    fn default() -> Self {
        Self {
            voxel_size: 1.0,
            translate: [0.0; 3],
        }
    }
}

/// Two frames whose lattices do not line up: different voxel sizes, or placements
/// that differ by a fraction of a voxel.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("frames do not line up: {first} and {second} ({reason})")]
pub struct FrameMismatch {
    /// The first operand's frame.
    pub first: Frame,
    /// The second operand's frame.
    pub second: Frame,
    /// Why: "voxel sizes differ" or "placements differ by a fraction of a voxel".
    pub reason: &'static str,
}

/// The relative tolerance within which two voxel sizes are equal and an offset is a
/// whole number of voxels: 1e-9, far below a float's rounding of a decimal resolution
/// such as 0.05 after a few operations, and far above nothing that could be meant.
pub const FRAME_TOLERANCE: f64 = 1e-9;

impl Frame {
    /// A frame with voxels of side `voxel_size` whose voxel `(0, 0, 0)` has its corner
    /// at `translate`.
    #[must_use]
    pub fn new(voxel_size: f64, translate: [f64; 3]) -> Self {
        Self {
            voxel_size,
            translate,
        }
    }

    /// Whether this is the default frame (unit voxels at the origin).
    #[must_use]
    pub fn is_unit(&self) -> bool {
        *self == Self::default()
    }

    /// The world position of the low corner of voxel `v`.
    #[must_use]
    pub fn voxel_corner(&self, v: Voxel) -> [f64; 3] {
        std::array::from_fn(|a| self.translate[a] + self.voxel_size * v[a] as f64)
    }

    /// The world position of a lattice point given in (fractional) voxel units.
    #[must_use]
    pub fn to_world(&self, p: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|a| self.translate[a] + self.voxel_size * p[a])
    }

    /// The lattice position (in fractional voxel units) of a world point.
    #[must_use]
    pub fn to_lattice(&self, p: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|a| (p[a] - self.translate[a]) / self.voxel_size)
    }

    /// The voxel holding world point `p` (half-open cubes; coordinates saturate at the
    /// ends of `i64`).
    #[must_use]
    pub fn voxel_of_point(&self, p: [f64; 3]) -> Voxel {
        self.to_lattice(p).map(|c| c.floor() as i64)
    }

    /// Where `other`'s voxel `(0, 0, 0)` lies in this frame's lattice: `other`'s voxel
    /// `v` is this frame's voxel `v + offset`.
    ///
    /// # Errors
    /// [`FrameMismatch`] naming both frames when the voxel sizes differ by more than
    /// [`FRAME_TOLERANCE`] (relative) or the placements differ by a fraction of a
    /// voxel.
    ///
    /// ```
    /// use tesseral::model::Frame;
    /// let a = Frame::new(0.05, [0.0; 3]);
    /// assert_eq!(a.offset_to(&Frame::new(0.05, [0.1, 0.0, -0.05])).unwrap(), [2, 0, -1]);
    /// assert!(a.offset_to(&Frame::new(0.1, [0.0; 3])).is_err());
    /// assert!(a.offset_to(&Frame::new(0.05, [0.01, 0.0, 0.0])).is_err());
    /// ```
    pub fn offset_to(&self, other: &Frame) -> Result<[i64; 3], FrameMismatch> {
        let mismatch = |reason| FrameMismatch {
            first: *self,
            second: *other,
            reason,
        };
        let (h, g) = (self.voxel_size, other.voxel_size);
        let close = (h - g).abs() <= FRAME_TOLERANCE * h.abs().max(g.abs());
        if !close {
            return Err(mismatch("voxel sizes differ"));
        }
        let mut out = [0i64; 3];
        for (a, slot) in out.iter_mut().enumerate() {
            let d = (other.translate[a] - self.translate[a]) / h;
            let r = d.round();
            let scale = 1.0 + (other.translate[a].abs() + self.translate[a].abs()) / h.abs();
            if !r.is_finite() || (d - r).abs() > FRAME_TOLERANCE * scale || r.abs() >= 9.0e18 {
                return Err(mismatch("placements differ by a fraction of a voxel"));
            }
            *slot = r as i64;
        }
        Ok(out)
    }

    /// A world vector as a whole number of voxels.
    ///
    /// # Errors
    /// When some component is not a whole number of voxels (within
    /// [`FRAME_TOLERANCE`]): the error gives the nearest whole vector, in voxels and in
    /// world units.
    ///
    /// ```
    /// use tesseral::model::Frame;
    /// let f = Frame::new(0.05, [0.0; 3]);
    /// assert_eq!(f.world_to_voxels([0.1, 0.0, -1.0]).unwrap(), [2, 0, -20]);
    /// assert!(f.world_to_voxels([0.07, 0.0, 0.0]).is_err());
    /// ```
    pub fn world_to_voxels(&self, by: [f64; 3]) -> Result<[i64; 3], String> {
        let d = by.map(|c| c / self.voxel_size);
        let r = d.map(f64::round);
        let ok = (0..3).all(|a| {
            r[a].is_finite()
                && r[a].abs() < 9.0e18
                && (d[a] - r[a]).abs() <= FRAME_TOLERANCE * (1.0 + d[a].abs())
        });
        if ok {
            return Ok(r.map(|c| c as i64));
        }
        let near = r.map(|c| c * self.voxel_size);
        Err(format!(
            "({}, {}, {}) is not a whole number of voxels of size {}; the nearest whole vector is ({}, {}, {}) voxels = ({}, {}, {})",
            by[0], by[1], by[2], self.voxel_size, r[0], r[1], r[2], near[0], near[1], near[2]
        ))
    }
}

impl fmt::Display for Frame {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let t = self.translate;
        write!(
            f,
            "voxel size {} at ({}, {}, {})",
            self.voxel_size, t[0], t[1], t[2]
        )
    }
}
