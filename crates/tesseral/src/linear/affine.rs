//! Any affine map of an existing octree, and integer scaling by any factor per axis,
//! by point sampling (the papers' last rows: Ahuja & Nash Fig. 5 discusses why such
//! maps fragment the tree).
//!
//! **Definition.** The output lives on the input's lattice. Output voxel `w` is black
//! iff the inverse map of its centre `w + ½` lies in a black input voxel (voxels are
//! half-open, as everywhere). The definition is exact, so it is tested against brute
//! force over every output centre.
//!
//! **Top-down.** An output cell's centres map back into a parallelepiped of the
//! input. Its bounding box of input voxels is classified against the input octree
//! ([`LinearOctree::box_state`]): all black makes the cell black, all white makes it
//! white, and only the rest is split. The work then follows the output's leaves, not
//! its voxels. A single voxel is decided by its centre exactly.

use super::mapped::{build_mapped, Sampling, MAX_VIEW_BRICKS};
use super::{LinearOctree, OctreeError, MAX_DEPTH};
use crate::Voxel;

/// Scaling by an integer per axis: `w ↦ floor((2w + 1) / 2k)`, exact.
struct IntScale([i64; 3]);

impl Sampling for IntScale {
    fn preimage(&self, w: Voxel) -> Voxel {
        std::array::from_fn(|a| {
            // floor((2w + 1) / 2k), the divisor made positive for div_euclid.
            let (n, d) = (2 * i128::from(w[a]) + 1, 2 * i128::from(self.0[a]));
            let (n, d) = if d < 0 { (-n, -d) } else { (n, d) };
            n.div_euclid(d) as i64
        })
    }
    fn preimage_box(&self, min: Voxel, max: Voxel) -> (Voxel, Voxel) {
        let (a, b) = (self.preimage(min), self.preimage(max));
        (
            std::array::from_fn(|i| a[i].min(b[i])),
            std::array::from_fn(|i| a[i].max(b[i])),
        )
    }
}

/// An affine map `q = m p + t` on continuous lattice coordinates, sampled through its
/// inverse.
struct Affine {
    inv: [[f64; 3]; 3],
    t: [f64; 3],
}

/// `c.floor() as i64` (saturating, NaN to 0) without a call to `floor`: truncate,
/// then step down where truncation went up.
#[inline]
pub(super) fn floor_i64(c: f64) -> i64 {
    let i = c as i64;
    // Without a branch: for negative coordinates it would be taken half the time.
    i.saturating_sub(i64::from((i as f64) > c))
}

/// Slack added around a preimage box so that float rounding in the box never
/// disagrees with the single-centre test.
const SLACK: f64 = 1e-7;

impl Affine {
    fn back(&self, q: [f64; 3]) -> [f64; 3] {
        let d = [0, 1, 2].map(|j| q[j] - self.t[j]);
        [0, 1, 2].map(|i| (0..3).map(|j| self.inv[i][j] * d[j]).sum())
    }
}

impl Sampling for Affine {
    fn preimage(&self, w: Voxel) -> Voxel {
        self.back(w.map(|c| c as f64 + 0.5)).map(floor_i64)
    }
    fn preimage_row(&self, w: Voxel, out: &mut [Voxel]) {
        // The very operations of `back`, in its order, with the terms of y and z
        // computed once for the row: the answers are those of `preimage`.
        let (m, t) = (&self.inv, &self.t);
        let (dy, dz) = ((w[1] as f64 + 0.5) - t[1], (w[2] as f64 + 0.5) - t[2]);
        let by: [f64; 3] = std::array::from_fn(|i| m[i][1] * dy);
        let bz: [f64; 3] = std::array::from_fn(|i| m[i][2] * dz);
        for (x, o) in out.iter_mut().enumerate() {
            let dx = ((w[0] + x as i64) as f64 + 0.5) - t[0];
            *o = std::array::from_fn(|i| floor_i64((m[i][0] * dx + by[i]) + bz[i]));
        }
    }
    fn preimage_box(&self, min: Voxel, max: Voxel) -> (Voxel, Voxel) {
        let c = self.back(min.map(|c| c as f64 + 0.5));
        let (mut lo, mut hi) = (c, c);
        for i in 0..3 {
            for j in 0..3 {
                let span = self.inv[i][j] * (max[j] - min[j]) as f64;
                if span < 0.0 {
                    lo[i] += span;
                } else {
                    hi[i] += span;
                }
            }
        }
        (
            lo.map(|c| floor_i64(c - SLACK)),
            hi.map(|c| floor_i64(c + SLACK)),
        )
    }
}

