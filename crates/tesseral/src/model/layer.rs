//! A value per voxel, stored as regions of equal value.

use std::collections::HashMap;
use std::sync::OnceLock;

use crate::linear::{gallop, Leaf, LinearOctree, OctreeError};
use crate::Voxel;

/// A value a [`Layer`] can hold: copied, and grouped into regions by a key (so
/// floats group by their bits and round-trip exactly).
pub trait LayerValue: Copy + std::fmt::Debug + Send + Sync + 'static {
    /// The grouping key: equal keys mean the same value.
    fn key(&self) -> u64;
}

impl LayerValue for [u8; 4] {
    fn key(&self) -> u64 {
        u64::from(u32::from_le_bytes(*self))
    }
}

impl LayerValue for f32 {
    fn key(&self) -> u64 {
        u64::from(self.to_bits())
    }
}

/// A colour `[r, g, b, a]`.
pub type Rgba = [u8; 4];

/// A value per voxel over part of a space, kept as a list of disjoint regions of
/// equal value, each a canonical [`LinearOctree`] in the layer's space.
///
/// Every fast operation of the linear octree (translation, rotation, mirroring,
/// scaling, set operations) therefore applies to a layer region by region. Lookups
/// go through an index of all regions' leaves sorted by code, built on first use.
///
/// ```
/// use tesseral::model::Layer;
/// let l = Layer::from_voxels(3, [0, 0, 0], [([0, 0, 0], [255, 0, 0, 255]), ([1, 0, 0], [0, 0, 255, 255])]).unwrap();
/// assert_eq!(l.get([1, 0, 0]), Some([0, 0, 255, 255]));
/// assert_eq!(l.get([2, 0, 0]), None);
/// assert_eq!(l.region_count(), 2);
/// ```
#[derive(Debug, Clone)]
pub struct Layer<T: LayerValue> {
    depth: u8,
    origin: Voxel,
    regions: Vec<(T, LinearOctree)>,
    index: OnceLock<Vec<(u64, u32)>>,
}

impl<T: LayerValue> PartialEq for Layer<T> {
    /// Equal when every voxel has the same value (compared by key).
    fn eq(&self, other: &Self) -> bool {
        let keys = |l: &Self| -> Vec<(Voxel, u64)> {
            l.to_voxels().into_iter().map(|(v, k, _)| (v, k)).collect()
        };
        keys(self) == keys(other)
    }
}

/// `tree` in the space `(depth, origin)`, which must hold its voxels.
fn in_space(tree: LinearOctree, depth: u8, origin: Voxel) -> Result<LinearOctree, OctreeError> {
    if tree.depth() == depth && tree.origin() == origin {
        return Ok(tree);
    }
    Ok(tree.resample(depth, origin)?.0)
}

impl<T: LayerValue> Layer<T> {
    /// An empty layer in the space of `2^depth` voxels per axis from `origin`.
    #[must_use]
    pub fn empty(depth: u8, origin: Voxel) -> Self {
        Self {
            depth,
            origin,
            regions: Vec::new(),
            index: OnceLock::new(),
        }
    }

    /// A layer from `(voxel, value)` pairs; a later pair for the same voxel wins.
    ///
    /// # Runtime
    /// O(n log n) for n pairs.
    ///
    /// # Errors
    /// As [`LinearOctree::from_voxels`] (a voxel outside the space, a depth too large).
    pub fn from_voxels(
        depth: u8,
        origin: Voxel,
        pairs: impl IntoIterator<Item = (Voxel, T)>,
    ) -> Result<Self, OctreeError> {
        let mut last: HashMap<Voxel, T> = HashMap::new();
        for (v, x) in pairs {
            last.insert(v, x);
        }
        let mut groups: HashMap<u64, (T, Vec<Voxel>)> = HashMap::new();
        for (v, x) in last {
            groups
                .entry(x.key())
                .or_insert_with(|| (x, Vec::new()))
                .1
                .push(v);
        }
        let mut regions = Vec::with_capacity(groups.len());
        for (_, (x, voxels)) in groups {
            regions.push((x, LinearOctree::from_voxels(depth, origin, voxels)?));
        }
        Ok(Self::from_regions_unchecked(depth, origin, regions))
    }

