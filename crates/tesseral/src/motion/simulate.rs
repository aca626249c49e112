//! [`World::simulate_each`]: the simulation loop, handing each step to the caller as
//! it is found, so that a long run keeps one step in memory, not all of them.

use std::ops::ControlFlow;

use super::interfere::{interference_placed, Placed, Placement};
use super::plan::rotated;
use super::sweep::{first_contact, Fraction};
use super::view::BoxTree;
use super::world::{Contact, Frame, Prepared, TranslationMethod, World};
use crate::linear::{LinearOctree, OctreeError};
use crate::pointer::PointerOctree;
use crate::Voxel;

/// One step of a simulation, as [`World::simulate_each`] hands it over.
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    /// The world at this step.
    pub frame: Frame,
    /// The contacts that begin at this step: at step 0 the pairs that overlap from
    /// the start, then those that begin during the move to the next step, in time
    /// order.
    pub contacts: Vec<Contact>,
}

impl World {
    /// Advances the world `steps` times by `time_step`, from time 0, testing every
    /// pair for interference at each step and with the swept test between steps, and
    /// hands each step to `on_step` as soon as it is known; `on_step` returns
    /// [`ControlFlow::Break`] to stop early. Only the current step is held in memory.
    ///
    /// A contact is reported when a pair that does not overlap at the start of a step
    /// begins to overlap during the move to the next step (or at step 0 when it
    /// overlaps from the start). The contact time is exact for the linear move
    /// between the two rounded step positions. With `contact_boxes` false the frames'
    /// `contact_boxes` stay empty (the overlap counts are still given), which is
    /// much less work where bodies rest inside each other.
    ///
    /// # Runtime
    /// `steps × pairs` interference and swept traversals, plus, with
    /// [`TranslationMethod::Linear`] or [`TranslationMethod::Labels`], one translation
    /// of each object's tree per step.
    ///
    /// # Errors
    /// Only when trees are kept current: [`OctreeError`] when a translated tree
    /// would outgrow [`crate::linear::MAX_DEPTH`] or its coordinates overflow.
    ///
    /// ```
    /// use std::ops::ControlFlow;
    /// use tesseral::linear::LinearOctree;
    /// use tesseral::motion::{MovingObject, Rotation, Trajectory, World};
    /// let dot = LinearOctree::from_voxels(0, [0, 0, 0], [[0, 0, 0]]).unwrap();
    /// let mut world = World::new(LinearOctree::from_voxels(0, [5, 0, 0], [[5, 0, 0]]).unwrap());
    /// world.objects.push(MovingObject {
    ///     name: "dot".into(),
    ///     tree: dot,
    ///     rotation: Rotation::IDENTITY,
    ///     trajectory: Trajectory::Constant { start: [0.0; 3], velocity: [1.0, 0.0, 0.0] },
    /// });
    /// let mut first = None;
    /// world.simulate_each(1.0, 10, false, |s| {
    ///     if let Some(c) = s.contacts.first() {
    ///         first = Some(c.time);
    ///         return ControlFlow::Break(());
    ///     }
    ///     ControlFlow::Continue(())
    /// }).unwrap();
    /// assert_eq!(first, Some(4.0));
    /// ```
    pub fn simulate_each(
        &self,
        time_step: f64,
        steps: u64,
        contact_boxes: bool,
        mut on_step: impl FnMut(Step) -> ControlFlow<()>,
    ) -> Result<(), OctreeError> {
        let pairs = self.pairs();
        let offsets_at = |n: u64| -> Vec<Voxel> {
            let t = n as f64 * time_step;
            self.objects
                .iter()
                .map(|o| o.trajectory.offset_at(t))
                .collect()
        };
        let mut offsets = offsets_at(0);
        let mut current: Vec<LinearOctree> = Vec::new();
        let mut pointers: Vec<PointerOctree> = Vec::new();
        if self.method.keeps_trees() {
            for (o, off) in self.objects.iter().zip(&offsets) {
                current.push(rotated(&o.tree, o.rotation).translate(*off)?);
            }
        }
        if self.method == TranslationMethod::Labels {
            pointers = current.iter().map(PointerOctree::from_linear).collect();
        }
        // Each body is prepared once (the objects again after each move when their
        // trees are kept current), so every query runs on tight boxes.
        let mut boxes = Prepared {
            environment: BoxTree::new(&self.environment),
            objects: if self.method.keeps_trees() {
                current.iter().map(BoxTree::new).collect()
            } else {
                self.objects.iter().map(|o| BoxTree::new(&o.tree)).collect()
            },
        };
        let mut overlapping = vec![false; pairs.len()];
        for n in 0..=steps {
            let time = n as f64 * time_step;
            let mut frame = Frame {
                step: n,
                time,
                offsets: offsets.clone(),
                overlaps: Vec::new(),
                contact_boxes: Vec::new(),
            };
            let mut contacts = Vec::new();
            for (p, &(i, j)) in pairs.iter().enumerate() {
                let hit = interference_placed(
                    self.placed(&boxes, i, &offsets),
                    self.placed(&boxes, Some(j), &offsets),
                    contact_boxes,
                );
                if hit.intersects {
                    frame.overlaps.push((i, j, hit.overlap_voxels));
                    frame.contact_boxes.extend(hit.contacts);
                    if n == 0 {
                        // In contact from the start.
                        let c = first_contact(
                            self.placed(&boxes, i, &offsets),
                            [0; 3],
                            self.placed(&boxes, Some(j), &offsets),
                            [0; 3],
                        );
                        if let Some(c) = c {
                            contacts.push(Contact {
                                time,
                                step: 0,
                                fraction: Fraction::ZERO,
                                a: self.body(i),
                                b: self.body(Some(j)),
                                a_block: c.a_block,
                                b_block: c.b_block,
                                between_steps: false,
                            });
                        }
                    }
                }
                overlapping[p] = hit.intersects;
            }
            if n == steps {
                // The last step: no move follows it.
                let _ = on_step(Step { frame, contacts });
                break;
            }
            let next = offsets_at(n + 1);
            let moves: Vec<Voxel> = (0..self.objects.len())
                .map(|k| [0, 1, 2].map(|a| next[k][a] - offsets[k][a]))
                .collect();
            let mut step_contacts = Vec::new();
            for (p, &(i, j)) in pairs.iter().enumerate() {
                if overlapping[p] {
                    continue;
                }
                let a_move = i.map_or([0; 3], |i| moves[i]);
                let Some(c) = first_contact(
                    self.placed(&boxes, i, &offsets),
                    a_move,
                    self.placed(&boxes, Some(j), &offsets),
                    moves[j],
                ) else {
                    continue;
                };
                let still = match self.method {
                    TranslationMethod::Offset => interference_placed(
                        self.placed(&boxes, i, &next),
                        self.placed(&boxes, Some(j), &next),
                        false,
                    ),
                    TranslationMethod::Linear | TranslationMethod::Labels => {
                        // The trees stand at the step's start: place them by the moves.
                        let at = |k: Option<usize>| match k {
                            None => Placed::fixed(&boxes.environment),
                            Some(k) => Placed::new(&boxes.objects[k], Placement::at(moves[k])),
                        };
                        interference_placed(at(i), at(Some(j)), false)
                    }
                };
                step_contacts.push(Contact {
                    time: time + c.time.to_f64() * time_step,
                    step: n,
                    fraction: c.time,
                    a: self.body(i),
                    b: self.body(Some(j)),
                    a_block: c.a_block,
                    b_block: c.b_block,
                    between_steps: !still.intersects,
                });
            }
            step_contacts.sort_by_key(|x| x.fraction);
            contacts.extend(step_contacts);
            if on_step(Step { frame, contacts }).is_break() {
                return Ok(());
            }
            match self.method {
                TranslationMethod::Offset => {}
                TranslationMethod::Linear => {
                    for (k, mv) in moves.iter().enumerate() {
                        if *mv != [0; 3] {
                            current[k] = current[k].translate(*mv)?;
                            boxes.objects[k] = BoxTree::new(&current[k]);
                        }
                    }
                }
                TranslationMethod::Labels => {
                    for (k, mv) in moves.iter().enumerate() {
                        if *mv != [0; 3] {
                            pointers[k].translate(*mv)?;
                            current[k] = pointers[k].to_linear();
                            boxes.objects[k] = BoxTree::new(&current[k]);
                        }
                    }
                }
            }
            offsets = next;
        }
        Ok(())
    }
}
