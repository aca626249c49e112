//! Occupancy maps built from range scans, with OctoMap's semantics.
//!
//! A cell is *unknown*, *free* or *occupied*; a known cell keeps a log-odds value,
//! updated by OctoMap's sensor model ([`SensorModel::octomap`]) and clamped.
//! [`OccupancyMap::insert_scan`] follows OctoMap's `insertPointCloud`: cell `i` spans
//! `[i·res, (i+1)·res)`; the cells a segment from the sensor origin to a point
//! crosses are missed and the point's cell is hit; a cell both hit and missed in one
//! scan is only hit; each cell is updated at most once per scan; a point beyond the
//! maximum range clears its ray up to that range and records no hit; NaN and
//! infinite points, and rays that would end past ±2^61 cells, are skipped and
//! counted.
//!
//! # Layout
//! Cell keys are `i64` per axis, so the map is unbounded. Cells are grouped in
//! 8×8×8 blocks (the bit-block size of [`crate::dynamic::DynamicOctree`]), found
//! through a two-level directory: superblocks (8×8×8 blocks; found by index
//! arithmetic in a dense array over their bounding box, or through a hash map when
//! they lie far apart), each a flat table of 512 four-byte block entries. A block is *uniform* (all 512 cells
//! clamped to the same value: the entry alone, as OctoMap prunes), *sparse* (its
//! known cells, 2 bytes each, and up to six distinct values), a *palette* (1, 2, 4
//! or 8 bits a cell and a list of the values) or *dense* (512 log-odds), whichever
//! is smallest, in one of two arenas (blocks that list an occupied value, and the
//! others, so that the surfaces most lookups land on lie together); log-odds are
//! `i16` fixed point.
//! Unknown blocks are not stored. See `ARCHITECTURE.md` for why.
//!
//! ```
//! use tesseral::occupancy::{CellState, OccupancyMap, SensorModel};
//! let mut map = OccupancyMap::new(0.1, SensorModel::octomap()).unwrap();
//! let stats = map.insert_scan([0.05, 0.05, 0.05], &[[1.05, 0.05, 0.05]], None);
//! assert_eq!((stats.rays, stats.hits, stats.misses), (1, 1, 10));
//! assert_eq!(map.state([10, 0, 0]), CellState::Occupied);
//! assert_eq!(map.state([3, 0, 0]), CellState::Free);
//! assert_eq!(map.state([11, 0, 0]), CellState::Unknown);
//! map.assert_valid();
//! ```

mod convert;
mod dda;
mod far;
mod octomap;
mod ray;
mod scan;
mod scan_order;
mod sensor;
mod store;
mod tess_map;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_clamped;
#[cfg(test)]
mod tests_dense;
#[cfg(test)]
mod tests_flat;
#[cfg(test)]
mod tests_lookup;
#[cfg(test)]
mod tests_map;
#[cfg(test)]
mod tests_ray;
#[cfg(test)]
mod tests_store;
#[cfg(test)]
mod tests_tess_map;
mod work;

pub use sensor::{log_odds, probability, Pose, SensorModel};
pub use work::ScanWork;

use sensor::{Fixed, UNKNOWN};
use store::Store;

/// What can go wrong building or converting a map.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum OccupancyError {
    /// The resolution is not a positive finite number.
    #[error("resolution {0} must be a positive finite number")]
    Resolution(f64),
    /// A sensor-model parameter is out of range.
    #[error("sensor model: {0}")]
    Sensor(String),
    /// A model cannot be read as a map (its frame, or its extent).
    #[error("model: {0}")]
    Model(String),
    /// The map's blocks outgrew the most one of its two arenas addresses (4 GiB of
    /// blocks each, as far as a block entry's offset reaches): the updates of the
    /// blocks that did not fit were dropped, the map is otherwise valid.
    #[error(
        "the map's blocks would pass {limit_bytes} bytes in one of its two arenas, \
         the most an arena addresses: \
         some updates were dropped (use a coarser resolution or a shorter max range, \
         or split the scans into several maps)"
    )]
    Capacity {
        /// The limit, in bytes of blocks.
        limit_bytes: usize,
    },
    /// The octree operation failed.
    #[error(transparent)]
    Octree(#[from] crate::linear::OctreeError),
    /// The map reaches past OctoMap's keys, so it has no `.bt` or `.ot`.
    #[error(
        "the map's blocks reach cells {lo:?} to {hi:?}, past OctoMap's keys \
         (cells −32768..32767 on each axis); .tess keeps the full range"
    )]
    KeyRange {
        /// The lowest cell of the map's blocks.
        lo: [i64; 3],
        /// The highest.
        hi: [i64; 3],
    },
}

/// What one scan did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ScanStats {
    /// Points given.
    pub points: u64,
    /// Rays cast (points that are finite).
    pub rays: u64,
    /// Points skipped: a coordinate NaN or infinite, or the ray's end (the point,
    /// or where the maximum range cuts the ray) past ±2^61 cells on an axis (or
    /// every point, for such a sensor origin).
    pub skipped: u64,
    /// Cells updated as hits (each once).
    pub hits: u64,
    /// Cells updated as misses (each once, none of them hit), not counting the
    /// cells of blocks that the map held clamped free (all 512 cells at the lower
    /// clamp), which a miss leaves unchanged.
    pub misses: u64,
}

