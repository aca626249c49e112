//! Pointer octrees (Ahuja & Nash §2) and their translation by label arithmetic
//! (Ahuja & Nash §3).
//!
//! A [`PointerOctree`] keeps gray nodes with eight child links, black leaves, and
//! NIL links for white: "only the black leaves in the octree are retained. The white
//! children of a gray node are deleted and their corresponding links in the parent
//! are marked ... NIL" (§2). Nodes live in one arena and link by index.
//!
//! [`PointerOctree::translate`] is the algorithm of §3.2, step by step, with counters
//! ([`TranslationStats`]) that show the cost analysis of §3.3. [`label_transition`]
//! and [`add_along_axis`] are Tables 1–2 and the path addition of §3.1, computed
//! rather than copied. Unlike the paper, which works in a fixed space and drops the
//! carry out of the top digit, the tree first grows its root (Libes §3) until the
//! moved object fits, so a translation never loses or wraps voxels.

// Per-axis loops index several arrays at once.
#![allow(clippy::needless_range_loop)]

use crate::linear::{LinearOctree, OctreeError, MAX_DEPTH};
use crate::Voxel;

const NIL: u32 = u32::MAX;

/// The index of a node in a [`PointerOctree`]'s arena.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct NodeId(u32);

/// The colour of a stored node. White nodes are not stored: their links are NIL.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Color {
    /// Inside the object: a leaf.
    Black,
    /// Partly inside: a node with child links.
    Gray,
}

#[derive(Debug, Clone, PartialEq, Eq)]
struct Node {
    color: Color,
    children: [u32; 8],
}

impl Node {
    const BLACK: Node = Node {
        color: Color::Black,
        children: [NIL; 8],
    };
    const EMPTY_GRAY: Node = Node {
        color: Color::Gray,
        children: [NIL; 8],
    };
}

/// An octree of gray nodes with child links, black leaves, and NIL for white
/// (Ahuja & Nash §2), spanning `2^depth` voxels per axis from an integer origin.
///
/// ```
/// use tesseral::linear::LinearOctree;
/// use tesseral::pointer::PointerOctree;
/// let lin = LinearOctree::from_voxels(2, [0, 0, 0], [[0, 0, 0], [3, 3, 3]]).unwrap();
/// let p = PointerOctree::from_linear(&lin);
/// p.assert_valid();
/// assert_eq!((p.black_count(), p.gray_count()), (2, 3));
/// assert_eq!(p.to_linear(), lin);
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PointerOctree {
    depth: u8,
    origin: Voxel,
    nodes: Vec<Node>,
    root: u32,
}

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

/// Table 2 of Ahuja & Nash: the label a node takes after a unit displacement along
/// `axis` (0 = x, 1 = y, 2 = z), and whether a carry moves its parent too.
/// Table 1's increment is `(new − old) mod 8`.
///
/// ```
/// use tesseral::pointer::label_transition;
/// assert_eq!(label_transition(7, 1), (true, 5)); // the paper's "15"
/// assert_eq!(label_transition(0, 2), (false, 4));
/// ```
#[must_use]
pub fn label_transition(label: u8, axis: usize) -> (bool, u8) {
    let bit = 1u8 << axis;
    (label & bit != 0, label ^ bit)
}

/// Adds `t` (two's complement when negative) along `axis` to a path of labels, most
/// significant (the root's child) first, digit by digit with the Table 2 carries;
/// the carry out of the top digit is dropped (§3.1).
///
/// ```
/// use tesseral::pointer::add_along_axis;
/// // §3.1: r057 moved by 1 and by 5 along +y, and r275 by -5 along y.
/// assert_eq!(add_along_axis(&[0, 5, 7], 1, 1), vec![0, 7, 5]);
/// assert_eq!(add_along_axis(&[0, 5, 7], 1, 5), vec![2, 7, 5]);
/// assert_eq!(add_along_axis(&[2, 7, 5], 1, -5), vec![0, 5, 7]);
/// ```
#[must_use]
pub fn add_along_axis(path: &[u8], axis: usize, t: i64) -> Vec<u8> {
    let mut out = path.to_vec();
    let mut carry = false;
    for (i, label) in out.iter_mut().rev().enumerate() {
        // Digit i (from the bottom) receives bit i of t and the carry from below:
        // each is one unit transition of Table 2, and at most one of them carries.
        let bit = i < 64 && (t >> i.min(63)) & 1 == 1;
        let mut next_carry = false;
        for step in [bit, carry] {
            if step {
                let (c, l) = label_transition(*label, axis);
                *label = l;
                next_carry |= c;
            }
        }
        carry = next_carry;
    }
    out
}

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

    fn push(&mut self, node: Node) -> u32 {
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

#[cfg(test)]
mod tests;
