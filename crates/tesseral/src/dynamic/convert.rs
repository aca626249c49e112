//! Conversions: voxels, to and from linear octrees, and cell classification.

#[allow(unused_imports)]
use super::*;

impl DynamicOctree {
    // ----- conversions ------------------------------------------------------------------

    /// Calls `f(min_offsets, size_log2, full_block)` for every uniform full octant
    /// (`full_block = None`) and every stored block (`Some(bits)`), in tesseral order.
    pub(super) fn visit<F: FnMut([u64; 3], u32, Option<&[u64; 8]>)>(&self, mut f: F) {
        if self.root == EMPTY {
            return;
        }
        let mut stack = vec![(self.root, self.phys_log2(), [0u64; 3])];
        while let Some((slot, level, base)) = stack.pop() {
            match slot {
                EMPTY => {}
                FULL => f(base, level, None),
                _ if level > LEAF_LOG2 => {
                    let ch = &self.nodes[slot as usize].child;
                    let h = level - 1;
                    for ci in (0..8).rev() {
                        if ch[ci] != EMPTY {
                            let b = [
                                base[0] | ((ci as u64 & 1) << h),
                                base[1] | ((ci as u64 >> 1 & 1) << h),
                                base[2] | ((ci as u64 >> 2 & 1) << h),
                            ];
                            stack.push((ch[ci], h, b));
                        }
                    }
                }
                _ => f(base, LEAF_LOG2, Some(&self.block_words(slot))),
            }
        }
    }

    /// Every black voxel, in tesseral (Morton) order relative to the root corner.
    /// O(voxels + nodes): full octants are enumerated voxel by voxel, so for large
    /// solids prefer [`DynamicOctree::to_linear`], whose cost follows the surface.
    ///
    /// ```
    /// let t = tesseral::dynamic::DynamicOctree::from_voxels([[1, 0, 0], [0, 0, 0]]);
    /// assert_eq!(t.voxels(), vec![[0, 0, 0], [1, 0, 0]]);
    /// ```
    #[must_use]
    pub fn voxels(&self) -> Vec<Voxel> {
        let mut out = Vec::with_capacity(usize::try_from(self.voxels.min(1 << 24)).unwrap_or(0));
        self.visit(|base, level, bits| match bits {
            None => {
                let side = 1u64 << level;
                for ci in 0..side * side * side {
                    let [x, y, z] = crate::code::decode(ci);
                    out.push(self.world([
                        base[0] + u64::from(x),
                        base[1] + u64::from(y),
                        base[2] + u64::from(z),
                    ]));
                }
            }
            Some(l) => {
                for ci in 0..512u64 {
                    let [x, y, z] = crate::code::decode(ci);
                    if l[z as usize] >> (x + 8 * y) & 1 == 1 {
                        out.push(self.world([
                            base[0] + u64::from(x),
                            base[1] + u64::from(y),
                            base[2] + u64::from(z),
                        ]));
                    }
                }
            }
        });
        out
    }

    /// Builds a tree (without face bookkeeping) from a linear octree: each black leaf
    /// becomes a full slot (or bits of a block), so a solid costs its surface, not its
    /// volume. O(leaves · depth).
    ///
    /// ```
    /// use tesseral::{dynamic::DynamicOctree, linear::LinearOctree};
    /// let cube = (0..4).flat_map(|x| (0..4).flat_map(move |y| (0..4).map(move |z| [x, y, z])));
    /// let lin = LinearOctree::from_voxels(5, [-8, -8, -8], cube).unwrap();
    /// let t = DynamicOctree::from_linear(&lin);
    /// assert_eq!(t.voxel_count(), 64);
    /// assert_eq!((t.root_min(), t.root_size_log2()), ([0, 0, 0], 2));
    /// t.assert_valid();
    /// ```
    #[must_use]
    pub fn from_linear(lin: &LinearOctree) -> Self {
        let mut t = Self::new();
        let count = lin.voxel_count();
        if count == 0 {
            return t;
        }
        t.root_min = lin.origin();
        t.size_log2 = u32::from(lin.depth());
        for leaf in lin.leaves() {
            let [x, y, z] = crate::code::decode(leaf.code());
            t.fill_aligned(
                [u64::from(x), u64::from(y), u64::from(z)],
                u32::from(leaf.size_log2()),
            );
        }
        t.voxels = count;
        t.contract();
        t.rebuild_dir();
        t
    }

    /// The voxels of this tree inside the window `[origin, origin + 2^depth)³` as a
    /// linear octree. Built top-down with [`LinearOctree::from_classifier`], each cell
    /// classified by [`DynamicOctree::classify`], so the cost follows the surface.
    ///
    /// # Errors
    /// [`OctreeError::DepthTooLarge`] when `depth` exceeds [`crate::linear::MAX_DEPTH`].
    ///
    /// ```
    /// use tesseral::dynamic::DynamicOctree;
    /// let t = DynamicOctree::from_voxels([[0, 0, 0], [1, 0, 0], [100, 0, 0]]);
    /// let lin = t.to_linear(2, [-1, -1, -1]).unwrap(); // a 4³ window: [100, 0, 0] is cut
    /// assert_eq!(lin.voxel_count(), 2);
    /// ```
    pub fn to_linear(&self, depth: u8, origin: Voxel) -> Result<LinearOctree, OctreeError> {
        LinearOctree::from_classifier(depth, origin, self)
    }

