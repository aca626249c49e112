//! The mesher's steps 3 and 4 as they were before the lattice (`lattice.rs`): every
//! point's colouring, groups and vertex id in hash maps, filled as the rectangles
//! are walked one after another. Obviously right and slow; the tests ask the
//! mesher for the same mesh, vertex for vertex.

use rustc_hash::{FxHashMap, FxHashSet};

use super::groups::{group_table, is_pinch_edge, joined_by_black};
use super::rects::{rectangles, Rect};
use super::squares::boundary_squares;
use super::triangulate::{Built, Fans};
use super::vertices::point;
use crate::linear::LinearOctree;
use crate::Voxel;

struct Vertices<'t> {
    tree: &'t LinearOctree,
    config: FxHashMap<Voxel, u8>,
    groups: FxHashMap<Voxel, [i8; 12]>,
    ids: FxHashMap<(Voxel, i8), u32>,
    keys: Vec<(Voxel, i8)>,
}

impl Vertices<'_> {
    fn config(&mut self, p: Voxel) -> u8 {
        let tree = self.tree;
        // Bit o: voxel p − 1 + (o & 1, o >> 1 & 1, o >> 2 & 1) is black.
        *self
            .config
            .entry(p)
            .or_insert_with(|| tree.octet(p.map(|c| c - 1)))
    }

    /// The vertex groups of the 12 faces at `p`. An edge with four boundary faces
    /// pairs them by black voxel, unless that pinches the edge at both of its ends,
    /// in which case it pairs them by white voxel (which then cannot pinch at either
    /// end), so that no two triangles' edges share both vertices twice.
    fn groups(&mut self, p: Voxel) -> [i8; 12] {
        if let Some(g) = self.groups.get(&p) {
            return *g;
        }
        let cfg = usize::from(self.config(p));
        let mut mask = 0usize;
        for e in 0..3 {
            for s in 0..2 {
                if is_pinch_edge(cfg, e, s) && joined_by_black(cfg, e, s) {
                    let mut q = p;
                    q[e] += if s == 1 { 1 } else { -1 };
                    let qcfg = usize::from(self.config(q));
                    if joined_by_black(qcfg, e, 1 - s) {
                        mask |= 1 << (2 * e + s);
                    }
                }
            }
        }
        let g = group_table()[cfg][mask];
        self.groups.insert(p, g);
        g
    }

    /// Whether an edge at `p` has four boundary faces: such points must be vertices
    /// of every rectangle whose side passes through them.
    fn is_pinch_point(&mut self, p: Voxel) -> bool {
        let cfg = usize::from(self.config(p));
        (0..3).any(|e| (0..2).any(|s| is_pinch_edge(cfg, e, s)))
    }

    /// The vertex group at `p` of the face of `r` that touches `p`.
    fn group(&mut self, r: &Rect, p: Voxel) -> i8 {
        let (u, v) = ((r.a + 1) % 3, (r.a + 2) % 3);
        let du = usize::from(p[u] < r.u1);
        let dv = usize::from(p[v] < r.v1);
        let g = self.groups(p)[4 * r.a + du + 2 * dv];
        debug_assert!(g >= 0, "rectangle face at {p:?} is not boundary");
        g
    }

    fn id(&mut self, key: (Voxel, i8)) -> u32 {
        let next = self.keys.len() as u32;
        *self.ids.entry(key).or_insert_with(|| {
            self.keys.push(key);
            next
        })
    }
}

/// The mesh, its vertices' keys, and each key's row of groups, as the hash maps
/// gave them.
pub(super) fn build(tree: &LinearOctree, merge: bool) -> Built {
    let squares = boundary_squares(tree);
    let rects = rectangles(&squares, merge);
    // The squares are larger than the rectangles they became: freed before the
    // vertices' maps grow.
    drop(squares);
    let mut verts = Vertices {
        tree,
        config: FxHashMap::default(),
        groups: FxHashMap::default(),
        ids: FxHashMap::default(),
        keys: Vec::new(),
    };
    // Corners first: they are the vertices every side must include. Each
    // rectangle's four corner ids are kept for its polygon below.
    let mut corners: FxHashSet<Voxel> = FxHashSet::default();
    let mut corner_ids: Vec<[u32; 4]> = Vec::with_capacity(rects.len());
    for r in &rects {
        let mut ids = [0u32; 4];
        for (k, (pu, pv)) in [(r.u0, r.v0), (r.u1, r.v0), (r.u1, r.v1), (r.u0, r.v1)]
            .into_iter()
            .enumerate()
        {
            let p = point(r, pu, pv);
            let g = verts.group(r, p);
            ids[k] = verts.id((p, g));
            corners.insert(p);
        }
        corner_ids.push(ids);
    }
    let mut fans = Fans::with_capacity(rects.len());
    let mut poly: Vec<u32> = Vec::new();
    for (r, ids) in rects.iter().zip(&corner_ids) {
        poly.clear();
        // Counter-clockwise seen from +a: along v0, up u1, back along v1, down u0;
        // each side its first corner, then the points inside it that are vertices
        // (pinch points, and other rectangles' corners of the same group).
        let mut side =
            |corner: u32, inside: &mut dyn Iterator<Item = (i64, i64)>, verts: &mut Vertices| {
                poly.push(corner);
                for (pu, pv) in inside {
                    let p = point(r, pu, pv);
                    if verts.is_pinch_point(p) {
                        let g = verts.group(r, p);
                        poly.push(verts.id((p, g)));
                    } else if corners.contains(&p) {
                        let g = verts.group(r, p);
                        if let Some(&id) = verts.ids.get(&(p, g)) {
                            poly.push(id);
                        }
                    }
                }
            };
        side(ids[0], &mut (r.u0 + 1..r.u1).map(|u| (u, r.v0)), &mut verts);
        side(ids[1], &mut (r.v0 + 1..r.v1).map(|v| (r.u1, v)), &mut verts);
        side(
            ids[2],
            &mut (r.u0 + 1..r.u1).rev().map(|u| (u, r.v1)),
            &mut verts,
        );
        side(
            ids[3],
            &mut (r.v0 + 1..r.v1).rev().map(|v| (r.u0, v)),
            &mut verts,
        );
        fans.add(r, &mut poly);
    }
    // Only the keys and groups are given back: the rest goes before the positions
    // are made.
    drop((corners, corner_ids));
    let Vertices { keys, groups, .. } = verts;
    let rows = keys.iter().map(|(p, _)| groups[p]).collect();
    (fans.into_mesh(&keys), keys, rows)
}
