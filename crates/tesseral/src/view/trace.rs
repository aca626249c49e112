//! The viewer's traversal, step for step as the fragment shader (`assets/trace.frag`)
//! and the page's picking code (`assets/viewer.js`) do it, so that the packing can
//! be checked against the tree in Rust.
//!
//! A ray walks the packed tree by point queries: from the root down to the cell
//! holding the current voxel; a black leaf is a hit, a white cell is left through
//! its nearest exit face and the walk goes on in the voxel beyond. Coordinates are
//! voxels relative to the tree's origin.

use super::pack::PackedTree;

/// The most white cells a ray crosses before it gives up (the shader's loop bound).
pub const MAX_STEPS: usize = 2048;

/// The cell of the packed tree that holds a voxel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Cell {
    /// The palette index when the cell is black, `None` when white.
    pub colour: Option<u32>,
    /// The cell's lowest voxel.
    pub min: [i64; 3],
    /// The cell's side, as a power of two.
    pub size_log2: u8,
}

/// Where a ray first meets a black cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PackedHit {
    /// The ray parameter.
    pub t: f64,
    /// The axis of the face entered (the outward normal is minus the ray's sign on it).
    pub axis: usize,
    /// The voxel hit.
    pub voxel: [i64; 3],
    /// The black cell hit.
    pub cell: Cell,
}

/// The cell holding voxel `v` (relative to the origin, inside the space).
#[must_use]
pub fn lookup(entries: &[u32], tree: &PackedTree, v: [i64; 3]) -> Cell {
    let mut s = tree.depth;
    if tree.empty {
        return Cell {
            colour: None,
            min: [0; 3],
            size_log2: s,
        };
    }
    let mut e = entries[tree.root as usize];
    loop {
        let mask = e & 0xff;
        if mask == 0 {
            let min = v.map(|c| (c >> s) << s);
            return Cell {
                colour: Some(e >> 8),
                min,
                size_log2: s,
            };
        }
        s -= 1;
        let bit = |a: usize| ((v[a] >> s) & 1) as u32;
        let d = bit(0) | bit(1) << 1 | bit(2) << 2;
        if mask & (1 << d) == 0 {
            return Cell {
                colour: None,
                min: v.map(|c| (c >> s) << s),
                size_log2: s,
            };
        }
        let i = (e >> 8) + (mask & ((1 << d) - 1)).count_ones();
        e = entries[i as usize];
    }
}

/// The first black voxel along the ray `origin + t · dir` (t ≥ 0) inside the box of
/// voxels `[lo, hi)` (clipped to the space): the viewer's cut and slice box.
#[must_use]
pub fn cast(
    entries: &[u32],
    tree: &PackedTree,
    origin: [f64; 3],
    dir: [f64; 3],
    lo: [i64; 3],
    hi: [i64; 3],
) -> Option<PackedHit> {
    let side = 1i64 << tree.depth;
    let lo = lo.map(|c| c.max(0));
    let hi = hi.map(|c| c.min(side));
    if (0..3).any(|a| lo[a] >= hi[a]) {
        return None;
    }
    // Enter the box.
    let (mut t0, mut t1, mut axis) = (0.0f64, f64::INFINITY, 0);
    for a in 0..3 {
        let (l, h) = (lo[a] as f64, hi[a] as f64);
        if dir[a] == 0.0 {
            if origin[a] < l || origin[a] > h {
                return None;
            }
            continue;
        }
        let ta = (l - origin[a]) / dir[a];
        let tb = (h - origin[a]) / dir[a];
        let (tn, tf) = (ta.min(tb), ta.max(tb));
        if tn > t0 {
            t0 = tn;
            axis = a;
        }
        t1 = t1.min(tf);
    }
    if t0 >= t1 {
        return None;
    }
    let mut c = [0i64; 3];
    for a in 0..3 {
        c[a] = ((origin[a] + dir[a] * t0).floor() as i64).clamp(lo[a], hi[a] - 1);
    }
    for _ in 0..MAX_STEPS {
        let cell = lookup(entries, tree, c);
        if cell.colour.is_some() {
            return Some(PackedHit {
                t: t0,
                axis,
                voxel: c,
                cell,
            });
        }
        // Leave the white cell through its nearest face.
        let size = 1i64 << cell.size_log2;
        let mut exit = [f64::INFINITY; 3];
        for a in 0..3 {
            if dir[a] > 0.0 {
                exit[a] = ((cell.min[a] + size) as f64 - origin[a]) / dir[a];
            } else if dir[a] < 0.0 {
                exit[a] = (cell.min[a] as f64 - origin[a]) / dir[a];
            }
        }
        let tn = exit[0].min(exit[1]).min(exit[2]);
        for a in 0..3 {
            if exit[a] <= tn {
                axis = a;
                c[a] = if dir[a] > 0.0 {
                    cell.min[a] + size
                } else {
                    cell.min[a] - 1
                };
            } else {
                let p = (origin[a] + dir[a] * tn).floor() as i64;
                c[a] = p.clamp(cell.min[a], cell.min[a] + size - 1);
            }
        }
        t0 = tn;
        if (0..3).any(|a| c[a] < lo[a] || c[a] >= hi[a]) {
            return None;
        }
    }
    None
}