    /// A layer from `(leaf, value)` pairs of disjoint leaves in tesseral order (as a
    /// preorder file walk yields them).
    ///
    /// # Runtime
    /// O(n) expected for n leaves.
    ///
    /// # Errors
    /// As [`LinearOctree::from_sorted_leaves`].
    pub fn from_sorted_leaves(
        depth: u8,
        origin: Voxel,
        leaves: impl IntoIterator<Item = (Leaf, T)>,
    ) -> Result<Self, OctreeError> {
        let mut groups: HashMap<u64, (T, Vec<Leaf>)> = HashMap::new();
        for (l, x) in leaves {
            groups
                .entry(x.key())
                .or_insert_with(|| (x, Vec::new()))
                .1
                .push(l);
        }
        let mut regions = Vec::with_capacity(groups.len());
        for (_, (x, leaves)) in groups {
            regions.push((x, LinearOctree::from_sorted_leaves(depth, origin, leaves)?));
        }
        Ok(Self::from_regions_unchecked(depth, origin, regions))
    }

    /// Every leaf of every region with its value, in tesseral order.
    #[must_use]
    pub fn leaves(&self) -> Vec<(Leaf, T)> {
        let mut out: Vec<(Leaf, T)> = self
            .regions
            .iter()
            .flat_map(|(x, t)| t.leaves().iter().map(move |l| (*l, *x)))
            .collect();
        // Each region's leaves are one sorted run: a stable sort merges the runs.
        out.sort_by_key(|(l, _)| l.code());
        out
    }

    /// A layer from regions already in the space and disjoint; regions with the same
    /// value are merged and empty ones dropped, and the order made canonical. Tests
    /// use it to write the files that readers must refuse.
    pub(crate) fn from_regions_unchecked(
        depth: u8,
        origin: Voxel,
        regions: Vec<(T, LinearOctree)>,
    ) -> Self {
        let mut by_key: HashMap<u64, (T, LinearOctree)> = HashMap::new();
        for (x, t) in regions {
            if t.is_empty() {
                continue;
            }
            match by_key.entry(x.key()) {
                std::collections::hash_map::Entry::Occupied(mut e) => {
                    let u = e.get().1.set_op_same_space(&t, crate::linear::SetOp::Union);
                    e.get_mut().1 = u;
                }
                std::collections::hash_map::Entry::Vacant(e) => {
                    e.insert((x, t));
                }
            }
        }
        let mut regions: Vec<(T, LinearOctree)> = by_key.into_values().collect();
        regions.sort_unstable_by_key(|(x, _)| x.key());
        Self {
            depth,
            origin,
            regions,
            index: OnceLock::new(),
        }
    }

    /// A layer from regions of equal value in any spaces; they are re-expressed in
    /// the space `(depth, origin)`, which must hold them, and must be disjoint
    /// (regions of the same value may overlap: they are merged).
    ///
    /// # Runtime
    /// O(n log n) in the regions' leaves, for the disjointness check.
    ///
    /// # Errors
    /// As [`LinearOctree::resample`]; [`OctreeError::InvalidArgument`] when two
    /// regions of different values share a voxel (a layer holds one value per
    /// voxel, and a file written from such a layer could not be read back).
    pub fn from_regions(
        depth: u8,
        origin: Voxel,
        regions: impl IntoIterator<Item = (T, LinearOctree)>,
    ) -> Result<Self, OctreeError> {
        let mut out = Vec::new();
        for (x, t) in regions {
            out.push((x, in_space(t, depth, origin)?));
        }
        let layer = Self::from_regions_unchecked(depth, origin, out);
        if !disjoint(&layer.regions) {
            return Err(OctreeError::InvalidArgument(
                "the regions overlap: a voxel would hold two values".into(),
            ));
        }
        Ok(layer)
    }

