//! The top of a streamed tree, from the chunk index alone: a node whose code range
//! meets no chunk is white; one that meets two or more chunks holds two or more
//! leaves, so it is gray (or, across the parts of a dataset, possibly black: see
//! [`Top::build`]); one that meets a single chunk is answered by that chunk, decoded
//! when a traversal reaches it.

use super::super::index::Root;
use crate::io::FormatError;

/// One chunk of the streamed tree: which file holds it and the codes its leaves cover.
#[derive(Debug, Clone, Copy)]
pub(super) struct ChunkRef {
    pub(super) part: u32,
    pub(super) chunk: u32,
    pub(super) lo: u64,
    pub(super) hi: u64,
    pub(super) count: u64,
    /// Its bytes in the file, `[start, end)` (`end` past the file for the last).
    pub(super) bytes: (u64, u64),
}

/// A child of a top node.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum TopKid {
    White,
    Black,
    /// Another top node.
    Top(u32),
    /// A node meeting one chunk only: that chunk decides.
    Chunk(u32),
}

/// The top nodes (each with its eight children) and the root.
pub(super) struct Top {
    pub(super) nodes: Vec<[TopKid; 8]>,
    pub(super) root: Root,
    pub(super) root_node: u32,
}

struct Builder<'a, F> {
    chunks: &'a [ChunkRef],
    nodes: Vec<[TopKid; 8]>,
    full: F,
}

impl Top {
    /// The top of a tree of depth `depth` whose leaves lie in `chunks` (sorted,
    /// disjoint). `full(code, k, a, b)` says whether the node `(code, k)` is covered
    /// by the leaves of chunks `a..b`; it is asked only where a node spans chunks of
    /// two parts with no gap between them, the one case where joining the parts
    /// merges leaves into a bigger block (as `PartitionedOctree::concat` does).
    ///
    /// # Errors
    /// What `full` returns.
    ///
    /// # Runtime
    /// O(chunks × depth) nodes.
    pub(super) fn build(
        depth: u8,
        chunks: &[ChunkRef],
        full: impl FnMut(u64, u8, usize, usize) -> Result<bool, FormatError>,
    ) -> Result<Top, FormatError> {
        let end = 1u64 << (3 * u32::from(depth));
        let mut b = Builder {
            chunks,
            nodes: Vec::new(),
            full,
        };
        let n = chunks.len();
        let root = if n == 0 {
            Root::White
        } else if (n == 1 && chunks[0].count == 1 && chunks[0].lo == 0 && chunks[0].hi == end)
            || (b.may_be_full(0, depth, 0, n) && (b.full)(0, depth, 0, n)?)
        {
            Root::Black
        } else {
            Root::Gray
        };
        let root_node = if root == Root::Gray {
            b.split(0, depth, 0, n)?
        } else {
            0
        };
        Ok(Top {
            nodes: b.nodes,
            root,
            root_node,
        })
    }
}

impl<F: FnMut(u64, u8, usize, usize) -> Result<bool, FormatError>> Builder<'_, F> {
    /// A top node for `(code, k)`, whose range meets chunks `a..b`.
    fn split(&mut self, code: u64, k: u8, a: usize, b: usize) -> Result<u32, FormatError> {
        let at = self.nodes.len();
        self.nodes.push([TopKid::White; 8]);
        let size = 1u64 << (3 * u32::from(k - 1));
        let mut from = a;
        for d in 0..8u64 {
            let (c0, c1) = (code + d * size, code + (d + 1) * size);
            let a2 = from + self.chunks[from..b].partition_point(|c| c.hi <= c0);
            let b2 = a2 + self.chunks[a2..b].partition_point(|c| c.lo < c1);
            let kid = match b2 - a2 {
                0 => TopKid::White,
                1 => TopKid::Chunk(a2 as u32),
                _ if self.may_be_full(c0, k - 1, a2, b2) && (self.full)(c0, k - 1, a2, b2)? => {
                    TopKid::Black
                }
                _ => TopKid::Top(self.split(c0, k - 1, a2, b2)?),
            };
            self.nodes[at][d as usize] = kid;
            from = a2;
        }
        Ok(at as u32)
    }

    /// Whether chunks `a..b` (two or more) come from two parts and leave no gap in
    /// the node `(code, k)`.
    fn may_be_full(&self, code: u64, k: u8, a: usize, b: usize) -> bool {
        let c = &self.chunks[a..b];
        c.len() >= 2
            && c[0].part != c[c.len() - 1].part
            && c[0].lo <= code
            && c[c.len() - 1].hi >= code + (1u64 << (3 * u32::from(k)))
            && c.windows(2).all(|w| w[0].hi == w[1].lo)
    }
}
