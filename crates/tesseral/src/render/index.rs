//! The ray index of a linear octree ([`RayTree`]): its gray nodes, each with the
//! colours of its eight children, built in one pass over the sorted leaves.

use crate::linear::{Leaf, LinearOctree};

/// One gray node: which children are gray and which are black (the rest are white),
/// and where the gray children's nodes start (they are stored together, in label
/// order).
#[derive(Debug, Clone, Copy)]
pub(super) struct Node {
    pub(super) first: u32,
    pub(super) gray: u8,
    pub(super) black: u8,
}

/// The colour of the root.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Root {
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
    pub(super) depth: u8,
    pub(super) origin: [i64; 3],
    pub(super) root: Root,
    pub(super) nodes: Vec<Node>,
    pub(super) root_node: u32,
    pub(super) bbox: Option<([i64; 3], [i64; 3])>,
}

/// A node still open in the one-pass index build: its children so far.
struct Open {
    code: u64,
    k: u8,
    gray: u8,
    black: u8,
    n: u8,
    kids: [Node; 8],
}

impl Open {
    fn new(code: u64, k: u8) -> Self {
        Open {
            code,
            k,
            gray: 0,
            black: 0,
            n: 0,
            kids: [Node {
                first: 0,
                gray: 0,
                black: 0,
            }; 8],
        }
    }

    /// Whether the node's code range holds `code`.
    fn holds(&self, code: u64) -> bool {
        let shift = 3 * u32::from(self.k);
        shift >= 64 || code >> shift == self.code >> shift
    }
}

/// Closes the node on top of the stack: stores its gray children together and
/// records it as a gray child of its parent.
fn close(stack: &mut Vec<Open>, nodes: &mut Vec<Node>) {
    let o = stack.pop().expect("a node to close");
    let first = nodes.len() as u32;
    nodes.extend_from_slice(&o.kids[..usize::from(o.n)]);
    let parent = stack.last_mut().expect("the root is never closed here");
    parent.gray |= 1 << ((o.code >> (3 * u32::from(o.k))) & 7);
    parent.kids[usize::from(parent.n)] = Node {
        first,
        gray: o.gray,
        black: o.black,
    };
    parent.n += 1;
}

impl RayTree {
    /// The index of `tree` with its root classified and no nodes yet. O(1).
    #[cfg(test)]
    fn unindexed(tree: &LinearOctree) -> Self {
        let mut rt = Self::unindexed_leaves(tree.depth(), tree.origin(), tree.leaves());
        rt.bbox = tree.bbox();
        rt
    }

    /// As `RayTree::unindexed` (built for tests), for sorted leaves in a space; no
    /// bounding box.
    fn unindexed_leaves(depth: u8, origin: [i64; 3], leaves: &[Leaf]) -> Self {
        RayTree {
            depth,
            origin,
            root: match colour_of(leaves, 0, depth) {
                Colour::White => Root::White,
                Colour::Black => Root::Black,
                Colour::Gray => Root::Gray,
            },
            nodes: Vec::new(),
            root_node: 0,
            bbox: None,
        }
    }

    /// Indexes the gray nodes of `tree` in one pass over its sorted leaves: the open
    /// ancestors of the current leaf are kept on a stack; a node is closed when the
    /// leaves leave it, and its gray children's records are then stored together.
    ///
    /// # Runtime
    /// O(n) for n leaves (each leaf opens and closes at most `depth` nodes, and every
    /// node is opened once).
    #[must_use]
    pub fn new(tree: &LinearOctree) -> Self {
        let mut rt = Self::from_leaves(tree.depth(), tree.origin(), tree.leaves());
        rt.bbox = tree.bbox();
        rt
    }

    /// The index of sorted, disjoint `leaves` of the space `(depth, origin)` (a chunk
    /// of a file, say), without a bounding box.
    pub(crate) fn from_leaves(depth: u8, origin: [i64; 3], leaves: &[Leaf]) -> Self {
        let mut rt = Self::unindexed_leaves(depth, origin, leaves);
        if rt.root != Root::Gray {
            return rt;
        }
        let mut nodes = Vec::with_capacity(leaves.len() / 3 + 1);
        let mut stack = vec![Open::new(0, depth)];
        for leaf in leaves {
            let (c, s) = (leaf.code(), leaf.size_log2());
            while !stack[stack.len() - 1].holds(c) {
                close(&mut stack, &mut nodes);
            }
            loop {
                let top = &stack[stack.len() - 1];
                if top.k == s + 1 {
                    break;
                }
                let k = top.k - 1;
                stack.push(Open::new(c >> (3 * u32::from(k)) << (3 * u32::from(k)), k));
            }
            let top = stack.last_mut().expect("the root stays open");
            top.black |= 1 << ((c >> (3 * u32::from(s))) & 7);
        }
        while stack.len() > 1 {
            close(&mut stack, &mut nodes);
        }
        let root = stack.pop().expect("the root");
        let first = nodes.len() as u32;
        nodes.extend_from_slice(&root.kids[..usize::from(root.n)]);
        nodes.push(Node {
            first,
            gray: root.gray,
            black: root.black,
        });
        rt.root_node = nodes.len() as u32 - 1;
        rt.nodes = nodes;
        rt
    }

    /// The same index built top-down by partitioning the leaf slice: the reference the
    /// one-pass builder is tested against.
    #[cfg(test)]
    pub(crate) fn new_by_partition(tree: &LinearOctree) -> Self {
        let mut rt = Self::unindexed(tree);
        if rt.root == Root::Gray {
            rt.nodes.push(Node {
                first: 0,
                gray: 0,
                black: 0,
            });
            rt.index(0, 0, tree.depth(), tree.leaves());
        }
        rt
    }

    /// Whether two indexes describe the same tree (layouts may differ).
    #[cfg(test)]
    pub(crate) fn same_tree(&self, other: &RayTree) -> bool {
        fn eq(a: &RayTree, i: u32, b: &RayTree, j: u32) -> bool {
            let (x, y) = (a.nodes[i as usize], b.nodes[j as usize]);
            x.gray == y.gray
                && x.black == y.black
                && (0..x.gray.count_ones()).all(|c| eq(a, x.first + c, b, y.first + c))
        }
        self.root == other.root
            && (self.root != Root::Gray || eq(self, self.root_node, other, other.root_node))
    }

    #[cfg(test)]
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

    /// The inclusive bounding box of the black voxels (as [`LinearOctree::bbox`]).
    #[must_use]
    pub fn bbox(&self) -> Option<([i64; 3], [i64; 3])> {
        self.bbox
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