    /// The layer's space: depth.
    #[must_use]
    pub fn depth(&self) -> u8 {
        self.depth
    }

    /// The layer's space: lowest corner.
    #[must_use]
    pub fn origin(&self) -> Voxel {
        self.origin
    }

    /// The regions: each distinct value with the voxels that hold it, sorted by key.
    #[must_use]
    pub fn regions(&self) -> &[(T, LinearOctree)] {
        &self.regions
    }

    /// The number of distinct values.
    #[must_use]
    pub fn region_count(&self) -> usize {
        self.regions.len()
    }

    /// Whether no voxel has a value.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.regions.is_empty()
    }

    /// The number of voxels that have a value.
    #[must_use]
    pub fn voxel_count(&self) -> u64 {
        self.regions.iter().map(|(_, t)| t.voxel_count()).sum()
    }

    /// The voxels that have a value, as one tree in the layer's space.
    #[must_use]
    pub fn domain(&self) -> LinearOctree {
        let mut acc = LinearOctree::empty(self.depth, self.origin).expect("layer space is valid");
        for (_, t) in &self.regions {
            acc = acc.set_op_same_space(t, crate::linear::SetOp::Union);
        }
        acc
    }

    fn index(&self) -> &[(u64, u32)] {
        self.index.get_or_init(|| {
            let mut idx: Vec<(u64, u32)> = self
                .regions
                .iter()
                .enumerate()
                .flat_map(|(i, (_, t))| t.leaves().iter().map(move |l| (l.packed(), i as u32)))
                .collect();
            idx.sort_unstable_by_key(|&(p, _)| p);
            idx
        })
    }

    /// The value at voxel `v`, if it has one.
    ///
    /// # Runtime
    /// O(log n) for n leaves over all regions, after an O(n log n) index built on the
    /// first call.
    #[must_use]
    pub fn get(&self, v: Voxel) -> Option<T> {
        self.get_near(v, &mut 0)
    }

    /// [`get`](Self::get), its search started from index entry `near` (one found
    /// for a voxel nearby, as when the voxels come in order) and `near` left at the
    /// entry found, for the next voxel.
    ///
    /// # Runtime
    /// O(log d) for d index entries between `near` and the voxel's, after the
    /// index is built.
    pub(crate) fn get_near(&self, v: Voxel, near: &mut usize) -> Option<T> {
        let probe = LinearOctree::empty(self.depth, self.origin).ok()?;
        let c = probe.code_of(v)?;
        let idx = self.index();
        let i = gallop(idx, *near, |&(p, _)| Leaf::from_packed(p).code() <= c);
        *near = i.saturating_sub(1);
        if i == 0 {
            return None;
        }
        let (p, r) = idx[i - 1];
        Leaf::from_packed(p)
            .contains_code(c)
            .then(|| self.regions[r as usize].0)
    }

    /// Every `(voxel, value)` pair, sorted by voxel.
    #[must_use]
    pub fn to_voxels(&self) -> Vec<(Voxel, u64, T)> {
        let mut out: Vec<(Voxel, u64, T)> = self
            .regions
            .iter()
            .flat_map(|(x, t)| t.voxels().map(move |v| (v, x.key(), *x)))
            .collect();
        out.sort_unstable_by_key(|&(v, k, _)| (v, k));
        out
    }

    /// Applies a tree operation to every region, then re-expresses the regions in the
    /// space `(depth, origin)`, which must hold the results.
    ///
    /// # Errors
    /// What `f` returns; as [`LinearOctree::resample`].
    pub fn map_regions(
        &self,
        depth: u8,
        origin: Voxel,
        f: impl Fn(&LinearOctree) -> Result<LinearOctree, OctreeError>,
    ) -> Result<Self, OctreeError> {
        let mut out = Vec::with_capacity(self.regions.len());
        for (x, t) in &self.regions {
            out.push((*x, in_space(f(t)?, depth, origin)?));
        }
        Ok(Self::from_regions_unchecked(depth, origin, out))
    }

    /// The layer restricted to the voxels of `keep` and re-expressed in `keep`'s space.
    ///
    /// # Errors
    /// As [`LinearOctree::set_op`].
    pub fn restrict(&self, keep: &LinearOctree) -> Result<Self, OctreeError> {
        let (depth, origin) = (keep.depth(), keep.origin());
        let mut out = Vec::with_capacity(self.regions.len());
        for (x, t) in &self.regions {
            out.push((*x, in_space(t.intersection(keep)?, depth, origin)?));
        }
        Ok(Self::from_regions_unchecked(depth, origin, out))
    }

    /// `self`'s values where it has one, else `other`'s, in `self`'s space grown to
    /// hold both: the rule "the first operand's value wins".
    ///
    /// # Errors
    /// As [`LinearOctree::set_op`].
    pub fn overlay(&self, other: &Self, depth: u8, origin: Voxel) -> Result<Self, OctreeError> {
        let mine = self.map_regions(depth, origin, |t| Ok(t.clone()))?;
        let taken = mine.domain();
        let mut regions = mine.regions;
        for (x, t) in &other.regions {
            let t = in_space(t.clone(), depth, origin)?;
            regions.push((
                *x,
                t.set_op_same_space(&taken, crate::linear::SetOp::Difference),
            ));
        }
        Ok(Self::from_regions_unchecked(depth, origin, regions))
    }

    /// Panics unless the regions are canonical trees in the layer's space, pairwise
    /// disjoint, non-empty, and of distinct values.
    pub fn assert_valid(&self) {
        let mut keys = std::collections::HashSet::new();
        let mut total = 0;
        for (x, t) in &self.regions {
            t.assert_valid();
            assert_eq!(
                (t.depth(), t.origin()),
                (self.depth, self.origin),
                "region outside the layer's space"
            );
            assert!(!t.is_empty(), "empty region for {x:?}");
            assert!(keys.insert(x.key()), "two regions hold {x:?}");
            total += t.voxel_count();
        }
        assert_eq!(self.domain().voxel_count(), total, "regions overlap");
        assert!(disjoint(&self.regions), "regions overlap");
    }
}

