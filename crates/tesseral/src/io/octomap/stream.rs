//! Writing OctoMap trees from a stream of pieces in tesseral order, with no tree
//! in memory: [`Merger`] joins eight sibling pieces of one class into their parent
//! (OctoMap prunes such nodes), and [`Encoder`] writes each node's bytes in
//! preorder as the pieces arrive, keeping only the path of open nodes (at most 16)
//! and filling in an inner node's bytes when it closes.
//!
//! A map (`occupancy`) streams its blocks straight into these, in key order; a
//! model's pieces come from its layers ([`super::write`]).

use crate::linear::Leaf;

use super::OCTOMAP_DEPTH;

/// OctoMap's "no colour set" (white); its inner nodes average only set colours.
pub(crate) const UNSET_RGB: [u8; 3] = [255, 255, 255];

/// A cell of one state, log-odds and colour, in OctoMap's key space (a leaf of the
/// depth-16 tree from key 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Piece {
    pub leaf: Leaf,
    pub occupied: bool,
    pub value: f32,
    pub rgb: [u8; 3],
}

impl Piece {
    /// Whether a `.bt` writes `self` and `other` alike (the same state).
    pub fn same_state(&self, other: &Piece) -> bool {
        self.occupied == other.occupied
    }

    /// Whether an `.ot` writes `self` and `other` alike: the same state, log-odds
    /// (bit for bit) and colour, as OctoMap's node comparison when it prunes.
    pub fn same_node(&self, other: &Piece) -> bool {
        self.occupied == other.occupied
            && self.value.to_bits() == other.value.to_bits()
            && self.rgb == other.rgb
    }
}

/// Joins pieces given in tesseral order (disjoint) into maximal ones: eight
/// siblings of one class (by `same`) become their parent, repeatedly.
///
/// The pieces held back are those that may still join: groups of consecutive
/// siblings of one class, each group starting at its parent's first child, and each
/// lying (with the groups after it) before the next child of the group before it.
/// A piece that breaks the pattern sends them all on, in order.
pub(crate) struct Merger<F> {
    held: Vec<Piece>,
    same: F,
}

impl<F: Fn(&Piece, &Piece) -> bool> Merger<F> {
    pub fn new(same: F) -> Self {
        Merger {
            held: Vec::with_capacity(8 * usize::from(OCTOMAP_DEPTH)),
            same,
        }
    }

    /// Takes the next piece (after every piece given before), sending on to `out`
    /// the pieces that can no longer join.
    pub fn push(&mut self, mut p: Piece, out: &mut impl FnMut(Piece)) {
        loop {
            let k = p.leaf.size_log2();
            if k >= OCTOMAP_DEPTH {
                self.flush(out);
                out(p);
                return;
            }
            let child = (p.leaf.code() >> (3 * u32::from(k))) & 7;
            let top = self.held.last();
            if child == 0 {
                // A first child starts a group, after the groups waiting for its cell.
                if top.is_some_and(|t| t.leaf.end() != p.leaf.code() || t.leaf.size_log2() <= k) {
                    self.flush(out);
                }
                self.held.push(p);
                return;
            }
            let follows = top.is_some_and(|t| {
                t.leaf.size_log2() == k && t.leaf.end() == p.leaf.code() && (self.same)(t, &p)
            });
            if !follows {
                self.flush(out);
                out(p);
                return;
            }
            if child < 7 {
                self.held.push(p);
                return;
            }
            // The eighth sibling: the group is the parent's seven other children.
            let first = self.held[self.held.len() - 7];
            self.held.truncate(self.held.len() - 7);
            p = Piece {
                leaf: Leaf::new(first.leaf.code(), k + 1),
                ..first
            };
        }
    }

    /// Sends on every piece held back (after the last piece).
    pub fn flush(&mut self, out: &mut impl FnMut(Piece)) {
        self.held.drain(..).for_each(out);
    }
}

/// The two OctoMap streams.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    /// `.bt`: two bits a child per inner node.
    Bt,
    /// `.ot`: log-odds (and colour) per node, then its children's mask.
    Ot { colour: bool },
}

/// An inner node written but not closed: where its bytes are, and what its
/// children gave so far.
struct Open {
    leaf: Leaf,
    at: usize,
    /// `.bt`: the children's two bits each. `.ot`: the children's mask.
    bits: u16,
    max: f32,
    sum: [u32; 3],
    set: u32,
}

/// Writes the data section of a `.bt` or `.ot` from maximal pieces in tesseral
/// order (as [`Merger`] gives them), node by node in preorder.
pub(crate) struct Encoder {
    kind: Kind,
    out: Vec<u8>,
    nodes: u64,
    open: Vec<Open>,
}

impl Encoder {
    pub fn new(kind: Kind) -> Self {
        Encoder {
            kind,
            out: Vec::new(),
            nodes: 0,
            open: Vec::with_capacity(usize::from(OCTOMAP_DEPTH)),
        }
    }

    /// Bytes of an `.ot` node before its mask: log-odds, and colour in a
    /// `ColorOcTree`.
    fn ot_data(&self) -> usize {
        match self.kind {
            Kind::Ot { colour: true } => 7,
            _ => 4,
        }
    }

