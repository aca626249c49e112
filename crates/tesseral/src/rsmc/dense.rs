//! The dense-array lattice: the baseline and test oracle for RS/MC.

use super::{Direction, Face, Lattice, Neighbourhood};
use crate::Voxel;

/// Cells of margin kept white around every black voxel, so that the 3×3×3 block of
/// any voxel next to the surface lies inside the box.
const MARGIN: i64 = 2;
/// The largest box, in cells (5 bytes each: 20 GiB). Beyond it `insert` panics.
pub const MAX_CELLS: u64 = 1 << 32;
/// No face index.
const NONE: u32 = u32::MAX;

/// A black set stored in a dense box of cells that follows the set around, with the
/// face list of the dynamic octree contract. The baseline of the RS/MC benchmarks
/// (Libes §6: "prior implementations used a fixed-size array") and the oracle of
/// the octree backend.
///
/// Memory is O(box volume): 5 bytes per cell of the bounding box (plus margin and
/// slack), plus 24 bytes per black voxel and 32 per face. `insert`, `remove`,
/// `contains` and `neighbourhood` are O(1), except when the box must move or grow,
/// which costs O(box volume) and happens rarely (the box doubles). `insert` panics
/// when the box would exceed [`MAX_CELLS`] cells.
///
/// ```
/// use tesseral::rsmc::{DenseLattice, Lattice};
/// let mut l = DenseLattice::new();
/// assert!(l.insert([0, 0, 0]));
/// assert!(l.insert([1, 0, 0]));
/// assert_eq!(l.face_count(), 10);
/// assert_eq!(l.voxel_count(), 2);
/// ```
#[derive(Clone, Debug)]
pub struct DenseLattice {
    origin: Voxel,
    dims: [i64; 3],
    /// 0 = white; otherwise 1 + the slot of the black voxel.
    cells: Vec<u32>,
    /// 1 = black: the occupancy alone, four times denser than `cells`, for the
    /// 3×3×3 reads of every step.
    occ: Vec<u8>,
    /// For each black voxel's slot: the index in `faces` of its face in each
    /// direction, or `NONE`.
    slots: Vec<[u32; 6]>,
    free_slots: Vec<u32>,
    faces: Vec<Face>,
    count: u64,
}

impl Default for DenseLattice {
    fn default() -> Self {
        Self::new()
    }
}

impl DenseLattice {
    /// An empty lattice with a small box around the origin.
    #[must_use]
    pub fn new() -> Self {
        let dims = [8, 8, 8];
        DenseLattice {
            origin: [-4, -4, -4],
            dims,
            cells: vec![0; 512],
            occ: vec![0; 512],
            slots: Vec::new(),
            free_slots: Vec::new(),
            faces: Vec::new(),
            count: 0,
        }
    }

    /// The box: its lowest corner and its size per axis.
    #[must_use]
    pub fn bounds(&self) -> (Voxel, [i64; 3]) {
        (self.origin, self.dims)
    }

    /// Heap bytes held (cells, slots and faces), for memory reports.
    #[must_use]
    pub fn heap_bytes(&self) -> usize {
        self.cells.capacity() * 5
            + self.slots.capacity() * 24
            + self.free_slots.capacity() * 4
            + self.faces.capacity() * std::mem::size_of::<Face>()
    }

    #[inline]
    fn index(&self, v: Voxel) -> Option<usize> {
        let x = v[0].wrapping_sub(self.origin[0]);
        let y = v[1].wrapping_sub(self.origin[1]);
        let z = v[2].wrapping_sub(self.origin[2]);
        if (x as u64) < self.dims[0] as u64
            && (y as u64) < self.dims[1] as u64
            && (z as u64) < self.dims[2] as u64
        {
            Some((x + self.dims[0] * (y + self.dims[1] * z)) as usize)
        } else {
            None
        }
    }

    #[inline]
    fn slot(&self, v: Voxel) -> Option<usize> {
        self.index(v)
            .and_then(|i| self.cells[i].checked_sub(1))
            .map(|s| s as usize)
    }

    /// Whether `v` lies at least `MARGIN` cells inside the box.
    #[inline]
    fn well_inside(&self, v: Voxel) -> bool {
        (0..3).all(|a| {
            v[a] >= self.origin[a] + MARGIN && v[a] < self.origin[a] + self.dims[a] - MARGIN
        })
    }

