//! The surface-face list of a [`DynamicOctree`](super::DynamicOctree): a dense `Vec` of
//! faces with back-pointers, so that a face is removed in O(1) (`swap_remove`) and a
//! uniformly random face is drawn in O(1) (Libes §5: "we stored face information in a
//! separate array (which we could randomly choose from)").

use crate::Voxel;

/// One exposed face (plaquette) of the surface: the face of the black voxel `voxel`
/// that points in direction `dir` towards a white voxel.
///
/// `dir`: 0 = −x, 1 = +x, 2 = −y, 3 = +y, 4 = −z, 5 = +z.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Face {
    /// The black voxel that owns the face.
    pub voxel: Voxel,
    /// The direction the face points in: 0 = −x, 1 = +x, 2 = −y, 3 = +y, 4 = −z, 5 = +z.
    pub dir: u8,
}

impl Face {
    /// The white voxel on the other side of the face.
    ///
    /// ```
    /// use tesseral::dynamic::Face;
    /// let f = Face { voxel: [1, 2, 3], dir: 5 };
    /// assert_eq!(f.outside(), [1, 2, 4]);
    /// ```
    #[must_use]
    pub fn outside(&self) -> Voxel {
        step(self.voxel, self.dir)
    }
}

/// The unit step of direction `dir` (0 = −x, 1 = +x, 2 = −y, 3 = +y, 4 = −z, 5 = +z).
/// Coordinates wrap at ±2^63.
#[inline]
#[must_use]
pub fn step(v: Voxel, dir: u8) -> Voxel {
    let mut n = v;
    let a = usize::from(dir >> 1);
    n[a] = if dir & 1 == 0 {
        n[a].wrapping_sub(1)
    } else {
        n[a].wrapping_add(1)
    };
    n
}

/// The opposite direction: −x ↔ +x and so on.
#[inline]
#[must_use]
pub fn opposite(dir: u8) -> u8 {
    dir ^ 1
}

