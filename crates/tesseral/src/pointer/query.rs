//! Reading a [`PointerOctree`]: its space, nodes, counts, membership and bounds.

use super::{Color, NodeId, PointerOctree, NIL};
use crate::Voxel;

impl PointerOctree {
    /// The depth D: the tree spans `2^D` voxels per axis.
    #[must_use]
    pub fn depth(&self) -> u8 {
        self.depth
    }

    /// The world coordinates of the space's lowest corner.
    #[must_use]
    pub fn origin(&self) -> Voxel {
        self.origin
    }

    /// The root, or `None` when the tree is empty (a NIL root).
    #[must_use]
    pub fn root(&self) -> Option<NodeId> {
        (self.root != NIL).then_some(NodeId(self.root))
    }

    /// The colour of a node.
    ///
    /// # Panics
    /// When `id` is not a node of this tree.
    #[must_use]
    pub fn color(&self, id: NodeId) -> Color {
        self.nodes[id.0 as usize].color
    }

    /// The eight child links of a node, by label `x + 2y + 4z`; `None` is NIL.
    ///
    /// # Panics
    /// When `id` is not a node of this tree.
    #[must_use]
    pub fn children(&self, id: NodeId) -> [Option<NodeId>; 8] {
        self.nodes[id.0 as usize]
            .children
            .map(|c| (c != NIL).then_some(NodeId(c)))
    }

    /// The number of stored nodes (gray and black).
    #[must_use]
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// The number of black leaves.
    #[must_use]
    pub fn black_count(&self) -> usize {
        self.nodes
            .iter()
            .filter(|n| n.color == Color::Black)
            .count()
    }

    /// The number of gray nodes.
    #[must_use]
    pub fn gray_count(&self) -> usize {
        self.nodes.len() - self.black_count()
    }

    /// Whether world voxel `v` is black.
    ///
    /// # Runtime
    /// O(depth).
    #[must_use]
    pub fn contains(&self, v: Voxel) -> bool {
        let mut rel = [0u64; 3];
        for a in 0..3 {
            let Some(d) = v[a].checked_sub(self.origin[a]) else {
                return false;
            };
            if d < 0 || d >> self.depth != 0 {
                return false;
            }
            rel[a] = d as u64;
        }
        let mut id = self.root;
        for level in (0..self.depth).rev() {
            if id == NIL {
                return false;
            }
            let node = &self.nodes[id as usize];
            if node.color == Color::Black {
                return true;
            }
            let d = ((rel[0] >> level) & 1)
                | (((rel[1] >> level) & 1) << 1)
                | (((rel[2] >> level) & 1) << 2);
            id = node.children[d as usize];
        }
        id != NIL && self.nodes[id as usize].color == Color::Black
    }

    /// The inclusive bounding box of the black voxels, in world coordinates.
    #[must_use]
    pub fn bbox(&self) -> Option<(Voxel, Voxel)> {
        let mut acc: Option<(Voxel, Voxel)> = None;
        self.for_each_black(self.root, [0; 3], self.depth, &mut |min, k| {
            let s = (1i64 << k) - 1;
            let max = [min[0] + s, min[1] + s, min[2] + s];
            acc = Some(match acc {
                None => (min, max),
                Some((lo, hi)) => (
                    std::array::from_fn(|a| lo[a].min(min[a])),
                    std::array::from_fn(|a| hi[a].max(max[a])),
                ),
            });
        });
        acc.map(|(lo, hi)| {
            (
                std::array::from_fn(|a| lo[a] + self.origin[a]),
                std::array::from_fn(|a| hi[a] + self.origin[a]),
            )
        })
    }

    fn for_each_black(&self, id: u32, min: [i64; 3], k: u8, f: &mut impl FnMut([i64; 3], u8)) {
        if id == NIL {
            return;
        }
        let node = &self.nodes[id as usize];
        if node.color == Color::Black {
            f(min, k);
            return;
        }
        if k == 0 {
            return;
        }
        let h = 1i64 << (k - 1);
        for (d, &c) in node.children.iter().enumerate() {
            let m = [
                min[0] + (d as i64 & 1) * h,
                min[1] + ((d as i64 >> 1) & 1) * h,
                min[2] + ((d as i64 >> 2) & 1) * h,
            ];
            self.for_each_black(c, m, k - 1, f);
        }
    }
}
