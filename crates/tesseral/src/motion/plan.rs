//! Collision-free motion planning for a translating object (Ahuja & Nash §5, after
//! Lozano-Pérez & Wesley's configuration space).
//!
//! 1. **Configuration-space obstacles.** The object, placed at integer offset `p`,
//!    hits the environment exactly when `p` lies in `env ⊕ (−object)`, the Minkowski
//!    sum of the environment and the reflected object. [`minkowski_sum`] computes it
//!    on octrees: a cell of the result is classified by a parallel traversal of the
//!    two trees (a pair of blocks sums to a box), and the top-down builder splits
//!    only the cells on the obstacles' boundary.
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
//!    ([`first_contact`]) proves each segment collision-free.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap};
use std::ops::ControlFlow;

use serde::Serialize;

use super::interfere::{clearance_at, interference, narrow, wide, IBox, Placed, Placement};
use super::orient::Rotation;
use super::sweep::first_contact;
use super::traverse::Node;
use super::view::BoxTree;
use super::Aabb;
use crate::code;
use crate::linear::{Block, CellClass, Classifier, Leaf, LinearOctree, OctreeError, MAX_DEPTH};
use crate::Voxel;

/// Maps every block of `tree` by the cube map of `rotation` (which may be the point
/// reflection) and then shifts it by `shift`. The result is a tree of the same
/// depth with as many leaves.
pub(crate) fn map_tree(tree: &LinearOctree, rotation: Rotation, shift: Voxel) -> LinearOctree {
    let side = tree.side() as i64;
    let o = rotation.apply_cube(tree.origin(), side);
    let origin = [o[0] + shift[0], o[1] + shift[1], o[2] + shift[2]];
    let mut leaves: Vec<Leaf> = tree
        .blocks()
        .map(|b| {
            let m = rotation.apply_cube(b.min, b.size());
            let rel = [0, 1, 2].map(|a| (m[a] + shift[a] - origin[a]) as u32);
            Leaf::new(code::encode(rel[0], rel[1], rel[2]), b.size_log2)
        })
        .collect();
    leaves.sort_unstable();
    LinearOctree::from_sorted_leaves(tree.depth(), origin, leaves)
        .expect("same depth as a valid tree")
}

/// The solid rotated: voxel `v` goes to `rotation.apply_voxel(v)`.
///
/// # Runtime
/// O(n log n) for n leaves.
#[must_use]
pub fn rotated(tree: &LinearOctree, rotation: Rotation) -> LinearOctree {
    map_tree(tree, rotation, [0; 3])
}

/// The point reflection of a set of lattice points: `v` goes to `−v`.
#[must_use]
pub fn reflected(tree: &LinearOctree) -> LinearOctree {
    map_tree(tree, Rotation::REFLECTION, [1, 1, 1])
}

/// Classifies cells of `a ⊕ b` by a parallel traversal of both trees.
struct MinkowskiClassifier<'t> {
    a: &'t LinearOctree,
    b: &'t LinearOctree,
    ra: Option<Node>,
    rb: Option<Node>,
}

struct MinkowskiQuery<'t> {
    a: &'t [Leaf],
    b: &'t [Leaf],
    p: IBox,
    partial: bool,
}

