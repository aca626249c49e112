//! [`PointerOctree::translate`]: Ahuja & Nash §3.2, with the §3.3 cost counters.

use super::{add_along_axis, Color, Node, PointerOctree, NIL};
use crate::linear::OctreeError;
use crate::Voxel;

/// What one axis of a translation cost (Ahuja & Nash §3.3).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct AxisStats {
    /// The displacement along this axis.
    pub displacement: i64,
    /// The side (log2) of the moved nodes: the lowest set bit of the displacement,
    /// the paper's H counted from the bottom.
    pub moved_size_log2: u8,
    /// Black nodes created by splitting leaves down to the moved size (step 0).
    pub split_created: u64,
    /// Nodes visited by the postorder traversal of step 1 (the paper's N_i).
    pub traversed: u64,
    /// Nodes of the moved size that held something and were moved (N_f).
    pub moved: u64,
    /// Nodes visited on the root-to-destination paths of step 2(ii): O(N_f · H).
    pub path_steps: u64,
    /// Gray nodes created on those paths.
    pub path_created: u64,
    /// Nodes visited by the compaction traversal of step 3 (N').
    pub compacted: u64,
}

/// The cost of a whole translation: the three axes in turn, and root growth.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TranslationStats {
    /// Root expansions needed so that the moved object fits.
    pub root_expansions: u8,
    /// Per axis, x, y, z.
    pub axes: [AxisStats; 3],
}

impl TranslationStats {
    /// All nodes visited: traversal, destination paths and compaction, summed over
    /// the axes — the quantity that §3.3 bounds by O(N_i · H + N').
    #[must_use]
    pub fn nodes_visited(&self) -> u64 {
        self.axes
            .iter()
            .map(|a| a.traversed + a.path_steps + a.compacted)
            .sum()
    }
}

impl PointerOctree {
    /// Translates the object by `by`, following Ahuja & Nash §3.2 axis by axis:
    ///
    /// 0. the root grows (root expansion, the old root becoming a child of a new
    ///    root) until the moved object fits, so no carry is ever lost;
    ///
    /// and then for each axis with a non-zero displacement `t`:
    ///
    /// 1. every black leaf larger than `2^H` (H the lowest set bit of `t`) is split
    ///    into eight black children, recursively, down to side `2^H`;
    /// 2. the nodes of side `≥ 2^H` are traversed in postorder, children in
    ///    decreasing label order for a positive `t` (increasing for a negative one),
    ///    so that nodes ahead in the direction of motion are met first;
    /// 3. for each non-empty node of side `2^H`, the destination path is computed by
    ///    label arithmetic with the Table 2 carries ([`add_along_axis`]), the
    ///    destination is reached from the root (creating gray nodes on the way), the
    ///    node's data (colour and child links) is copied there, and the source is
    ///    marked gray with no children;
    /// 4. the tree is compacted in postorder: childless gray nodes are deleted and
    ///    gray nodes with eight black children become black.
    ///
    /// Finally the arena is rebuilt without the deleted nodes.
    ///
    /// # Runtime
    /// O(N_i · H + N') per axis (§3.3): [`TranslationStats`] counts the nodes
    /// visited. Splitting to side `2^H` can create many nodes for an odd
    /// displacement; [`LinearOctree::translate`] avoids that.
    ///
    /// # Errors
    /// [`OctreeError::DepthTooLarge`] when the grown space would exceed
    /// [`MAX_DEPTH`]; [`OctreeError::Overflow`] when a coordinate overflows.
    ///
    /// ```
    /// use tesseral::linear::LinearOctree;
    /// use tesseral::pointer::PointerOctree;
    /// let lin = LinearOctree::from_voxels(3, [0, 0, 0], [[1, 2, 3]]).unwrap();
    /// let mut p = PointerOctree::from_linear(&lin);
    /// let stats = p.translate([2, 0, -1]).unwrap();
    /// p.assert_valid();
    /// assert!(p.contains([3, 2, 2]));
    /// assert_eq!(stats.axes[0].moved_size_log2, 1);
    /// ```
    ///
    /// [`LinearOctree::translate`]: crate::linear::LinearOctree::translate
    /// [`MAX_DEPTH`]: crate::linear::MAX_DEPTH
    pub fn translate(&mut self, by: [i64; 3]) -> Result<TranslationStats, OctreeError> {
        let mut stats = TranslationStats::default();
        for a in 0..3 {
            stats.axes[a].displacement = by[a];
        }
        let Some((lo, hi)) = self.bbox() else {
            return Ok(stats);
        };
        let shift = |v: Voxel| -> Result<Voxel, OctreeError> {
            let mut out = [0; 3];
            for a in 0..3 {
                out[a] = v[a].checked_add(by[a]).ok_or(OctreeError::Overflow)?;
            }
            Ok(out)
        };
        let (depth, origin) =
            crate::linear::grow::grown_space(self.depth, self.origin, shift(lo)?, shift(hi)?)?;
        while self.depth < depth {
            // The old root's label in the new root: upper half on the axes where
            // the space grew downwards.
            let mut label = 0;
            for a in 0..3 {
                let rel = i128::from(self.origin[a]) - i128::from(origin[a]);
                if (rel >> self.depth) & 1 == 1 {
                    label |= 1 << a;
                    self.origin[a] -= 1i64 << self.depth;
                }
            }
            let mut root = Node::EMPTY_GRAY;
            root.children[label] = self.root;
            self.root = self.push(root);
            self.depth += 1;
            stats.root_expansions += 1;
        }
        debug_assert_eq!(self.origin, origin);
        for axis in 0..3 {
            let t = by[axis];
            if t == 0 {
                continue;
            }
            let s = &mut stats.axes[axis];
            let h = t.unsigned_abs().trailing_zeros() as u8;
            s.moved_size_log2 = h;
            self.split_down_to(self.root, self.depth, h, s);
            let root = self.root;
            self.traverse(root, 0, self.depth, axis, t, h, s);
            self.root = self.compact(self.root, s);
        }
        self.collect_garbage();
        Ok(stats)
    }

