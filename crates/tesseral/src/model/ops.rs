//! Set operations on models: the trees combined, and the layers (colours, free space,
//! log-odds) by the rules of the module docs.

use super::{Layer, LayerValue, Model, ModelError, Rgba};
use crate::linear::{grow, LinearOctree, OctreeError, SetOp};

impl Model {
    /// The set operation `op` of `self` and `other` (see the module docs for the
    /// rules on frames, values and free space).
    ///
    /// # Errors
    /// [`ModelError::Frame`] when the frames do not line up; as
    /// [`LinearOctree::set_op`].
    pub fn set_op(&self, other: &Self, op: SetOp) -> Result<Self, ModelError> {
        let off = self.frame.offset_to(&other.frame)?;
        if !self.has_layers() && !other.has_layers() {
            // Solids only: the trees' own operation, with the same spaces.
            let tree = if off == [0; 3] {
                self.tree.set_op(&other.tree, op)?
            } else {
                self.tree.set_op(&other.tree.translate(off)?, op)?
            };
            return Ok(Self::new(tree).with_frame(self.frame));
        }
        let b = if off == [0; 3] {
            other.clone()
        } else {
            other.translate(off)?
        };
        // The result's space: the first operand's, grown to hold everything of the
        // second for union and symmetric difference.
        let (mut depth, mut origin) = (self.tree.depth(), self.tree.origin());
        if matches!(op, SetOp::Union | SetOp::SymmetricDifference) {
            if let Some((lo, hi)) = b.known().bbox() {
                (depth, origin) = grow::grown_space(depth, origin, lo, hi)?;
            }
        }
        let a = self.in_space(depth, origin)?;
        let b = b.in_space(depth, origin)?;
        let tree = a.tree.set_op_same_space(&b.tree, op);
        let free = if a.free.is_some() || b.free.is_some() {
            let known = a.known().set_op_same_space(&b.known(), SetOp::Union);
            Some(known.set_op_same_space(&tree, SetOp::Difference))
        } else {
            None
        };
        let overlay = |x: &Option<Layer<Rgba>>, y: &Option<Layer<Rgba>>| match (x, y) {
            (None, None) => Ok(None),
            (Some(x), None) | (None, Some(x)) => Ok(Some(x.clone())),
            (Some(x), Some(y)) => x.overlay(y, depth, origin).map(Some),
        };
        let colors = overlay(&a.colors, &b.colors)?;
        let log_odds = match (&a.log_odds, &b.log_odds) {
            (None, None) => None,
            (Some(x), None) | (None, Some(x)) => Some(x.clone()),
            (Some(x), Some(y)) => Some(x.overlay(y, depth, origin)?),
        };
        Ok(Self::from_parts(tree, self.frame, colors, free, log_odds)?)
    }

    /// Union: [`Model::set_op`] with [`SetOp::Union`].
    ///
    /// # Errors
    /// As [`Model::set_op`].
    pub fn union(&self, other: &Self) -> Result<Self, ModelError> {
        self.set_op(other, SetOp::Union)
    }

    /// Intersection: [`Model::set_op`] with [`SetOp::Intersection`].
    ///
    /// # Errors
    /// As [`Model::set_op`].
    pub fn intersection(&self, other: &Self) -> Result<Self, ModelError> {
        self.set_op(other, SetOp::Intersection)
    }

    /// Difference: [`Model::set_op`] with [`SetOp::Difference`].
    ///
    /// # Errors
    /// As [`Model::set_op`].
    pub fn difference(&self, other: &Self) -> Result<Self, ModelError> {
        self.set_op(other, SetOp::Difference)
    }

    /// Symmetric difference: [`Model::set_op`] with [`SetOp::SymmetricDifference`].
    ///
    /// # Errors
    /// As [`Model::set_op`].
    pub fn symmetric_difference(&self, other: &Self) -> Result<Self, ModelError> {
        self.set_op(other, SetOp::SymmetricDifference)
    }
}

/// Regions that may overlap made disjoint: where several cover a voxel, the one
/// with the lowest key keeps it.
pub(super) fn first_wins<T: LayerValue>(
    regions: impl Iterator<Item = Result<(T, LinearOctree), OctreeError>>,
) -> Result<Vec<(T, LinearOctree)>, OctreeError> {
    let mut all = regions.collect::<Result<Vec<_>, _>>()?;
    all.sort_by_key(|(x, _)| x.key());
    let mut taken: Option<LinearOctree> = None;
    let mut out = Vec::with_capacity(all.len());
    for (x, t) in all {
        let mine = match &taken {
            Some(d) => t.difference(d)?,
            None => t.clone(),
        };
        taken = Some(match taken {
            Some(d) => d.union(&t)?,
            None => t,
        });
        out.push((x, mine));
    }
    Ok(out)
}
