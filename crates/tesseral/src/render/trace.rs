//! Rays through a linear octree: the parametric traversal of Revelles, Ureña and
//! Lastra ("An efficient parametric algorithm for octree traversal", WSCG 2000), with
//! octant mirroring, over the gray nodes of the linear octree.

use super::index::{RayTree, Root};
use super::nodes::{Kid, NodeId, Nodes, Trace};

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
        contains(self, v)
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
        cast(self, ray, tmin, tmax, stack)
    }
}

/// Whether the voxel `v` of `t` is black: a descent from the root.
pub(crate) fn contains<T: Trace + ?Sized>(t: &T, v: [i64; 3]) -> bool {
    let (depth, origin) = t.space();
    let side = 1i64 << depth;
    let rel = [v[0] - origin[0], v[1] - origin[1], v[2] - origin[2]];
    if rel.iter().any(|&c| c < 0 || c >= side) {
        return false;
    }
    let mut id = match t.root() {
        (Root::White, _) => return false,
        (Root::Black, _) => return true,
        (Root::Gray, id) => id,
    };
    let mut cur = t.cursor();
    let mut k = depth;
    let mut path = 0u64;
    loop {
        k -= 1;
        let d = ((rel[0] >> k) & 1) | (((rel[1] >> k) & 1) << 1) | (((rel[2] >> k) & 1) << 2);
        let label = d as u8;
        if !cur.maybe(id, label) {
            return false;
        }
        path = (path << 3) | u64::from(label);
        match cur.kid(id, label, path, k) {
            Kid::White => return false,
            Kid::Black => return true,
            Kid::Gray(c) => id = c,
        }
    }
}

/// The first black block of `t` along `ray` in `[tmin, tmax]` (see
/// [`RayTree::cast`]).
pub(crate) fn cast<T: Trace + ?Sized>(
    t: &T,
    ray: &Ray,
    tmin: f64,
    tmax: f64,
    stack: &mut TraversalStack,
) -> Option<Hit> {
    let (root, root_id) = t.root();
    if root == Root::White {
        return None;
    }
    let (depth, origin) = t.space();
    let side = f64::from(1u32 << depth);
    let lo = origin.map(|v| v as f64);
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
    if root == Root::Black {
        let (axis, t) = argmax(t0);
        let at_start = t < tmin;
        return Some(Hit {
            t: if at_start { tmin } else { t },
            axis,
            block_min: origin,
            size_log2: depth,
            at_start,
        });
    }
    let walk = Walk {
        root: root_id,
        depth,
        origin,
        a,
        tmin,
        tmax,
    };
    walk.run(&mut t.cursor(), t0, t1, &mut stack.levels)
}

/// One ray's traversal below a gray root.
struct Walk {
    root: NodeId,
    depth: u8,
    origin: [i64; 3],
    /// The mirrored axes.
    a: u8,
    tmin: f64,
    tmax: f64,
}

impl Walk {
    /// The iterative traversal below a gray root: an explicit stack of nodes, each
    /// with its slab parameters (mirrored space) and the child being visited.
    #[inline]
    fn run<N: Nodes>(
        &self,
        n: &mut N,
        t0: [f64; 3],
        t1: [f64; 3],
        stack: &mut [Level; 22],
    ) -> Option<Hit> {
        let (a, tmin, tmax) = (self.a, self.tmin, self.tmax);
        if lt(t1[0], tmin) || lt(t1[1], tmin) || lt(t1[2], tmin) {
            return None;
        }
        let mut sp = 0usize;
        stack[0] = Level::new(self.root, t0, t1, 0, self.depth);
        loop {
            let lv = &mut stack[sp];
            let cur = lv.cur;
            let (c0, c1) = lv.child(cur);
            let entry = max3(c0);
            if entry <= tmax {
                let label = cur ^ a;
                if n.maybe(lv.node, label) {
                    let exit = min3(c1);
                    if exit >= tmin {
                        let path = (lv.path << 3) | u64::from(label);
                        let k = lv.k - 1;
                        match n.kid(lv.node, label, path, k) {
                            Kid::Black => {
                                let (axis, t) = argmax(c0);
                                let at_start = t < tmin;
                                let rel = crate::code::decode(path << (3 * u32::from(k)));
                                return Some(Hit {
                                    t: if at_start { tmin } else { t },
                                    axis,
                                    block_min: [0, 1, 2]
                                        .map(|i| self.origin[i] + i64::from(rel[i])),
                                    size_log2: k,
                                    at_start,
                                });
                            }
                            Kid::Gray(child) => {
                                sp += 1;
                                stack[sp] = Level::new(child, c0, c1, path, k);
                                continue;
                            }
                            Kid::White => {}
                        }
                    }
                }
                // Not entered: cross the nearest exit plane of this child, reusing
                // the slab parameters just computed.
                let lv = &mut stack[sp];
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
    node: NodeId,
    k: u8,
    cur: u8,
}

impl Level {
    #[inline]
    fn new(node: NodeId, t0: [f64; 3], t1: [f64; 3], path: u64, k: u8) -> Self {
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