    /// Moves and grows the box so that it holds every black voxel and `extra` with
    /// margin, with slack for growth. O(box volume).
    ///
    /// # Panics
    /// When the box would need more than [`MAX_CELLS`] cells: the dense baseline is
    /// for comparisons, the octree for unbounded runs.
    fn refit(&mut self, extra: Voxel) {
        let mut lo = extra;
        let mut hi = extra;
        for i in 0..self.cells.len() {
            if self.cells[i] != 0 {
                let v = self.voxel_at(i);
                for a in 0..3 {
                    lo[a] = lo[a].min(v[a]);
                    hi[a] = hi[a].max(v[a]);
                }
            }
        }
        let mut origin = [0; 3];
        let mut dims = [0; 3];
        for a in 0..3 {
            let extent = hi[a] - lo[a] + 1 + 2 * MARGIN;
            // Keep the old size when the set only drifted; double when it is cramped.
            let size = if extent * 2 <= self.dims[a] {
                self.dims[a]
            } else {
                (extent * 2).max(8)
            };
            dims[a] = size;
            origin[a] = lo[a] - (size - (hi[a] - lo[a] + 1)) / 2;
        }
        let total = dims
            .iter()
            .try_fold(1u128, |t, &d| t.checked_mul(d as u128));
        let total = match total {
            Some(t) if t <= MAX_CELLS as u128 => t as usize,
            _ => panic!("DenseLattice: a box of {dims:?} cells exceeds {MAX_CELLS} cells"),
        };
        let mut cells = vec![0u32; total];
        let mut occ = vec![0u8; total];
        for i in 0..self.cells.len() {
            if self.cells[i] != 0 {
                let v = self.voxel_at(i);
                let x = v[0] - origin[0];
                let y = v[1] - origin[1];
                let z = v[2] - origin[2];
                let j = (x + dims[0] * (y + dims[1] * z)) as usize;
                cells[j] = self.cells[i];
                occ[j] = 1;
            }
        }
        self.cells = cells;
        self.occ = occ;
        self.origin = origin;
        self.dims = dims;
    }

    fn voxel_at(&self, i: usize) -> Voxel {
        let i = i as i64;
        let x = i % self.dims[0];
        let y = (i / self.dims[0]) % self.dims[1];
        let z = i / (self.dims[0] * self.dims[1]);
        [x + self.origin[0], y + self.origin[1], z + self.origin[2]]
    }

    #[inline]
    fn push_face(&mut self, slot: usize, v: Voxel, dir: Direction) {
        self.slots[slot][dir.index()] = self.faces.len() as u32;
        self.faces.push(Face { voxel: v, dir });
    }

    #[inline]
    fn remove_face(&mut self, slot: usize, dir: Direction) {
        let i = self.slots[slot][dir.index()] as usize;
        debug_assert!(i != NONE as usize);
        self.slots[slot][dir.index()] = NONE;
        self.faces.swap_remove(i);
        if i < self.faces.len() {
            let moved = self.faces[i];
            let s = self.slot(moved.voxel).expect("face of a black voxel");
            self.slots[s][moved.dir.index()] = i as u32;
        }
    }

    /// Checks every invariant: the face list holds exactly the exposed faces, the
    /// back-pointers agree, the voxel count and the margin hold. O(box volume).
    ///
    /// # Panics
    /// When an invariant is broken.
    pub fn assert_valid(&self) {
        let mut count = 0u64;
        let mut used = vec![false; self.slots.len()];
        let mut exposed = 0usize;
        for i in 0..self.cells.len() {
            if self.cells[i] == 0 {
                assert_eq!(self.occ[i], 0, "occupancy of a white cell");
                continue;
            }
            count += 1;
            let v = self.voxel_at(i);
            assert!(self.well_inside(v), "voxel {v:?} within the margin");
            assert_eq!(self.occ[i], 1, "occupancy of {v:?}");
            let s = (self.cells[i] - 1) as usize;
            assert!(!used[s], "slot {s} used twice");
            used[s] = true;
            for d in Direction::ALL {
                let n = d.step(v);
                let fi = self.slots[s][d.index()];
                if self.contains(n) {
                    assert_eq!(fi, NONE, "hidden face {v:?} dir {d:?} is listed");
                } else {
                    exposed += 1;
                    assert!((fi as usize) < self.faces.len(), "face {v:?} {d:?} missing");
                    assert_eq!(self.faces[fi as usize], Face { voxel: v, dir: d });
                }
            }
        }
        assert_eq!(count, self.count, "voxel count");
        assert_eq!(exposed, self.faces.len(), "face count");
        for &f in &self.free_slots {
            assert!(!used[f as usize], "free slot {f} in use");
        }
    }
}

impl Lattice for DenseLattice {
    fn empty() -> Self {
        Self::new()
    }

    fn insert(&mut self, v: Voxel) -> bool {
        if !self.well_inside(v) {
            if self.contains(v) {
                return false;
            }
            self.refit(v);
        }
        let i = self.index(v).expect("inside after refit");
        if self.cells[i] != 0 {
            return false;
        }
        let slot = match self.free_slots.pop() {
            Some(s) => {
                self.slots[s as usize] = [NONE; 6];
                s as usize
            }
            None => {
                self.slots.push([NONE; 6]);
                self.slots.len() - 1
            }
        };
        self.cells[i] = slot as u32 + 1;
        self.occ[i] = 1;
        self.count += 1;
        for d in Direction::ALL {
            let n = d.step(v);
            match self.slot(n) {
                Some(ns) => self.remove_face(ns, d.opposite()),
                None => self.push_face(slot, v, d),
            }
        }
        true
    }