/// Mixes a voxel into 64 well-spread bits (murmur3's fmix64 over a multiply-xor fold).
#[inline]
fn mix(v: Voxel) -> u64 {
    let mut h = (v[0] as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    h = (h.rotate_left(23) ^ v[1] as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    h = (h.rotate_left(23) ^ v[2] as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    h ^= h >> 33;
    h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
    h ^= h >> 33;
    h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    h ^ (h >> 33)
}

/// An empty slot of [`VoxelTable`].
const VACANT: u32 = u32::MAX;

#[derive(Clone, Copy)]
#[repr(C, align(32))]
struct Slot {
    key: Voxel,
    val: u32,
}

/// A map from voxel to `u32`: open addressing with linear probing, keys stored in
/// the slots (one cache line per lookup, where a SwissTable touches two), load
/// factor at most 1/2, deletion by backward shift (no tombstones).
#[derive(Clone, Default)]
pub(crate) struct VoxelTable {
    slots: Vec<Slot>,
    len: usize,
}

impl VoxelTable {
    #[inline]
    fn mask(&self) -> usize {
        self.slots.len() - 1
    }

    /// The value of `key`, if any. O(1) expected.
    #[inline]
    pub(crate) fn get(&self, key: Voxel) -> Option<u32> {
        if self.slots.is_empty() {
            return None;
        }
        let m = self.mask();
        let mut i = mix(key) as usize & m;
        loop {
            let s = &self.slots[i];
            if s.val == VACANT {
                return None;
            }
            if s.key == key {
                return Some(s.val);
            }
            i = (i + 1) & m;
        }
    }

    /// The value of `key`, inserting `make()` first if it has none. O(1) amortised.
    #[inline]
    pub(crate) fn get_or_insert_with<F: FnOnce() -> u32>(&mut self, key: Voxel, make: F) -> u32 {
        if 2 * (self.len + 1) > self.slots.len() {
            self.grow();
        }
        let m = self.mask();
        let mut i = mix(key) as usize & m;
        loop {
            let s = &mut self.slots[i];
            if s.val == VACANT {
                let v = make();
                debug_assert!(v != VACANT);
                *s = Slot { key, val: v };
                self.len += 1;
                return v;
            }
            if s.key == key {
                return s.val;
            }
            i = (i + 1) & m;
        }
    }

    /// Removes `key`; returns its value. O(1) expected.
    pub(crate) fn remove(&mut self, key: Voxel) -> Option<u32> {
        if self.slots.is_empty() {
            return None;
        }
        let m = self.mask();
        let mut i = mix(key) as usize & m;
        loop {
            if self.slots[i].val == VACANT {
                return None;
            }
            if self.slots[i].key == key {
                break;
            }
            i = (i + 1) & m;
        }
        let val = self.slots[i].val;
        // Backward-shift deletion: pull later entries of the probe run into the hole
        // when their home slot does not lie cyclically in (hole, j].
        let mut hole = i;
        let mut j = i;
        loop {
            j = (j + 1) & m;
            if self.slots[j].val == VACANT {
                break;
            }
            let home = mix(self.slots[j].key) as usize & m;
            let stays = if hole <= j {
                hole < home && home <= j
            } else {
                hole < home || home <= j
            };
            if !stays {
                self.slots[hole] = self.slots[j];
                hole = j;
            }
        }
        self.slots[hole].val = VACANT;
        self.len -= 1;
        Some(val)
    }

    fn grow(&mut self) {
        let cap = (self.slots.len() * 2).max(16);
        self.rebuild(cap);
    }

    fn rebuild(&mut self, cap: usize) {
        let old = std::mem::replace(
            &mut self.slots,
            vec![
                Slot {
                    key: [0; 3],
                    val: VACANT
                };
                cap
            ],
        );
        let m = cap - 1;
        for s in old.into_iter().filter(|s| s.val != VACANT) {
            let mut i = mix(s.key) as usize & m;
            while self.slots[i].val != VACANT {
                i = (i + 1) & m;
            }
            self.slots[i] = s;
        }
    }

    /// Shrinks to the smallest power of two that keeps the load at most 1/2.
    pub(crate) fn shrink_to_fit(&mut self) {
        let cap = (2 * self.len).next_power_of_two().max(16);
        if cap < self.slots.len() {
            self.rebuild(cap);
        }
    }

    pub(crate) fn len(&self) -> usize {
        self.len
    }

    pub(crate) fn iter(&self) -> impl Iterator<Item = (Voxel, u32)> + '_ {
        self.slots
            .iter()
            .filter(|s| s.val != VACANT)
            .map(|s| (s.key, s.val))
    }

    pub(crate) fn heap_bytes(&self) -> usize {
        self.slots.capacity() * std::mem::size_of::<Slot>()
    }
}

/// No face in that direction.
const NO_FACE: u32 = u32::MAX;

/// One entry of the dense face list: the face and the back-pointer record of its
/// voxel, so that a face moved by `swap_remove` updates its back-pointer without
/// hashing.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Entry {
    pub(crate) voxel: Voxel,
    pub(crate) dir: u8,
    pub(crate) owner: u32,
}

impl Entry {
    #[inline]
    pub(crate) fn face(&self) -> Face {
        Face {
            voxel: self.voxel,
            dir: self.dir,
        }
    }
}

/// The back-pointers of one surface voxel: where each of its six faces sits in the
/// list (`NO_FACE` when covered), and how many it has.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Record {
    pub(crate) at: [u32; 6],
    pub(crate) count: u32,
}

/// The dense face list and its back-pointers. A surface voxel has one record (six
/// list positions) found through one hash lookup; faces in the list point back at
/// their record by index. So creating an isolated voxel costs one hash insertion, and
/// a face removed by `swap_remove` costs one hash lookup for its owner.
#[derive(Clone, Default)]
pub(crate) struct FaceList {
    pub(crate) list: Vec<Entry>,
    pub(crate) owners: VoxelTable,
    pub(crate) records: Vec<Record>,
    pub(crate) free: Vec<u32>,
}

