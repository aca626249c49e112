//! What the parallel traversals walk: a tree of boxes whose leaves are black cells.
//!
//! Two kinds implement [`Traversable`]:
//! - [`LinearOctree`] itself, walked without any preparation: a node is a cell with
//!   its run of leaves (see `traverse.rs`), and its box is the whole cell;
//! - [`BoxTree`], prepared once per object (not per placement, so the moved tree is
//!   still never built): the same octree as an explicit array of nodes, each with the
//!   *tight* bounding box of its black voxels. Tight boxes prune pairs of cells long
//!   before the cells themselves are small, which is what makes repeated queries
//!   (every step of a simulation, every offset of a benchmark) fast.

use super::interfere::IBox;
use super::traverse::Node;
use crate::linear::{Leaf, LinearOctree};
use crate::Voxel;

mod sealed {
    pub trait Sealed {}
    impl Sealed for crate::linear::LinearOctree {}
    impl Sealed for super::BoxTree {}
}

/// A solid the interference, clearance and swept tests can traverse:
/// [`LinearOctree`] (no preparation) or [`BoxTree`] (prepared once, faster for
/// repeated queries). Sealed: its methods are internal.
pub trait Traversable: sealed::Sealed + Sync {
    #[doc(hidden)]
    type Node: Copy;
    #[doc(hidden)]
    fn root_node(&self) -> Option<Self::Node>;
    /// The node's box in the tree's own coordinates, half-open.
    #[doc(hidden)]
    fn node_box(&self, n: &Self::Node) -> IBox;
    /// Whether the node is one black cell (its box is all black).
    #[doc(hidden)]
    fn is_black(&self, n: &Self::Node) -> bool;
    /// A measure of the node's size, to choose which of two nodes to split.
    #[doc(hidden)]
    fn node_size(&self, n: &Self::Node) -> i64;
    /// The non-empty children of a node that is not black.
    #[doc(hidden)]
    fn node_children(&self, n: &Self::Node, out: &mut [Self::Node; 8]) -> usize;
    /// The number of black voxels under the node.
    #[doc(hidden)]
    fn node_voxels(&self, n: &Self::Node) -> u64;
    /// The non-empty children whose boxes meet `q` (in the tree's coordinates).
    #[doc(hidden)]
    #[inline]
    fn children_meeting(&self, n: &Self::Node, q: &IBox, out: &mut [Self::Node; 8]) -> usize {
        let k = self.node_children(n, out);
        let mut m = 0;
        for i in 0..k {
            if self.node_box(&out[i]).overlaps(q) {
                out[m] = out[i];
                m += 1;
            }
        }
        m
    }
    /// For a node inside a 4³ cell: that cell's lowest voxel (tree coordinates) and
    /// the node's voxels in it as a 64-bit mask (bit `x + 4y + 16z`).
    #[doc(hidden)]
    #[inline]
    fn small_mask(&self, _n: &Self::Node) -> Option<(Voxel, u64)> {
        None
    }
}

/// Bits of a 4³ mask whose coordinate on an axis is at least `s` (`GE`) or below `s`
/// (`LT`), for x, y and z.
const fn axis_masks(axis: u32, at_least: bool) -> [u64; 5] {
    let mut out = [0u64; 5];
    let mut s = 0;
    while s < 5 {
        let mut i = 0;
        while i < 64 {
            let c = (i >> (2 * axis)) & 3;
            if (at_least && c >= s) || (!at_least && c < s) {
                out[s as usize] |= 1 << i;
            }
            i += 1;
        }
        s += 1;
    }
    out
}

const GE: [[u64; 5]; 3] = [
    axis_masks(0, true),
    axis_masks(1, true),
    axis_masks(2, true),
];
const LT: [[u64; 5]; 3] = [
    axis_masks(0, false),
    axis_masks(1, false),
    axis_masks(2, false),
];

/// The 4³ mask `m` moved by `d` (each component in `-3..=3`); voxels leaving the cell
/// are dropped.
#[inline]
pub(crate) fn shift_mask(mut m: u64, d: Voxel) -> u64 {
    for a in 0..3 {
        let s = d[a];
        let unit = 2 * a as u32; // log2 of the bit stride: 1, 4, 16
        if s > 0 {
            m = (m << ((s as u32) << unit)) & GE[a][s as usize];
        } else if s < 0 {
            m = (m >> (((-s) as u32) << unit)) & LT[a][(4 + s) as usize];
        }
    }
    m
}

/// The mask of the cube `[min, min + side)` inside the 4³ cell at `cell`.
fn cube_mask(min: [i32; 3], side: i32, cell: [i32; 3]) -> u64 {
    let mut m = 0;
    for z in 0..side {
        for y in 0..side {
            for x in 0..side {
                let (i, j, k) = (
                    min[0] - cell[0] + x,
                    min[1] - cell[1] + y,
                    min[2] - cell[2] + z,
                );
                m |= 1u64 << (i + 4 * j + 16 * k);
            }
        }
    }
    m
}

