//! What the tracer asks of a tree, node by node: whether a child of a gray node is
//! white, black or gray. The in-memory [`RayTree`] answers from its node array; the
//! streamed tree ([`super::StreamedTree`]) from the chunk index, decoding a chunk
//! only when a ray, a beam or a normal estimate reaches into it. Every traversal
//! (rays, beams, point queries, normal bricks, the bounding box) is written once,
//! over [`Nodes`], so both trees give the same answers bit for bit.

use super::index::{RayTree, Root};
use super::trace::{rank, Hit, Ray, TraversalStack};

/// A gray node: which index holds it (`src`) and where in it (`node`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct NodeId {
    pub(crate) src: u32,
    pub(crate) node: u32,
}

/// The colour of a child.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kid {
    White,
    Black,
    Gray(NodeId),
}

/// Read access to the gray nodes of a tree.
pub(crate) trait Nodes {
    /// Whether child `label` of the gray node `id` may be non-white; `false` means
    /// white for sure. Cheap: it reads nothing new.
    fn maybe(&mut self, id: NodeId, label: u8) -> bool;
    /// The colour of child `label` of the gray node `id`. `path` is the child's path
    /// from the root (one octal digit per depth, the child's own label last) and `k`
    /// the log2 of its side.
    fn kid(&mut self, id: NodeId, label: u8, path: u64, k: u8) -> Kid;
}

/// A tree rays can be cast through.
pub(crate) trait Trace: Sync {
    /// A reader of the nodes (it may keep the chunk it is in).
    type Cursor<'a>: Nodes
    where
        Self: 'a;
    /// A new reader.
    fn cursor(&self) -> Self::Cursor<'_>;
    /// The depth and lowest voxel of the space.
    fn space(&self) -> (u8, [i64; 3]);
    /// The root's colour and, when gray, its node.
    fn root(&self) -> (Root, NodeId);
    /// The inclusive bounding box of the black voxels.
    fn bbox(&self) -> Option<([i64; 3], [i64; 3])>;

    /// The first black block along `ray` in `[tmin, tmax]` (see [`RayTree::cast`]).
    fn cast(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<Hit> {
        super::trace::cast(self, ray, tmin, tmax, &mut TraversalStack::default())
    }
}

impl Nodes for &RayTree {
    #[inline]
    fn maybe(&mut self, id: NodeId, label: u8) -> bool {
        let n = self.nodes[id.node as usize];
        (n.black | n.gray) & (1 << label) != 0
    }

    #[inline]
    fn kid(&mut self, id: NodeId, label: u8, _path: u64, _k: u8) -> Kid {
        let n = self.nodes[id.node as usize];
        let bit = 1u8 << label;
        if n.black & bit != 0 {
            Kid::Black
        } else if n.gray & bit != 0 {
            Kid::Gray(NodeId {
                src: 0,
                node: n.first + rank(n.gray, bit),
            })
        } else {
            Kid::White
        }
    }
}

impl Trace for RayTree {
    type Cursor<'a> = &'a RayTree;

    fn cursor(&self) -> &RayTree {
        self
    }

    fn space(&self) -> (u8, [i64; 3]) {
        (self.depth, self.origin)
    }

    fn root(&self) -> (Root, NodeId) {
        (
            self.root,
            NodeId {
                src: 0,
                node: self.root_node,
            },
        )
    }