impl MinkowskiQuery<'_> {
    fn visit(&mut self, na: Node, nb: Node) -> ControlFlow<()> {
        // Points a + b with a in [a.lo, a.hi) and b in [b.lo, b.hi): [a.lo + b.lo, a.hi + b.hi - 1).
        let s = IBox {
            lo: [0, 1, 2].map(|i| i128::from(na.min[i]) + i128::from(nb.min[i])),
            hi: [0, 1, 2].map(|i| {
                i128::from(na.min[i])
                    + i128::from(nb.min[i])
                    + i128::from(na.side())
                    + i128::from(nb.side())
                    - 1
            }),
        };
        if !s.overlaps(&self.p) {
            return ControlFlow::Continue(());
        }
        // Once the cell is known to be partly covered, only a pair whose sum covers
        // the whole cell can change the answer, and no descendant of a pair that
        // does not cover it covers it.
        let covers = self.p.inside(&s);
        if self.partial && !covers {
            return ControlFlow::Continue(());
        }
        let fa = na.is_full(self.a);
        let fb = nb.is_full(self.b);
        if fa && fb {
            if covers {
                return ControlFlow::Break(());
            }
            self.partial = true;
            return ControlFlow::Continue(());
        }
        let mut kids = [na; 8];
        if !fa && (fb || na.k >= nb.k) {
            let n = na.children(self.a, &mut kids);
            for &c in &kids[..n] {
                self.visit(c, nb)?;
            }
        } else {
            let n = nb.children(self.b, &mut kids);
            for &c in &kids[..n] {
                self.visit(na, c)?;
            }
        }
        ControlFlow::Continue(())
    }
}

impl Classifier for MinkowskiClassifier<'_> {
    fn classify(&self, min: Voxel, size_log2: u8) -> CellClass {
        let (Some(ra), Some(rb)) = (self.ra, self.rb) else {
            return CellClass::Outside;
        };
        let side = 1i64 << size_log2;
        let mut q = MinkowskiQuery {
            a: self.a.leaves(),
            b: self.b.leaves(),
            p: IBox::cube(min, side),
            partial: false,
        };
        match q.visit(ra, rb) {
            ControlFlow::Break(()) => CellClass::Inside,
            ControlFlow::Continue(()) if q.partial => CellClass::Partial,
            ControlFlow::Continue(()) => CellClass::Outside,
        }
    }
}

/// The Minkowski sum `a ⊕ b = {x + y : x ∈ a, y ∈ b}` of two sets of lattice points
/// (voxel indices), as an octree whose space spans both: origin `a.origin +
/// b.origin`, depth one more than the deeper tree.
///
/// Built top down: a cell is outside when no pair of blocks sums to a box meeting
/// it, inside when one pair's box covers it, and split otherwise.
///
/// # Runtime
/// Proportional to the number of cells on the boundary of the sum, times the pairs
/// of cells of `a` and `b` whose sum meets each.
///
/// # Errors
/// [`OctreeError::DepthTooLarge`] when the sum would be deeper than [`MAX_DEPTH`].
///
/// ```
/// use tesseral::linear::LinearOctree;
/// use tesseral::motion::minkowski_sum;
/// let bar = LinearOctree::from_voxels(2, [0, 0, 0], (0..4).map(|x| [x, 0, 0])).unwrap();
/// let post = LinearOctree::from_voxels(2, [0, 0, 0], (0..3).map(|z| [0, 0, z])).unwrap();
/// let plate = minkowski_sum(&bar, &post).unwrap();
/// assert_eq!(plate.voxel_count(), 4 * 3);
/// assert!(plate.contains([3, 0, 2]) && !plate.contains([0, 1, 0]));
/// ```
pub fn minkowski_sum(a: &LinearOctree, b: &LinearOctree) -> Result<LinearOctree, OctreeError> {
    let depth = a.depth().max(b.depth()) + 1;
    let origin = [0, 1, 2].map(|i| a.origin()[i] + b.origin()[i]);
    minkowski_in(a, b, depth, origin)
}

pub(crate) fn minkowski_in(
    a: &LinearOctree,
    b: &LinearOctree,
    depth: u8,
    origin: Voxel,
) -> Result<LinearOctree, OctreeError> {
    let c = MinkowskiClassifier {
        a,
        b,
        ra: Node::tight_root(a),
        rb: Node::tight_root(b),
    };
    LinearOctree::from_classifier(depth, origin, &c)
}

