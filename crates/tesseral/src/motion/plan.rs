//! Collision-free motion planning for a translating object (Ahuja & Nash §5, after
//! Lozano-Pérez & Wesley's configuration space).
//!
//! 1. **Configuration-space obstacles.** The object, placed at integer offset `p`,
//!    hits the environment exactly when `p` lies in `env ⊕ (−object)`, the Minkowski
//!    sum of the environment and the reflected object, computed on octrees by
//!    [`minkowski_sum`] (`minkowski.rs`).
//! 2. **Free cells.** The free configurations inside the bounds form a linear octree
//!    whose leaves are the free cells, of varying sizes.
//! 3. **A\*.** The search runs over free cells with exact face adjacency (found by a
//!    range query of the cells beyond each face). A state is a cell and the point at
//!    which the path enters it; crossing a face moves to the nearest point of the
//!    shared face (per axis, this lazy choice is optimal for any fixed sequence of
//!    cells), at its L1 cost. With the L1 distance to the goal as the (consistent)
//!    heuristic, the path found has the least number of unit axis moves: the same
//!    cost as Dijkstra on the dense grid of positions.
//! 4. **Smoothing.** Waypoints are joined by straight segments while the swept test
//!    ([`first_contact`](super::sweep::first_contact)) proves each segment
//!    collision-free.

use serde::Serialize;

use super::interfere::{interference, wide, IBox, Placement};
use super::orient::Rotation;
use super::traverse::Node;
use super::view::BoxTree;
use super::Aabb;
use crate::linear::{Block, CellClass, Classifier, LinearOctree, OctreeError, MAX_DEPTH};
use crate::Voxel;

pub use super::minkowski::{config_obstacles, minkowski_sum, reflected, rotated};
pub(crate) use super::minkowski::{map_tree, minkowski_in};
use super::plan_search::{astar, path_clearance, smooth};

/// Settings of [`plan`].
#[derive(Debug, Clone, PartialEq)]
pub struct PlanOptions {
    /// The object's fixed orientation.
    pub rotation: Rotation,
    /// The box of world voxels the object must stay inside. `None`: the bounding box
    /// of the environment and of the object at the start and at the goal, grown by
    /// [`PlanOptions::margin`] on every side.
    pub region: Option<Aabb>,
    /// How far the default region reaches beyond the bounding box, in voxels (room
    /// to go around the outside of the obstacles).
    pub margin: i64,
    /// Join waypoints by straight collision-free segments.
    pub smooth: bool,
    /// Give up after settling this many search states.
    pub max_states: usize,
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions {
            rotation: Rotation::IDENTITY,
            region: None,
            margin: 0,
            smooth: true,
            max_states: 4_000_000,
        }
    }
}

/// Why [`plan`] found no path.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum NoPath {
    /// The object has no voxels.
    #[error("no path: the object is empty")]
    EmptyObject,
    /// The object does not fit inside the region at any offset.
    #[error("no path: the object does not fit in the region")]
    ObjectTooLarge,
    /// The start offset leaves the bounds.
    #[error("no path: the start ({}, {}, {}) puts the object outside the region (offsets {}..={}, {}..={}, {}..={} allowed)", .start[0], .start[1], .start[2], .bounds.min[0], .bounds.max[0], .bounds.min[1], .bounds.max[1], .bounds.min[2], .bounds.max[2])]
    StartOutOfBounds {
        /// The start.
        start: Voxel,
        /// The allowed offsets.
        bounds: Aabb,
    },
    /// The goal offset leaves the bounds.
    #[error("no path: the goal ({}, {}, {}) puts the object outside the region (offsets {}..={}, {}..={}, {}..={} allowed)", .goal[0], .goal[1], .goal[2], .bounds.min[0], .bounds.max[0], .bounds.min[1], .bounds.max[1], .bounds.min[2], .bounds.max[2])]
    GoalOutOfBounds {
        /// The goal.
        goal: Voxel,
        /// The allowed offsets.
        bounds: Aabb,
    },
    /// At the start the object already overlaps the environment.
    #[error(
        "no path: at the start the object overlaps the environment in {overlap_voxels} voxels"
    )]
    StartBlocked {
        /// Shared voxels at the start.
        overlap_voxels: u64,
    },
    /// At the goal the object would overlap the environment.
    #[error(
        "no path: at the goal the object would overlap the environment in {overlap_voxels} voxels"
    )]
    GoalBlocked {
        /// Shared voxels at the goal.
        overlap_voxels: u64,
    },
    /// The free region around the start does not reach the goal.
    #[error("no path: the goal is not reachable; the free region around the start ({cells} cells, {positions} positions) is enclosed")]
    Unreachable {
        /// Free cells reached from the start.
        cells: usize,
        /// Positions (offsets) in those cells.
        positions: u64,
    },
    /// The search stopped at [`PlanOptions::max_states`].
    #[error("no path found within the search limit of {0} states")]
    SearchLimit(usize),
    /// The configuration space is too large for an octree.
    #[error("no path: {0}")]
    Octree(#[from] OctreeError),
}

