//! Planning with turns (Ahuja & Nash §5): the object may also turn by quarter turns
//! about x, y and z, over the 24 orientations of the cube.
//!
//! The configuration space is one octree per orientation (the Minkowski sum of the
//! environment and the reflected, turned object, built when the search first needs
//! it). A* runs over states (offset, orientation): a unit axis move costs 1, and so
//! does a quarter turn about the pivot (the object's lattice origin, as everywhere in
//! [`Rotation`]). A turn is allowed where the object is free in both orientations
//! **and** along the sweep between them. The sweep is conservative: every block of
//! the object is turned in steps small enough that no point moves more than half a
//! voxel between samples, and every voxel within half a voxel of a turned block's
//! bounding box counts as swept.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap, HashSet};

use super::interfere::{interference, Aabb, Placement};
use super::orient::Rotation;
use super::plan::{map_tree, minkowski_in, rotated, NoPath, PlanOptions};
use crate::linear::{LinearOctree, OctreeError, MAX_DEPTH};
use crate::Voxel;

/// A search state: an offset and an orientation's index in [`Rotation::all`].
type State = (Voxel, usize);
/// The best cost found to each state, and the state it came from.
type Distances = HashMap<State, (u64, Option<State>)>;

/// A path that may turn: each state is an offset and an orientation, and
/// consecutive states differ by one unit move or one quarter turn.
#[derive(Debug, Clone, PartialEq)]
pub struct TurnPlan {
    /// Every state from the start to the goal.
    pub states: Vec<(Voxel, Rotation)>,
    /// Unit axis moves along the path.
    pub moves: u64,
    /// Quarter turns along the path.
    pub turns: u64,
    /// States settled by the search.
    pub settled: usize,
}

impl TurnPlan {
    /// The states where the motion changes: the start, each state before a turn or a
    /// change of direction, the goal.
    #[must_use]
    pub fn waypoints(&self) -> Vec<(Voxel, Rotation)> {
        let s = &self.states;
        let mut out: Vec<(Voxel, Rotation)> = s.first().copied().into_iter().collect();
        for i in 1..s.len().saturating_sub(1) {
            let step = |a: usize, b: usize| -> (Voxel, bool) {
                (
                    std::array::from_fn(|k| s[b].0[k] - s[a].0[k]),
                    s[a].1 != s[b].1,
                )
            };
            if step(i - 1, i) != step(i, i + 1) {
                out.push(s[i]);
            }
        }
        if s.len() > 1 {
            out.push(s[s.len() - 1]);
        }
        out
    }
}

/// The voxels the object (already turned to `from`) sweeps while turning a quarter
/// turn `dir` (±1) about `axis` through its lattice origin: a conservative superset.
#[must_use]
pub fn quarter_turn_sweep(object: &LinearOctree, axis: usize, dir: i32) -> HashSet<Voxel> {
    let blocks: Vec<_> = object.blocks().collect();
    let corners = |b: &crate::linear::Block| -> Vec<[f64; 3]> {
        (0..8)
            .map(|c| std::array::from_fn(|a| (b.min[a] + ((c >> a) & 1) * b.size()) as f64))
            .collect()
    };
    let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
    // The farthest corner from the axis bounds every point's speed.
    let reach = blocks
        .iter()
        .flat_map(&corners)
        .map(|p| p[u].hypot(p[w]))
        .fold(0.0f64, f64::max);
    // Chord between samples at most half a voxel: reach * step <= 1/2.
    let samples = ((std::f64::consts::FRAC_PI_2 * reach / 0.5).ceil() as usize).max(1);
    let mut swept = HashSet::new();
    for i in 0..=samples {
        let theta = f64::from(dir) * std::f64::consts::FRAC_PI_2 * i as f64 / samples as f64;
        let (s, c) = theta.sin_cos();
        for b in &blocks {
            let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            for p in corners(b) {
                let mut q = p;
                q[u] = c * p[u] - s * p[w];
                q[w] = s * p[u] + c * p[w];
                for a in 0..3 {
                    lo[a] = lo[a].min(q[a]);
                    hi[a] = hi[a].max(q[a]);
                }
            }
            // Every voxel whose cube meets the box grown by half a voxel across the
            // axis (points do not move along it).
            let grow = |a: usize| if a == axis { 0.0 } else { 0.5 };
            let first: [i64; 3] = std::array::from_fn(|a| (lo[a] - grow(a)).floor() as i64);
            let last: [i64; 3] = std::array::from_fn(|a| (hi[a] + grow(a)).ceil() as i64 - 1);
            for x in first[0]..=last[0] {
                for y in first[1]..=last[1] {
                    for z in first[2]..=last[2] {
                        swept.insert([x, y, z]);
                    }
                }
            }
        }
    }
    swept
}

