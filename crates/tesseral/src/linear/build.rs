//! Top-down construction of a linear octree from a classifier of cells.

use rayon::prelude::*;

use super::{check_space, push_merging, Leaf, LinearOctree, OctreeError};
use crate::Voxel;

/// How a cell relates to a solid.
///
/// The colours of Ahuja & Nash: `Inside` is black, `Outside` white, `Partial` gray.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CellClass {
    /// Every voxel centre in the cell is inside the solid.
    Inside,
    /// No voxel centre in the cell is inside the solid.
    Outside,
    /// Some may be inside and some not: the cell must be split.
    Partial,
}

/// Answers, conservatively, whether a cell of voxels is inside, outside or partly
/// inside a solid. [`LinearOctree::from_classifier`] builds on it, and so do the CSG
/// scenes and the mesh voxelizer.
///
/// A cell is the cube of voxels `[min, min + 2^size_log2)` per axis, in world
/// coordinates. A voxel belongs to the solid exactly when its centre does.
/// `Partial` is always a safe answer for a cell of more than one voxel; for a single
/// voxel (`size_log2 == 0`) the answer must be `Inside` or `Outside`, and it is a
/// logic error to answer `Partial` there (the builder then counts it as `Inside`).
pub trait Classifier: Sync {
    /// Classifies the cell `[min, min + 2^size_log2)`.
    fn classify(&self, min: Voxel, size_log2: u8) -> CellClass;
}

impl<F: Fn(Voxel, u8) -> CellClass + Sync> Classifier for F {
    fn classify(&self, min: Voxel, size_log2: u8) -> CellClass {
        self(min, size_log2)
    }
}

/// Below this cell size (as log2) the recursion runs on one thread: small subtrees
/// are not worth a rayon task.
const PARALLEL_MIN_SIZE_LOG2: u8 = 5;

impl LinearOctree {
    /// Builds the tree top-down: each cell is classified, `Partial` cells are split
    /// into their eight children, recursively, and the leaves come out in tesseral
    /// order and canonical form. Subtrees are built in parallel with rayon.
    ///
    /// # Runtime
    /// Proportional to the number of cells classified: about 8 × the number of
    /// partial cells, so the cost follows the surface of the solid, not its volume.
    ///
    /// # Errors
    /// [`OctreeError::DepthTooLarge`] when `depth > MAX_DEPTH`.
    ///
    /// ```
    /// use tesseral::linear::{CellClass, LinearOctree};
    /// // The voxels with x < 3, in an 8^3 space.
    /// let half = |min: [i64; 3], k: u8| {
    ///     if min[0] + (1 << k) <= 3 { CellClass::Inside }
    ///     else if min[0] >= 3 { CellClass::Outside }
    ///     else { CellClass::Partial }
    /// };
    /// let tree = LinearOctree::from_classifier(3, [0, 0, 0], &half).unwrap();
    /// assert_eq!(tree.voxel_count(), 3 * 64);
    /// ```
    pub fn from_classifier(
        depth: u8,
        origin: Voxel,
        classifier: &impl Classifier,
    ) -> Result<Self, OctreeError> {
        check_space(depth, origin)?;
        let space = Self::from_parts(depth, origin, Vec::new());
        let mut leaves = Vec::new();
        build_cell(&space, classifier, 0, depth, &mut leaves);
        Ok(Self::from_parts(depth, origin, leaves).with_bricks())
    }
}

fn build_cell(
    space: &LinearOctree,
    classifier: &impl Classifier,
    code: u64,
    k: u8,
    out: &mut Vec<Leaf>,
) {
    match classifier.classify(space.voxel_of(code), k) {
        CellClass::Outside => {}
        CellClass::Inside => out.push(Leaf::new(code, k)),
        CellClass::Partial if k == 0 => out.push(Leaf::new(code, 0)),
        CellClass::Partial => {
            let child_cells = 1u64 << (3 * u32::from(k - 1));
            if k >= PARALLEL_MIN_SIZE_LOG2 {
                let parts: Vec<Vec<Leaf>> = (0..8u64)
                    .into_par_iter()
                    .map(|d| {
                        let mut part = Vec::new();
                        build_cell(space, classifier, code + d * child_cells, k - 1, &mut part);
                        part
                    })
                    .collect();
                out.extend(parts.into_iter().flatten());
            } else {
                for d in 0..8 {
                    build_cell(space, classifier, code + d * child_cells, k - 1, out);
                }
            }
            // Each child's leaves are canonical already, so the only merge left is of
            // eight full children into this cell; re-pushing the last leaf checks it.
            if let Some(last) = out.pop() {
                push_merging(out, last);
            }
        }
    }
}