impl Traversable for LinearOctree {
    type Node = Node;

    #[inline]
    fn root_node(&self) -> Option<Node> {
        Node::tight_root(self)
    }

    #[inline]
    fn node_box(&self, n: &Node) -> IBox {
        let s = n.side();
        IBox::cube(n.min, s)
    }

    #[inline]
    fn is_black(&self, n: &Node) -> bool {
        n.is_full(self.leaves())
    }

    #[inline]
    fn node_size(&self, n: &Node) -> i64 {
        n.side()
    }

    #[inline]
    fn node_children(&self, n: &Node, out: &mut [Node; 8]) -> usize {
        n.children(self.leaves(), out)
    }

    fn node_voxels(&self, n: &Node) -> u64 {
        n.voxel_count(self.leaves())
    }
}

/// One node of a [`BoxTree`]: a tight box (relative to the tree's origin) and its
/// children, which are stored together.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct BoxNode {
    lo: [i32; 3],
    hi: [i32; 3],
    /// Index of the first child; unused for a black node.
    first: u32,
    /// Number of children; 0 for a black node.
    count: u8,
    /// The cell's side as a power of two.
    k: u8,
    voxels: u64,
    /// For `k <= 2`: the node's voxels in its 4³ cell (see [`shift_mask`]).
    mask: u64,
}

/// An octree prepared for repeated interference queries: every node carries the
/// tight bounding box of its black voxels, and the nodes sit in one array with each
/// node's children side by side.
///
/// It is built once per object from its [`LinearOctree`] and serves every
/// placement: queries never build a moved tree.
///
/// ```
/// use tesseral::linear::LinearOctree;
/// use tesseral::motion::{intersects, BoxTree, Placement};
/// let ball = LinearOctree::from_voxels_fitted(&[[0, 0, 0], [1, 0, 0], [5, 5, 5]]).unwrap();
/// let prepared = BoxTree::new(&ball);
/// prepared.assert_valid();
/// assert_eq!(
///     intersects(&prepared, &prepared, Placement::at([4, 5, 5])),
///     intersects(&ball, &ball, Placement::at([4, 5, 5])),
/// );
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BoxTree {
    origin: Voxel,
    nodes: Vec<BoxNode>,
}

/// Index of a [`BoxTree`] node.
#[doc(hidden)]
#[derive(Debug, Clone, Copy)]
pub struct BoxRef(u32);

impl BoxTree {
    /// Prepares `tree`.
    ///
    /// # Runtime
    /// O(n) nodes for n leaves, plus the binary searches that split runs.
    #[must_use]
    pub fn new(tree: &LinearOctree) -> BoxTree {
        let mut t = BoxTree {
            origin: tree.origin(),
            nodes: Vec::with_capacity(tree.leaf_count() * 8 / 7 + 1),
        };
        if let Some(root) = Node::tight_root(tree) {
            t.nodes.push(BoxNode {
                lo: [0; 3],
                hi: [0; 3],
                first: 0,
                count: 0,
                k: 0,
                voxels: 0,
                mask: 0,
            });
            t.fill(tree.leaves(), root, 0);
        }
        t
    }

    /// Writes node `at` for cell `n` and, below it, its children; returns nothing but
    /// fills boxes bottom-up.
    fn fill(&mut self, leaves: &[Leaf], n: Node, at: usize) {
        let rel = |v: Voxel, o: Voxel| -> [i32; 3] { [0, 1, 2].map(|a| (v[a] - o[a]) as i32) };
        if n.is_full(leaves) {
            let s = n.side();
            let lo = rel(n.min, self.origin);
            let mask = if n.k <= 2 {
                cube_mask(lo, s as i32, lo.map(|c| c & !3))
            } else {
                0
            };
            self.nodes[at] = BoxNode {
                lo,
                hi: rel([n.min[0] + s, n.min[1] + s, n.min[2] + s], self.origin),
                first: 0,
                count: 0,
                k: n.k,
                voxels: 1u64 << (3 * u32::from(n.k)),
                mask,
            };
            return;
        }
        let mut kids = [n; 8];
        let k = n.children(leaves, &mut kids);
        let first = self.nodes.len();
        for _ in 0..k {
            self.nodes.push(self.nodes[at]);
        }
        let mut lo = [i32::MAX; 3];
        let mut hi = [i32::MIN; 3];
        let mut voxels = 0;
        let mut mask = 0;
        for (i, kid) in kids[..k].iter().enumerate() {
            self.fill(leaves, *kid, first + i);
            let c = self.nodes[first + i];
            for a in 0..3 {
                lo[a] = lo[a].min(c.lo[a]);
                hi[a] = hi[a].max(c.hi[a]);
            }
            voxels += c.voxels;
            mask |= c.mask;
        }
        self.nodes[at] = BoxNode {
            lo,
            hi,
            first: first as u32,
            count: k as u8,
            k: n.k,
            voxels,
            mask: if n.k <= 2 { mask } else { 0 },
        };
    }

