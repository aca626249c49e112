//! The search and smoothing of [`plan`](super::plan()): A* over (free cell, entry
//! point) states with the L1 heuristic, then string pulling checked by the swept test.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap};

use super::interfere::{clearance_at, narrow, Placed, Placement};
use super::orient::Rotation;
use super::plan::{FreeSpace, NoPath};
use super::sweep::first_contact;
use super::view::BoxTree;
use crate::linear::LinearOctree;
use crate::Voxel;

fn l1(a: Voxel, b: Voxel) -> u64 {
    (0..3).map(|i| a[i].abs_diff(b[i])).sum()
}

pub(super) struct Search {
    pub(super) points: Vec<Voxel>,
    pub(super) cost: u64,
    pub(super) settled: usize,
}

/// A* over (cell, entry point) states.
pub(super) fn astar(
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
pub(super) fn smooth(
    env: &BoxTree,
    obj: &BoxTree,
    rotation: Rotation,
    raw: &[Voxel],
) -> Vec<Voxel> {
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
pub(super) fn path_clearance(
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
