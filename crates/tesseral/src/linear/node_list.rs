//! The papers' notations for an octree: the indented node list of Ahuja & Nash
//! Fig. 4 and the locational codes with an "X" postfix of Harakal & Chmúrny §2.
//!
//! Both are read straight from the sorted leaves. A leaf at depth `d` of a space of
//! depth `D` is the path of its top `d` octal digits; the gray nodes above it are its
//! proper prefixes, each listed once, before the first leaf below it (tesseral order is
//! depth-first order). White nodes are not listed, as in the paper.

use super::{Leaf, LinearOctree};

/// A node's colour in the node list (white nodes are not listed).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum NodeColour {
    /// A leaf: wholly inside the solid.
    Black,
    /// An inner node: partly inside.
    Gray,
}

/// One line of the node list: the path of child labels from the root (`r`), its
/// depth and its colour.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Node {
    /// Child labels from the root, one octal digit each (`[]` is the root).
    pub path: Vec<u8>,
    /// The colour.
    pub colour: NodeColour,
}

impl Node {
    /// The depth: 0 for the root.
    #[must_use]
    pub fn depth(&self) -> usize {
        self.path.len()
    }

    /// The label as the paper writes it: `r` followed by the path, such as `r05`.
    #[must_use]
    pub fn label(&self) -> String {
        let digits: String = self.path.iter().map(|d| char::from(b'0' + d)).collect();
        format!("r{digits}")
    }
}

impl std::fmt::Display for Node {
    /// `r05 black`, indented two spaces per depth.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let colour = match self.colour {
            NodeColour::Black => "black",
            NodeColour::Gray => "gray",
        };
        write!(f, "{:1$}{2} {colour}", "", 2 * self.depth(), self.label())
    }
}

/// The path of a leaf's block in a space of depth `depth`.
fn leaf_path(leaf: Leaf, depth: u8) -> Vec<u8> {
    let d = depth - leaf.size_log2();
    (0..d)
        .map(|i| ((leaf.code() >> (3 * u32::from(depth - 1 - i))) & 7) as u8)
        .collect()
}

