//! The unbounded dynamic octree as an RS/MC lattice (Libes §5–6): O(|S|) memory and
//! unbounded growth. Its face list follows the same order rule as
//! [`DenseLattice`](super::DenseLattice), so the two give identical trajectories.

use super::{Face, Lattice, Neighbourhood};
use crate::dynamic::DynamicOctree;
use crate::Voxel;

impl Lattice for DynamicOctree {
    fn empty() -> Self {
        DynamicOctree::with_faces()
    }
    #[inline]
    fn insert(&mut self, v: Voxel) -> bool {
        DynamicOctree::insert(self, v)
    }
    #[inline]
    fn remove(&mut self, v: Voxel) -> bool {
        DynamicOctree::remove(self, v)
    }
    #[inline]
    fn contains(&self, v: Voxel) -> bool {
        DynamicOctree::contains(self, v)
    }
    #[inline]
    fn voxel_count(&self) -> u64 {
        DynamicOctree::voxel_count(self)
    }
    #[inline]
    fn face_count(&self) -> usize {
        DynamicOctree::face_count(self)
    }
    #[inline]
    fn face(&self, i: usize) -> Face {
        let f = DynamicOctree::face(self, i);
        Face {
            voxel: f.voxel,
            dir: f.dir,
        }
    }
    #[inline]
    fn neighbourhood(&self, v: Voxel) -> Neighbourhood {
        DynamicOctree::neighbourhood(self, v)
    }
    #[inline]
    fn insert_with_neighbourhood(&mut self, v: Voxel, nb: Neighbourhood) -> bool {
        DynamicOctree::insert_with_neighbourhood(self, v, nb)
    }
    #[inline]
    fn remove_with_neighbourhood(&mut self, v: Voxel, nb: Neighbourhood) -> bool {
        DynamicOctree::remove_with_neighbourhood(self, v, nb)
    }
}
