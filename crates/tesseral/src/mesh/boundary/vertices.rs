//! Step 3 applied: the vertices of the mesh, one per lattice point and group,
//! numbered as they are first met.

use rustc_hash::FxHashMap;

use super::groups::{group_table, is_pinch_edge, joined_by_black};
use super::rects::Rect;
use crate::linear::LinearOctree;
use crate::Voxel;

pub(super) struct Vertices<'t> {
    pub(super) tree: &'t LinearOctree,
    pub(super) config: FxHashMap<Voxel, u8>,
    pub(super) groups: FxHashMap<Voxel, [i8; 12]>,
    pub(super) ids: FxHashMap<(Voxel, i8), u32>,
    pub(super) keys: Vec<(Voxel, i8)>,
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
    pub(super) fn is_pinch_point(&mut self, p: Voxel) -> bool {
        let cfg = usize::from(self.config(p));
        (0..3).any(|e| (0..2).any(|s| is_pinch_edge(cfg, e, s)))
    }

    /// The vertex group at `p` of the face of `r` that touches `p`.
    pub(super) fn group(&mut self, r: &Rect, p: Voxel) -> i8 {
        let (u, v) = ((r.a + 1) % 3, (r.a + 2) % 3);
        let du = usize::from(p[u] < r.u1);
        let dv = usize::from(p[v] < r.v1);
        let g = self.groups(p)[4 * r.a + du + 2 * dv];
        debug_assert!(g >= 0, "rectangle face at {p:?} is not boundary");
        g
    }

    pub(super) fn id(&mut self, key: (Voxel, i8)) -> u32 {
        let next = self.keys.len() as u32;
        *self.ids.entry(key).or_insert_with(|| {
            self.keys.push(key);
            next
        })
    }
}

pub(super) fn point(r: &Rect, pu: i64, pv: i64) -> Voxel {
    let mut p = [0i64; 3];
    p[r.a] = r.c;
    p[(r.a + 1) % 3] = pu;
    p[(r.a + 2) % 3] = pv;
    p
}
