//! Global checks that a voxel set is bounded by one closed surface of sphere
//! topology. Slow (O(V log V) plus a flood fill of the bounding box), for tests and
//! periodic checks of a running chain.
//!
//! ```
//! use tesseral::rsmc::topology::check_sphere;
//! let report = check_sphere(&[[0, 0, 0], [1, 0, 0]]).unwrap();
//! assert_eq!((report.vertices, report.edges, report.faces), (12, 20, 10));
//! assert_eq!(report.euler(), 2);
//! // Two voxels that share only an edge: not a manifold.
//! assert!(check_sphere(&[[0, 0, 0], [1, 1, 0]]).is_err());
//! ```

use std::collections::{HashMap, HashSet};

use super::Direction;
use crate::Voxel;

/// The counts of the surface's cell complex.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SurfaceReport {
    /// Lattice points on the surface.
    pub vertices: u64,
    /// Lattice edges on the surface.
    pub edges: u64,
    /// Plaquettes (the area).
    pub faces: u64,
    /// Black voxels.
    pub volume: u64,
}

impl SurfaceReport {
    /// `V − E + F`.
    #[must_use]
    pub fn euler(&self) -> i64 {
        self.vertices as i64 - self.edges as i64 + self.faces as i64
    }
}

/// Why a voxel set is not bounded by one sphere.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum TopologyError {
    /// The set is empty.
    #[error("empty set")]
    Empty,
    /// The black voxels are not face-connected.
    #[error("black voxels are not face-connected")]
    Disconnected,
    /// The white cells are not face-connected: there is a cavity.
    #[error("the complement is not connected (cavity)")]
    Cavity,
    /// A lattice edge lies on a number of faces other than 2 (two voxels, or two empty
    /// cells, share only that edge).
    #[error("edge at {at:?} axis {axis} lies on {faces} faces")]
    Edge {
        /// Lowest point of the edge.
        at: Voxel,
        /// Axis of the edge (0 = x, 1 = y, 2 = z).
        axis: u8,
        /// How many surface faces contain it.
        faces: u32,
    },
    /// The faces around a lattice point do not form a single disc (a pinch).
    #[error("surface is pinched at vertex {0:?}")]
    Pinch(Voxel),
    /// `V − E + F` is not 2: the surface has handles.
    #[error("Euler characteristic {0}, not 2")]
    Euler(i64),
    /// A coordinate is beyond ±[`MAX_COORD`].
    #[error("voxel {0:?} is beyond ±2^60")]
    OutOfRange(Voxel),
}

/// The largest coordinate magnitude accepted (2^60), far from `i64` overflow.
pub const MAX_COORD: i64 = 1 << 60;

/// Corner points of the face of voxel `v` in direction `dir`, in cyclic order.
fn face_corners(v: Voxel, dir: Direction) -> [Voxel; 4] {
    let axis = dir.axis() as usize;
    let side = i64::from(dir.is_positive());
    let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
    let mut base = v;
    base[axis] += side;
    let mut out = [base; 4];
    out[1][a] += 1;
    out[2][a] += 1;
    out[2][b] += 1;
    out[3][b] += 1;
    out
}

