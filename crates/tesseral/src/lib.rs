//! # tesseral
//!
//! Octrees of 3-D solids and surfaces. See `ARCHITECTURE.md` at the repository root
//! for how the parts fit together, and `docs/conventions.md` for the conventions
//! every module shares (axes, child labels, depth, voxel centres).
//!
//! Conventions in one breath: x east, y north, z up; a child label is
//! `d = x + 2y + 4z`; a tesseral (Morton) code holds the octal digits of the path from
//! the root, most significant first; voxel `(i, j, k)` is the half-open unit cube at
//! that corner, sampled at its centre.
#![deny(missing_docs)]

pub mod code;
pub mod csg;
pub mod dynamic;
pub mod io;
pub mod lattice;
pub mod linear;
pub mod mesh;
pub mod model;
pub mod motion;
pub mod occupancy;
pub mod partition;
pub mod pointer;
pub mod render;
pub mod rsmc;
pub mod view;

// The main types at the crate root, as rstar does: `tesseral::LinearOctree` and
// friends; the modules stay public for everything else.
pub use csg::{Scene, SceneError};
pub use dynamic::DynamicOctree;
pub use io::{read_model, write_model, FormatError};
pub use linear::{LinearOctree, OctreeError, SetOp};
pub use model::{Frame, Model, ModelError};
pub use occupancy::OccupancyMap;
pub use pointer::PointerOctree;

/// A voxel (or any lattice point) in world coordinates.
pub type Voxel = [i64; 3];