    /// Step 0 of §3.2: black leaves larger than `2^h` get eight black children.
    fn split_down_to(&mut self, id: u32, k: u8, h: u8, s: &mut AxisStats) {
        if id == NIL || k <= h {
            return;
        }
        if self.nodes[id as usize].color == Color::Black {
            let mut children = [NIL; 8];
            for c in &mut children {
                *c = self.push(Node::BLACK);
            }
            s.split_created += 8;
            self.nodes[id as usize] = Node {
                color: Color::Gray,
                children,
            };
        }
        for d in 0..8 {
            let c = self.nodes[id as usize].children[d];
            self.split_down_to(c, k - 1, h, s);
        }
    }

    /// Steps 1–2 of §3.3: postorder in the direction of motion, moving each
    /// non-empty node of side `2^h`.
    #[allow(clippy::too_many_arguments)]
    fn traverse(
        &mut self,
        id: u32,
        code: u64,
        k: u8,
        axis: usize,
        t: i64,
        h: u8,
        s: &mut AxisStats,
    ) {
        if id == NIL {
            return;
        }
        s.traversed += 1;
        if k == h {
            let node = &self.nodes[id as usize];
            if node.color == Color::Black || node.children.iter().any(|&c| c != NIL) {
                self.move_node(id, code, axis, t, h, s);
            }
            return;
        }
        let child = 1u64 << (3 * u32::from(k - 1));
        for i in 0..8u64 {
            let d = if t > 0 { 7 - i } else { i };
            // Read the link now: moves may have created children behind us.
            let c = self.nodes[id as usize].children[d as usize];
            self.traverse(c, code + d * child, k - 1, axis, t, h, s);
        }
    }

    /// Step 2 (i–iv) of §3.3 for one node.
    fn move_node(&mut self, src: u32, code: u64, axis: usize, t: i64, h: u8, s: &mut AxisStats) {
        let digits = usize::from(self.depth - h);
        let path: Vec<u8> = (0..digits)
            .map(|j| ((code >> (3 * (usize::from(self.depth) - 1 - j))) & 7) as u8)
            .collect();
        // (i) the destination, by label arithmetic; the displacement's bit H goes
        // with the moved node's own digit.
        let dest_path = add_along_axis(&path, axis, t >> h);
        // (ii) access it from the root, adding nodes where the path does not exist.
        let mut cur = self.root;
        for (j, &label) in dest_path.iter().enumerate() {
            s.path_steps += 1;
            let mut next = self.nodes[cur as usize].children[usize::from(label)];
            if next == NIL {
                next = self.push(Node::EMPTY_GRAY);
                self.nodes[cur as usize].children[usize::from(label)] = next;
                s.path_created += 1;
            }
            debug_assert!(
                j + 1 == dest_path.len() || self.nodes[next as usize].color == Color::Gray,
                "a black leaf above the moved size"
            );
            cur = next;
        }
        debug_assert!(
            self.nodes[cur as usize] == Node::EMPTY_GRAY,
            "destination not yet vacated: traversal order broken"
        );
        // (iii) copy the data, (iv) mark the source gray with no children.
        self.nodes[cur as usize] = self.nodes[src as usize].clone();
        self.nodes[src as usize] = Node::EMPTY_GRAY;
        s.moved += 1;
    }

    /// Step 3: postorder compaction. Returns the node's new link.
    fn compact(&mut self, id: u32, s: &mut AxisStats) -> u32 {
        if id == NIL {
            return NIL;
        }
        s.compacted += 1;
        if self.nodes[id as usize].color == Color::Black {
            return id;
        }
        let mut children = self.nodes[id as usize].children;
        for c in &mut children {
            *c = self.compact(*c, s);
        }
        if children.iter().all(|&c| c == NIL) {
            return NIL;
        }
        if children
            .iter()
            .all(|&c| c != NIL && self.nodes[c as usize].color == Color::Black)
        {
            self.nodes[id as usize] = Node::BLACK;
        } else {
            self.nodes[id as usize].children = children;
        }
        id
    }

    /// Rebuilds the arena with only the nodes reachable from the root, in preorder.
    fn collect_garbage(&mut self) {
        let old = std::mem::take(&mut self.nodes);
        fn copy(old: &[Node], id: u32, out: &mut Vec<Node>) -> u32 {
            if id == NIL {
                return NIL;
            }
            let new = out.len() as u32;
            out.push(old[id as usize].clone());
            for d in 0..8 {
                let c = copy(old, old[id as usize].children[d], out);
                out[new as usize].children[d] = c;
            }
            new
        }
        let mut nodes = Vec::with_capacity(old.len());
        self.root = copy(&old, self.root, &mut nodes);
        self.nodes = nodes;
    }
}
