//! The face list seen from the tree: bookkeeping after a create or delete, and the face queries.

#[allow(unused_imports)]
use super::*;

impl DynamicOctree {
    // ----- faces (Libes §4, §5) -------------------------------------------------------

    /// Face passing after `v` was created; `nb` is its face-neighbour mask.
    pub(super) fn faces_after_insert(&mut self, v: Voxel, nb: Directions) {
        let f = self.faces.as_mut().expect("face bookkeeping");
        let mut own = None;
        for dir in Direction::ALL {
            if nb.contains(dir) {
                let n = dir.step(v);
                let r = f.existing_record(n);
                f.remove(r, n, dir.opposite());
            } else {
                let r = *own.get_or_insert_with(|| f.record_of(v));
                f.push(r, dir);
            }
        }
    }

    /// Face passing after `v` was deleted; `nb` is its face-neighbour mask.
    pub(super) fn faces_after_remove(&mut self, v: Voxel, nb: Directions) {
        let f = self.faces.as_mut().expect("face bookkeeping");
        // A black voxel with a white neighbour has a record; one with six black
        // neighbours has no face to remove.
        let own = if nb != Directions::ALL {
            f.existing_record(v)
        } else {
            0
        };
        for dir in Direction::ALL {
            if nb.contains(dir) {
                let n = dir.step(v);
                let r = f.record_of(n);
                f.push(r, dir.opposite());
            } else {
                f.remove(own, v, dir);
            }
        }
    }

    /// The number of exposed faces (the surface area in unit squares); exact.
    /// 0 without face bookkeeping. O(1).
    #[must_use]
    pub fn face_count(&self) -> usize {
        self.faces.as_ref().map_or(0, |f| f.list.len())
    }

    /// The number of exposed faces (the surface area), whether or not the face list
    /// is kept: `face_count()` with face bookkeeping, otherwise
    /// `6·voxels − 2·(face-adjacent pairs)`, the pairs counted now piece by piece:
    /// inside a stored block by shifts and popcounts, inside a full octant of side
    /// s as 3·s²·(s − 1), and across each piece's three positive faces by one
    /// lookup per cell of the piece on that face. Saturates at `u64::MAX`.
    ///
    /// # Runtime
    /// O(w · depth) for the w lookups of [`exposed_faces_work`](Self::exposed_faces_work),
    /// in constant memory: it follows the pieces' surface, not the voxels (a full
    /// octant of 2^27 voxels takes 3 · 2^18 lookups).
    ///
    /// ```
    /// let t = tesseral::dynamic::DynamicOctree::from_voxels([[0, 0, 0], [0, 1, 0]]);
    /// assert_eq!(t.exposed_faces(), 10);
    /// ```
    #[must_use]
    pub fn exposed_faces(&self) -> u64 {
        if let Some(f) = &self.faces {
            return f.list.len() as u64;
        }
        let mut pairs = 0u128;
        self.visit(|base, level, bits| {
            pairs += match bits {
                None => self.octant_pairs(base, level),
                Some(l) => self.block_pairs(base, l),
            };
        });
        let faces = 6 * u128::from(self.voxels) - 2 * pairs;
        u64::try_from(faces).unwrap_or(u64::MAX)
    }

    /// The lookups [`exposed_faces`](Self::exposed_faces) makes (0 with face
    /// bookkeeping): 3·s² for each full octant of side s, and for each stored block
    /// its voxels on its three positive faces (at most 3 a voxel in all). Saturates
    /// at `u64::MAX`. O(nodes + blocks), so that a caller can refuse the count
    /// before it starts.
    #[must_use]
    pub fn exposed_faces_work(&self) -> u64 {
        if self.faces.is_some() {
            return 0;
        }
        let mut work = 0u64;
        self.visit(|_, level, bits| {
            let w = match bits {
                None => 1u64
                    .checked_shl(2 * level)
                    .map_or(u64::MAX, |s2| s2.saturating_mul(3)),
                Some(l) => face_cells(l),
            };
            work = work.saturating_add(w);
        });
        work
    }

    /// Whether the voxel at offsets `u` from the root corner, moved one step along
    /// `axis` in the positive direction, is black (as `Direction::step`, wrapping).
    fn black_after(&self, mut u: [u64; 3], axis: usize) -> bool {
        u[axis] = u[axis].wrapping_add(1);
        self.contains(self.world(u))
    }

