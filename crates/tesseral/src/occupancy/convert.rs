//! Maps to and from [`Model`]s: the tree is the occupied cells, the free layer the
//! free ones, and the log-odds layer every known cell's value.

use super::sensor::UNKNOWN;
use super::{OccupancyError, OccupancyMap, SensorModel};
use crate::linear::{Leaf, LinearOctree, MAX_DEPTH};
use crate::model::{Frame, Layer, Model};
use crate::Voxel;

impl OccupancyMap {
    /// Whether the map fits a model ([`to_model`](Self::to_model)): its blocks span
    /// at most 2^21 cells on each axis (anywhere in the `i64` range). A map past
    /// that is written as its own `.tess` ([`encode_tess_map`](Self::encode_tess_map)).
    #[must_use]
    pub fn fits_model(&self) -> bool {
        self.store
            .cell_bounds()
            .is_none_or(|(lo, hi)| space(lo, hi).is_ok())
    }

    /// The map as a model: frame of voxel size `resolution` with voxel `(0, 0, 0)` at
    /// the world origin; tree = occupied cells; `free` = free cells; `log_odds` =
    /// every known cell's log-odds. The space is an aligned cube holding the map's
    /// blocks (OctoMap's key cube, depth 16 from −32768, for a map across 0 inside
    /// OctoMap's range; see `space`).
    ///
    /// # Runtime
    /// O(b log b + k) for b blocks and k cells of blocks not uniform: the cells come
    /// in tesseral order (the store's `for_each_in_order`), so no
    /// cell is sorted.
    ///
    /// # Errors
    /// [`OccupancyError::Octree`] when the map spans more than a linear octree can
    /// (2^21 cells per axis).
    pub fn to_model(&self) -> Result<Model, OccupancyError> {
        let frame = Frame::new(self.resolution, [0.0; 3]);
        let Some((lo, hi)) = self.store.cell_bounds() else {
            let empty = LinearOctree::empty(0, [0; 3])?;
            return Ok(Model::from_parts(
                empty.clone(),
                frame,
                None,
                Some(empty),
                Some(Layer::empty(0, [0; 3])),
            )?);
        };
        let (depth, origin) = space(lo, hi)?;
        // The cells come in tesseral order: every part is built from sorted leaves,
        // each value's cells grouped through a table indexed by the value.
        let t = self.fixed.threshold;
        let (mut occupied, mut free) = (Vec::new(), Vec::new());
        let mut group = vec![u32::MAX; 1 << 16];
        let mut groups: Vec<(i16, Vec<Leaf>)> = Vec::new();
        self.store.for_each_in_order(origin, depth, |leaf, v| {
            debug_assert_ne!(v, UNKNOWN);
            if v >= t {
                occupied.push(leaf);
            } else {
                free.push(leaf);
            }
            let g = &mut group[usize::from(v as u16)];
            if *g == u32::MAX {
                *g = groups.len() as u32;
                groups.push((v, Vec::new()));
            }
            groups[*g as usize].1.push(leaf);
        });
        let tree = LinearOctree::from_sorted_leaves(depth, origin, occupied)?;
        let free = LinearOctree::from_sorted_leaves(depth, origin, free)?;
        let regions = groups
            .into_iter()
            .map(|(v, leaves)| {
                let region = LinearOctree::from_sorted_leaves(depth, origin, leaves)?;
                Ok((self.fixed.to_f32(v), region))
            })
            .collect::<Result<Vec<_>, OccupancyError>>()?;
        let layer = Layer::from_regions_unchecked(depth, origin, regions);
        // The model's invariants hold as built, so the parts are not put through
        // `Model::from_parts` (set operations over every leaf, a fifth of `tesseral
        // map`'s time writing the street's `.tess`): every part is in the one
        // space, a cell's value puts it in the tree or in `free`, never both, and in
        // the region of that value alone, so the regions cover the known cells
        // once. (`models_hold_every_cell_in_every_space` checks the model.)
        Ok(Model {
            tree,
            frame,
            colors: None,
            free: Some(free),
            log_odds: Some(layer),
        })
    }