    /// Whether the cube `[min, min + 2^size_log2)³` (any alignment) is all black
    /// (`Inside`), all white (`Outside`) or mixed (`Partial`). A stored node always
    /// holds both colours, so the search stops at every node that lies wholly inside
    /// the cube: the cost follows the cube's boundary. A single voxel is never
    /// `Partial`.
    ///
    /// ```
    /// use tesseral::{dynamic::DynamicOctree, linear::CellClass};
    /// let t = DynamicOctree::from_voxels([[0, 0, 0], [1, 0, 0]]);
    /// assert_eq!(t.classify([0, 0, 0], 0), CellClass::Inside);
    /// assert_eq!(t.classify([0, 0, 0], 1), CellClass::Partial);
    /// assert_eq!(t.classify([2, 0, 0], 1), CellClass::Outside);
    /// ```
    #[must_use]
    pub fn classify(&self, min: Voxel, size_log2: u8) -> CellClass {
        if self.root == EMPTY {
            return CellClass::Outside;
        }
        let side = 1i128 << size_log2.min(64);
        let k = self.size_log2;
        let modulus = 1i128 << 64;
        // Per axis: the cube's intervals in root offsets, clipped to the root
        // (a k = 64 root wraps, so an interval may split in two).
        let mut spans: [[(u128, u128); 2]; 3] = [[(0, 0); 2]; 3];
        let mut nspans = [0usize; 3];
        let mut outside = false;
        for a in 0..3 {
            let lo = i128::from(min[a]) - i128::from(self.root_min[a]);
            let hi = lo + side;
            if k >= 64 {
                let lo = lo.rem_euclid(modulus);
                let hi = lo + side.min(modulus);
                if hi <= modulus {
                    spans[a][0] = (lo as u128, hi as u128);
                    nspans[a] = 1;
                } else {
                    spans[a][0] = (lo as u128, modulus as u128);
                    spans[a][1] = (0, (hi - modulus) as u128);
                    nspans[a] = 2;
                }
            } else {
                let root = 1i128 << k;
                let (clo, chi) = (lo.max(0), hi.min(root));
                if lo < 0 || hi > root {
                    outside = true;
                }
                if clo < chi {
                    spans[a][0] = (clo as u128, chi as u128);
                    nspans[a] = 1;
                }
            }
        }
        let (mut black, mut white) = (false, outside);
        'boxes: for i in 0..nspans[0] {
            for j in 0..nspans[1] {
                for l in 0..nspans[2] {
                    let b = [spans[0][i], spans[1][j], spans[2][l]];
                    let (bl, wh) = self.probe(self.root, self.phys_log2(), [0; 3], b);
                    black |= bl;
                    white |= wh;
                    if black && white {
                        break 'boxes;
                    }
                }
            }
        }
        match (black, white) {
            (true, false) => CellClass::Inside,
            (false, _) => CellClass::Outside,
            (true, true) => CellClass::Partial,
        }
    }

    /// (any black, any white) in the intersection of cell (`slot`, `level`, `base`)
    /// with the box `b` (half-open offset intervals per axis).
    pub(super) fn probe(
        &self,
        slot: u32,
        level: u32,
        base: [u128; 3],
        b: [(u128, u128); 3],
    ) -> (bool, bool) {
        let size = 1u128 << level;
        let mut inside = true;
        for a in 0..3 {
            let (lo, hi) = (b[a].0.max(base[a]), b[a].1.min(base[a] + size));
            if lo >= hi {
                return (false, false);
            }
            inside &= lo == base[a] && hi == base[a] + size;
        }
        match slot {
            EMPTY => (false, true),
            FULL => (true, false),
            // A stored node or block holds both colours (checked by assert_valid).
            _ if inside => (true, true),
            _ if level > LEAF_LOG2 => {
                let ch = &self.nodes[slot as usize].child;
                let h = size >> 1;
                let (mut black, mut white) = (false, false);
                for (ci, &c) in ch.iter().enumerate() {
                    let cb = [
                        base[0] + (ci as u128 & 1) * h,
                        base[1] + (ci as u128 >> 1 & 1) * h,
                        base[2] + (ci as u128 >> 2 & 1) * h,
                    ];
                    let (bl, wh) = self.probe(c, level - 1, cb, b);
                    black |= bl;
                    white |= wh;
                    if black && white {
                        break;
                    }
                }
                (black, white)
            }
            _ => {
                let l = self.block_words(slot);
                let r: [(u128, u128); 3] = std::array::from_fn(|a| {
                    (
                        b[a].0.max(base[a]) - base[a],
                        b[a].1.min(base[a] + 8) - base[a],
                    )
                });
                let row = ((1u64 << (r[0].1 - r[0].0)) - 1) << r[0].0;
                let plane = (r[1].0..r[1].1).fold(0u64, |p, y| p | row << (8 * y));
                let (mut black, mut white) = (false, false);
                for z in r[2].0..r[2].1 {
                    let w = l[z as usize] & plane;
                    black |= w != 0;
                    white |= w != plane;
                }
                (black, white)
            }
        }
    }
}

/// A dynamic octree classifies cells for [`LinearOctree::from_classifier`] (and so for
/// CSG scenes) through [`DynamicOctree::classify`].
impl Classifier for DynamicOctree {
    fn classify(&self, min: Voxel, size_log2: u8) -> CellClass {
        DynamicOctree::classify(self, min, size_log2)
    }
}
