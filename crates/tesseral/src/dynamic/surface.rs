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
    /// `6·voxels − 2·(face-adjacent pairs)` counted now in O(voxels · depth).
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
        let mut pairs = 0u64;
        for v in self.voxels() {
            pairs += u64::from(self.face_neighbours(v).positive().len());
        }
        6 * self.voxels - 2 * pairs
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