impl FaceList {
    /// The record of `v`, made if `v` has none. One hash lookup.
    #[inline]
    pub(crate) fn record_of(&mut self, v: Voxel) -> u32 {
        let records = &mut self.records;
        let free = &mut self.free;
        self.owners.get_or_insert_with(v, || {
            let r = Record {
                at: [NO_FACE; 6],
                count: 0,
            };
            if let Some(i) = free.pop() {
                records[i as usize] = r;
                i
            } else {
                records.push(r);
                (records.len() - 1) as u32
            }
        })
    }

    /// The record of `v`, which must have one. One hash lookup.
    #[inline]
    pub(crate) fn existing_record(&self, v: Voxel) -> u32 {
        self.owners
            .get(v)
            .unwrap_or_else(|| panic!("voxel {v:?} has no faces"))
    }

    /// Appends face (`v`, `dir`) owned by record `rec`. O(1) amortised.
    #[inline]
    pub(crate) fn push(&mut self, rec: u32, v: Voxel, dir: u8) {
        let i = u32::try_from(self.list.len()).expect("more than 2^32 faces");
        let r = &mut self.records[rec as usize];
        debug_assert_eq!(r.at[usize::from(dir)], NO_FACE, "face pushed twice");
        r.at[usize::from(dir)] = i;
        r.count += 1;
        self.list.push(Entry {
            voxel: v,
            dir,
            owner: rec,
        });
    }

    /// Removes face (`v`, `dir`) owned by record `rec` by `swap_remove`: the last face
    /// takes its place. When `v` has no face left its record goes (one hash removal).
    #[inline]
    pub(crate) fn remove(&mut self, rec: u32, v: Voxel, dir: u8) {
        let r = &mut self.records[rec as usize];
        let i = r.at[usize::from(dir)];
        assert!(i != NO_FACE, "face {v:?} {dir} missing from the face list");
        r.at[usize::from(dir)] = NO_FACE;
        r.count -= 1;
        let gone = r.count == 0;
        let last = self.list.pop().expect("face list is empty");
        if (i as usize) < self.list.len() {
            self.list[i as usize] = last;
            self.records[last.owner as usize].at[usize::from(last.dir)] = i;
        }
        if gone {
            self.owners.remove(v);
            self.free.push(rec);
        }
    }

    /// Checks the back-pointers; panics naming the first broken one.
    pub(crate) fn assert_valid(&self) {
        for (i, e) in self.list.iter().enumerate() {
            assert!(e.dir < 6, "face {i} has direction {}", e.dir);
            assert_eq!(self.owners.get(e.voxel), Some(e.owner), "owner of face {i}");
            assert_eq!(
                self.records[e.owner as usize].at[usize::from(e.dir)],
                i as u32,
                "back-pointer of face {i}"
            );
        }
        let free: std::collections::HashSet<u32> = self.free.iter().copied().collect();
        assert_eq!(
            free.len(),
            self.free.len(),
            "record free list has duplicates"
        );
        assert_eq!(
            self.owners.len() + self.free.len(),
            self.records.len(),
            "live + free records"
        );
        let mut total = 0usize;
        for (v, r) in self.owners.iter() {
            assert!(!free.contains(&r), "record of {v:?} is free");
            let rec = &self.records[r as usize];
            let n = rec.at.iter().filter(|&&a| a != NO_FACE).count();
            assert_eq!(n as u32, rec.count, "face count in the record of {v:?}");
            assert!(n > 0, "record of {v:?} has no face");
            total += n;
        }
        assert_eq!(total, self.list.len(), "faces in records vs list");
    }

    /// Heap bytes held (capacity, not length).
    pub(crate) fn heap_bytes(&self) -> usize {
        self.list.capacity() * std::mem::size_of::<Entry>()
            + self.records.capacity() * std::mem::size_of::<Record>()
            + self.free.capacity() * 4
            + self.owners.heap_bytes()
    }
}
