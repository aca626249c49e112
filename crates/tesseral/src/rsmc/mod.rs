//! Monte Carlo of self-avoiding random surfaces on the cubic lattice (RS/MC),
//! after Libes, *Modeling dynamic surfaces with octrees*, §6.
//!
//! The state is a finite set `B` of black voxels whose boundary is one closed surface
//! of sphere topology; equivalently (PL topology), the union of the closed unit cubes
//! of `B` is a 3-ball. A step picks a uniformly random boundary face (plaquette),
//! proposes to grow the voxel outside it or to shrink the voxel inside it, rejects
//! moves that would break the sphere topology ([`legality`]), and accepts the rest
//! with the Metropolis–Hastings probability for the weight `exp(-β·A - μ·V)`
//! ([`Chain`]).
//!
//! The chain runs on any [`Lattice`]: the unbounded
//! [`DynamicOctree`](crate::dynamic::DynamicOctree) (O(|S|) memory, the default) and
//! [`DenseLattice`], the dense-array baseline (O(box volume) memory). Both follow the face-list order rule of the dynamic octree
//! contract, so for the same seed they produce the same trajectory, step for step.
//!
//! ```
//! use tesseral::dynamic::DynamicOctree;
//! use tesseral::rsmc::{Chain, Params};
//! let params = Params { beta: 0.0, ..Params::default() };
//! let mut chain = Chain::new(DynamicOctree::with_faces(), params, 7, &[[0, 0, 0]]).unwrap();
//! chain.run(10_000);
//! assert_eq!(chain.steps(), 10_000);
//! assert!(tesseral::rsmc::topology::check_sphere(&chain.voxels()).is_ok());
//! ```

mod chain;
mod checkpoint;
mod dense;
pub mod enumerate;
pub mod legality;
pub mod mesh;
mod octree;
pub mod plot;
mod start;
pub mod stats;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_balance;
pub mod topology;

pub use chain::{Chain, Checkpoint, Counters, Params, Sample, CHECKPOINT_FORMAT};
pub use checkpoint::MAX_CHECKPOINT_COORDINATE;
pub use dense::{DenseLattice, MAX_CELLS};
pub use start::{parse_start, MAX_BOX_SIDE, MAX_START_VOXELS};

use crate::Voxel;

/// One plaquette of the surface is a lattice [`Face`], as in the dynamic octree: the
/// lattice has one vocabulary ([`crate::lattice`]).
pub use crate::lattice::{Direction, Face, Neighbourhood};

/// The lattice operations the chain needs: a set of black voxels with the list of
/// exposed faces.
///
/// Implementations must keep the faces in one dense list and follow the face-list
/// order rule of the dynamic octree contract, so that two implementations fed the
/// same operations hold the same list, index for index:
/// - `insert(v)` of a new voxel: for `dir` in [`Direction::ALL`] (−x, +x, −y, +y,
///   −z, +z), let `n` be the neighbour in that direction. If `n` is black, remove
///   `n`'s face pointing at `v` (`swap_remove`); otherwise push the face `(v, dir)`.
/// - `remove(v)` of a present voxel: for `dir` in the same order, if `n` is black,
///   push `(n, dir.opposite())`; otherwise remove the face `(v, dir)` (`swap_remove`).
pub trait Lattice {
    /// An empty lattice of the same kind (used to rebuild in canonical order).
    #[must_use]
    fn empty() -> Self
    where
        Self: Sized;
    /// Makes `v` black; true when it was white before.
    fn insert(&mut self, v: Voxel) -> bool;
    /// Makes `v` white; true when it was black before.
    fn remove(&mut self, v: Voxel) -> bool;
    /// Whether `v` is black.
    fn contains(&self, v: Voxel) -> bool;
    /// The number of black voxels.
    fn voxel_count(&self) -> u64;
    /// The number of exposed faces (the area `A`).
    fn face_count(&self) -> usize;
    /// The `i`-th face of the face list; `i < face_count()`.
    fn face(&self, i: usize) -> Face;
    /// The occupancy of the 3×3×3 block around `v`.
    fn neighbourhood(&self, v: Voxel) -> Neighbourhood;
    /// [`insert`](Self::insert) for a caller that holds `nb = neighbourhood(v)`,
    /// taken since the last change; a backend may use it to skip a search. The
    /// default ignores `nb`.
    fn insert_with_neighbourhood(&mut self, v: Voxel, nb: Neighbourhood) -> bool {
        let _ = nb;
        self.insert(v)
    }
    /// [`remove`](Self::remove) for a caller that holds `nb = neighbourhood(v)`,
    /// taken since the last change; a backend may use it to skip a search. The
    /// default ignores `nb`.
    fn remove_with_neighbourhood(&mut self, v: Voxel, nb: Neighbourhood) -> bool {
        let _ = nb;
        self.remove(v)
    }
}

/// Errors of the random-surface Monte Carlo.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RsmcError {
    /// A parameter is out of range (the message names it).
    #[error("invalid parameter: {0}")]
    InvalidParameter(String),
    /// The start shape is not a set of voxels bounded by one sphere-topology surface.
    #[error("start shape is not a sphere-topology surface: {0}")]
    BadStart(#[from] topology::TopologyError),
    /// A checkpoint could not be read or does not fit this program.
    #[error("bad checkpoint: {0}")]
    BadCheckpoint(String),
    /// The request is larger than the configured limit.
    #[error("too large: {0}")]
    TooLarge(String),
}