/// Whether no two regions share a voxel: every leaf's code range, in code order
/// over all regions, ends before the next one begins. Each region's leaves are one
/// sorted run, so the runs are merged (a heap of the r regions' next leaves):
/// O(n log r) in the n leaves, with O(r) memory (a sorted copy of the leaves cost
/// 16 bytes a leaf), where unions of the regions would cost O(r·n).
fn disjoint<T>(regions: &[(T, LinearOctree)]) -> bool {
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    if regions.len() < 2 {
        return true;
    }
    let leaves = |i: usize| regions[i].1.leaves();
    // (next leaf's code, region, its position), smallest code first.
    let mut heap: BinaryHeap<Reverse<(u64, usize, usize)>> = (0..regions.len())
        .filter_map(|i| leaves(i).first().map(|l| Reverse((l.code(), i, 0))))
        .collect();
    let mut end = 0u64;
    let mut first = true;
    while let Some(Reverse((code, i, k))) = heap.pop() {
        if !first && code < end {
            return false;
        }
        first = false;
        // Within a region the leaves are disjoint and sorted: take its run while
        // no other region's next leaf comes first.
        let run = leaves(i);
        let next_other = heap.peek().map_or(u64::MAX, |r| r.0 .0);
        let mut k = k;
        end = run[k].end();
        while let Some(l) = run.get(k + 1).filter(|l| l.code() < next_other) {
            end = l.end();
            k += 1;
        }
        if let Some(l) = run.get(k + 1) {
            heap.push(Reverse((l.code(), i, k + 1)));
        }
    }
    true
}
