//! Maps to and from [`Model`]s: the tree is the occupied cells, the free layer the
//! free ones, and the log-odds layer every known cell's value.

use std::collections::HashMap;

use super::sensor::UNKNOWN;
use super::{OccupancyError, OccupancyMap, SensorModel};
use crate::linear::{LinearOctree, MAX_DEPTH};
use crate::model::{Frame, Layer, Model};
use crate::Voxel;

impl OccupancyMap {
    /// The map as a model: frame of voxel size `resolution` with voxel `(0, 0, 0)` at
    /// the world origin; tree = occupied cells; `free` = free cells; `log_odds` =
    /// every known cell's log-odds.
    ///
    /// # Errors
    /// [`OccupancyError::Octree`] when the map spans more than a linear octree can
    /// (2^21 cells per axis).
    pub fn to_model(&self) -> Result<Model, OccupancyError> {
        let t = self.fixed.threshold;
        let mut occupied: Vec<Voxel> = Vec::new();
        let mut free: Vec<Voxel> = Vec::new();
        let mut by_value: HashMap<i16, Vec<Voxel>> = HashMap::new();
        let (mut lo, mut hi) = ([i64::MAX; 3], [i64::MIN; 3]);
        self.store.for_each(|c, v| {
            for a in 0..3 {
                lo[a] = lo[a].min(c[a]);
                hi[a] = hi[a].max(c[a]);
            }
            if v >= t {
                occupied.push(c);
            } else {
                free.push(c);
            }
            by_value.entry(v).or_default().push(c);
        });
        let frame = Frame::new(self.resolution, [0.0; 3]);
        if occupied.is_empty() && free.is_empty() {
            let empty = LinearOctree::empty(0, [0; 3])?;
            return Ok(Model::from_parts(
                empty.clone(),
                frame,
                None,
                Some(empty),
                Some(Layer::empty(0, [0; 3])),
            )?);
        }
        let extent = (0..3).map(|a| hi[a].abs_diff(lo[a]) + 1).max().unwrap_or(1);
        let depth = u8::try_from(extent.next_power_of_two().trailing_zeros()).unwrap_or(u8::MAX);
        if depth > MAX_DEPTH {
            return Err(OccupancyError::Model(format!(
                "the map spans {extent} cells, more than a model holds (2^{MAX_DEPTH})"
            )));
        }
        let last = (1i64 << depth) - 1;
        let origin = lo.map(|c| c.min(i64::MAX - last));
        let tree = LinearOctree::from_voxels(depth, origin, occupied)?;
        let free = LinearOctree::from_voxels(depth, origin, free)?;
        let mut regions = Vec::with_capacity(by_value.len());
        let mut values: Vec<_> = by_value.into_iter().collect();
        values.sort_unstable_by_key(|(v, _)| *v);
        for (v, cells) in values {
            debug_assert_ne!(v, UNKNOWN);
            regions.push((
                self.fixed.to_f32(v),
                LinearOctree::from_voxels(depth, origin, cells)?,
            ));
        }
        let layer = Layer::from_regions(depth, origin, regions)?;
        Ok(Model::from_parts(
            tree,
            frame,
            None,
            Some(free),
            Some(layer),
        )?)
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