/// Finds a shortest path (moves and quarter turns, each costing 1) for `object`
/// starting at offset `from` in orientation `start`, to offset `to` in any
/// orientation. See the module docs.
///
/// # Errors
/// [`NoPath`] with its reason: an empty object, a start or goal outside the region
/// or blocked in every orientation the search could reach, an enclosed start, or the
/// search limit.
pub fn plan_with_turns(
    environment: &LinearOctree,
    object: &LinearOctree,
    from: Voxel,
    to: Voxel,
    start: Rotation,
    options: &PlanOptions,
) -> Result<TurnPlan, NoPath> {
    let orientations = Rotation::all();
    let index: HashMap<Rotation, usize> = orientations
        .iter()
        .enumerate()
        .map(|(i, &r)| (r, i))
        .collect();
    let turned: Vec<LinearOctree> = orientations.iter().map(|&r| rotated(object, r)).collect();
    let boxes: Vec<(Voxel, Voxel)> = turned
        .iter()
        .map(|t| t.bbox().ok_or(NoPath::EmptyObject))
        .collect::<Result<_, _>>()?;
    let region = match options.region {
        Some(r) => r,
        None => {
            let (mut lo, mut hi) = environment.bbox().unwrap_or((from, from));
            let s = index[&start];
            for p in [from, to] {
                for a in 0..3 {
                    lo[a] = lo[a].min(p[a].saturating_add(boxes[s].0[a]));
                    hi[a] = hi[a].max(p[a].saturating_add(boxes[s].1[a]));
                }
            }
            let m = options.margin.max(0);
            Aabb {
                min: lo.map(|c| c.saturating_sub(m)),
                max: hi.map(|c| c.saturating_add(m)),
            }
        }
    };
    // Per orientation, the offsets that keep the object inside the region.
    let bounds: Vec<Aabb> = boxes
        .iter()
        .map(|(lo, hi)| Aabb {
            min: [0, 1, 2].map(|a| region.min[a].saturating_sub(lo[a])),
            max: [0, 1, 2].map(|a| region.max[a].saturating_sub(hi[a])),
        })
        .collect();
    let within =
        |p: Voxel, o: usize| (0..3).all(|a| bounds[o].min[a] <= p[a] && p[a] <= bounds[o].max[a]);
    let s0 = index[&start];
    if !within(from, s0) {
        return Err(NoPath::StartOutOfBounds {
            start: from,
            bounds: bounds[s0],
        });
    }
    if !(0..24).any(|o| within(to, o)) {
        return Err(NoPath::GoalOutOfBounds {
            goal: to,
            bounds: bounds[s0],
        });
    }
    let hit = interference(environment, &turned[s0], Placement::at(from), false);
    if hit.intersects {
        return Err(NoPath::StartBlocked {
            overlap_voxels: hit.overlap_voxels,
        });
    }
    // One configuration space for every orientation, over the union of the bounds.
    let lo: Voxel = std::array::from_fn(|a| bounds.iter().map(|b| b.min[a]).min().unwrap_or(0));
    let hi: Voxel = std::array::from_fn(|a| bounds.iter().map(|b| b.max[a]).max().unwrap_or(0));
    let extent = (0..3).map(|a| hi[a].abs_diff(lo[a]) + 1).max().unwrap_or(1);
    let depth = u8::try_from(extent.next_power_of_two().trailing_zeros()).unwrap_or(u8::MAX);
    if depth > MAX_DEPTH {
        return Err(OctreeError::DepthTooLarge(depth).into());
    }
    let mut cspace: Vec<Option<LinearOctree>> = vec![None; 24];
    let mut sweeps: HashMap<(usize, usize, i32), LinearOctree> = HashMap::new();
    let free =
        |p: Voxel, o: usize, cspace: &mut Vec<Option<LinearOctree>>| -> Result<bool, NoPath> {
            if !within(p, o) {
                return Ok(false);
            }
            if cspace[o].is_none() {
                // The offsets where the turned object meets the environment: the sum with
                // the point reflection -v (a voxel reflects to -v - 1, hence the shift).
                let neg = map_tree(
                    object,
                    Rotation::REFLECTION.compose(orientations[o]),
                    [1, 1, 1],
                );
                cspace[o] = Some(minkowski_in(environment, &neg, depth, lo)?);
            }
            Ok(!cspace[o].as_ref().is_some_and(|c| c.contains(p)))
        };
    let h = |p: Voxel| -> u64 { (0..3).map(|a| p[a].abs_diff(to[a])).sum() };
    let mut dist: Distances = HashMap::new();
    let mut heap = BinaryHeap::new();
    dist.insert((from, s0), (0, None));
    heap.push(Reverse((h(from), 0u64, from, s0)));
    let mut settled = 0usize;
    let mut done = HashSet::new();
    while let Some(Reverse((_, g, p, o))) = heap.pop() {
        if !done.insert((p, o)) {
            continue;
        }
        settled += 1;
        if p == to {
            return Ok(trace(&dist, (p, o), &orientations, settled));
        }
        if settled >= options.max_states {
            return Err(NoPath::SearchLimit(options.max_states));
        }
        let mut next: Vec<(Voxel, usize)> = Vec::with_capacity(12);
        for a in 0..3 {
            for d in [-1i64, 1] {
                let mut q = p;
                q[a] += d;
                if free(q, o, &mut cspace)? {
                    next.push((q, o));
                }
            }
        }
        for axis in 0..3 {
            for dir in [-1i32, 1] {
                let o2 = index[&Rotation::about_axis(axis, dir).compose(orientations[o])];
                if done.contains(&(p, o2)) || !free(p, o2, &mut cspace)? {
                    continue;
                }
                let sweep = sweeps.entry((o, axis, dir)).or_insert_with(|| {
                    let cells = quarter_turn_sweep(&turned[o], axis, dir);
                    let v: Vec<Voxel> = cells.into_iter().collect();
                    LinearOctree::from_voxels_fitted(&v).expect("a small sweep")
                });
                if !interference(environment, &*sweep, Placement::at(p), false).intersects {
                    next.push((p, o2));
                }
            }
        }
        for s in next {
            let g2 = g + 1;
            if dist.get(&s).is_none_or(|&(d, _)| g2 < d) {
                dist.insert(s, (g2, Some((p, o))));
                heap.push(Reverse((g2 + h(s.0), g2, s.0, s.1)));
            }
        }
    }
    Err(NoPath::Unreachable {
        cells: settled,
        positions: done.iter().map(|s| s.0).collect::<HashSet<_>>().len() as u64,
    })
}

fn trace(
    dist: &Distances,
    end: (Voxel, usize),
    orientations: &[Rotation],
    settled: usize,
) -> TurnPlan {
    let mut states = vec![end];
    while let Some(&(_, Some(prev))) = dist.get(states.last().expect("non-empty")) {
        states.push(prev);
    }
    states.reverse();
    let turns = states.windows(2).filter(|w| w[0].1 != w[1].1).count() as u64;
    TurnPlan {
        moves: states.len() as u64 - 1 - turns,
        turns,
        states: states
            .into_iter()
            .map(|(p, o)| (p, orientations[o]))
            .collect(),
        settled,
    }
}