/// The configuration-space obstacles of `object` (turned by `rotation`) among
/// `environment`: the offsets `p` at which the placed object shares a voxel with the
/// environment, `environment ⊕ −rotation(object)`.
///
/// # Errors
/// [`OctreeError::DepthTooLarge`] when the result would be deeper than [`MAX_DEPTH`].
///
/// ```
/// use tesseral::linear::LinearOctree;
/// use tesseral::motion::{config_obstacles, intersects, Placement, Rotation};
/// let env = LinearOctree::from_voxels(3, [0, 0, 0], [[4, 4, 4], [5, 4, 4]]).unwrap();
/// let obj = LinearOctree::from_voxels(1, [0, 0, 0], [[0, 0, 0], [1, 0, 0]]).unwrap();
/// let c = config_obstacles(&env, &obj, Rotation::IDENTITY).unwrap();
/// assert_eq!(c.voxel_count(), 3); // offsets x = 3, 4, 5 at (y, z) = (4, 4)
/// assert_eq!(c.contains([3, 4, 4]), intersects(&env, &obj, Placement::at([3, 4, 4])));
/// ```
pub fn config_obstacles(
    environment: &LinearOctree,
    object: &LinearOctree,
    rotation: Rotation,
) -> Result<LinearOctree, OctreeError> {
    let neg = map_tree(object, Rotation::REFLECTION.compose(rotation), [1, 1, 1]);
    minkowski_sum(environment, &neg)
}

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
struct FreeSpace {
    tree: LinearOctree,
    cells: Vec<Block>,
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

