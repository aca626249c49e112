//! Step 3 applied: the vertices of the mesh, one per lattice point and group,
//! numbered as they are first met (corners first, rectangle by rectangle, then the
//! pinch points in the polygons' order), in arrays indexed by the lattice's
//! distinct points.

use super::groups::is_pinch_point;
use super::lattice::Lattice;
use super::rects::Rect;
use crate::Voxel;

/// No id yet.
const NONE: u32 = u32::MAX;

pub(super) struct Vertices<'l> {
    lattice: &'l Lattice,
    /// Per distinct point, where its groups' ids start in `ids`.
    slot: Vec<usize>,
    /// Per group of each distinct point, its vertex id, or [`NONE`].
    ids: Vec<u32>,
    /// Per distinct point, whether it is a corner of some rectangle.
    corner: Vec<bool>,
    /// Per vertex id: its lattice point and group.
    pub(super) keys: Vec<(Voxel, i8)>,
    /// Per vertex id: the groups of the 12 faces at its point.
    pub(super) rows: Vec<[i8; 12]>,
}

impl<'l> Vertices<'l> {
    pub(super) fn new(lattice: &'l Lattice) -> Self {
        let mut slot = Vec::with_capacity(lattice.groups.len());
        let mut n = 0usize;
        for row in &lattice.groups {
            slot.push(n);
            n += row.iter().map(|&g| g + 1).max().unwrap_or(0) as usize;
        }
        Self {
            lattice,
            slot,
            ids: vec![NONE; n],
            corner: vec![false; lattice.groups.len()],
            keys: Vec::new(),
            rows: Vec::new(),
        }
    }

    /// The vertex group at `p` (distinct point `at`) of the face of `r` that
    /// touches `p`.
    pub(super) fn group(&self, r: &Rect, p: Voxel, at: u32) -> i8 {
        let (u, v) = ((r.a + 1) % 3, (r.a + 2) % 3);
        let du = usize::from(p[u] < r.u1);
        let dv = usize::from(p[v] < r.v1);
        let g = self.lattice.groups[at as usize][4 * r.a + du + 2 * dv];
        debug_assert!(g >= 0, "rectangle face at {p:?} is not boundary");
        g
    }

    /// The id of group `g` at `p` (distinct point `at`), given now if it has none.
    pub(super) fn id(&mut self, at: u32, p: Voxel, g: i8) -> u32 {
        let s = self.slot[at as usize] + g as usize;
        if self.ids[s] == NONE {
            self.ids[s] = self.keys.len() as u32;
            self.keys.push((p, g));
            self.rows.push(self.lattice.groups[at as usize]);
        }
        self.ids[s]
    }

    /// The id of group `g` at distinct point `at`, if it has one.
    pub(super) fn existing(&self, at: u32, g: i8) -> Option<u32> {
        let id = self.ids[self.slot[at as usize] + g as usize];
        (id != NONE).then_some(id)
    }

    /// Records that distinct point `at` is a rectangle's corner.
    pub(super) fn mark_corner(&mut self, at: u32) {
        self.corner[at as usize] = true;
    }

    /// Whether distinct point `at` is a rectangle's corner.
    pub(super) fn is_corner(&self, at: u32) -> bool {
        self.corner[at as usize]
    }

    /// Whether an edge at distinct point `at` has four boundary faces: such points
    /// must be vertices of every rectangle whose side passes through them.
    pub(super) fn is_pinch_point(&self, at: u32) -> bool {
        is_pinch_point(self.lattice.config[at as usize])
    }
}

pub(super) fn point(r: &Rect, pu: i64, pv: i64) -> Voxel {
    let mut p = [0i64; 3];
    p[r.a] = r.c;
    p[(r.a + 1) % 3] = pu;
    p[(r.a + 2) % 3] = pv;
    p
}