    /// Writes the next piece.
    pub fn push(&mut self, p: Piece) {
        let k = p.leaf.size_log2();
        if self.nodes == 0 {
            if k >= OCTOMAP_DEPTH && self.kind != Kind::Bt {
                // The whole key cube known alike: the root is a leaf.
                self.nodes = 1;
                self.write_ot_leaf(&p);
                return;
            }
            self.open_node(Leaf::new(0, OCTOMAP_DEPTH));
        }
        if k >= OCTOMAP_DEPTH {
            // `.bt` has no leaf root: eight leaf children.
            for c in 0..8 {
                let child = Leaf::new(c << (3 * u32::from(k - 1)), k - 1);
                self.push(Piece { leaf: child, ..p });
            }
            return;
        }
        while let Some(top) = self.open.last() {
            if top.leaf.contains_code(p.leaf.code()) {
                break;
            }
            self.close();
        }
        let Some(mut parent) = self.open.last().map(|o| o.leaf.size_log2()) else {
            unreachable!("the root contains every piece of the key cube");
        };
        while parent - 1 > k {
            let shift = 3 * u32::from(parent - 1);
            let child = Leaf::new(p.leaf.code() >> shift << shift, parent - 1);
            self.mark_child(child, 0b11);
            self.open_node(child);
            parent -= 1;
        }
        match self.kind {
            Kind::Bt => self.mark_child(p.leaf, if p.occupied { 0b10 } else { 0b01 }),
            Kind::Ot { .. } => {
                self.mark_child(p.leaf, 0);
                self.write_ot_leaf(&p);
                self.give_parent(p.value, p.rgb);
            }
        }
        self.nodes += 1;
    }

    /// Records child `c` of the innermost open node: two bits in a `.bt` (`bt`),
    /// the mask's bit in an `.ot`.
    fn mark_child(&mut self, c: Leaf, bt: u16) {
        let i = (c.code() >> (3 * u32::from(c.size_log2()))) & 7;
        let kind = self.kind;
        if let Some(o) = self.open.last_mut() {
            o.bits |= match kind {
                Kind::Bt => bt << (2 * i),
                Kind::Ot { .. } => 1 << i,
            };
        }
    }

    /// Opens inner node `leaf`: room for its bytes, filled in when it closes.
    fn open_node(&mut self, leaf: Leaf) {
        self.nodes += 1;
        let at = self.out.len();
        let bytes = match self.kind {
            Kind::Bt => 2,
            Kind::Ot { .. } => self.ot_data() + 1,
        };
        self.out.resize(at + bytes, 0);
        self.open.push(Open {
            leaf,
            at,
            bits: 0,
            max: f32::NEG_INFINITY,
            sum: [0; 3],
            set: 0,
        });
    }

    /// Writes an `.ot` leaf: its data and an empty mask.
    fn write_ot_leaf(&mut self, p: &Piece) {
        self.out.extend_from_slice(&p.value.to_le_bytes());
        if self.kind == (Kind::Ot { colour: true }) {
            self.out.extend_from_slice(&p.rgb);
        }
        self.out.push(0);
    }

    /// Adds a child's log-odds and colour to the innermost open node (`.ot`): its
    /// value is the children's maximum, as OctoMap's `updateInnerOccupancy`, its
    /// colour the mean of the set ones, as `getAverageChildColor`.
    fn give_parent(&mut self, value: f32, rgb: [u8; 3]) {
        if let Some(o) = self.open.last_mut() {
            o.max = o.max.max(value);
            if rgb != UNSET_RGB {
                for (s, c) in o.sum.iter_mut().zip(rgb) {
                    *s += u32::from(c);
                }
                o.set += 1;
            }
        }
    }

    /// Closes the innermost open node: fills in its bytes, and in an `.ot` hands its
    /// value and colour to its parent.
    fn close(&mut self) {
        let Some(o) = self.open.pop() else { return };
        match self.kind {
            Kind::Bt => self.out[o.at..o.at + 2].copy_from_slice(&o.bits.to_le_bytes()),
            Kind::Ot { colour } => {
                let rgb = if o.set == 0 {
                    UNSET_RGB
                } else {
                    o.sum.map(|s| (s / o.set) as u8)
                };
                self.out[o.at..o.at + 4].copy_from_slice(&o.max.to_le_bytes());
                if colour {
                    self.out[o.at + 4..o.at + 7].copy_from_slice(&rgb);
                }
                let mask_at = o.at + self.ot_data();
                self.out[mask_at] = o.bits as u8;
                self.give_parent(o.max, rgb);
            }
        }
    }

    /// The data section and its node count, every node closed.
    pub fn finish(mut self) -> (Vec<u8>, u64) {
        while !self.open.is_empty() {
            self.close();
        }
        (self.out, self.nodes)
    }
}

/// A [`Merger`] into an [`Encoder`]: takes pieces in tesseral order, not
/// necessarily maximal, and joins them as OctoMap prunes (by state for `.bt`; by
/// state, log-odds and colour for `.ot`) before writing them.
pub(crate) struct Writer {
    merger: Merger<fn(&Piece, &Piece) -> bool>,
    encoder: Encoder,
}

impl Writer {
    pub fn new(kind: Kind) -> Self {
        let same = if kind == Kind::Bt {
            Piece::same_state
        } else {
            Piece::same_node
        };
        Writer {
            merger: Merger::new(same),
            encoder: Encoder::new(kind),
        }
    }

    /// Takes the next piece (after every piece given before).
    pub fn push(&mut self, p: Piece) {
        let encoder = &mut self.encoder;
        self.merger.push(p, &mut |q| encoder.push(q));
    }

    /// The data section and its node count.
    pub fn finish(mut self) -> (Vec<u8>, u64) {
        let encoder = &mut self.encoder;
        self.merger.flush(&mut |q| encoder.push(q));
        self.encoder.finish()
    }
}

/// The data section of a `kind` stream of `pieces` (see [`Writer`]), and its node
/// count.
pub(crate) fn encode_pieces(kind: Kind, pieces: impl IntoIterator<Item = Piece>) -> (Vec<u8>, u64) {
    let mut w = Writer::new(kind);
    pieces.into_iter().for_each(|p| w.push(p));
    w.finish()
}