    /// Face-adjacent pairs of black voxels with the first in the full octant at
    /// `base` of side `2^level`: those inside it, and those across its three
    /// positive faces.
    fn octant_pairs(&self, base: [u64; 3], level: u32) -> u128 {
        let s = 1u64 << level;
        let side = u128::from(s);
        let mut pairs = 3 * side * side * (side - 1);
        for a in 0..3 {
            let (b, c) = ((a + 1) % 3, (a + 2) % 3);
            for i in 0..s {
                for j in 0..s {
                    let mut u = base;
                    u[a] += s - 1;
                    u[b] += i;
                    u[c] += j;
                    pairs += u128::from(self.black_after(u, a));
                }
            }
        }
        pairs
    }

    /// Face-adjacent pairs of black voxels with the first in the block at `base`
    /// (bits `x + 8y` of word `z`): those inside it by shifts and popcounts, and
    /// those across its three positive faces by lookups.
    fn block_pairs(&self, base: [u64; 3], l: &[u64; 8]) -> u128 {
        let mut pairs = 0u32;
        for z in 0..8 {
            pairs += (l[z] & l[z] >> 1 & NOT_X7).count_ones() + (l[z] & l[z] >> 8).count_ones();
            if z < 7 {
                pairs += (l[z] & l[z + 1]).count_ones();
            }
        }
        let mut across = 0u128;
        for (mut m, z, axis) in face_rows(l) {
            while m != 0 {
                let i = u64::from(m.trailing_zeros());
                m &= m - 1;
                let u = [base[0] + (i & 7), base[1] + (i >> 3), base[2] + z];
                across += u128::from(self.black_after(u, axis));
            }
        }
        u128::from(pairs) + across
    }

    /// The `i`-th face of the face list. O(1).
    ///
    /// # Panics
    /// When `i >= face_count()`.
    #[must_use]
    pub fn face(&self, i: usize) -> Face {
        let n = self.face_count();
        assert!(i < n, "face index {i} out of range (face_count {n})");
        self.faces.as_ref().expect("face bookkeeping").face(i)
    }

    /// The whole face list, in face-list order (empty without face bookkeeping).
    /// O(faces).
    #[must_use]
    pub fn faces(&self) -> Vec<Face> {
        self.faces
            .as_ref()
            .map_or_else(Vec::new, |f| (0..f.list.len()).map(|i| f.face(i)).collect())
    }

    /// A uniformly random exposed face, or `None` when there is none. O(1).
    ///
    /// ```
    /// use rand::SeedableRng;
    /// let mut t = tesseral::dynamic::DynamicOctree::with_faces();
    /// t.insert([0, 0, 0]);
    /// let mut rng = rand_pcg::Pcg64::seed_from_u64(1);
    /// assert_eq!(t.random_face(&mut rng).unwrap().voxel, [0, 0, 0]);
    /// ```
    pub fn random_face<R: rand::Rng + ?Sized>(&self, rng: &mut R) -> Option<Face> {
        let n = self.face_count();
        (n > 0).then(|| self.face(rng.random_range(0..n)))
    }
}

/// The cells of a block's word (bits `x + 8y`) with x < 7, with x = 7, and with
/// y = 7.
const NOT_X7: u64 = 0x7f7f_7f7f_7f7f_7f7f;
const X7: u64 = !NOT_X7;
const Y7: u64 = 0xff << 56;

/// The black cells of block `l` on its positive faces, by word: (the cells of word
/// `z` on the face, `z`, the axis the face is across).
fn face_rows(l: &[u64; 8]) -> impl Iterator<Item = (u64, u64, usize)> + '_ {
    (0..8u64)
        .flat_map(move |z| [(l[z as usize] & X7, z, 0), (l[z as usize] & Y7, z, 1)])
        .chain([(l[7], 7, 2)])
}

/// The black cells of block `l` on its positive faces, each counted once a face.
fn face_cells(l: &[u64; 8]) -> u64 {
    face_rows(l)
        .map(|(m, _, _)| u64::from(m.count_ones()))
        .sum()
}