/// The cells a map knows, by state, and its stored entries
/// ([`OccupancyMap::counts`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct CellCounts {
    /// Known cells at or above the threshold.
    pub occupied: u64,
    /// Known cells below the threshold.
    pub free: u64,
    /// Entries: one per uniform block, one per known cell of another block (see
    /// [`OccupancyMap::leaf_count`]).
    pub leaves: u64,
}

/// A cell's state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CellState {
    /// Never observed.
    Unknown,
    /// Known, log-odds below the threshold.
    Free,
    /// Known, log-odds at or above the threshold.
    Occupied,
}

/// An unbounded occupancy map: see the [module docs](self).
#[derive(Clone)]
pub struct OccupancyMap {
    resolution: f64,
    sensor: SensorModel,
    fixed: Fixed,
    store: Store,
}

impl std::fmt::Debug for OccupancyMap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("OccupancyMap")
            .field("resolution", &self.resolution)
            .field("sensor", &self.sensor)
            .field("blocks", &self.store.block_count())
            .finish()
    }
}

impl OccupancyMap {
    /// An empty map with cells of side `resolution` (world units).
    ///
    /// # Errors
    /// [`OccupancyError::Resolution`] unless `resolution` is positive and finite.
    pub fn new(resolution: f64, sensor: SensorModel) -> Result<Self, OccupancyError> {
        if !(resolution.is_finite() && resolution > 0.0) {
            return Err(OccupancyError::Resolution(resolution));
        }
        Ok(Self {
            resolution,
            sensor,
            fixed: Fixed::new(&sensor),
            store: Store::default(),
        })
    }

    /// The side of a cell, in world units.
    #[must_use]
    pub fn resolution(&self) -> f64 {
        self.resolution
    }

    /// The sensor model.
    #[must_use]
    pub fn sensor(&self) -> &SensorModel {
        &self.sensor
    }

    /// The cell holding a world point (OctoMap's `coordToKey`: `floor(p / res)`,
    /// computed as `p × (1 / res)`).
    #[must_use]
    pub fn cell_of(&self, p: [f64; 3]) -> [i64; 3] {
        let inv = 1.0 / self.resolution;
        p.map(|c| (c * inv).floor() as i64)
    }

    /// A cell's state.
    ///
    /// # Runtime
    /// O(1): the block's entry found by index arithmetic in the read index over the
    /// blocks' bounding box (or, while that is not built, through the superblock
    /// directory: index arithmetic or one hash probe, then a table load), then one
    /// or two loads in the block (compares over a sparse block's cells).
    #[must_use]
    #[inline]
    pub fn state(&self, cell: [i64; 3]) -> CellState {
        match self.store.get(cell) {
            UNKNOWN => CellState::Unknown,
            v if v >= self.fixed.threshold => CellState::Occupied,
            _ => CellState::Free,
        }
    }

    /// A known cell's log-odds (a multiple of the fixed-point step).
    #[must_use]
    #[inline]
    pub fn log_odds(&self, cell: [i64; 3]) -> Option<f32> {
        match self.store.get(cell) {
            UNKNOWN => None,
            v => Some(self.fixed.to_f32(v)),
        }
    }

    /// The log-odds of many cells, as [`log_odds`](Self::log_odds) gives them one by
    /// one, into `out`. On a map bigger than the CPU's caches (more than 32 MiB) the
    /// cells are looked up in batches whose memory accesses are prefetched
    /// together, so that their cache misses overlap; on a smaller one, where that
    /// costs more than it saves, it is that loop.
    ///
    /// # Runtime
    /// O(n), with the cost of one lookup as [`state`](Self::state).
    ///
    /// # Panics
    /// When `cells` and `out` differ in length.
    ///
    /// ```
    /// use tesseral::occupancy::{OccupancyMap, SensorModel};
    /// let mut map = OccupancyMap::new(0.1, SensorModel::octomap()).unwrap();
    /// map.insert_scan([0.05, 0.05, 0.05], &[[1.05, 0.05, 0.05]], None);
    /// let cells = [[10, 0, 0], [3, 0, 0], [11, 0, 0]];
    /// let mut out = [None; 3];
    /// map.log_odds_many(&cells, &mut out);
    /// assert_eq!(out, cells.map(|c| map.log_odds(c)));
    /// ```
    pub fn log_odds_many(&self, cells: &[[i64; 3]], out: &mut [Option<f32>]) {
        assert_eq!(cells.len(), out.len(), "as many values as cells");
        let mut values = [UNKNOWN; store::BATCH];
        let passes = self.store.prefetches();
        for (cells, out) in cells.chunks(store::BATCH).zip(out.chunks_mut(store::BATCH)) {
            let values = &mut values[..cells.len()];
            self.store.get_many(cells, values, passes);
            for (o, &v) in out.iter_mut().zip(values.iter()) {
                *o = (v != UNKNOWN).then(|| self.fixed.to_f32(v));
            }
        }
    }

