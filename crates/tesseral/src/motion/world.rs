//! A world in motion: one static environment octree and moving objects, each with its
//! own octree and trajectory, advanced in time steps (Ahuja & Nash §5: "one octree is
//! maintained for the entire static environment and one is maintained for each of
//! the moving objects").
//!
//! At every step each object stands at its trajectory's position rounded to the
//! nearest voxel, and every pair (environment–object and object–object) is tested
//! for interference. Between two steps each object moves in a straight line between
//! its two step positions, and the swept test
//! ([`first_contact`](super::sweep::first_contact)) gives the exact time at which a
//! pair begins to overlap, so a fast object cannot tunnel through a thin wall unseen.

use std::ops::ControlFlow;

use serde::Serialize;

use super::interfere::{Aabb, Placed, Placement};
use super::orient::Rotation;
use super::sweep::Fraction;
use super::view::BoxTree;
use crate::linear::{LinearOctree, OctreeError};
use crate::Voxel;

/// How an object moves: its position (the offset added to its octree's voxels after
/// rotation) as a function of time.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Trajectory {
    /// `start + velocity * t`.
    Constant {
        /// The position at time 0.
        start: [f64; 3],
        /// Voxels per unit time.
        velocity: [f64; 3],
    },
    /// Straight lines through `(time, position)` points sorted by time; the object
    /// waits at the first point before its time and at the last one after.
    Waypoints(Vec<(f64, [f64; 3])>),
}

impl Trajectory {
    /// The position at time `t`.
    #[must_use]
    pub fn position(&self, t: f64) -> [f64; 3] {
        match self {
            Trajectory::Constant { start, velocity } => {
                [0, 1, 2].map(|a| start[a] + velocity[a] * t)
            }
            Trajectory::Waypoints(points) => {
                let Some(first) = points.first() else {
                    return [0.0; 3];
                };
                if t <= first.0 {
                    return first.1;
                }
                for w in points.windows(2) {
                    let ((t0, p0), (t1, p1)) = (w[0], w[1]);
                    if t <= t1 {
                        let s = if t1 > t0 { (t - t0) / (t1 - t0) } else { 1.0 };
                        return [0, 1, 2].map(|a| p0[a] + (p1[a] - p0[a]) * s);
                    }
                }
                points[points.len() - 1].1
            }
        }
    }

    /// The position at time `t` rounded to the nearest voxel.
    #[must_use]
    pub fn offset_at(&self, t: f64) -> Voxel {
        self.position(t).map(|c| c.round() as i64)
    }
}

/// How the world keeps each object where it is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[non_exhaustive]
pub enum TranslationMethod {
    /// The object's octree stays as built and its placement (rotation and integer
    /// offset) changes; interference places cells on the fly during the parallel
    /// traversal. No tree is rebuilt, so this is the fastest.
    #[default]
    Offset,
    /// Each object's octree is rotated once and then translated at every step by its
    /// displacement since the last step with [`LinearOctree::translate`] (the linear
    /// octree's translation by tesseral addition), so the stored tree always stands
    /// where the object is, as Ahuja & Nash keep a moving object's octree current.
    Linear,
    /// As [`TranslationMethod::Linear`], but each object is kept as a pointer octree
    /// and translated by Ahuja & Nash's label arithmetic
    /// ([`crate::pointer::PointerOctree::translate`]: label increments with carries,
    /// postorder in the direction of motion, compaction); its linear form is read
    /// off after each move for the interference tests.
    Labels,
}

impl TranslationMethod {
    pub(super) fn keeps_trees(self) -> bool {
        self != TranslationMethod::Offset
    }
}

/// The bodies of a world prepared for queries.
pub(super) struct Prepared {
    pub(super) environment: BoxTree,
    pub(super) objects: Vec<BoxTree>,
}

/// One moving object.
#[derive(Debug, Clone)]
pub struct MovingObject {
    /// A name for reports.
    pub name: String,
    /// Its solid, in its own coordinates.
    pub tree: LinearOctree,
    /// Its fixed orientation.
    pub rotation: Rotation,
    /// Where it is over time.
    pub trajectory: Trajectory,
}

/// The static environment and the moving objects.
#[derive(Debug, Clone)]
pub struct World {
    /// The static scene.
    pub environment: LinearOctree,
    /// The moving objects.
    pub objects: Vec<MovingObject>,
    /// How objects are kept current.
    pub method: TranslationMethod,
}