/// A collision-free path.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Plan {
    /// The smoothed path: offsets joined by straight collision-free segments, from
    /// the start to the goal.
    pub waypoints: Vec<Voxel>,
    /// The path found by A*, before smoothing: straight segments inside free cells
    /// and unit steps across their faces.
    pub raw: Vec<Voxel>,
    /// The number of unit axis moves of the shortest lattice path (the A* cost).
    pub steps: u64,
    /// The Euclidean length of `waypoints`.
    pub length: f64,
    /// The least clearance between the object and the environment along the
    /// smoothed path (sampled every half voxel), in voxels; `None` for an empty
    /// environment.
    pub clearance: Option<f64>,
    /// The number of free cells in the configuration space.
    pub free_cells: usize,
    /// The number of search states settled.
    pub settled: usize,
}

/// The free configuration space: a linear octree whose leaves are free cells.
pub(super) struct FreeSpace {
    tree: LinearOctree,
    pub(super) cells: Vec<Block>,
}

struct FreeClassifier<'t> {
    cobs: &'t LinearOctree,
    bounds: IBox,
}

impl Classifier for FreeClassifier<'_> {
    fn classify(&self, min: Voxel, size_log2: u8) -> CellClass {
        let side = 1i64 << size_log2;
        let p = IBox::cube(min, side);
        if !p.overlaps(&self.bounds) {
            return CellClass::Outside;
        }
        let Some(c) = self.cobs.code_of(min) else {
            return CellClass::Outside;
        };
        let end = c + (1u64 << (3 * u32::from(size_log2)));
        let leaves = self.cobs.leaves();
        let i = leaves.partition_point(|l| l.end() <= c);
        let empty = i == leaves.len() || leaves[i].code() >= end;
        let full = !empty && leaves[i].code() <= c && leaves[i].end() >= end;
        if full {
            CellClass::Outside
        } else if empty && p.inside(&self.bounds) {
            CellClass::Inside
        } else if size_log2 == 0 {
            if empty {
                CellClass::Inside
            } else {
                CellClass::Outside
            }
        } else {
            CellClass::Partial
        }
    }
}

impl FreeSpace {
    fn cell_of(&self, p: Voxel) -> Option<usize> {
        let c = self.tree.code_of(p)?;
        let leaves = self.tree.leaves();
        let i = leaves.partition_point(|l| l.code() <= c);
        (i > 0 && leaves[i - 1].contains_code(c)).then(|| i - 1)
    }

    pub(super) fn ibox(&self, i: usize) -> IBox {
        let b = self.cells[i];
        IBox::cube(b.min, b.size())
    }

    /// Free cells meeting the box `q`.
    fn cells_in(&self, q: &IBox, out: &mut Vec<usize>) {
        if let Some(root) = Node::root(&self.tree) {
            self.cells_in_node(root, q, out);
        }
    }

    fn cells_in_node(&self, n: Node, q: &IBox, out: &mut Vec<usize>) {
        let b = IBox::cube(n.min, n.side());
        if !b.overlaps(q) {
            return;
        }
        let leaves = self.tree.leaves();
        if n.is_full(leaves) {
            out.push(n.lo);
            return;
        }
        let mut kids = [n; 8];
        let k = n.children(leaves, &mut kids);
        for &c in &kids[..k] {
            self.cells_in_node(c, q, out);
        }
    }

    /// The cells sharing a face with cell `i`, with the axis and direction crossed.
    pub(super) fn neighbours(&self, i: usize) -> Vec<(u32, u8, bool)> {
        let b = self.ibox(i);
        let mut out = Vec::new();
        let mut found = Vec::new();
        for axis in 0..3 {
            for up in [false, true] {
                let mut q = b;
                if up {
                    q.lo[axis] = b.hi[axis];
                    q.hi[axis] = b.hi[axis] + 1;
                } else {
                    q.lo[axis] = b.lo[axis] - 1;
                    q.hi[axis] = b.lo[axis];
                }
                found.clear();
                self.cells_in(&q, &mut found);
                out.extend(found.iter().map(|&j| (j as u32, axis as u8, up)));
            }
        }
        out
    }
}