impl LinearOctree {
    /// The indented node list of Ahuja & Nash Fig. 4: every gray and black node in
    /// depth-first (tesseral) order, each gray node before its children. An empty
    /// tree lists nothing (its root is white). Streams: O(depth) memory.
    ///
    /// ```
    /// use tesseral::linear::LinearOctree;
    /// let t = LinearOctree::from_voxels(2, [0; 3], [[0, 0, 0], [1, 0, 0], [3, 3, 3]]).unwrap();
    /// let lines: Vec<String> = t.node_list().map(|n| n.to_string()).collect();
    /// assert_eq!(lines, ["r gray", "  r0 gray", "    r00 black", "    r01 black",
    ///                    "  r7 gray", "    r77 black"]);
    /// ```
    pub fn node_list(&self) -> impl Iterator<Item = Node> + '_ {
        let depth = self.depth();
        // The deepest gray node listed so far: its prefixes are all listed.
        let mut listed: Option<Vec<u8>> = None;
        self.leaves().iter().flat_map(move |&leaf| {
            let path = leaf_path(leaf, depth);
            let common = listed
                .as_ref()
                .map(|l| l.iter().zip(&path).take_while(|(a, b)| a == b).count());
            let mut out: Vec<Node> = (0..path.len())
                .filter(|&k| common.is_none_or(|c| k > c))
                .map(|k| Node {
                    path: path[..k].to_vec(),
                    colour: NodeColour::Gray,
                })
                .collect();
            listed = path.split_last().map(|(_, up)| up.to_vec());
            out.push(Node {
                path,
                colour: NodeColour::Black,
            });
            out
        })
    }

    /// The leaves as locational codes with Harakal & Chmúrny's "X" postfix: the
    /// path's octal digits, padded to the space's depth with `X` in place of the
    /// digits below the block, such as `05XX` for a block two levels above a voxel
    /// in a depth-4 space. The whole space is all `X`.
    ///
    /// ```
    /// use tesseral::linear::LinearOctree;
    /// let t = LinearOctree::from_voxels(2, [0; 3], (0..2).flat_map(|x| (0..2)
    ///     .flat_map(move |y| (0..2).map(move |z| [x, y, z])))).unwrap();
    /// assert_eq!(t.locational_codes().collect::<Vec<_>>(), ["0X"]);
    /// ```
    pub fn locational_codes(&self) -> impl Iterator<Item = String> + '_ {
        let depth = self.depth();
        self.leaves().iter().map(move |&leaf| {
            let mut s: String = leaf_path(leaf, depth)
                .iter()
                .map(|d| char::from(b'0' + d))
                .collect();
            s.extend(std::iter::repeat_n('X', usize::from(leaf.size_log2())));
            s
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pointer::PointerOctree;
    use rand::{Rng, SeedableRng};
    use std::collections::BTreeSet;

    /// The node list from the definition: every cell of the space, top-down, that is
    /// wholly black (listed, not entered) or partly black (gray, entered).
    fn brute_force(t: &LinearOctree) -> Vec<Node> {
        fn visit(t: &LinearOctree, path: &mut Vec<u8>, out: &mut Vec<Node>) {
            let size = t.depth() - path.len() as u8;
            let mut min = t.origin();
            for (i, &d) in path.iter().enumerate() {
                let s = 1i64 << (t.depth() as usize - 1 - i);
                min = [0, 1, 2].map(|a| min[a] + s * i64::from((d >> a) & 1));
            }
            let side = 1i64 << size;
            let mut black = 0u64;
            for x in 0..side {
                for y in 0..side {
                    for z in 0..side {
                        black += u64::from(t.contains([min[0] + x, min[1] + y, min[2] + z]));
                    }
                }
            }
            if black == 0 {
                return;
            }
            if black == (side * side * side) as u64 {
                out.push(Node {
                    path: path.clone(),
                    colour: NodeColour::Black,
                });
                return;
            }
            out.push(Node {
                path: path.clone(),
                colour: NodeColour::Gray,
            });
            for d in 0..8 {
                path.push(d);
                visit(t, path, out);
                path.pop();
            }
        }
        let mut out = Vec::new();
        visit(t, &mut Vec::new(), &mut out);
        out
    }

    #[test]
    fn the_node_list_is_the_definition_on_random_trees() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(4);
        for _ in 0..200 {
            let depth = rng.random_range(0..4u8);
            let side = 1i64 << depth;
            let n = rng.random_range(0..=(side * side * side) as usize);
            let voxels: BTreeSet<[i64; 3]> = (0..n)
                .map(|_| [0; 3].map(|_| rng.random_range(0..side) + 5))
                .collect();
            let t = LinearOctree::from_voxels(depth, [5; 3], voxels.iter().copied()).unwrap();
            t.assert_valid();
            assert_eq!(t.node_list().collect::<Vec<_>>(), brute_force(&t));
            // Codes: one per leaf, each D characters, X exactly below the block.
            let codes: Vec<String> = t.locational_codes().collect();
            assert_eq!(codes.len(), t.leaf_count());
            for (code, leaf) in codes.iter().zip(t.leaves()) {
                assert_eq!(code.len(), usize::from(depth));
                assert_eq!(
                    code.chars().filter(|&c| c == 'X').count(),
                    usize::from(leaf.size_log2())
                );
                assert!(t.node_list().any(|n| n.colour == NodeColour::Black
                    && code.starts_with(&n.label()[1..])
                    && n.depth() + usize::from(leaf.size_log2()) == usize::from(depth)));
            }
        }
    }

    #[test]
    fn harakal_postfix_example() {
        // A block two levels above a voxel at path 0, 5 in a depth-4 space.
        let s = 4i64;
        let min = [4, 0, 4]; // path digits 0 (x0 y0 z0 at the top), then 5 (x1 z1)
        let voxels = (0..s).flat_map(|x| {
            (0..s).flat_map(move |y| (0..s).map(move |z| [min[0] + x, min[1] + y, min[2] + z]))
        });
        let t = LinearOctree::from_voxels(4, [0; 3], voxels).unwrap();
        assert_eq!(t.locational_codes().collect::<Vec<_>>(), ["05XX"]);
    }

    /// Harakal & Chmúrny eq. (1): a full octree of depth n (every inner node gray
    /// down to single voxels) has 1 + 8 + … + 8^n = (8^(n+1) − 1)/7 nodes; the
    /// printed (8^n + 1)/7 is an erratum. A checkerboard is such a tree.
    #[test]
    fn full_octrees_have_the_summed_node_count() {
        for n in 0..=4u8 {
            let side = 1i64 << n;
            let board = (0..side).flat_map(|x| {
                (0..side).flat_map(move |y| {
                    (0..side)
                        .filter(move |z| (x + y + z) % 2 == 0)
                        .map(move |z| [x, y, z])
                })
            });
            let t = LinearOctree::from_voxels(n, [0; 3], board).unwrap();
            // Every gray node of a full octree has eight children, so the full
            // tree has 1 + 8 × (gray nodes) nodes.
            let gray = t
                .node_list()
                .filter(|n| n.colour == NodeColour::Gray)
                .count() as u64;
            let full = if n == 0 { 1 } else { 1 + 8 * gray };
            let sum: u64 = (0..=u32::from(n)).map(|k| 8u64.pow(k)).sum();
            assert_eq!(full, sum, "n = {n}");
            assert_eq!(full, (8u64.pow(u32::from(n) + 1) - 1) / 7, "n = {n}");
            if n > 0 {
                assert_ne!(full, (8u64.pow(u32::from(n)) + 1) / 7, "printed, n = {n}");
            }
            // The pointer octree stores the listed nodes: gray and black, not white.
            let p = PointerOctree::from_linear(&t);
            assert_eq!(p.node_count(), t.node_list().count(), "n = {n}");
        }
    }
}