    fn remove(&mut self, v: Voxel) -> bool {
        let Some(i) = self.index(v) else { return false };
        if self.cells[i] == 0 {
            return false;
        }
        let slot = (self.cells[i] - 1) as usize;
        for d in Direction::ALL {
            let n = d.step(v);
            match self.slot(n) {
                Some(ns) => self.push_face(ns, n, d.opposite()),
                None => self.remove_face(slot, d),
            }
        }
        self.cells[i] = 0;
        self.occ[i] = 0;
        self.free_slots.push(slot as u32);
        self.count -= 1;
        true
    }

    #[inline]
    fn contains(&self, v: Voxel) -> bool {
        self.index(v).is_some_and(|i| self.occ[i] != 0)
    }

    fn voxel_count(&self) -> u64 {
        self.count
    }

    #[inline]
    fn face_count(&self) -> usize {
        self.faces.len()
    }

    #[inline]
    fn face(&self, i: usize) -> Face {
        self.faces[i]
    }

    #[inline]
    fn neighbourhood(&self, v: Voxel) -> Neighbourhood {
        let lo = [v[0] - 1, v[1] - 1, v[2] - 1];
        let hi = [v[0] + 1, v[1] + 1, v[2] + 1];
        match (self.index(lo), self.index(hi)) {
            (Some(base), Some(_)) => {
                let sx = 1usize;
                let sy = self.dims[0] as usize;
                let sz = (self.dims[0] * self.dims[1]) as usize;
                let occ = &self.occ[base..=base + 2 * (sx + sy + sz)];
                let mut bits = 0u32;
                let mut b = 0;
                for z in 0..3 {
                    for y in 0..3 {
                        let row = z * sz + y * sy;
                        let three = u32::from(occ[row])
                            | (u32::from(occ[row + 1]) << 1)
                            | (u32::from(occ[row + 2]) << 2);
                        bits |= three << b;
                        b += 3;
                    }
                }
                Neighbourhood::from_bits(bits)
            }
            _ => {
                let mut bits = 0u32;
                for b in 0..27i64 {
                    let w = [v[0] + b % 3 - 1, v[1] + (b / 3) % 3 - 1, v[2] + b / 9 - 1];
                    bits |= u32::from(self.contains(w)) << b;
                }
                Neighbourhood::from_bits(bits)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use std::collections::HashSet;

    #[test]
    fn random_ops_match_hash_set_model() {
        let seed = 0xd3_45e;
        println!("seed {seed:#x}");
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
        let mut l = DenseLattice::new();
        let mut model: HashSet<Voxel> = HashSet::new();
        for i in 0..3000 {
            let r = if i < 1500 { 4 } else { 12 };
            let v = [
                rng.random_range(-r..=r),
                rng.random_range(-r..=r) + i / 300,
                rng.random_range(-r..=r),
            ];
            if rng.random_bool(0.6) {
                assert_eq!(l.insert(v), model.insert(v), "insert {v:?} op {i}");
            } else {
                assert_eq!(l.remove(v), model.remove(&v), "remove {v:?} op {i}");
            }
            if i % 97 == 0 {
                l.assert_valid();
            }
            let q = [
                rng.random_range(-r..=r),
                rng.random_range(-r..=r),
                rng.random_range(-r..=r),
            ];
            let mut expect = 0u32;
            for b in 0..27i64 {
                let w = [q[0] + b % 3 - 1, q[1] + (b / 3) % 3 - 1, q[2] + b / 9 - 1];
                expect |= u32::from(model.contains(&w)) << b;
            }
            assert_eq!(
                l.neighbourhood(q).bits(),
                expect,
                "neighbourhood {q:?} op {i}"
            );
        }
        l.assert_valid();
        assert_eq!(l.voxel_count(), model.len() as u64);
    }

    #[test]
    fn face_order_rule_by_hand() {
        let mut l = DenseLattice::new();
        l.insert([0, 0, 0]);
        let dirs: Vec<u8> = (0..6).map(|i| l.face(i).dir as u8).collect();
        assert_eq!(dirs, vec![0, 1, 2, 3, 4, 5]);
        // Insert +x: dir 0 of the new voxel hits (0,0,0): remove its face 1 (index 1,
        // the last face (0,0,0,5) moves there), then push dirs 1..6.
        l.insert([1, 0, 0]);
        let got: Vec<(i64, u8)> = (0..l.face_count())
            .map(|i| (l.face(i).voxel[0], l.face(i).dir as u8))
            .collect();
        assert_eq!(
            got,
            vec![
                (0, 0),
                (0, 5),
                (0, 2),
                (0, 3),
                (0, 4),
                (1, 1),
                (1, 2),
                (1, 3),
                (1, 4),
                (1, 5)
            ]
        );
        l.assert_valid();
    }
}
