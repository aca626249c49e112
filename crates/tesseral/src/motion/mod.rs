//! Moving objects: interference, continuous collision, a world in motion, and
//! collision-free motion planning (Ahuja & Nash 1983, §1 and §5).
//!
//! - [`intersects`], [`interference`], [`clearance`]: two octrees, the second placed
//!   at an integer offset in any of the 24 orientations ([`Rotation`]), compared by
//!   one parallel traversal of both trees without building the moved tree.
//! - [`first_contact`]: the exact first time of contact for linear motion, so a fast
//!   object cannot tunnel through a thin wall between time steps.
//! - [`World`]: one static environment and moving objects with trajectories, advanced
//!   in time steps, with interference at each step and a swept test between steps.
//! - [`read_world`]: the JSON world file of `tesseral simulate`.
//! - [`plan()`]: configuration-space obstacles as a Minkowski sum of octrees, A* over free
//!   octree cells of varying sizes with exact adjacency, then smoothing.
//!
//! Conventions: a voxel is the unit cube at its lowest corner; two solids *intersect*
//! when they share a voxel (interior), and *touch* when their closed cubes meet
//! without sharing interior.

mod draw;
mod interfere;
mod minkowski;
mod orient;
mod plan;
mod plan_estimate;
mod plan_search;
mod plan_turns;
mod simulate;
mod sweep;
mod traverse;
mod view;
mod world;
mod world_file;

pub use draw::{
    frame_regions, render_frame, render_plan, CONTACT_COLOUR, ENVIRONMENT_COLOUR, OBJECT_COLOURS,
    PATH_COLOUR, SWEPT_COLOUR,
};
pub use interfere::{
    clearance, clearance_at, clearance_squared, interference, interference_placed, intersects,
    intersects_placed, Aabb, Interference, Placed, Placement,
};
pub use orient::{Rotation, RotationError};
pub use plan::{
    config_obstacles, minkowski_sum, plan, reflected, rotated, NoPath, Plan, PlanOptions,
};
pub use plan_estimate::{estimate_plan, PlanEstimate, PLAN_BYTES_PER_CELL};
pub use plan_turns::{plan_with_turns, quarter_turn_sweep, TurnPlan};
pub use simulate::Step;
#[cfg(test)]
use sweep::first_contact_brute;
pub use sweep::{first_contact, Fraction, SweptContact};
pub use view::{BoxTree, Traversable};
pub use world::{
    Body, Contact, Frame, MovingObject, Simulation, Trajectory, TranslationMethod, World,
};
pub use world_file::{
    read_body, read_solid, read_world, read_world_limited, WorldError, WorldFile, MAX_OBJECTS,
    MAX_STEPS,
};

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_turns;