    /// A map from a model with OctoMap's default sensor model: its frame's voxel
    /// size is the resolution (the frame must place voxel `(0, 0, 0)` at the world
    /// origin). Known cells take their log-odds when the model has them, else the
    /// upper clamp (occupied) or the lower clamp (free), as OctoMap reads a `.bt`.
    ///
    /// # Errors
    /// [`OccupancyError::Model`] for a frame not at the origin, or a log-odds value
    /// that contradicts its cell's state; [`OccupancyError::Resolution`].
    pub fn from_model(m: &Model) -> Result<Self, OccupancyError> {
        Self::from_model_with(m, SensorModel::octomap())
    }

    /// [`from_model`](Self::from_model) with a given sensor model.
    ///
    /// # Errors
    /// As [`from_model`](Self::from_model).
    pub fn from_model_with(m: &Model, sensor: SensorModel) -> Result<Self, OccupancyError> {
        if m.frame.translate != [0.0; 3] {
            return Err(OccupancyError::Model(format!(
                "the frame places voxel (0, 0, 0) at {:?}, not at the world origin",
                m.frame.translate
            )));
        }
        let mut map = Self::new(m.frame.voxel_size, sensor)?;
        let (lo, hi) = (map.fixed.min, map.fixed.max);
        let value = |v: Voxel, default: i16| -> i16 {
            m.log_odds
                .as_ref()
                .and_then(|l| l.get(v))
                .map_or(default, |l| map.fixed.quantise(l))
        };
        let mut cells: Vec<([i64; 3], i16)> = Vec::new();
        for v in m.tree.voxels() {
            cells.push((v, value(v, hi)));
        }
        for v in m.free.iter().flat_map(LinearOctree::voxels) {
            cells.push((v, value(v, lo)));
        }
        let t = map.fixed.threshold;
        let occupied = m.tree.voxel_count() as usize;
        for (i, &(v, x)) in cells.iter().enumerate() {
            if (i < occupied) != (x >= t) {
                return Err(OccupancyError::Model(format!(
                    "voxel {v:?} is {} but its log-odds {} says otherwise",
                    if i < occupied { "occupied" } else { "free" },
                    map.fixed.to_f32(x)
                )));
            }
        }
        let fixed = map.fixed;
        for (v, x) in cells {
            map.store.set(v, x, fixed);
        }
        map.store.settle();
        Ok(map)
    }
}

/// The space of a map's model, for whole blocks of cells `lo..=hi` (`lo` a multiple
/// of 8 on each axis, `hi` 7 more than one; so the space is at least a block): the
/// smallest cube whose corner is a multiple of its side on each axis (a node of the
/// octree of every power-of-two grid through the origin, OctoMap's among them), or
/// OctoMap's whole key cube (cells −32768..32767, depth 16) for a map across 0
/// inside it. Writing `.bt` or `.ot` then moves each leaf's code by a constant
/// ([`crate::io::reframe`]'s fast path), where a space from `lo` would cut leaves
/// and sort them again. A map beyond OctoMap's keys takes the smallest cube from
/// `lo`.
fn space(lo: [i64; 3], hi: [i64; 3]) -> Result<(u8, [i64; 3]), OccupancyError> {
    use crate::io::octomap::{in_key_range, KEY_ORIGIN, OCTOMAP_DEPTH};
    debug_assert!((0..3).all(|a| lo[a].rem_euclid(8) == 0 && hi[a].rem_euclid(8) == 7));
    let extent = (0..3).map(|a| hi[a].abs_diff(lo[a]) + 1).max().unwrap_or(8);
    let least = u8::try_from(extent.next_power_of_two().trailing_zeros()).unwrap_or(u8::MAX);
    if least > MAX_DEPTH {
        return Err(OccupancyError::Model(format!(
            "the map spans {extent} cells, more than a model holds (2^{MAX_DEPTH}); \
             its own .tess keeps it whole (OccupancyMap::write_file)"
        )));
    }
    for d in least..OCTOMAP_DEPTH {
        if (0..3).all(|a| lo[a] >> d == hi[a] >> d) {
            return Ok((d, lo.map(|c| c >> d << d)));
        }
    }
    if in_key_range(lo) && in_key_range(hi) {
        return Ok((OCTOMAP_DEPTH, [KEY_ORIGIN; 3]));
    }
    let last = (1i64 << least) - 1;
    Ok((least, lo.map(|c| c.min(i64::MAX - last))))
}