    /// Whether every update so far was stored.
    ///
    /// # Errors
    /// [`OccupancyError::Capacity`] once a block was refused because the map's blocks
    /// would pass 4 GiB in one of its two arenas (the most a block entry addresses:
    /// those of occupied surfaces, and the others): the updates to that block
    /// were dropped, the map is otherwise valid. Check after each scan.
    pub fn check_capacity(&self) -> Result<(), OccupancyError> {
        if self.store.overflowed() {
            return Err(OccupancyError::Capacity {
                limit_bytes: self.store.limit_bytes(),
            });
        }
        Ok(())
    }

    /// Sets a cell's log-odds (clamped), or forgets it with `None`.
    ///
    /// A cell in a new block outside the bounding box of the map's blocks retires
    /// the read index that lookups use: they go through the superblock directory
    /// (a little slower) until the next scan inserted rebuilds it.
    pub fn set_log_odds(&mut self, cell: [i64; 3], l: Option<f32>) {
        let v = l.map_or(UNKNOWN, |l| self.fixed.quantise(l));
        self.store.set(cell, v, self.fixed);
    }

    /// The numbers of occupied and free cells and of stored entries, counted in
    /// one pass over the map (each of [`occupied_count`](Self::occupied_count),
    /// [`free_count`](Self::free_count) and [`leaf_count`](Self::leaf_count)
    /// makes that pass for one of them).
    ///
    /// # Runtime
    /// O(b + k) for b blocks stored and k cells in blocks that are not uniform; no
    /// block is decoded (a palette's cells are counted by popcounts).
    #[must_use]
    pub fn counts(&self) -> CellCounts {
        self.store.census(self.fixed.threshold)
    }

    /// The number of occupied cells.
    #[must_use]
    pub fn occupied_count(&self) -> u64 {
        self.counts().occupied
    }

    /// The number of free cells.
    #[must_use]
    pub fn free_count(&self) -> u64 {
        self.counts().free
    }

    /// The number of stored entries: one per uniform block, one per known cell of a
    /// sparse or dense block (what OctoMap's leaf count is after pruning, at block grain).
    #[must_use]
    pub fn leaf_count(&self) -> u64 {
        self.counts().leaves
    }

    /// The number of 8×8×8 blocks stored (uniform, sparse and dense).
    #[must_use]
    pub fn block_count(&self) -> usize {
        self.store.block_count()
    }

    /// The lowest and highest cells of the box of the map's blocks (whole 8³
    /// blocks, so it may reach up to 7 cells past the known ones); `None` when the
    /// map is empty.
    #[must_use]
    pub fn block_bounds(&self) -> Option<([i64; 3], [i64; 3])> {
        self.store.cell_bounds()
    }

    /// Bytes held by the map (capacities, not lengths).
    #[must_use]
    pub fn bytes(&self) -> usize {
        std::mem::size_of::<Self>() + self.store.bytes()
    }

    /// Packs the map's storage as the end of
    /// [`insert_scans`](Self::insert_scans) does: blocks left as wide palettes by
    /// the scans since become patched palettes where that is smaller, and the
    /// arenas are compacted where an eighth of their bytes hold no block. For a
    /// map built by a loop of [`insert_scan`](Self::insert_scan), which does not.
    /// The cells are unchanged.
    ///
    /// # Runtime
    /// O(512 n + u) for n blocks left as wide palettes and u units of the arenas
    /// compacted.
    pub fn shrink_to_fit(&mut self) {
        self.store.pack(self.fixed);
    }

    /// Every known cell and its log-odds, sorted by cell.
    #[must_use]
    pub fn cells(&self) -> Vec<([i64; 3], f32)> {
        let mut out: Vec<([i64; 3], f32)> = Vec::new();
        self.store
            .for_each(|c, v| out.push((c, self.fixed.to_f32(v))));
        out.sort_unstable_by_key(|&(c, _)| c);
        out
    }

    /// Checks the invariants: the directory and its tables agree; every uniform
    /// block is clamped; no block is all unknown or uniformly clamped; each arena's
    /// blocks and free chunks tile it without overlap; a block lies in the arena of
    /// surfaces if and only if it lists an occupied value; sparse blocks list their cells
    /// in order; palette numbers lie in their value lists; every known value lies in
    /// the clamps.
    ///
    /// # Panics
    /// When an invariant is broken.
    pub fn assert_valid(&self) {
        self.store.assert_valid(self.fixed);
    }
}

/// Asks the CPU (shared by the scan's block updates and the store's lookups) to bring the cache line of `x` in (a hint: no effect on results).
#[inline(always)]
pub(crate) fn prefetch<T>(x: &T) {
    // SAFETY: SSE is part of every x86_64 CPU, and a prefetch reads nothing (the
    // address is that of a live reference anyway).
    #[cfg(target_arch = "x86_64")]
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(
            (x as *const T).cast(),
        );
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = x;
}
