//! Maps straight to OctoMap files: the store's blocks in key order, streamed into
//! the `.bt`/`.ot` writer (`io::octomap::stream`), with no model in between.

use std::path::Path;

use super::{OccupancyError, OccupancyMap};
use crate::io::native::MAP_MAGIC;
use crate::io::octomap::stream::{Kind, Piece, Writer, UNSET_RGB};
use crate::io::octomap::{bt_file, in_key_range, ot_file, KEY_ORIGIN, OCTOMAP_DEPTH};
use crate::io::FormatError;

impl OccupancyMap {
    /// The map as a `.bt` file's bytes: every known cell occupied or free, as
    /// OctoMap's `writeBinary` (maximum likelihood, pruned by state). The same bytes
    /// as [`crate::io::octomap::encode_bt`] of [`to_model`](Self::to_model), without
    /// building the model.
    ///
    /// # Runtime
    /// O(b log b + k) for b blocks and k cells of blocks not uniform.
    ///
    /// # Errors
    /// [`OccupancyError::KeyRange`] for a map past OctoMap's keys (cells
    /// −32768..32767 on each axis).
    pub fn encode_bt(&self) -> Result<Vec<u8>, OccupancyError> {
        let (data, nodes) = self.encode(Kind::Bt)?;
        Ok(bt_file(self.resolution, nodes, &data))
    }

    /// The map as an `.ot` file's bytes: every known cell's log-odds, inner nodes
    /// the maximum of their children's, pruned where eight children hold one value
    /// (as OctoMap's tree after `insertPointCloud`). The same bytes as
    /// [`crate::io::octomap::encode_ot`] of [`to_model`](Self::to_model).
    ///
    /// # Runtime
    /// As [`encode_bt`](Self::encode_bt).
    ///
    /// # Errors
    /// As [`encode_bt`](Self::encode_bt).
    pub fn encode_ot(&self) -> Result<Vec<u8>, OccupancyError> {
        let (data, nodes) = self.encode(Kind::Ot { colour: false })?;
        Ok(ot_file(false, self.resolution, nodes, &data))
    }

    /// The map's file bytes in format `ext` when it is OctoMap's (`bt` or `ot`:
    /// [`encode_bt`](Self::encode_bt), [`encode_ot`](Self::encode_ot)); `None`
    /// for any other format, which is written through [`to_model`](Self::to_model).
    ///
    /// # Errors
    /// As [`encode_bt`](Self::encode_bt).
    pub fn encode_octomap(&self, ext: &str) -> Option<Result<Vec<u8>, OccupancyError>> {
        match ext {
            "bt" => Some(self.encode_bt()),
            "ot" => Some(self.encode_ot()),
            _ => None,
        }
    }

    /// The map's file bytes in format `ext` where they come straight from its
    /// blocks: OctoMap's `.bt` and `.ot` ([`encode_octomap`](Self::encode_octomap)),
    /// and its own `.tess` ([`encode_tess_map`](Self::encode_tess_map)) for a map
    /// that does not [fit a model](Self::fits_model); `None` for any other, which
    /// is written through [`to_model`](Self::to_model).
    ///
    /// # Errors
    /// As [`encode_bt`](Self::encode_bt).
    pub fn encode_direct(&self, ext: &str) -> Option<Result<Vec<u8>, OccupancyError>> {
        match ext {
            "tess" if !self.fits_model() => Some(Ok(self.encode_tess_map())),
            _ => self.encode_octomap(ext),
        }
    }

    /// Writes the map, atomically, in the format named by the extension: `.bt`,
    /// `.ot`, and `.tess` of a map wider than a model, straight from its blocks
    /// ([`encode_direct`](Self::encode_direct)); any other through
    /// [`to_model`](Self::to_model).
    ///
    /// # Errors
    /// [`FormatError::Unsupported`] for a map the format cannot hold (past
    /// OctoMap's keys; past a model's extent, in a format other than `.tess`),
    /// named with the path; the errors of [`crate::io::write_model`].
    pub fn write_file(&self, path: &Path) -> Result<(), FormatError> {
        let cannot = |e: OccupancyError| FormatError::unsupported(e.to_string()).with_path(path);
        match self.encode_direct(&crate::io::extension(path)) {
            Some(bytes) => {
                let bytes = bytes.map_err(cannot)?;
                crate::io::write_atomic(path, |w| w.write_all(&bytes))
            }
            None => crate::io::write_model(path, &self.to_model().map_err(cannot)?),
        }
    }

    /// Reads a map: a map's own `.tess` ([`decode_tess_map`](Self::decode_tess_map)),
    /// or any model file ([`from_model`](Self::from_model): OctoMap's sensor model).
    ///
    /// # Errors
    /// The reader's [`FormatError`], named with the path;
    /// [`FormatError::Unsupported`] for a model that is no map (see
    /// [`from_model`](Self::from_model)).
    pub fn read_file(path: &Path) -> Result<Self, FormatError> {
        if let Some(bytes) = crate::io::wide::read_if(path, &MAP_MAGIC)? {
            return Self::decode_tess_map(&bytes).map_err(|e| e.with_path(path));
        }
        let model = crate::io::read_model(path)?;
        Self::from_model(&model)
            .map_err(|e| FormatError::unsupported(e.to_string()).with_path(path))
    }

    /// The data section of a `kind` file and its node count.
    fn encode(&self, kind: Kind) -> Result<(Vec<u8>, u64), OccupancyError> {
        let mut w = Writer::new(kind);
        let Some((lo, hi)) = self.store.cell_bounds() else {
            return Ok(w.finish());
        };
        if !(in_key_range(lo) && in_key_range(hi)) {
            return Err(OccupancyError::KeyRange { lo, hi });
        }
        let (t, fixed) = (self.fixed.threshold, self.fixed);
        let origin = [KEY_ORIGIN; 3];
        self.store
            .for_each_in_order(origin, OCTOMAP_DEPTH, |leaf, v| {
                w.push(Piece {
                    leaf,
                    occupied: v >= t,
                    value: fixed.to_f32(v),
                    rgb: UNSET_RGB,
                });
            });
        Ok(w.finish())
    }
}
