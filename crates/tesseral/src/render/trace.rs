//! Rays through a linear octree: the parametric traversal of Revelles, Ureña and
//! Lastra ("An efficient parametric algorithm for octree traversal", WSCG 2000), with
//! octant mirroring, over the gray nodes of the linear octree.

use crate::linear::{Leaf, LinearOctree};

/// One gray node: which children are gray and which are black (the rest are white),
/// and where the gray children's nodes start (they are stored together, in label
/// order).
#[derive(Debug, Clone, Copy)]
struct Node {
    first: u32,
    gray: u8,
    black: u8,
}

/// The colour of the root.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Root {
    White,
    Black,
    Gray,
}

/// The gray nodes of a linear octree, in a form rays can descend quickly.
///
/// The linear octree keeps only its black leaves, sorted; a node of the implicit tree
/// is a code range, white when no leaf falls in it, black when one leaf covers it,
/// gray otherwise. This index records, for each gray node, the colours of its eight
/// children: 8 bytes per gray node (about a seventh of the leaves' 8 bytes each). It
/// is derived from the leaves in one pass, never from the solid: rendering an octree
/// file never rebuilds the solid.
///
/// ```
/// use tesseral::linear::LinearOctree;
/// use tesseral::render::{Ray, RayTree};
/// let tree = LinearOctree::from_voxels(2, [0, 0, 0], [[1, 1, 1]]).unwrap();
/// let rt = RayTree::new(&tree);
/// let hit = rt.cast(&Ray::new([-5.0, 1.5, 1.5], [1.0, 0.0, 0.0]), 0.0, f64::INFINITY).unwrap();
/// assert!((hit.t - 6.0).abs() < 1e-9 && hit.axis == 0 && hit.block_min == [1, 1, 1]);
/// ```
#[derive(Debug, Clone)]
pub struct RayTree {
    depth: u8,
    origin: [i64; 3],
    root: Root,
    nodes: Vec<Node>,
}

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
    /// Indexes the gray nodes of `tree`.
    ///
    /// # Runtime
    /// O(g log n) for g gray nodes and n leaves.
    #[must_use]
    pub fn new(tree: &LinearOctree) -> Self {
        let depth = tree.depth();
        let leaves = tree.leaves();
        let mut rt = RayTree {
            depth,
            origin: tree.origin(),
            root: Root::White,
            nodes: Vec::new(),
        };
        rt.root = match colour_of(leaves, 0, depth) {
            Colour::White => Root::White,
            Colour::Black => Root::Black,
            Colour::Gray => {
                rt.nodes.push(Node {
                    first: 0,
                    gray: 0,
                    black: 0,
                });
                rt.index(0, 0, depth, leaves);
                Root::Gray
            }
        };
        rt
    }

    fn index(&mut self, at: usize, code: u64, k: u8, leaves: &[Leaf]) {
        let child_cells = 1u64 << (3 * u32::from(k - 1));
        let mut ranges = [(0usize, 0usize); 8];
        let (mut gray, mut black) = (0u8, 0u8);
        let mut lo = 0;
        for d in 0..8u64 {
            let end_code = code + (d + 1) * child_cells;
            let hi = lo + leaves[lo..].partition_point(|l| l.code() < end_code);
            ranges[d as usize] = (lo, hi);
            match colour_of(&leaves[lo..hi], code + d * child_cells, k - 1) {
                Colour::White => {}
                Colour::Black => black |= 1 << d,
                Colour::Gray => gray |= 1 << d,
            }
            lo = hi;
        }
        let first = self.nodes.len();
        self.nodes[at] = Node {
            first: first as u32,
            gray,
            black,
        };
        for _ in 0..gray.count_ones() {
            self.nodes.push(Node {
                first: 0,
                gray: 0,
                black: 0,
            });
        }
        let mut j = first;
        for d in 0..8u64 {
            if gray & (1 << d) != 0 {
                let (a, b) = ranges[d as usize];
                self.index(j, code + d * child_cells, k - 1, &leaves[a..b]);
                j += 1;
            }
        }
    }

    /// The number of gray nodes indexed.
    #[must_use]
    pub fn gray_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// The tree's depth.
    #[must_use]
    pub fn depth(&self) -> u8 {
        self.depth
    }

    /// The lowest corner of the tree's space.
    #[must_use]
    pub fn origin(&self) -> [i64; 3] {
        self.origin
    }

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
        let mut node = self.nodes[0];
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
            let j = (node.gray & (bit - 1)).count_ones();
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
            t0[ax] = (lo[ax] - o[ax]) / d[ax];
            t1[ax] = (lo[ax] + side - o[ax]) / d[ax];
        }
        let enter = t0[0].max(t0[1]).max(t0[2]);
        let exit = t1[0].min(t1[1]).min(t1[2]);
        if enter >= exit || exit < tmin || enter > tmax {
            return None;
        }
        let walk = Walk {
            rt: self,
            a,
            tmin,
            tmax,
        };
        if self.root == Root::Black {
            return walk.black(t0, self.origin, self.depth);
        }
        walk.node(0, t0, t1, self.origin, self.depth)
    }
}