    /// The number of nodes.
    #[must_use]
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// The number of black voxels.
    #[must_use]
    pub fn voxel_count(&self) -> u64 {
        self.nodes.first().map_or(0, |n| n.voxels)
    }

    /// Panics with a description of the first broken invariant: each node's box is
    /// the tight union of its children's, children lie after their parent, black
    /// nodes are non-empty cubes, and voxel counts add up.
    pub fn assert_valid(&self) {
        for (i, n) in self.nodes.iter().enumerate() {
            assert!((0..3).all(|a| n.lo[a] < n.hi[a]), "node {i}: empty box");
            if n.count == 0 {
                let s = n.hi[0] - n.lo[0];
                assert!(
                    (0..3).all(|a| n.hi[a] - n.lo[a] == s) && (s as u32).is_power_of_two(),
                    "node {i}: black node is not a cube of side 2^k"
                );
                assert_eq!(n.voxels, (s as u64).pow(3), "node {i}: voxel count");
                continue;
            }
            let (f, c) = (n.first as usize, usize::from(n.count));
            assert!(
                f > i && f + c <= self.nodes.len(),
                "node {i}: children out of place"
            );
            let kids = &self.nodes[f..f + c];
            for a in 0..3 {
                assert_eq!(
                    n.lo[a],
                    kids.iter().map(|k| k.lo[a]).min().unwrap(),
                    "node {i}: box not tight"
                );
                assert_eq!(
                    n.hi[a],
                    kids.iter().map(|k| k.hi[a]).max().unwrap(),
                    "node {i}: box not tight"
                );
            }
            assert_eq!(
                n.voxels,
                kids.iter().map(|k| k.voxels).sum::<u64>(),
                "node {i}: voxel count"
            );
        }
    }
}

impl Traversable for BoxTree {
    type Node = BoxRef;

    #[inline]
    fn root_node(&self) -> Option<BoxRef> {
        (!self.nodes.is_empty()).then_some(BoxRef(0))
    }

    #[inline]
    fn node_box(&self, n: &BoxRef) -> IBox {
        let b = &self.nodes[n.0 as usize];
        let o = self.origin;
        IBox {
            lo: [0, 1, 2].map(|a| i128::from(o[a]) + i128::from(b.lo[a])),
            hi: [0, 1, 2].map(|a| i128::from(o[a]) + i128::from(b.hi[a])),
        }
    }

    #[inline]
    fn is_black(&self, n: &BoxRef) -> bool {
        self.nodes[n.0 as usize].count == 0
    }

    #[inline]
    fn node_size(&self, n: &BoxRef) -> i64 {
        let b = &self.nodes[n.0 as usize];
        i64::from((0..3).map(|a| b.hi[a] - b.lo[a]).max().unwrap_or(0))
    }

    #[inline]
    fn node_children(&self, n: &BoxRef, out: &mut [BoxRef; 8]) -> usize {
        let b = &self.nodes[n.0 as usize];
        for (i, slot) in out.iter_mut().take(usize::from(b.count)).enumerate() {
            *slot = BoxRef(b.first + i as u32);
        }
        usize::from(b.count)
    }

    #[inline]
    fn node_voxels(&self, n: &BoxRef) -> u64 {
        self.nodes[n.0 as usize].voxels
    }

    #[inline]
    fn children_meeting(&self, n: &BoxRef, q: &IBox, out: &mut [BoxRef; 8]) -> usize {
        let b = &self.nodes[n.0 as usize];
        let o = self.origin;
        // The query relative to the origin, clamped into i32 (the nodes' range).
        let clamp = |v: i128| v.clamp(i128::from(i32::MIN), i128::from(i32::MAX)) as i32;
        let lo = [0, 1, 2].map(|a| clamp(q.lo[a] - i128::from(o[a])));
        let hi = [0, 1, 2].map(|a| clamp(q.hi[a] - i128::from(o[a])));
        let first = b.first as usize;
        let mut m = 0;
        for (i, c) in self.nodes[first..first + usize::from(b.count)]
            .iter()
            .enumerate()
        {
            if c.lo[0] < hi[0]
                && lo[0] < c.hi[0]
                && c.lo[1] < hi[1]
                && lo[1] < c.hi[1]
                && c.lo[2] < hi[2]
                && lo[2] < c.hi[2]
            {
                out[m] = BoxRef((first + i) as u32);
                m += 1;
            }
        }
        m
    }

    #[inline]
    fn small_mask(&self, n: &BoxRef) -> Option<(Voxel, u64)> {
        let b = &self.nodes[n.0 as usize];
        (b.k <= 2).then(|| {
            let o = self.origin;
            ([0, 1, 2].map(|a| o[a] + i64::from(b.lo[a] & !3)), b.mask)
        })
    }
}
