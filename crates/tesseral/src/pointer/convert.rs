//! Building a [`PointerOctree`]: empty, from a linear octree, and back.

use super::{Color, Node, PointerOctree, NIL};
use crate::linear::{LinearOctree, OctreeError, MAX_DEPTH};
use crate::Voxel;

impl PointerOctree {
    /// An empty tree (a NIL root).
    ///
    /// # Errors
    /// [`OctreeError::DepthTooLarge`] when `depth > MAX_DEPTH`.
    pub fn empty(depth: u8, origin: Voxel) -> Result<Self, OctreeError> {
        if depth > MAX_DEPTH {
            return Err(OctreeError::DepthTooLarge(depth));
        }
        Ok(Self {
            depth,
            origin,
            nodes: Vec::new(),
            root: NIL,
        })
    }

    /// Converts a linear octree: one black node per leaf, one gray node per cell
    /// that holds black and white.
    ///
    /// # Runtime
    /// O(n · depth) for n leaves.
    #[must_use]
    pub fn from_linear(tree: &LinearOctree) -> Self {
        let mut p = Self {
            depth: tree.depth(),
            origin: tree.origin(),
            nodes: Vec::with_capacity(tree.leaf_count() * 8 / 7 + 1),
            root: NIL,
        };
        p.root = p.build(tree.leaves(), 0, tree.depth());
        p
    }

    fn build(&mut self, leaves: &[crate::linear::Leaf], code: u64, k: u8) -> u32 {
        if leaves.is_empty() {
            return NIL;
        }
        if leaves.len() == 1 && leaves[0].size_log2() >= k {
            return self.push(Node::BLACK);
        }
        let id = self.push(Node::EMPTY_GRAY);
        let child = 1u64 << (3 * u32::from(k - 1));
        let mut rest = leaves;
        for d in 0..8u64 {
            let end = code + (d + 1) * child;
            let n = rest.partition_point(|l| l.code() < end);
            let (part, r) = rest.split_at(n);
            rest = r;
            let c = self.build(part, code + d * child, k - 1);
            self.nodes[id as usize].children[d as usize] = c;
        }
        id
    }

    pub(super) fn push(&mut self, node: Node) -> u32 {
        self.nodes.push(node);
        (self.nodes.len() - 1) as u32
    }

    /// Converts back to a linear octree (canonical, whatever this tree's shape).
    ///
    /// # Runtime
    /// O(N) in the nodes.
    #[must_use]
    pub fn to_linear(&self) -> LinearOctree {
        let mut leaves = Vec::new();
        self.collect(self.root, 0, self.depth, &mut leaves);
        LinearOctree::from_sorted_leaves(self.depth, self.origin, leaves)
            .expect("the depth was checked on construction")
    }

    fn collect(&self, id: u32, code: u64, k: u8, out: &mut Vec<crate::linear::Leaf>) {
        if id == NIL {
            return;
        }
        let node = &self.nodes[id as usize];
        match node.color {
            Color::Black => out.push(crate::linear::Leaf::new(code, k)),
            Color::Gray if k == 0 => {}
            Color::Gray => {
                let child = 1u64 << (3 * u32::from(k - 1));
                for (d, &c) in node.children.iter().enumerate() {
                    self.collect(c, code + d as u64 * child, k - 1, out);
                }
            }
        }
    }
}
