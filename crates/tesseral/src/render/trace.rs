//! Rays through a linear octree: the parametric traversal of Revelles, Ureña and
//! Lastra ("An efficient parametric algorithm for octree traversal", WSCG 2000), with
//! octant mirroring, over the gray nodes of the linear octree.

use super::index::{RayTree, Root};

/// A ray `origin + t · dir`, in the voxel coordinates of the tree.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    /// The start point.
    pub origin: [f64; 3],
    /// The direction (any non-zero length).
    pub dir: [f64; 3],
}

impl Ray {
    /// A ray from `origin` along `dir`.
    #[must_use]
    pub fn new(origin: [f64; 3], dir: [f64; 3]) -> Self {
        Self { origin, dir }
    }

    /// The point at parameter `t`.
    #[must_use]
    pub fn at(&self, t: f64) -> [f64; 3] {
        [
            self.origin[0] + t * self.dir[0],
            self.origin[1] + t * self.dir[1],
            self.origin[2] + t * self.dir[2],
        ]
    }
}

/// Where a ray first meets a black block.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// The ray parameter of the hit.
    pub t: f64,
    /// The axis of the face entered (0 x, 1 y, 2 z); the outward normal is minus the
    /// sign of the ray's direction on that axis. When the ray starts inside a block (or
    /// at the near end of its interval) this is the axis whose slab it entered last.
    pub axis: usize,
    /// The lowest voxel of the black block hit.
    pub block_min: [i64; 3],
    /// The side of that block, as a power of two.
    pub size_log2: u8,
    /// Whether the hit lies at the start of the ray's interval (the ray began inside a
    /// black block: a cut face of a cross-section).
    pub at_start: bool,
}

impl RayTree {
    /// Whether the voxel `v` is black: a descent from the root.
    ///
    /// # Runtime
    /// O(depth).
    #[must_use]
    pub fn contains(&self, v: [i64; 3]) -> bool {
        let side = 1i64 << self.depth;
        let rel = [
            v[0] - self.origin[0],
            v[1] - self.origin[1],
            v[2] - self.origin[2],
        ];
        if rel.iter().any(|&c| c < 0 || c >= side) {
            return false;
        }
        match self.root {
            Root::White => return false,
            Root::Black => return true,
            Root::Gray => {}
        }
        let mut node = self.nodes[self.root_node as usize];
        let mut k = self.depth;
        loop {
            k -= 1;
            let d = ((rel[0] >> k) & 1) | (((rel[1] >> k) & 1) << 1) | (((rel[2] >> k) & 1) << 2);
            let bit = 1u8 << d;
            if node.black & bit != 0 {
                return true;
            }
            if node.gray & bit == 0 {
                return false;
            }
            let j = rank(node.gray, bit);
            node = self.nodes[(node.first + j) as usize];
        }
    }

