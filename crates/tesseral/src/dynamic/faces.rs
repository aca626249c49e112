//! The surface-face list of a [`DynamicOctree`](super::DynamicOctree): a dense `Vec` of
//! faces with back-pointers, so that a face is removed in O(1) (`swap_remove`) and a
//! uniformly random face is drawn in O(1) (Libes §5: "we stored face information in a
//! separate array (which we could randomly choose from)").

use std::collections::HashMap;
use std::hash::{BuildHasher, Hasher};

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

/// A small, fast hasher for face keys (three `i64` and a direction). Not DoS-resistant,
/// which is fine for keys the program itself makes.
#[derive(Clone, Copy, Default)]
pub(crate) struct FaceHasher(u64);

impl Hasher for FaceHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }
    #[inline]
    fn write_u8(&mut self, i: u8) {
        self.write_u64(u64::from(i));
    }
    #[inline]
    fn write_i64(&mut self, i: i64) {
        self.write_u64(i as u64);
    }
    #[inline]
    fn write_usize(&mut self, i: usize) {
        self.write_u64(i as u64);
    }
    #[inline]
    fn write_u64(&mut self, i: u64) {
        self.0 = (self.0.rotate_left(23) ^ i).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    }
    #[inline]
    fn finish(&self) -> u64 {
        // murmur3 fmix64: spreads every input bit to the high bits (hashbrown's tag)
        // and the low bits (its bucket).
        let mut h = self.0;
        h ^= h >> 33;
        h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
        h ^= h >> 33;
        h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
        h ^ (h >> 33)
    }
}

#[derive(Clone, Copy, Default)]
pub(crate) struct FaceHasherBuilder;

impl BuildHasher for FaceHasherBuilder {
    type Hasher = FaceHasher;
    #[inline]
    fn build_hasher(&self) -> FaceHasher {
        FaceHasher(0)
    }
}

/// The dense face list and its back-pointers.
#[derive(Clone, Default)]
pub(crate) struct FaceList {
    pub(crate) list: Vec<Face>,
    pub(crate) index: HashMap<Face, u32, FaceHasherBuilder>,
}

impl FaceList {
    /// Appends a face. O(1) amortised.
    #[inline]
    pub(crate) fn push(&mut self, f: Face) {
        let i = u32::try_from(self.list.len()).expect("more than 2^32 faces");
        let old = self.index.insert(f, i);
        debug_assert!(old.is_none(), "face {f:?} pushed twice");
        self.list.push(f);
    }

    /// Removes a face by `swap_remove`: the last face takes its place. O(1).
    #[inline]
    pub(crate) fn remove(&mut self, f: Face) {
        let i = self
            .index
            .remove(&f)
            .unwrap_or_else(|| panic!("face {f:?} missing from the face list"))
            as usize;
        let last = self.list.pop().expect("face list is empty");
        if i < self.list.len() {
            self.list[i] = last;
            *self
                .index
                .get_mut(&last)
                .expect("back-pointer of the last face") = i as u32;
        }
    }

    /// Heap bytes held (capacity, not length). The hash table is estimated the way
    /// hashbrown lays it out: a power-of-two bucket count, one control byte per bucket.
    pub(crate) fn heap_bytes(&self) -> usize {
        let cap = self.index.capacity();
        let buckets = if cap == 0 {
            0
        } else {
            (cap * 8 / 7).next_power_of_two()
        };
        self.list.capacity() * std::mem::size_of::<Face>()
            + buckets * (std::mem::size_of::<(Face, u32)>() + 1)
    }
}
