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
pub mod stats;
#[cfg(test)]
mod tests;
pub mod topology;

pub use chain::{Chain, Checkpoint, Counters, Params, CHECKPOINT_FORMAT};
pub use checkpoint::MAX_CHECKPOINT_COORDINATE;
pub use dense::{DenseLattice, MAX_CELLS};

use crate::Voxel;

/// One plaquette of the surface is a [`Face`] of the dynamic octree: the lattice has
/// one vocabulary.
pub use crate::dynamic::Face;

/// Unit steps of the six face directions, in the order 0 = −x, 1 = +x, 2 = −y,
/// 3 = +y, 4 = −z, 5 = +z. The opposite of direction `d` is `d ^ 1`.
pub const DIRS: [[i64; 3]; 6] = [
    [-1, 0, 0],
    [1, 0, 0],
    [0, -1, 0],
    [0, 1, 0],
    [0, 0, -1],
    [0, 0, 1],
];

pub use crate::dynamic::step;

/// The lattice operations the chain needs: a set of black voxels with the list of
/// exposed faces.
///
/// Implementations must keep the faces in one dense list and follow the face-list
/// order rule of the dynamic octree contract, so that two implementations fed the
/// same operations hold the same list, index for index:
/// - `insert(v)` of a new voxel: for `dir` in `0..6`, let `n` be the neighbour in
///   that direction. If `n` is black, remove `n`'s face pointing at `v`
///   (`swap_remove`); otherwise push the face `(v, dir)`.
/// - `remove(v)` of a present voxel: for `dir` in `0..6`, if `n` is black, push
///   `(n, dir ^ 1)`; otherwise remove the face `(v, dir)` (`swap_remove`).
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
    /// The 27-bit occupancy of the 3×3×3 block around `v`: bit
    /// `(dx+1) + 3(dy+1) + 9(dz+1)`.
    fn neighbourhood(&self, v: Voxel) -> u32;
    /// [`insert`](Self::insert) for a caller that holds `nb = neighbourhood(v)`,
    /// taken since the last change; a backend may use it to skip a search. The
    /// default ignores `nb`.
    fn insert_with_neighbourhood(&mut self, v: Voxel, nb: u32) -> bool {
        let _ = nb;
        self.insert(v)
    }
    /// [`remove`](Self::remove) for a caller that holds `nb = neighbourhood(v)`,
    /// taken since the last change; a backend may use it to skip a search. The
    /// default ignores `nb`.
    fn remove_with_neighbourhood(&mut self, v: Voxel, nb: u32) -> bool {
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