/// Checks that `voxels` (no duplicates) is bounded by one closed 2-manifold of sphere
/// topology: black face-connected, complement connected, every surface edge on
/// exactly two faces, no pinched vertex, and Euler characteristic 2.
///
/// # Errors
/// The first failed condition, as a [`TopologyError`].
pub fn check_sphere(voxels: &[Voxel]) -> Result<SurfaceReport, TopologyError> {
    if voxels.is_empty() {
        return Err(TopologyError::Empty);
    }
    if let Some(v) = voxels
        .iter()
        .find(|v| v.iter().any(|c| c.unsigned_abs() > MAX_COORD as u64))
    {
        return Err(TopologyError::OutOfRange(*v));
    }
    let set: HashSet<Voxel> = voxels.iter().copied().collect();
    // Black connected.
    let mut seen: HashSet<Voxel> = HashSet::with_capacity(set.len());
    let mut stack = vec![voxels[0]];
    seen.insert(voxels[0]);
    while let Some(v) = stack.pop() {
        for d in Direction::ALL {
            let n = d.step(v);
            if set.contains(&n) && seen.insert(n) {
                stack.push(n);
            }
        }
    }
    if seen.len() != set.len() {
        return Err(TopologyError::Disconnected);
    }
    // Complement connected: flood the bounding box grown by one; every white cell in
    // it must be reached from the outer shell.
    let mut lo = voxels[0];
    let mut hi = voxels[0];
    for v in voxels {
        for a in 0..3 {
            lo[a] = lo[a].min(v[a] - 1);
            hi[a] = hi[a].max(v[a] + 1);
        }
    }
    let dims = [hi[0] - lo[0] + 1, hi[1] - lo[1] + 1, hi[2] - lo[2] + 1];
    let total = (dims[0] as u128) * (dims[1] as u128) * (dims[2] as u128);
    if total <= 50_000_000 {
        let idx = |v: Voxel| {
            ((v[0] - lo[0]) + dims[0] * ((v[1] - lo[1]) + dims[1] * (v[2] - lo[2]))) as usize
        };
        let mut state = vec![0u8; total as usize]; // 0 white unseen, 1 black, 2 white seen
        for v in voxels {
            state[idx(*v)] = 1;
        }
        let mut stack = vec![lo];
        state[idx(lo)] = 2;
        let mut reached = 1u64;
        while let Some(v) = stack.pop() {
            for d in Direction::ALL {
                let n = d.step(v);
                if (0..3).all(|a| n[a] >= lo[a] && n[a] <= hi[a]) && state[idx(n)] == 0 {
                    state[idx(n)] = 2;
                    reached += 1;
                    stack.push(n);
                }
            }
        }
        let white = total as u64 - set.len() as u64;
        if reached != white {
            return Err(TopologyError::Cavity);
        }
    } else {
        // Too big a box to flood: flood the white cells near the surface instead, from
        // the outermost one; the white shell of a cavity is not reached.
        let mut shell: HashSet<Voxel> = HashSet::new();
        for v in &set {
            for b in 0..27i64 {
                let w = [v[0] + b % 3 - 1, v[1] + (b / 3) % 3 - 1, v[2] + b / 9 - 1];
                if !set.contains(&w) {
                    shell.insert(w);
                }
            }
        }
        let start = *shell.iter().min().expect("non-empty shell");
        let mut seen = HashSet::new();
        seen.insert(start);
        let mut stack = vec![start];
        while let Some(v) = stack.pop() {
            for b in 0..27i64 {
                let n = [v[0] + b % 3 - 1, v[1] + (b / 3) % 3 - 1, v[2] + b / 9 - 1];
                if shell.contains(&n) && seen.insert(n) {
                    stack.push(n);
                }
            }
        }
        if seen.len() != shell.len() {
            return Err(TopologyError::Cavity);
        }
    }
    // Faces, edges, vertices.
    let mut faces = 0u64;
    let mut edges: HashMap<(Voxel, u8), u32> = HashMap::new();
    let mut vertex_faces: HashMap<Voxel, Vec<[Voxel; 4]>> = HashMap::new();
    for v in &set {
        for d in Direction::ALL {
            if set.contains(&d.step(*v)) {
                continue;
            }
            faces += 1;
            let c = face_corners(*v, d);
            for k in 0..4 {
                let (p, q) = (c[k], c[(k + 1) % 4]);
                let axis = (0..3).find(|&a| p[a] != q[a]).expect("edge") as u8;
                let low = if p < q { p } else { q };
                *edges.entry((low, axis)).or_default() += 1;
                vertex_faces.entry(c[k]).or_default().push(c);
            }
        }
    }
    for (&(at, axis), &n) in &edges {
        if n != 2 {
            return Err(TopologyError::Edge { at, axis, faces: n });
        }
    }
    // Each vertex: its faces, joined through shared edges, must form one cycle.
    for (&p, fs) in &vertex_faces {
        let mut comp: Vec<usize> = (0..fs.len()).collect();
        fn find(c: &mut [usize], i: usize) -> usize {
            let mut r = i;
            while c[r] != r {
                r = c[r];
            }
            c[i] = r;
            r
        }
        for a in 0..fs.len() {
            for b in a + 1..fs.len() {
                let shared = fs[a].iter().filter(|q| fs[b].contains(q)).count();
                if shared == 2 {
                    let (ra, rb) = (find(&mut comp, a), find(&mut comp, b));
                    comp[ra] = rb;
                }
            }
        }
        let root = find(&mut comp, 0);
        if (0..fs.len()).any(|i| find(&mut comp, i) != root) {
            return Err(TopologyError::Pinch(p));
        }
    }
    let report = SurfaceReport {
        vertices: vertex_faces.len() as u64,
        edges: edges.len() as u64,
        faces,
        volume: set.len() as u64,
    };
    if report.euler() != 2 {
        return Err(TopologyError::Euler(report.euler()));
    }
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_and_bad_shapes() {
        let r = check_sphere(&[[0, 0, 0]]).unwrap();
        assert_eq!((r.vertices, r.edges, r.faces), (8, 12, 6));
        let mut block = Vec::new();
        for x in 0..3 {
            for y in 0..3 {
                for z in 0..3 {
                    block.push([x, y, z]);
                }
            }
        }
        assert_eq!(check_sphere(&block).unwrap().faces, 54);
        // Cavity: the block minus its centre.
        let hollow: Vec<Voxel> = block.iter().copied().filter(|&v| v != [1, 1, 1]).collect();
        assert_eq!(check_sphere(&hollow), Err(TopologyError::Cavity));
        // Handle: the block minus the centre column.
        let ring: Vec<Voxel> = block
            .iter()
            .copied()
            .filter(|v| !(v[0] == 1 && v[1] == 1))
            .collect();
        assert_eq!(check_sphere(&ring), Err(TopologyError::Euler(0)));
        // Vertex pinch.
        assert!(matches!(
            check_sphere(&[[0, 0, 0], [1, 1, 1]]),
            Err(TopologyError::Disconnected)
        ));
        let pinch = [
            [0, 0, 0],
            [0, 0, 1],
            [0, 1, 1],
            [1, 1, 1],
            [1, 1, 0],
            [1, 2, 0],
            [1, 2, 1],
        ];
        // (0,0,0) and (1,1,0) share only an edge, with (1,0,0) and (0,1,0) white.
        assert!(matches!(
            check_sphere(&pinch),
            Err(TopologyError::Edge { .. })
        ));
        // A true vertex-only pinch between two blocks joined far away.
        let mut v = vec![[0, 0, 0], [1, 1, 1]];
        v.extend([
            [0, 0, -1],
            [0, 0, -2],
            [1, 0, -2],
            [2, 0, -2],
            [2, 0, -1],
            [2, 0, 0],
            [2, 0, 1],
            [2, 1, 1],
        ]);
        assert!(matches!(
            check_sphere(&v),
            Err(TopologyError::Pinch(_)) | Err(TopologyError::Edge { .. })
        ));
        assert!(matches!(
            check_sphere(&[[i64::MAX, 0, 0]]),
            Err(TopologyError::OutOfRange(_))
        ));
        // Far from the origin but in range: fine.
        assert_eq!(
            check_sphere(&[[MAX_COORD, -MAX_COORD, 5]]).unwrap().faces,
            6
        );
    }
}