    fn bbox(&self) -> Option<([i64; 3], [i64; 3])> {
        self.bbox
    }
}

/// The lowest corner of child `label` of the node at `min` with children of side
/// `half`.
#[inline]
pub(crate) fn child_min(min: [i64; 3], half: i64, label: u8) -> [i64; 3] {
    [
        min[0] + half * i64::from(label & 1),
        min[1] + half * i64::from((label >> 1) & 1),
        min[2] + half * i64::from((label >> 2) & 1),
    ]
}

/// The inclusive bounding box of the black voxels, found by six branch-and-bound
/// descents (nearest children first, pruned by the best bound so far): only the
/// nodes at the solid's extreme faces are read.
pub(crate) fn bounding_box<T: Trace + ?Sized>(t: &T) -> Option<([i64; 3], [i64; 3])> {
    let (depth, origin) = t.space();
    let side = 1i64 << depth;
    match t.root() {
        (Root::White, _) => None,
        (Root::Black, _) => Some((origin, origin.map(|v| v + side - 1))),
        (Root::Gray, root) => {
            let mut cur = t.cursor();
            let mut lo = [0i64; 3];
            let mut hi = [0i64; 3];
            for axis in 0..3 {
                // Lowest: minimise the low face; highest: maximise the high face,
                // as a minimum of its negation.
                for high in [false, true] {
                    let mut best = i64::MAX;
                    extreme(&mut cur, root, origin, depth, 0, axis, high, &mut best);
                    if high {
                        hi[axis] = -best;
                    } else {
                        lo[axis] = best;
                    }
                }
            }
            Some((lo, hi))
        }
    }
}

/// One branch-and-bound descent of [`bounding_box`]: `best` is the least value of
/// `cmin[axis]` (or of `-(cmin[axis] + size - 1)` when `high`) over black blocks.
#[allow(clippy::too_many_arguments)]
fn extreme<N: Nodes>(
    n: &mut N,
    id: NodeId,
    min: [i64; 3],
    k: u8,
    path: u64,
    axis: usize,
    high: bool,
    best: &mut i64,
) {
    let half = 1i64 << (k - 1);
    let near_first: [u8; 2] = if high { [1, 0] } else { [0, 1] };
    for side in near_first {
        for other in 0..4u8 {
            // The label with bit `axis` = side and the other two bits from `other`.
            let low_bits = other & ((1 << axis) - 1);
            let high_bits = (other >> axis) << (axis + 1);
            let label = low_bits | (side << axis) | high_bits;
            if !n.maybe(id, label) {
                continue;
            }
            let cmin = child_min(min, half, label);
            let value = if high {
                -(cmin[axis] + half - 1)
            } else {
                cmin[axis]
            };
            // Every voxel of the child scores at least `value` (low) / the child's
            // best voxel scores `value` (high): nothing better inside.
            if value >= *best {
                continue;
            }
            let cpath = (path << 3) | u64::from(label);
            match n.kid(id, label, cpath, k - 1) {
                Kid::White => {}
                Kid::Black => *best = value,
                Kid::Gray(c) => extreme(n, c, cmin, k - 1, cpath, axis, high, best),
            }
        }
    }
}

/// Calls `f(min, size)` for each black block of `t` that the layer of voxels with
/// coordinate `at` on `axis` crosses, found by a descent along the layer.
pub(crate) fn layer_blocks<T: Trace + ?Sized>(
    t: &T,
    axis: usize,
    at: i64,
    f: &mut dyn FnMut([i64; 3], i64),
) {
    let (depth, origin) = t.space();
    let side = 1i64 << depth;
    if at < origin[axis] || at - origin[axis] >= side {
        return;
    }
    match t.root() {
        (Root::White, _) => {}
        (Root::Black, _) => f(origin, side),
        (Root::Gray, root) => layer_rec(&mut t.cursor(), root, origin, depth, 0, axis, at, f),
    }
}

#[allow(clippy::too_many_arguments)]
fn layer_rec<N: Nodes>(
    n: &mut N,
    id: NodeId,
    min: [i64; 3],
    k: u8,
    path: u64,
    axis: usize,
    at: i64,
    f: &mut dyn FnMut([i64; 3], i64),
) {
    let half = 1i64 << (k - 1);
    let side = u8::from(at >= min[axis] + half);
    for label in 0..8u8 {
        if (label >> axis) & 1 != side || !n.maybe(id, label) {
            continue;
        }
        let cmin = child_min(min, half, label);
        let cpath = (path << 3) | u64::from(label);
        match n.kid(id, label, cpath, k - 1) {
            Kid::White => {}
            Kid::Black => f(cmin, half),
            Kid::Gray(c) => layer_rec(n, c, cmin, k - 1, cpath, axis, at, f),
        }
    }
}