    /// The first black block along `ray` with parameter in `[tmin, tmax]`.
    ///
    /// Revelles et al.: the ray is mirrored so that every direction component is
    /// positive (the mirrored axes are kept in the mask `a`, and a child's true label
    /// is its mirrored label xor `a`); each node's entry and exit parameters per axis
    /// give its children's without division, and the next child follows from the exit
    /// plane. The ray stops at the first black block, whatever its size.
    ///
    /// # Runtime
    /// O(nodes visited): about the depth plus the white and gray siblings crossed.
    #[must_use]
    pub fn cast(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<Hit> {
        self.cast_with(ray, tmin, tmax, &mut TraversalStack::default())
    }

    /// As [`RayTree::cast`], reusing a traversal stack: for many rays in a row.
    #[must_use]
    pub fn cast_with(
        &self,
        ray: &Ray,
        tmin: f64,
        tmax: f64,
        stack: &mut TraversalStack,
    ) -> Option<Hit> {
        if self.root == Root::White {
            return None;
        }
        let side = f64::from(1u32 << self.depth);
        let lo = self.origin.map(|v| v as f64);
        let mut o = ray.origin;
        let mut d = ray.dir;
        let mut a = 0u8;
        for ax in 0..3 {
            if d[ax] < 0.0 {
                o[ax] = 2.0 * lo[ax] + side - o[ax];
                d[ax] = -d[ax];
                a |= 1 << ax;
            }
            if d[ax] < 1e-12 {
                d[ax] = 1e-12;
            }
        }
        let mut t0 = [0.0; 3];
        let mut t1 = [0.0; 3];
        for ax in 0..3 {
            let inv = 1.0 / d[ax];
            t0[ax] = (lo[ax] - o[ax]) * inv;
            t1[ax] = (lo[ax] + side - o[ax]) * inv;
        }
        let enter = t0[0].max(t0[1]).max(t0[2]);
        let exit = t1[0].min(t1[1]).min(t1[2]);
        if enter >= exit || exit < tmin || enter > tmax {
            return None;
        }
        if self.root == Root::Black {
            let (axis, t) = argmax(t0);
            let at_start = t < tmin;
            return Some(Hit {
                t: if at_start { tmin } else { t },
                axis,
                block_min: self.origin,
                size_log2: self.depth,
                at_start,
            });
        }
        self.walk(t0, t1, a, tmin, tmax, &mut stack.levels)
    }

    /// The iterative traversal below a gray root: an explicit stack of nodes, each
    /// with its slab parameters (mirrored space) and the child being visited.
    #[inline]
    fn walk(
        &self,
        t0: [f64; 3],
        t1: [f64; 3],
        a: u8,
        tmin: f64,
        tmax: f64,
        stack: &mut [Level; 22],
    ) -> Option<Hit> {
        if lt(t1[0], tmin) || lt(t1[1], tmin) || lt(t1[2], tmin) {
            return None;
        }
        let mut sp = 0usize;
        stack[0] = Level::new(self.root_node, t0, t1, 0, self.depth);
        loop {
            let lv = &mut stack[sp];
            let cur = lv.cur;
            let (c0, c1) = lv.child(cur);
            let entry = max3(c0);
            if entry <= tmax {
                let node = self.nodes[lv.node as usize];
                let label = cur ^ a;
                let bit = 1u8 << label;
                if (node.black | node.gray) & bit != 0 {
                    let exit = min3(c1);
                    if exit >= tmin {
                        let path = (lv.path << 3) | u64::from(label);
                        let k = lv.k - 1;
                        if node.black & bit != 0 {
                            let (axis, t) = argmax(c0);
                            let at_start = t < tmin;
                            let rel = crate::code::decode(path << (3 * u32::from(k)));
                            return Some(Hit {
                                t: if at_start { tmin } else { t },
                                axis,
                                block_min: [0, 1, 2].map(|i| self.origin[i] + i64::from(rel[i])),
                                size_log2: k,
                                at_start,
                            });
                        }
                        let j = rank(node.gray, bit);
                        sp += 1;
                        stack[sp] = Level::new(node.first + j, c0, c1, path, k);
                        continue;
                    }
                }
                // Not entered: cross the nearest exit plane of this child, reusing
                // the slab parameters just computed.
                let ax = argmin(c1).0;
                if cur & (1 << ax) == 0 {
                    lv.cur = cur | (1 << ax);
                    continue;
                }
            }
            // Every later child of this node starts later still (or the ray leaves
            // it): pop finished nodes and advance the parent past the child it was in.
            loop {
                if sp == 0 {
                    return None;
                }
                sp -= 1;
                let lv = &mut stack[sp];
                let (_, c1) = lv.child(lv.cur);
                let ax = argmin(c1).0;
                if lv.cur & (1 << ax) == 0 {
                    lv.cur |= 1 << ax;
                    break;
                }
            }
        }
    }
}

/// Scratch space for [`RayTree::cast_with`]: one entry per tree depth.
#[derive(Debug, Clone, Default)]
pub struct TraversalStack {
    levels: [Level; 22],
}

/// One node on the traversal stack.
#[derive(Debug, Clone, Copy, Default)]
struct Level {
    t0: [f64; 3],
    tm: [f64; 3],
    t1: [f64; 3],
    /// The node's path from the root, one octal digit per level.
    path: u64,
    node: u32,
    k: u8,
    cur: u8,
}

impl Level {
    #[inline]
    fn new(node: u32, t0: [f64; 3], t1: [f64; 3], path: u64, k: u8) -> Self {
        let tm = [
            0.5 * (t0[0] + t1[0]),
            0.5 * (t0[1] + t1[1]),
            0.5 * (t0[2] + t1[2]),
        ];
        Level {
            t0,
            tm,
            t1,
            path,
            node,
            k,
            cur: first_child(t0, tm),
        }
    }

    /// The slab parameters of child `cur` (mirrored label).
    #[inline]
    fn child(&self, cur: u8) -> ([f64; 3], [f64; 3]) {
        let (x, y, z) = (cur & 1 != 0, cur & 2 != 0, cur & 4 != 0);
        (
            [
                if x { self.tm[0] } else { self.t0[0] },
                if y { self.tm[1] } else { self.t0[1] },
                if z { self.tm[2] } else { self.t0[2] },
            ],
            [
                if x { self.t1[0] } else { self.tm[0] },
                if y { self.t1[1] } else { self.tm[1] },
                if z { self.t1[2] } else { self.tm[2] },
            ],
        )
    }
}

#[inline]
fn lt(a: f64, b: f64) -> bool {
    a < b
}

#[inline]
fn max3(t: [f64; 3]) -> f64 {
    let m = if t[0] > t[1] { t[0] } else { t[1] };
    if m > t[2] {
        m
    } else {
        t[2]
    }
}

#[inline]
fn min3(t: [f64; 3]) -> f64 {
    let m = if t[0] < t[1] { t[0] } else { t[1] };
    if m < t[2] {
        m
    } else {
        t[2]
    }
}

/// Bit counts of the bytes: `x.count_ones()` without relying on the POPCNT
/// instruction, which the baseline x86-64 target lacks.
const POPCOUNT: [u8; 256] = {
    let mut t = [0u8; 256];
    let mut i = 0;
    while i < 256 {
        t[i] = (i as u8).count_ones() as u8;
        i += 1;
    }
    t
};

/// The index of the gray child `bit` among its gray siblings.
#[inline]
pub(super) fn rank(gray: u8, bit: u8) -> u32 {
    u32::from(POPCOUNT[usize::from(gray & (bit - 1))])
}

/// The first child a ray enters (Revelles Table 1, in our labels `x + 2y + 4z`).
#[inline]
fn first_child(t0: [f64; 3], tm: [f64; 3]) -> u8 {
    let (entry_axis, t) = argmax(t0);
    let mut c = 0u8;
    for (ax, &m) in tm.iter().enumerate() {
        if ax != entry_axis && m < t {
            c |= 1 << ax;
        }
    }
    c
}

#[inline]
fn argmax(t: [f64; 3]) -> (usize, f64) {
    if t[0] >= t[1] && t[0] >= t[2] {
        (0, t[0])
    } else if t[1] >= t[2] {
        (1, t[1])
    } else {
        (2, t[2])
    }
}

#[inline]
fn argmin(t: [f64; 3]) -> (usize, f64) {
    if t[0] <= t[1] && t[0] <= t[2] {
        (0, t[0])
    } else if t[1] <= t[2] {
        (1, t[1])
    } else {
        (2, t[2])
    }
}