/// One of the two bodies in a contact.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Body {
    /// The static environment.
    Environment,
    /// A moving object, by index and name.
    Object {
        /// Its index in [`World::objects`].
        index: usize,
        /// Its name.
        name: String,
    },
}

/// The start of a contact between two bodies.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Contact {
    /// The world time at which they begin to overlap (exact up to `f64` rounding of
    /// `step_time + fraction * time_step`).
    pub time: f64,
    /// The step at whose start the move that brings them together begins.
    pub step: u64,
    /// The exact fraction of that step's move at which they begin to overlap.
    pub fraction: Fraction,
    /// The first body (the environment, or the object with the lower index).
    pub a: Body,
    /// The second body.
    pub b: Body,
    /// A block of `a` that is hit.
    pub a_block: Aabb,
    /// The block of `b` that hits it, where `b` stands at the start of the move.
    pub b_block: Aabb,
    /// True when the bodies do not overlap at the next step: only the swept test sees
    /// this contact (the object tunnels through, or grazes and leaves).
    pub between_steps: bool,
}

/// The state of the world at one step.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Frame {
    /// The step number, from 0.
    pub step: u64,
    /// Its time.
    pub time: f64,
    /// Each object's integer offset.
    pub offsets: Vec<Voxel>,
    /// The pairs that overlap at this step, with the number of shared voxels:
    /// `(a, b, voxels)` where `a` is `None` for the environment.
    pub overlaps: Vec<(Option<usize>, usize, u64)>,
    /// Where the overlapping voxels are (boxes in world coordinates).
    pub contact_boxes: Vec<Aabb>,
}

/// What [`World::simulate`] found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Simulation {
    /// Every contact, in time order.
    pub contacts: Vec<Contact>,
    /// The world at each step, `steps + 1` of them (step 0 included).
    pub frames: Vec<Frame>,
}

impl World {
    /// A world with an environment and no objects.
    #[must_use]
    pub fn new(environment: LinearOctree) -> World {
        World {
            environment,
            objects: Vec::new(),
            method: TranslationMethod::default(),
        }
    }

    pub(super) fn body(&self, i: Option<usize>) -> Body {
        match i {
            None => Body::Environment,
            Some(index) => Body::Object {
                index,
                name: self.objects[index].name.clone(),
            },
        }
    }

    /// Body `i` (`None`: the environment) where it stands at `offsets`; `boxes` holds
    /// the prepared environment and objects.
    pub(super) fn placed<'s>(
        &self,
        boxes: &'s Prepared,
        i: Option<usize>,
        offsets: &[Voxel],
    ) -> Placed<'s, BoxTree> {
        match i {
            None => Placed::fixed(&boxes.environment),
            Some(i) if self.method.keeps_trees() => Placed::fixed(&boxes.objects[i]),
            Some(i) => Placed::new(
                &boxes.objects[i],
                Placement {
                    rotation: self.objects[i].rotation,
                    offset: offsets[i],
                },
            ),
        }
    }

    /// The pairs that can collide: environment–object, then object–object.
    pub(super) fn pairs(&self) -> Vec<(Option<usize>, usize)> {
        let n = self.objects.len();
        let mut pairs: Vec<(Option<usize>, usize)> = (0..n).map(|i| (None, i)).collect();
        for i in 0..n {
            for j in i + 1..n {
                pairs.push((Some(i), j));
            }
        }
        pairs
    }

    /// Advances the world `steps` times by `time_step`, from time 0, testing every
    /// pair for interference at each step and with the swept test between steps, and
    /// keeps every frame and contact (see [`World::simulate_each`], which streams them
    /// instead).
    ///
    /// # Runtime
    /// As [`World::simulate_each`]; the memory holds every frame's overlap boxes.
    ///
    /// # Errors
    /// As [`World::simulate_each`].
    pub fn simulate(&self, time_step: f64, steps: u64) -> Result<Simulation, OctreeError> {
        let mut sim = Simulation {
            contacts: Vec::new(),
            frames: Vec::new(),
        };
        self.simulate_each(time_step, steps, true, |step| {
            sim.frames.push(step.frame);
            sim.contacts.extend(step.contacts);
            ControlFlow::Continue(())
        })?;
        Ok(sim)
    }
}
