//! Interference and clearance of two octrees by one parallel traversal of both trees
//! (Ahuja & Nash §5: "detecting interference between two objects is easy if octree
//! representations of the objects are given, since it requires a single parallel
//! traversal of the two trees"). The moved tree is never built: each tree's cells are
//! placed in the world on the fly (a rotation by multiples of 90° and an integer
//! offset), so cells of the two trees need not be aligned with each other.

mod boxes;
mod clearance;
mod overlap;
mod place;

pub use boxes::{narrow, wide, Aabb, Gap2, IBox, Wide};
pub use clearance::{clearance, clearance_at, clearance_squared};
pub use overlap::{interference, interference_placed, intersects, intersects_placed, Interference};
pub use place::{Placed, Placement};