/// The inverse of a 3 × 3 matrix by cofactors, or `None` when it is singular
/// (|det| < 1e-12) or not finite.
#[must_use]
pub fn invert_matrix(m: [[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if !det.is_finite() || det.abs() < 1e-12 {
        return None;
    }
    let c = |i: usize, j: usize| {
        let (r0, r1) = ((i + 1) % 3, (i + 2) % 3);
        let (c0, c1) = ((j + 1) % 3, (j + 2) % 3);
        m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]
    };
    Some(std::array::from_fn(|i| {
        std::array::from_fn(|j| c(j, i) / det)
    }))
}

/// The smallest space (power-of-two cube) holding the inclusive box `[lo, hi]`.
fn space_for(lo: [i128; 3], hi: [i128; 3]) -> Result<(u8, Voxel), OctreeError> {
    let extent = (0..3).map(|a| hi[a] - lo[a] + 1).max().unwrap_or(1).max(1);
    let depth = (128 - (extent - 1).leading_zeros()) as u8;
    if depth > MAX_DEPTH {
        return Err(OctreeError::DepthTooLarge(depth));
    }
    let origin: Option<Voxel> = lo
        .iter()
        .map(|&c| i64::try_from(c).ok())
        .collect::<Option<Vec<_>>>()
        .map(|v| [v[0], v[1], v[2]]);
    let origin = origin.ok_or(OctreeError::Overflow)?;
    if (0..3).any(|a| i128::from(origin[a]) + (1i128 << depth) > i128::from(i64::MAX)) {
        return Err(OctreeError::Overflow);
    }
    Ok((depth, origin))
}

impl LinearOctree {
    /// The image of `input` under `map` in the space `(depth, origin)`.
    fn mapped<S: Sampling>(
        input: &Self,
        map: &S,
        depth: u8,
        origin: Voxel,
    ) -> Result<Self, OctreeError> {
        Self::mapped_with(input, map, depth, origin, MAX_VIEW_BRICKS)
    }

    /// [`LinearOctree::mapped`] with a dense view of the input of at most
    /// `max_view_bricks` bricks (0: none, every query goes to the tree).
    fn mapped_with<S: Sampling>(
        input: &Self,
        map: &S,
        depth: u8,
        origin: Voxel,
        max_view_bricks: usize,
    ) -> Result<Self, OctreeError> {
        super::check_space(depth, origin)?;
        let leaves = build_mapped(input, map, depth, origin, max_view_bricks);
        Ok(Self::from_parts(depth, origin, leaves))
    }

    /// [`LinearOctree::affine`] with every query answered by the tree (no dense
    /// view), to test the builder's other path.
    #[cfg(test)]
    pub(super) fn affine_without_view(&self, m: [[f64; 3]; 3], t: [f64; 3]) -> Self {
        let (depth, origin) = affine_space(self.bbox().expect("not empty"), m, t).unwrap();
        let inv = invert_matrix(m).unwrap();
        Self::mapped_with(self, &Affine { inv, t }, depth, origin, 0).unwrap()
    }

    /// [`LinearOctree::scale_axes`] with no dense view and no fast path.
    #[cfg(test)]
    pub(super) fn scale_axes_without_view(&self, k: [i64; 3]) -> Self {
        let (depth, origin) = scale_space(self.bbox().expect("not empty"), k).unwrap();
        Self::mapped_with(self, &IntScale(k), depth, origin, 0).unwrap()
    }

    /// The tree scaled by the integer `k[a]` along each axis about the lattice origin:
    /// voxel `v` becomes the block of voxels `w` with `floor((w + ½)/k) = v`, so
    /// `k = (3, 1, 2)` turns each voxel into a 3 × 1 × 2 block and a negative factor
    /// mirrors (`-1` maps `v` to `-1 - v`). Equal positive powers of two take the fast
    /// path of [`LinearOctree::scale_up`]. Exact.
    ///
    /// # Errors
    /// [`OctreeError::InvalidArgument`] for a zero factor; [`OctreeError::Overflow`] or
    /// [`OctreeError::DepthTooLarge`] when the result leaves the lattice.
    ///
    /// ```
    /// use tesseral::linear::LinearOctree;
    /// let t = LinearOctree::from_voxels(1, [0; 3], [[1, 0, 0]]).unwrap();
    /// let s = t.scale_axes([3, 1, -2]).unwrap();
    /// assert_eq!(s.voxel_count(), 6);
    /// assert!(s.contains([3, 0, -1]) && s.contains([5, 0, -2]) && !s.contains([2, 0, -1]));
    /// ```
    pub fn scale_axes(&self, k: [i64; 3]) -> Result<Self, OctreeError> {
        if k.contains(&0) {
            return Err(OctreeError::InvalidArgument(
                "a scale factor of 0 collapses the solid".into(),
            ));
        }
        if k[0] > 0 && k[0] == k[1] && k[1] == k[2] && (k[0] as u64).is_power_of_two() {
            return self.scale_up(k[0].trailing_zeros() as u8);
        }
        let Some(bbox) = self.bbox() else {
            return Ok(self.clone());
        };
        let (depth, origin) = scale_space(bbox, k)?;
        self.scale_axes_in(k, depth, origin)
    }

    /// [`LinearOctree::scale_axes`] into the given space (which should hold the
    /// image: see [`scale_space`]), with no fast path.
    ///
    /// # Errors
    /// [`OctreeError::InvalidArgument`] for a zero factor; as
    /// [`LinearOctree::from_classifier`].
    pub fn scale_axes_in(
        &self,
        k: [i64; 3],
        depth: u8,
        origin: Voxel,
    ) -> Result<Self, OctreeError> {
        if k.contains(&0) {
            return Err(OctreeError::InvalidArgument(
                "a scale factor of 0 collapses the solid".into(),
            ));
        }
        Self::mapped(self, &IntScale(k), depth, origin)
    }

    /// The tree under the affine map `q = m·p + t` of continuous lattice coordinates
    /// (voxel `v` spans `[v, v + 1)`), by point sampling on the same lattice: output
    /// voxel `w` is black iff `m⁻¹·(w + ½ − t)` lies in a black voxel. Built top-down,
    /// so the work follows the output's leaves.
    ///
    /// # Errors
    /// [`OctreeError::InvalidArgument`] for a singular or non-finite map;
    /// [`OctreeError::Overflow`] / [`OctreeError::DepthTooLarge`] when the image
    /// leaves the lattice.
    ///
    /// ```
    /// use tesseral::linear::LinearOctree;
    /// let t = LinearOctree::from_voxels(3, [0; 3], [[0, 0, 0], [1, 0, 0], [2, 0, 0]]).unwrap();
    /// // A quarter turn about z through the lattice origin: x becomes y.
    /// let r = t.affine([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]], [0.0; 3]).unwrap();
    /// assert!(r.contains([-1, 2, 0]) && r.voxel_count() == 3);
    /// ```
    pub fn affine(&self, m: [[f64; 3]; 3], t: [f64; 3]) -> Result<Self, OctreeError> {
        let Some(bbox) = self.bbox() else {
            return Ok(self.clone());
        };
        let (depth, origin) = affine_space(bbox, m, t)?;
        self.affine_in(m, t, depth, origin)
    }

    /// [`LinearOctree::affine`] into the given space (which should hold the image:
    /// see [`affine_space`]).
    ///
    /// # Errors
    /// As [`LinearOctree::affine`].
    pub fn affine_in(
        &self,
        m: [[f64; 3]; 3],
        t: [f64; 3],
        depth: u8,
        origin: Voxel,
    ) -> Result<Self, OctreeError> {
        let bad = || OctreeError::InvalidArgument("the map is singular or not finite".into());
        if !t.iter().chain(m.iter().flatten()).all(|c| c.is_finite()) {
            return Err(bad());
        }
        let inv = invert_matrix(m).ok_or_else(bad)?;
        Self::mapped(self, &Affine { inv, t }, depth, origin)
    }
}

/// The smallest space holding the image of the voxel box `bbox` (inclusive) under
/// scaling by `k` per axis.
///
/// # Errors
/// [`OctreeError::Overflow`] or [`OctreeError::DepthTooLarge`] past the lattice.
pub fn scale_space(bbox: (Voxel, Voxel), k: [i64; 3]) -> Result<(u8, Voxel), OctreeError> {
    let (blo, bhi) = bbox;
    let (mut lo, mut hi) = ([0i128; 3], [0i128; 3]);
    for a in 0..3 {
        let f = i128::from(k[a]);
        let (p, q) = (f * i128::from(blo[a]), f * (i128::from(bhi[a]) + 1));
        lo[a] = p.min(q);
        hi[a] = p.max(q) - 1;
    }
    space_for(lo, hi)
}

/// The lattice coordinates an affine map's image may reach (2^62 either way).
const AFFINE_LIMIT: f64 = 4_611_686_018_427_387_904.0;

/// The whole-voxel move `t` when the lattice map `q = m·p + t` is one: `m` the
/// identity and `t` whole (and within reach). Point sampling under such a map gives
/// the voxels of the translation by `t`.
#[must_use]
pub fn whole_translation(m: [[f64; 3]; 3], t: [f64; 3]) -> Option<Voxel> {
    let identity = (0..3).all(|i| (0..3).all(|j| m[i][j] == if i == j { 1.0 } else { 0.0 }));
    (identity && t.iter().all(|c| c.fract() == 0.0 && c.abs() < AFFINE_LIMIT))
        .then(|| t.map(|c| c as i64))
}

/// The smallest space holding the image of the voxel box `bbox` (inclusive) under
/// the affine map `q = m·p + t`, with a voxel of margin.
///
/// # Errors
/// [`OctreeError::Overflow`] or [`OctreeError::DepthTooLarge`] past the lattice.
pub fn affine_space(
    bbox: (Voxel, Voxel),
    m: [[f64; 3]; 3],
    t: [f64; 3],
) -> Result<(u8, Voxel), OctreeError> {
    let (blo, bhi) = bbox;
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for corner in 0..8 {
        let p: [f64; 3] = std::array::from_fn(|a| {
            if corner >> a & 1 == 0 {
                blo[a] as f64
            } else {
                bhi[a] as f64 + 1.0
            }
        });
        for i in 0..3 {
            let q = (0..3).map(|j| m[i][j] * p[j]).sum::<f64>() + t[i];
            lo[i] = lo[i].min(q);
            hi[i] = hi[i].max(q);
        }
    }
    if !(0..3).all(|a| lo[a].abs() < AFFINE_LIMIT && hi[a].abs() < AFFINE_LIMIT) {
        return Err(OctreeError::Overflow);
    }
    space_for(
        lo.map(|c| c.floor() as i128 - 1),
        hi.map(|c| c.ceil() as i128 + 1),
    )
}

/// The sine and cosine of `degrees`, exact (0 and ±1) at multiples of 90°, as
/// OpenSCAD's are: a quarter turn moves a face onto a face, not 10⁻¹⁶ off it.
pub(crate) fn sin_cos_degrees(degrees: f64) -> (f64, f64) {
    let turns = degrees / 90.0;
    // An infinite angle is no quarter turn: its sine and cosine stay NaN, which the
    // callers refuse as a non-finite transform.
    if turns.is_finite() && turns == turns.round() {
        // Whole turns and the remainder are exact in floating point, however large.
        match turns.rem_euclid(4.0) as u8 {
            0 => (0.0, 1.0),
            1 => (1.0, 0.0),
            2 => (0.0, -1.0),
            _ => (-1.0, 0.0),
        }
    } else {
        degrees.to_radians().sin_cos()
    }
}

/// The matrix of a rotation by `degrees` about the unit vector along `axis`
/// (Rodrigues), with exact entries for multiples of 90°.
#[must_use]
pub fn rotation_matrix(axis: [f64; 3], degrees: f64) -> [[f64; 3]; 3] {
    let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    let k = axis.map(|c| c / n);
    let (s, c) = sin_cos_degrees(degrees);
    let v = 1.0 - c;
    [
        [
            c + k[0] * k[0] * v,
            k[0] * k[1] * v - k[2] * s,
            k[0] * k[2] * v + k[1] * s,
        ],
        [
            k[1] * k[0] * v + k[2] * s,
            c + k[1] * k[1] * v,
            k[1] * k[2] * v - k[0] * s,
        ],
        [
            k[2] * k[0] * v - k[1] * s,
            k[2] * k[1] * v + k[0] * s,
            c + k[2] * k[2] * v,
        ],
    ]
}

#[cfg(test)]
pub(super) mod tests_support {
    /// The inverse the maps use, for the brute-force tests.
    pub fn inverse(m: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
        super::invert_matrix(m).expect("regular")
    }
}