struct Walk<'a> {
    rt: &'a RayTree,
    a: u8,
    tmin: f64,
    tmax: f64,
}

impl Walk<'_> {
    #[inline]
    fn black(&self, t0: [f64; 3], min: [i64; 3], k: u8) -> Option<Hit> {
        let (axis, t) = argmax(t0);
        if t > self.tmax {
            return None;
        }
        let at_start = t < self.tmin;
        Some(Hit {
            t: if at_start { self.tmin } else { t },
            axis,
            block_min: min,
            size_log2: k,
            at_start,
        })
    }

    /// Visits the children of a gray node of size `2^k` at `min` (true coordinates),
    /// whose mirrored slab parameters are `t0`, `t1`.
    fn node(&self, n: u32, t0: [f64; 3], t1: [f64; 3], min: [i64; 3], k: u8) -> Option<Hit> {
        if t1[0] < self.tmin || t1[1] < self.tmin || t1[2] < self.tmin {
            return None;
        }
        let node = self.rt.nodes[n as usize];
        let tm = [
            0.5 * (t0[0] + t1[0]),
            0.5 * (t0[1] + t1[1]),
            0.5 * (t0[2] + t1[2]),
        ];
        let half = 1i64 << (k - 1);
        let mut cur = first_child(t0, tm);
        loop {
            // The child's slab parameters, in mirrored space.
            let mut c0 = [0.0; 3];
            let mut c1 = [0.0; 3];
            for ax in 0..3 {
                if cur & (1 << ax) != 0 {
                    c0[ax] = tm[ax];
                    c1[ax] = t1[ax];
                } else {
                    c0[ax] = t0[ax];
                    c1[ax] = tm[ax];
                }
            }
            let entry = c0[0].max(c0[1]).max(c0[2]);
            if entry > self.tmax {
                return None;
            }
            let label = cur ^ self.a;
            let bit = 1u8 << label;
            if (node.black | node.gray) & bit != 0 {
                let exit = c1[0].min(c1[1]).min(c1[2]);
                if exit >= self.tmin {
                    let cmin = [
                        min[0] + half * i64::from(label & 1),
                        min[1] + half * i64::from((label >> 1) & 1),
                        min[2] + half * i64::from((label >> 2) & 1),
                    ];
                    if node.black & bit != 0 {
                        return self.black(c0, cmin, k - 1);
                    }
                    let j = (node.gray & (bit - 1)).count_ones();
                    if let Some(h) = self.node(node.first + j, c0, c1, cmin, k - 1) {
                        return Some(h);
                    }
                }
            }
            // The next child: across the exit plane nearest along the ray.
            let (ax, _) = argmin(c1);
            if cur & (1 << ax) != 0 {
                return None;
            }
            cur |= 1 << ax;
        }
    }
}

/// The first child a ray enters (Revelles Table 1, in our labels `x + 2y + 4z`).
#[inline]
fn first_child(t0: [f64; 3], tm: [f64; 3]) -> u8 {
    let (entry_axis, t) = argmax(t0);
    let mut c = 0u8;
    for ax in 0..3 {
        if ax != entry_axis && tm[ax] < t {
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

enum Colour {
    White,
    Black,
    Gray,
}

/// The colour of the node `(code, k)` whose leaves are `leaves` (all inside it).
fn colour_of(leaves: &[Leaf], code: u64, k: u8) -> Colour {
    match leaves {
        [] => Colour::White,
        [l] if l.code() == code && l.size_log2() == k => Colour::Black,
        _ => Colour::Gray,
    }
}