/// Finds a collision-free path that translates `object` (turned by
/// `options.rotation`) from offset `from` to offset `to` through `environment`.
///
/// The path is optimal in unit axis moves on the lattice of offsets (see the module
/// documentation), then smoothed. Every point of the returned path, and every point
/// between them, keeps the object clear of the environment's voxels (touching is
/// allowed) and inside the bounds.
///
/// # Errors
/// [`NoPath`], saying why: an endpoint out of bounds or blocked, the goal enclosed
/// away from the start, or the search limit reached.
///
/// ```
/// use tesseral::linear::LinearOctree;
/// use tesseral::motion::{plan, PlanOptions};
/// // A wall at x = 4 with a hole at (y, z) = (5, 5); the region is x, y, z in 0..8.
/// let wall: Vec<[i64; 3]> = (0..64).filter(|i| *i != 5 * 8 + 5).map(|i| [4, i / 8, i % 8]).collect();
/// let env = LinearOctree::from_voxels(3, [0, 0, 0], wall).unwrap();
/// let dot = LinearOctree::from_voxels(0, [0, 0, 0], [[0, 0, 0]]).unwrap();
/// let p = plan(&env, &dot, [0, 0, 0], [7, 0, 0], &PlanOptions::default()).unwrap();
/// assert_eq!(p.steps, 7 + 2 * 5 + 2 * 5); // up to the hole and back down
/// ```
pub fn plan(
    environment: &LinearOctree,
    object: &LinearOctree,
    from: Voxel,
    to: Voxel,
    options: &PlanOptions,
) -> Result<Plan, NoPath> {
    let rotation = options.rotation;
    let bounds = plan_bounds(environment, object, from, to, options)?;
    let inside = |p: Voxel| (0..3).all(|a| bounds.min[a] <= p[a] && p[a] <= bounds.max[a]);
    if !inside(from) {
        return Err(NoPath::StartOutOfBounds {
            start: from,
            bounds,
        });
    }
    if !inside(to) {
        return Err(NoPath::GoalOutOfBounds { goal: to, bounds });
    }
    let at = |p: Voxel| Placement {
        rotation,
        offset: p,
    };
    let hit = interference(environment, object, at(from), false);
    if hit.intersects {
        return Err(NoPath::StartBlocked {
            overlap_voxels: hit.overlap_voxels,
        });
    }
    let hit = interference(environment, object, at(to), false);
    if hit.intersects {
        return Err(NoPath::GoalBlocked {
            overlap_voxels: hit.overlap_voxels,
        });
    }

    // Configuration space: one cube spanning the bounds.
    let extent = (0..3)
        .map(|a| bounds.max[a].abs_diff(bounds.min[a]) + 1)
        .max()
        .unwrap_or(1);
    let depth = u8::try_from(extent.next_power_of_two().trailing_zeros()).unwrap_or(u8::MAX);
    if depth > MAX_DEPTH {
        return Err(OctreeError::DepthTooLarge(depth).into());
    }
    let neg = map_tree(object, Rotation::REFLECTION.compose(rotation), [1, 1, 1]);
    let cobs = minkowski_in(environment, &neg, depth, bounds.min)?;
    let free = LinearOctree::from_classifier(
        depth,
        bounds.min,
        &FreeClassifier {
            cobs: &cobs,
            bounds: IBox {
                lo: wide(bounds.min),
                hi: wide(bounds.max).map(|c| c + 1),
            },
        },
    )?;
    let space = FreeSpace {
        cells: free.blocks().collect(),
        tree: free,
    };
    let start_cell = space.cell_of(from).expect("start is free and in bounds");
    let goal_cell = space.cell_of(to).expect("goal is free and in bounds");

    let search = astar(&space, start_cell, from, goal_cell, to, options.max_states)?;
    let raw = search.points;
    let waypoints = if options.smooth {
        smooth(
            &BoxTree::new(environment),
            &BoxTree::new(object),
            rotation,
            &raw,
        )
    } else {
        raw.clone()
    };
    // Summed from +0.0: `Sum` for f64 starts at -0.0, which a path of one waypoint
    // (the start at the goal) would keep as its length, written -0.0 in JSON.
    let length = waypoints
        .windows(2)
        .map(|w| {
            (0..3)
                .map(|a| ((w[1][a] - w[0][a]) as f64).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .fold(0.0, |total, d| total + d);
    let clearance = path_clearance(environment, object, rotation, &waypoints);
    Ok(Plan {
        waypoints,
        raw,
        steps: search.cost,
        length,
        clearance,
        free_cells: space.cells.len(),
        settled: search.settled,
    })
}

/// The offsets of the object that keep it inside the planning region (the region
/// of `options`, or the bounding box grown by the margin).
///
/// # Errors
/// [`NoPath::EmptyObject`], [`NoPath::ObjectTooLarge`].
pub(crate) fn plan_bounds(
    environment: &LinearOctree,
    object: &LinearOctree,
    from: Voxel,
    to: Voxel,
    options: &PlanOptions,
) -> Result<Aabb, NoPath> {
    let rotation = options.rotation;
    let obj_box = rotated(object, rotation)
        .bbox()
        .ok_or(NoPath::EmptyObject)?;
    let region = match options.region {
        Some(r) => r,
        None => {
            let (mut lo, mut hi) = environment.bbox().unwrap_or((from, from));
            for p in [from, to] {
                for a in 0..3 {
                    lo[a] = lo[a].min(p[a].saturating_add(obj_box.0[a]));
                    hi[a] = hi[a].max(p[a].saturating_add(obj_box.1[a]));
                }
            }
            let m = options.margin.max(0);
            Aabb {
                min: lo.map(|c| c.saturating_sub(m)),
                max: hi.map(|c| c.saturating_add(m)),
            }
        }
    };
    // The offsets that keep the object's voxels inside the region.
    let bounds = Aabb {
        min: [0, 1, 2].map(|a| region.min[a].saturating_sub(obj_box.0[a])),
        max: [0, 1, 2].map(|a| region.max[a].saturating_sub(obj_box.1[a])),
    };
    if (0..3).any(|a| bounds.max[a] < bounds.min[a]) {
        return Err(NoPath::ObjectTooLarge);
    }
    Ok(bounds)
}
