//! [`PointerOctree::assert_valid`]: the tree's invariants.

use super::{Color, PointerOctree, NIL};
use crate::linear::MAX_DEPTH;

impl PointerOctree {
    /// Panics with a description of the first broken invariant: every stored node is
    /// reached from the root exactly once, black nodes are leaves, gray nodes have at
    /// least one child and lie above the voxel level, and no gray node has eight
    /// black children (the tree is compact).
    ///
    /// # Runtime
    /// O(N).
    pub fn assert_valid(&self) {
        assert!(
            self.depth <= MAX_DEPTH,
            "depth {} > {MAX_DEPTH}",
            self.depth
        );
        let mut seen = vec![false; self.nodes.len()];
        let mut stack = Vec::new();
        if self.root != NIL {
            stack.push((self.root, self.depth));
        }
        let mut reached = 0;
        while let Some((id, k)) = stack.pop() {
            let i = id as usize;
            assert!(i < self.nodes.len(), "link {id} out of the arena");
            assert!(!seen[i], "node {id} reached twice");
            seen[i] = true;
            reached += 1;
            let node = &self.nodes[i];
            match node.color {
                Color::Black => assert!(
                    node.children.iter().all(|&c| c == NIL),
                    "black node {id} has children"
                ),
                Color::Gray => {
                    assert!(k > 0, "gray node {id} at the voxel level");
                    assert!(
                        node.children.iter().any(|&c| c != NIL),
                        "gray node {id} has no children"
                    );
                    assert!(
                        !node
                            .children
                            .iter()
                            .all(|&c| c != NIL && self.nodes[c as usize].color == Color::Black),
                        "gray node {id} has eight black children"
                    );
                    for &c in &node.children {
                        if c != NIL {
                            stack.push((c, k - 1));
                        }
                    }
                }
            }
        }
        assert_eq!(reached, self.nodes.len(), "unreachable nodes in the arena");
    }
}
