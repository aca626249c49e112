//! The surface-face list of a [`DynamicOctree`](super::DynamicOctree): a dense `Vec` of
//! faces with back-pointers, so that a face is removed in O(1) (`swap_remove`) and a
//! uniformly random face is drawn in O(1) (Libes §5: "we stored face information in a
//! separate array (which we could randomly choose from)").

use crate::lattice::{Direction, Face};
use crate::Voxel;

/// Mixes a voxel into 32 well-spread bits (a multiply-xor fold, then murmur3's
/// fmix64).
#[inline]
fn mix(v: Voxel) -> u32 {
    let mut h = (v[0] as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    h = (h.rotate_left(23) ^ v[1] as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    h = (h.rotate_left(23) ^ v[2] as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    h ^= h >> 33;
    h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
    h ^= h >> 33;
    h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    (h ^ (h >> 33)) as u32
}

/// An empty slot of [`VoxelTable`].
const VACANT: u32 = u32::MAX;

/// A hash index from voxel to `u32` value, where the caller keeps the keys: each
/// slot holds only the key's 32-bit hash and the value (8 bytes), and the caller's
/// `key_of(value)` confirms a match. Open addressing, linear probing, load at most
/// 1/2, deletion by backward shift (no tombstones). So the index of a surface of
/// 100,000 voxels fits in 2 MiB, and a lookup touches one slot line plus the
/// record the caller reads anyway.
#[derive(Clone, Default)]
pub(crate) struct VoxelTable {
    /// `[hash, value]`; `value == VACANT` marks an empty slot.
    slots: Vec<[u32; 2]>,
    len: usize,
}

impl VoxelTable {
    /// The value whose key is `key`, if any. O(1) expected.
    #[inline]
    pub(crate) fn get(&self, key: Voxel, key_of: impl Fn(u32) -> Voxel) -> Option<u32> {
        self.find(key, key_of).map(|i| self.slots[i][1])
    }

    /// The slot holding `key`, by linear probing from its home slot. O(1) expected.
    #[inline]
    fn find(&self, key: Voxel, key_of: impl Fn(u32) -> Voxel) -> Option<usize> {
        if self.slots.is_empty() {
            return None;
        }
        let m = self.slots.len() - 1;
        let h = mix(key);
        let mut i = h as usize & m;
        loop {
            let [sh, val] = self.slots[i];
            if val == VACANT {
                return None;
            }
            if sh == h && key_of(val) == key {
                return Some(i);
            }
            i = (i + 1) & m;
        }
    }

    /// Adds `val` under `key`, which must be absent. O(1) amortised.
    #[inline]
    pub(crate) fn insert(&mut self, key: Voxel, val: u32) {
        debug_assert!(val != VACANT);
        if 2 * (self.len + 1) > self.slots.len() {
            let cap = (self.slots.len() * 2).max(16);
            self.rebuild(cap);
        }
        let m = self.slots.len() - 1;
        let h = mix(key);
        let mut i = h as usize & m;
        while self.slots[i][1] != VACANT {
            i = (i + 1) & m;
        }
        self.slots[i] = [h, val];
        self.len += 1;
    }

    /// Removes the entry whose key is `key`; returns its value. O(1) expected.
    pub(crate) fn remove(&mut self, key: Voxel, key_of: impl Fn(u32) -> Voxel) -> Option<u32> {
        let i = self.find(key, key_of)?;
        let m = self.slots.len() - 1;
        let val = self.slots[i][1];
        // Backward-shift deletion: pull later entries of the probe run into the hole
        // when their home slot does not lie cyclically in (hole, j].
        let mut hole = i;
        let mut j = i;
        loop {
            j = (j + 1) & m;
            if self.slots[j][1] == VACANT {
                break;
            }
            let home = self.slots[j][0] as usize & m;
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
        self.slots[hole][1] = VACANT;
        self.len -= 1;
        Some(val)
    }

    fn rebuild(&mut self, cap: usize) {
        let old = std::mem::replace(&mut self.slots, vec![[0, VACANT]; cap]);
        let m = cap - 1;
        for s in old.into_iter().filter(|s| s[1] != VACANT) {
            let mut i = s[0] as usize & m;
            while self.slots[i][1] != VACANT {
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

    /// Every value, in slot order.
    pub(crate) fn values(&self) -> impl Iterator<Item = u32> + '_ {
        self.slots.iter().filter(|s| s[1] != VACANT).map(|s| s[1])
    }

    pub(crate) fn heap_bytes(&self) -> usize {
        self.slots.capacity() * 8
    }
}

/// No face in that direction.
const NO_FACE: u32 = u32::MAX;

/// One entry of the dense face list, packed in 4 bytes: `owner << 3 | dir`, where
/// `owner` is the back-pointer record of the face's voxel. The voxel itself is read
/// from the record, so a face costs 4 bytes in the list instead of a full voxel, and
/// a face moved by `swap_remove` updates its back-pointer without hashing.
pub(crate) type Entry = u32;

/// The record index of a packed entry.
#[inline]
pub(crate) fn entry_owner(e: Entry) -> u32 {
    e >> 3
}

/// The direction of a packed entry (entries are made only from directions).
#[inline]
pub(crate) fn entry_dir(e: Entry) -> Direction {
    Direction::ALL[(e & 7) as usize]
}

/// The most records a face list can hold (the owner takes 29 bits of an entry).
const MAX_RECORDS: usize = 1 << 29;

/// The back-pointers of one surface voxel: the voxel, and where each of its six faces
/// sits in the list (`NO_FACE` when covered). 48 bytes.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Record {
    pub(crate) voxel: Voxel,
    pub(crate) at: [u32; 6],
}

impl Record {
    /// How many faces the voxel has.
    #[inline]
    fn count(&self) -> usize {
        self.at.iter().filter(|&&a| a != NO_FACE).count()
    }
}

/// The dense face list and its back-pointers. A surface voxel has one record (six
/// list positions) found through one hash lookup; faces in the list point back at
/// their record by index. So creating an isolated voxel costs one hash insertion, and
/// removing a neighbour's face costs one hash lookup.
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
        let records = &self.records;
        if let Some(r) = self.owners.get(v, |r| records[r as usize].voxel) {
            return r;
        }
        let rec = Record {
            voxel: v,
            at: [NO_FACE; 6],
        };
        let r = if let Some(i) = self.free.pop() {
            self.records[i as usize] = rec;
            i
        } else {
            assert!(
                self.records.len() < MAX_RECORDS,
                "more than 2^29 surface voxels"
            );
            self.records.push(rec);
            (self.records.len() - 1) as u32
        };
        self.owners.insert(v, r);
        r
    }

    /// The record of `v`, which must have one. One hash lookup.
    #[inline]
    pub(crate) fn existing_record(&self, v: Voxel) -> u32 {
        let records = &self.records;
        self.owners
            .get(v, |r| records[r as usize].voxel)
            .unwrap_or_else(|| panic!("voxel {v:?} has no faces"))
    }

    /// Appends face (`v`, `dir`) owned by record `rec`. O(1) amortised.
    #[inline]
    pub(crate) fn push(&mut self, rec: u32, dir: Direction) {
        let i = u32::try_from(self.list.len()).expect("more than 2^32 faces");
        let r = &mut self.records[rec as usize];
        debug_assert_eq!(r.at[dir.index()], NO_FACE, "face pushed twice");
        r.at[dir.index()] = i;
        self.list.push(rec << 3 | dir as u32);
    }

    /// The face at list position `i`. O(1).
    #[inline]
    pub(crate) fn face(&self, i: usize) -> Face {
        let e = self.list[i];
        Face {
            voxel: self.records[entry_owner(e) as usize].voxel,
            dir: entry_dir(e),
        }
    }

    /// Removes face (`v`, `dir`) owned by record `rec` by `swap_remove`: the last face
    /// takes its place. When `v` has no face left its record goes (one hash removal).
    #[inline]
    pub(crate) fn remove(&mut self, rec: u32, v: Voxel, dir: Direction) {
        let r = &mut self.records[rec as usize];
        let i = r.at[dir.index()];
        assert!(
            i != NO_FACE,
            "face {v:?} {dir:?} missing from the face list"
        );
        r.at[dir.index()] = NO_FACE;
        let gone = r.at == [NO_FACE; 6];
        let last = self.list.pop().expect("face list is empty");
        if (i as usize) < self.list.len() {
            self.list[i as usize] = last;
            self.records[entry_owner(last) as usize].at[entry_dir(last).index()] = i;
        }
        if gone {
            let records = &self.records;
            self.owners.remove(v, |r| records[r as usize].voxel);
            self.free.push(rec);
        }
    }

    /// Checks the back-pointers; panics naming the first broken one.
    pub(crate) fn assert_valid(&self) {
        let records = &self.records;
        let key_of = |r: u32| records[r as usize].voxel;
        let free: std::collections::HashSet<u32> = self.free.iter().copied().collect();
        for (i, &e) in self.list.iter().enumerate() {
            let (owner, dir) = (entry_owner(e), e & 7);
            assert!(dir < 6, "face {i} has direction {dir}");
            assert!(
                (owner as usize) < records.len(),
                "owner of face {i} out of range"
            );
            assert!(!free.contains(&owner), "face {i} owned by a free record");
            let v = records[owner as usize].voxel;
            assert_eq!(self.owners.get(v, key_of), Some(owner), "owner of face {i}");
            assert_eq!(
                records[owner as usize].at[dir as usize], i as u32,
                "back-pointer of face {i}"
            );
        }
        assert_eq!(
            free.len(),
            self.free.len(),
            "record free list has duplicates"
        );
        assert_eq!(
            self.owners.len() + self.free.len(),
            records.len(),
            "live + free records"
        );
        let mut total = 0usize;
        for r in self.owners.values() {
            assert!(!free.contains(&r), "record {r} is live and free");
            let rec = &records[r as usize];
            assert_eq!(
                self.owners.get(rec.voxel, key_of),
                Some(r),
                "index of record {r}"
            );
            let n = rec.count();
            assert!(n > 0, "record {r} has no face");
            for (d, &a) in rec.at.iter().enumerate() {
                if a != NO_FACE {
                    assert!(
                        (a as usize) < self.list.len(),
                        "record {r} points past the list"
                    );
                    assert_eq!(
                        self.list[a as usize],
                        r << 3 | d as u32,
                        "record {r} dir {d}"
                    );
                }
            }
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
