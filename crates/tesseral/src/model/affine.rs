//! Scaling by any integer per axis and any affine map of a model: every part (the
//! solid, its colours, free space and log-odds) is mapped into one shared space by
//! the same point sampling, so values still follow their voxels.

use super::{Model, ModelError};
use crate::linear::{affine_space, scale_space, whole_translation, LinearOctree};
use crate::Voxel;

impl Model {
    /// The box of voxels holding every part: the solid and the known-free space
    /// (colours and log-odds lie within them).
    fn known_bbox(&self) -> Option<(Voxel, Voxel)> {
        [Some(&self.tree), self.free.as_ref()]
            .into_iter()
            .flatten()
            .filter_map(LinearOctree::bbox)
            .reduce(|a, b| {
                (
                    std::array::from_fn(|i| a.0[i].min(b.0[i])),
                    std::array::from_fn(|i| a.1[i].max(b.1[i])),
                )
            })
    }

    /// The model scaled by the integer `k[a]` along each axis about the world origin:
    /// each voxel becomes a `k[0] × k[1] × k[2]` block, a negative factor mirrors, and
    /// the frame's placement scales with it (the voxel size is kept). Equal positive
    /// powers of two keep the fast path of [`Model::scale_up`]. Exact.
    ///
    /// # Errors
    /// As [`LinearOctree::scale_axes`].
    pub fn scale_axes(&self, k: [i64; 3]) -> Result<Self, ModelError> {
        if k[0] > 0 && k[0] == k[1] && k[1] == k[2] && (k[0] as u64).is_power_of_two() {
            return self.scale_up(k[0].trailing_zeros() as u8);
        }
        let mut frame = self.frame;
        for (t, &f) in frame.translate.iter_mut().zip(&k) {
            *t *= f as f64;
        }
        let Some(bbox) = self.known_bbox() else {
            let tree = self.tree.scale_axes(k)?;
            return Ok(Model::new(tree).with_frame(frame));
        };
        let (depth, origin) = scale_space(bbox, k)?;
        Ok(self.map(frame, |t| t.scale_axes_in(k, depth, origin))?)
    }

    /// The model under the world map `x ↦ m·x + offset` (world units), by point
    /// sampling on its own lattice: the frame is kept, and output voxel `w` is black
    /// when the preimage of its centre lies in a black voxel. Rotations by any angle
    /// are `m` = a rotation matrix (see [`crate::linear::rotation_matrix`]). The
    /// identity moving by whole voxels is [`Model::translate`] (the same voxels, the
    /// space kept rather than widened).
    ///
    /// # Errors
    /// As [`LinearOctree::affine`].
    pub fn affine_world(&self, m: [[f64; 3]; 3], offset: [f64; 3]) -> Result<Self, ModelError> {
        // World x = T + h v, so v' = m v + (m T + offset - T) / h on the lattice.
        let (h, tr) = (self.frame.voxel_size, self.frame.translate);
        let t: [f64; 3] = std::array::from_fn(|i| {
            ((0..3).map(|j| m[i][j] * tr[j]).sum::<f64>() + offset[i] - tr[i]) / h
        });
        // The identity moving by whole voxels is a translation: sampling gives the
        // same voxels, in a space a voxel wider on every side (often a level
        // deeper) than the translation keeps.
        if let Some(by) = whole_translation(m, t) {
            return self.translate(by);
        }
        let Some(bbox) = self.known_bbox() else {
            return Ok(self.clone());
        };
        let (depth, origin) = affine_space(bbox, m, t)?;
        Ok(self.map(self.frame, |tree| tree.affine_in(m, t, depth, origin))?)
    }

    /// The centre of the solid's bounding box in world units (the frame's origin
    /// for an empty solid).
    #[must_use]
    pub fn bbox_centre(&self) -> [f64; 3] {
        let Some((lo, hi)) = self.tree.bbox() else {
            return self.frame.translate;
        };
        let (a, b) = (
            self.frame.voxel_corner(lo),
            self.frame.voxel_corner(hi.map(|c| c + 1)),
        );
        std::array::from_fn(|i| (a[i] + b[i]) / 2.0)
    }

    /// The model turned by the rotation matrix `m` about the world point `about`.
    ///
    /// # Errors
    /// As [`Model::affine_world`].
    pub fn rotate_about(&self, m: [[f64; 3]; 3], about: [f64; 3]) -> Result<Self, ModelError> {
        let offset: [f64; 3] =
            std::array::from_fn(|i| about[i] - (0..3).map(|j| m[i][j] * about[j]).sum::<f64>());
        self.affine_world(m, offset)
    }
}
