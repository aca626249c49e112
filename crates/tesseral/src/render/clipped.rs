//! A tree seen through a clipping plane without cropping it: the nodes of
//! [`crop_to_clip`](super::crop_to_clip)'s result, answered from the uncropped tree
//! as a traversal reaches them. A node wholly on the removed side is white, one
//! wholly on the kept side is the tree's own, and one the plane crosses is:
//!
//! - white if it is white, or gray with no black voxel on the kept side (found by a
//!   descent along the plane, remembered per node of side 16 or more);
//! - gray if it is black (the crop splits it: a virtual node whose children are
//!   classified the same way) or gray with a black voxel on the kept side.
//!
//! No merge can happen in a crop (a node the plane crosses loses its removed side),
//! so this is exactly the cropped tree's structure, and a render through it is the
//! render of the cropped tree, byte for byte. It lets a streamed tree be cut
//! without reading the chunks the plane removes.

use std::sync::{Mutex, PoisonError};

use rustc_hash::FxHashMap;

use super::index::Root;
use super::nodes::{bounding_box, Kid, NodeId, Nodes, Trace};
use super::Clip;

/// The `src` of a virtual node: a black block of the tree that the plane crosses.
const SPLIT: NodeId = NodeId {
    src: u32::MAX - 1,
    node: 0,
};

/// The answers of [`Clipped::any_kept`] are remembered for nodes of side at least
/// 2^`MEMO_LOG2` only: smaller ones are cheap to ask again, and the plane crosses
/// 4 times fewer nodes at each level up, so at most about 1/256 as many nodes are
/// remembered as the plane crosses voxels.
const MEMO_LOG2: u8 = 4;

/// Where a node lies with respect to the plane.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Side {
    Kept,
    Removed,
    Across,
}

/// `inner` cropped to the half-space `clip` keeps, node by node.
pub(crate) struct Clipped<'b, T: Trace + ?Sized> {
    inner: &'b T,
    /// The kept range on the clip's axis, relative to the space: `[lo, hi)`.
    keep: (i128, i128),
    axis: usize,
    depth: u8,
    origin: [i64; 3],
    root: (Root, NodeId),
    bbox: Option<([i64; 3], [i64; 3])>,
    /// Whether a gray node the plane crosses has a black voxel on the kept side.
    kept: Mutex<FxHashMap<(u32, u32), bool>>,
}

impl<'b, T: Trace + ?Sized> Clipped<'b, T> {
    /// `inner` as [`crop_to_clip`](super::crop_to_clip) would crop it.
    ///
    /// # Runtime
    /// The nodes along the plane near the root, and the bounding box's descents.
    pub(crate) fn new(inner: &'b T, clip: Clip) -> Self {
        let (depth, origin) = inner.space();
        let b = i128::from(clip.boundary()) - i128::from(origin[clip.axis]);
        let keep = if clip.keep_above {
            (b, i128::MAX)
        } else {
            (i128::MIN, b)
        };
        let mut t = Clipped {
            inner,
            keep,
            axis: clip.axis,
            depth,
            origin,
            root: (Root::White, NodeId::default()),
            bbox: None,
            kept: Mutex::new(FxHashMap::default()),
        };
        let white = (Root::White, NodeId::default());
        t.root = match (t.side(0, depth), inner.root()) {
            (Side::Removed, _) | (_, (Root::White, _)) => white,
            (Side::Kept, r) => r,
            (Side::Across, (Root::Black, _)) => (Root::Gray, SPLIT),
            (Side::Across, (Root::Gray, id)) => {
                if t.any_kept(&mut inner.cursor(), id, 0, depth) {
                    (Root::Gray, id)
                } else {
                    white
                }
            }
        };
        t.bbox = bounding_box(&t);
        t
    }

    /// Where the node `(path, k)` lies.
    fn side(&self, path: u64, k: u8) -> Side {
        let rel = crate::code::decode(path << (3 * u32::from(k)));
        let lo = i128::from(rel[self.axis]);
        let hi = lo + (1i128 << k);
        if lo >= self.keep.0 && hi <= self.keep.1 {
            Side::Kept
        } else if hi <= self.keep.0 || lo >= self.keep.1 {
            Side::Removed
        } else {
            Side::Across
        }
    }

    /// Whether the gray node `id` at `(path, k)`, which the plane crosses, has a
    /// black voxel on the kept side: a descent through the nodes the plane crosses.
    fn any_kept(&self, cur: &mut T::Cursor<'b>, id: NodeId, path: u64, k: u8) -> bool {
        let key = (id.src, id.node);
        let memo = k >= MEMO_LOG2;
        if memo {
            if let Some(&b) = self
                .kept
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .get(&key)
            {
                return b;
            }
        }
        let mut found = false;
        for label in 0..8u8 {
            if !cur.maybe(id, label) {
                continue;
            }
            let cpath = (path << 3) | u64::from(label);
            let side = self.side(cpath, k - 1);
            if side == Side::Removed {
                continue;
            }
            found = match cur.kid(id, label, cpath, k - 1) {
                Kid::White => false,
                Kid::Black => true,
                // A gray node holds a black voxel; one the plane crosses may hold
                // them all on the removed side.
                Kid::Gray(c) => side == Side::Kept || self.any_kept(cur, c, cpath, k - 1),
            };
            if found {
                break;
            }
        }
        if memo {
            self.kept
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .insert(key, found);
        }
        found
    }
}

/// A reader of a [`Clipped`] tree's nodes: the inner tree's reader.
pub(crate) struct ClipCursor<'a, 'b, T: Trace + ?Sized + 'b> {
    t: &'a Clipped<'b, T>,
    cur: T::Cursor<'b>,
}

impl<'b, T: Trace + ?Sized> Nodes for ClipCursor<'_, 'b, T> {
    fn maybe(&mut self, id: NodeId, label: u8) -> bool {
        // The crop removes only: the inner tree's answer stays an upper bound.
        id == SPLIT || self.cur.maybe(id, label)
    }

    fn kid(&mut self, id: NodeId, label: u8, path: u64, k: u8) -> Kid {
        let side = self.t.side(path, k);
        if side == Side::Removed {
            return Kid::White;
        }
        let inner = if id == SPLIT {
            Kid::Black
        } else {
            self.cur.kid(id, label, path, k)
        };
        match (side, inner) {
            (Side::Kept, kid) | (_, kid @ Kid::White) => kid,
            (_, Kid::Black) => Kid::Gray(SPLIT),
            (_, Kid::Gray(c)) => {
                if self.t.any_kept(&mut self.cur, c, path, k) {
                    Kid::Gray(c)
                } else {
                    Kid::White
                }
            }
        }
    }
}

impl<'b, T: Trace + ?Sized> Trace for Clipped<'b, T> {
    type Cursor<'a>
        = ClipCursor<'a, 'b, T>
    where
        Self: 'a;

    fn cursor(&self) -> ClipCursor<'_, 'b, T> {
        ClipCursor {
            t: self,
            cur: self.inner.cursor(),
        }
    }

    fn space(&self) -> (u8, [i64; 3]) {
        (self.depth, self.origin)
    }

    fn root(&self) -> (Root, NodeId) {
        self.root
    }

    fn bbox(&self) -> Option<([i64; 3], [i64; 3])> {
        self.bbox
    }
}