    fn ibox(&self, i: usize) -> IBox {
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
    fn neighbours(&self, i: usize) -> Vec<(u32, u8, bool)> {
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

fn l1(a: Voxel, b: Voxel) -> u64 {
    (0..3).map(|i| a[i].abs_diff(b[i])).sum()
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
    let length = waypoints
        .windows(2)
        .map(|w| {
            (0..3)
                .map(|a| ((w[1][a] - w[0][a]) as f64).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .sum();
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

struct Search {
    points: Vec<Voxel>,
    cost: u64,
    settled: usize,
}

/// A* over (cell, entry point) states.
fn astar(
    space: &FreeSpace,
    start_cell: usize,
    start: Voxel,
    goal_cell: usize,
    goal: Voxel,
    max_states: usize,
) -> Result<Search, NoPath> {
    // State: (cell, entry point); arrival: (axis, up) crossed to enter, for the path.
    let mut states: Vec<(u32, Voxel)> = vec![(start_cell as u32, start)];
    let mut index: HashMap<(u32, Voxel), u32> = HashMap::new();
    index.insert((start_cell as u32, start), 0);
    let mut g: Vec<u64> = vec![0];
    let mut parent: Vec<(u32, u8, bool)> = vec![(u32::MAX, 0, false)];
    let mut done: Vec<bool> = vec![false];
    let mut neighbours: HashMap<u32, Vec<(u32, u8, bool)>> = HashMap::new();
    // Heap entries: (f, -g, state); state u32::MAX + 1.. are goal entries.
    const GOAL: u64 = 1 << 40;
    let mut heap = BinaryHeap::new();
    heap.push(Reverse((l1(start, goal), Reverse(0u64), 0u64)));
    let mut settled = 0usize;
    let mut reached_cells = std::collections::HashSet::new();
    while let Some(Reverse((f, Reverse(gs), item))) = heap.pop() {
        if item >= GOAL {
            // The goal, reached from state item - GOAL.
            let mut points = vec![goal];
            let mut s = (item - GOAL) as u32;
            loop {
                let (_, p) = states[s as usize];
                let (prev, axis, up) = parent[s as usize];
                push_point(&mut points, p);
                if prev == u32::MAX {
                    break;
                }
                // The exit point of the previous cell, one step back across the face.
                let mut exit = p;
                exit[usize::from(axis)] += if up { -1 } else { 1 };
                push_point(&mut points, exit);
                s = prev;
            }
            points.reverse();
            return Ok(Search {
                points,
                cost: f,
                settled,
            });
        }
        let s = item as usize;
        if done[s] || gs > g[s] {
            continue;
        }
        done[s] = true;
        settled += 1;
        if settled > max_states {
            return Err(NoPath::SearchLimit(max_states));
        }
        let (cell, p) = states[s];
        reached_cells.insert(cell);
        if cell as usize == goal_cell {
            let total = g[s] + l1(p, goal);
            heap.push(Reverse((total, Reverse(total), GOAL + s as u64)));
        }
        let nbrs = neighbours
            .entry(cell)
            .or_insert_with(|| space.neighbours(cell as usize))
            .clone();
        let here = space.ibox(cell as usize);
        for (next, axis, up) in nbrs {
            let there = space.ibox(next as usize);
            let a = usize::from(axis);
            let mut q = p;
            for b in 0..3 {
                if b == a {
                    q[b] = narrow(if up { there.lo[b] } else { there.hi[b] - 1 });
                } else {
                    let lo = here.lo[b].max(there.lo[b]);
                    let hi = here.hi[b].min(there.hi[b]) - 1;
                    q[b] = narrow(i128::from(p[b]).clamp(lo, hi));
                }
            }
            let ng = g[s] + l1(p, q);
            let key = (next, q);
            let t = match index.get(&key) {
                Some(&t) => {
                    if done[t as usize] || ng >= g[t as usize] {
                        continue;
                    }
                    g[t as usize] = ng;
                    parent[t as usize] = (s as u32, axis, up);
                    t
                }
                None => {
                    let t = states.len() as u32;
                    states.push(key);
                    index.insert(key, t);
                    g.push(ng);
                    parent.push((s as u32, axis, up));
                    done.push(false);
                    t
                }
            };
            heap.push(Reverse((ng + l1(q, goal), Reverse(ng), u64::from(t))));
        }
    }
    let positions = reached_cells
        .iter()
        .map(|&c| space.cells[c as usize].size().pow(3) as u64)
        .sum();
    Err(NoPath::Unreachable {
        cells: reached_cells.len(),
        positions,
    })
}

fn push_point(points: &mut Vec<Voxel>, p: Voxel) {
    if points.last() != Some(&p) {
        points.push(p);
    }
}

/// Whether the object moves from `p` to `q` in a straight line without sharing a
/// voxel with the environment at any instant.
fn segment_free(env: &BoxTree, obj: &BoxTree, rotation: Rotation, p: Voxel, q: Voxel) -> bool {
    let mv = [0, 1, 2].map(|a| q[a] - p[a]);
    first_contact(
        Placed::fixed(env),
        [0; 3],
        Placed::new(
            obj,
            Placement {
                rotation,
                offset: p,
            },
        ),
        mv,
    )
    .is_none()
}

/// String pulling: from each kept waypoint, go straight to the farthest later
/// waypoint reachable by a chain of free straight segments checked one at a time.
fn smooth(env: &BoxTree, obj: &BoxTree, rotation: Rotation, raw: &[Voxel]) -> Vec<Voxel> {
    let Some(&first) = raw.first() else {
        return Vec::new();
    };
    let mut out = vec![first];
    let mut i = 0;
    while i + 1 < raw.len() {
        let mut j = i + 1;
        while j + 1 < raw.len() && segment_free(env, obj, rotation, raw[i], raw[j + 1]) {
            j += 1;
        }
        out.push(raw[j]);
        i = j;
    }
    out
}

/// The least clearance along the polyline, sampled every half voxel.
fn path_clearance(
    env: &LinearOctree,
    obj: &LinearOctree,
    rotation: Rotation,
    path: &[Voxel],
) -> Option<f64> {
    let mut best: Option<f64> = None;
    let mut take = |p: [f64; 3]| {
        if let Some(d) = clearance_at(env, obj, rotation, p) {
            best = Some(best.map_or(d, |b: f64| b.min(d)));
        }
    };
    if let Some(&p) = path.first() {
        take(p.map(|c| c as f64));
    }
    for w in path.windows(2) {
        let len = (0..3).map(|a| w[1][a].abs_diff(w[0][a])).max().unwrap_or(0);
        let n = (2 * len).max(1);
        for k in 1..=n {
            let s = k as f64 / n as f64;
            take([0, 1, 2].map(|a| w[0][a] as f64 + (w[1][a] - w[0][a]) as f64 * s));
        }
    }
    best
}
