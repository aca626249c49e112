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

mod convert;
mod labels;
mod query;
mod translate;
mod validate;

pub use labels::{add_along_axis, label_transition};
pub use translate::{AxisStats, TranslationStats};

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

#[cfg(test)]
mod tests;
