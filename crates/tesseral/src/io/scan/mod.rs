//! Range scans: point clouds with the pose of the sensor that took them, the input of
//! occupancy mapping (`tesseral map`).
//!
//! | extension | format | module |
//! |---|---|---|
//! | `.graph` | OctoMap's binary scan graph (what `graph2tree` reads): scans, each with a 6-DoF pose | [`graph`] |
//! | `.log` | OctoMap's text log (what `log2graph` reads): `NODE x y z roll pitch yaw`, then `x y z` lines | [`log`] |
//! | `.xyz` | one point per line, `x y z` floats (more columns are ignored) | [`cloud`] |
//! | `.ply` | the `vertex` element's `x y z` (ASCII or binary) | [`cloud`] |
//! | `.pcd` | PCL point clouds (ASCII or binary; the `VIEWPOINT` is the sensor origin) | [`pcd`] |
//!
//! Decoders take bytes and know no path; their errors name the line and column or
//! the byte offset (counted from the start of the file), and [`read`] attaches the
//! file. Text may start with a UTF-8 byte order mark, which is skipped; a number
//! whose literal overflows its type (`1e400`) is an error, not an infinity. Whatever a header claims, no
//! decoder allocates more than the input's own size allows (a count is checked
//! against the bytes left before anything is reserved) and none returns more than
//! [`MAX_SCAN_POINTS`] points.

pub mod cloud;
pub mod graph;
pub mod log;
mod lzf_decode;
pub mod pcd;
mod pcd_data;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_faults;

use std::borrow::Cow;
use std::path::Path;

use super::FormatError;

/// The most points one file may hold (24 bytes each in memory, 1.5 GiB at the cap).
pub const MAX_SCAN_POINTS: usize = 1 << 26;

/// The extensions [`read`] understands.
pub const SCAN_EXTENSIONS: &str = "graph, log, xyz, ply, pcd";

/// In which frame a [`ScanRecord`]'s points are given.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PointFrame {
    /// The points are in the sensor's frame: the pose (translation, then OctoMap's
    /// roll, pitch, yaw) carries them into the world, and the sensor sits at the
    /// translation.
    #[default]
    Sensor,
    /// The points are already in world coordinates; the translation is the sensor
    /// origin and the rotation is unused (zero). A PCD file's `VIEWPOINT` gives this.
    World,
}

/// One scan: the sensor pose and the points it measured.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ScanRecord {
    /// The sensor position (world units).
    pub translation: [f64; 3],
    /// Roll, pitch and yaw in radians, OctoMap's convention: the rotation
    /// `Rz(yaw)·Ry(pitch)·Rx(roll)`.
    pub rpy: [f64; 3],
    /// The measured end points. Non-finite points are kept: mapping skips and counts
    /// them.
    pub points: Vec<[f64; 3]>,
    /// In which frame [`points`](Self::points) are given.
    pub frame: PointFrame,
}

impl ScanRecord {
    /// Places the scan as `placement` says, over what its file said.
    ///
    /// ```
    /// use tesseral::io::scan::{Placement, PointFrame, ScanRecord};
    /// let mut s = ScanRecord { points: vec![[1.0, 0.0, 0.0]], ..Default::default() };
    /// s.place(Placement::Origin([0.0, 0.0, 2.0]));
    /// assert_eq!((s.frame, s.translation), (PointFrame::World, [0.0, 0.0, 2.0]));
    /// ```
    pub fn place(&mut self, placement: Placement) {
        match placement {
            Placement::AsRead => {}
            Placement::Origin(o) => {
                self.translation = o;
                self.rpy = [0.0; 3];
                self.frame = PointFrame::World;
            }
            Placement::Pose([x, y, z, roll, pitch, yaw]) => {
                self.translation = [x, y, z];
                self.rpy = [roll, pitch, yaw];
                self.frame = PointFrame::Sensor;
            }
        }
    }

    /// The sensor's position in the frame [`points`](Self::points) are given in:
    /// the translation for world points, the origin for sensor-frame points. A
    /// pose moves points rigidly, so each ray's length is the distance from here.
    #[must_use]
    pub fn sensor_in_points_frame(&self) -> [f64; 3] {
        match self.frame {
            PointFrame::World => self.translation,
            PointFrame::Sensor => [0.0; 3],
        }
    }

    /// The points in world coordinates: the pose applied to sensor-frame points
    /// (in parallel), world-frame points borrowed as they are.
    ///
    /// ```
    /// use tesseral::io::scan::ScanRecord;
    /// let s = ScanRecord { translation: [1.0, 0.0, 0.0], rpy: [0.0, 0.0, std::f64::consts::FRAC_PI_2],
    ///     points: vec![[1.0, 0.0, 0.0]], ..Default::default() };
    /// let w = s.world_points();
    /// assert!((w[0][0] - 1.0).abs() < 1e-12 && (w[0][1] - 1.0).abs() < 1e-12);
    /// ```
    #[must_use]
    pub fn world_points(&self) -> Cow<'_, [[f64; 3]]> {
        use rayon::prelude::*;
        match self.frame {
            PointFrame::World => Cow::Borrowed(&self.points),
            PointFrame::Sensor => {
                let (m, t) = (rpy_matrix(self.rpy), self.translation);
                Cow::Owned(self.points.par_iter().map(|&p| moved(&m, t, p)).collect())
            }
        }
    }

    /// [`world_points`](Self::world_points), taking the scan: world points are
    /// handed over, not copied.
    #[must_use]
    pub fn into_world_points(self) -> Vec<[f64; 3]> {
        match self.frame {
            PointFrame::World => self.points,
            PointFrame::Sensor => self.world_points().into_owned(),
        }
    }
}

/// Where a file's scans are placed, over what the file says: what `tesseral map
/// --origin` / `--pose` and Python's `read_scans(origin=, pose=)` give. Only point
/// clouds take an override; a scan graph or log carries a pose per scan
/// ([`ScanFormat::has_poses`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Placement {
    /// As read: a graph's or log's poses, a PCD's `VIEWPOINT`, else the sensor at
    /// the origin of the points' frame.
    #[default]
    AsRead,
    /// The sensor at this point; the points are world coordinates.
    Origin([f64; 3]),
    /// The points are in the sensor's frame, moved into the world by this pose:
    /// x, y, z, then roll, pitch, yaw in radians (OctoMap's convention).
    Pose([f64; 6]),
}

impl Placement {
    /// The placement of an optional sensor origin and an optional pose (x, y, z,
    /// roll, pitch, yaw), as the CLI's `--origin`/`--pose` and Python's `origin=`/
    /// `pose=` give them; `None` when both are given.
    #[must_use]
    pub fn of(origin: Option<[f64; 3]>, pose: Option<[f64; 6]>) -> Option<Self> {
        match (origin, pose) {
            (Some(_), Some(_)) => None,
            (Some(o), None) => Some(Self::Origin(o)),
            (None, Some(p)) => Some(Self::Pose(p)),
            (None, None) => Some(Self::AsRead),
        }
    }

    /// Whether this overrides what a file says (not [`AsRead`](Self::AsRead)).
    #[must_use]
    pub fn overrides(self) -> bool {
        self != Self::AsRead
    }
}

/// The rotation matrix of roll, pitch, yaw: `Rz(yaw)·Ry(pitch)·Rx(roll)` (OctoMap's
/// `Quaternion(roll, pitch, yaw)`).
#[must_use]
pub fn rpy_matrix([roll, pitch, yaw]: [f64; 3]) -> [[f64; 3]; 3] {
    let (sr, cr) = roll.sin_cos();
    let (sp, cp) = pitch.sin_cos();
    let (sy, cy) = yaw.sin_cos();
    [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]
}

/// Point `p` rotated by `m` (rows first), then translated by `t`.
#[inline]
pub(crate) fn moved(m: &[[f64; 3]; 3], t: [f64; 3], p: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|r| m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + t[r])
}

/// A scan file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScanFormat {
    /// OctoMap's binary scan graph.
    Graph,
    /// OctoMap's text log.
    Log,
    /// Float `x y z` lines.
    Xyz,
    /// PLY point cloud.
    Ply,
    /// PCL point cloud.
    Pcd,
}

impl ScanFormat {
    /// The format of a lower-case extension, if it is one of [`SCAN_EXTENSIONS`].
    #[must_use]
    pub fn from_extension(ext: &str) -> Option<Self> {
        Some(match ext {
            "graph" => Self::Graph,
            "log" => Self::Log,
            "xyz" => Self::Xyz,
            "ply" => Self::Ply,
            "pcd" => Self::Pcd,
            _ => return None,
        })
    }

    /// Whether files of this format carry their own sensor poses.
    #[must_use]
    pub fn has_poses(self) -> bool {
        matches!(self, Self::Graph | Self::Log)
    }
}

/// Decodes scan bytes of a given format.
///
/// # Errors
/// [`FormatError::Syntax`] (line and column) for text, [`FormatError::Corrupt`]
/// naming the byte offset for binary data (and PCD's compressed data), and
/// [`FormatError::TooLarge`] past [`MAX_SCAN_POINTS`].
pub fn parse(bytes: &[u8], format: ScanFormat) -> Result<Vec<ScanRecord>, FormatError> {
    match format {
        ScanFormat::Graph => graph::decode(bytes),
        ScanFormat::Log => log::parse(bytes),
        ScanFormat::Xyz => cloud::parse_xyz(bytes).map(|s| vec![s]),
        ScanFormat::Ply => cloud::parse_ply(bytes).map(|s| vec![s]),
        ScanFormat::Pcd => pcd::parse(bytes).map(|s| vec![s]),
    }
}

/// Reads the scans in `path`, choosing the format by extension.
///
/// # Errors
/// As [`parse`], with the file named; [`FormatError::UnknownFormat`] for another
/// extension.
pub fn read(path: &Path) -> Result<Vec<ScanRecord>, FormatError> {
    let format = ScanFormat::from_extension(&super::extension(path)).ok_or_else(|| {
        FormatError::UnknownFormat {
            known: SCAN_EXTENSIONS,
        }
        .with_path(path)
    })?;
    let bytes = super::read_limited(path, super::MAX_FILE_BYTES)?;
    parse(&bytes, format).map_err(|e| e.with_path(path))
}

/// Refuses a point count past the budget.
fn check_budget(total: usize) -> Result<(), FormatError> {
    if total > MAX_SCAN_POINTS {
        return Err(FormatError::too_large(format!(
            "more than {MAX_SCAN_POINTS} points in one file"
        )));
    }
    Ok(())
}

/// A syntax error at a 1-based line and column.
fn syntax(line: usize, column: usize, message: impl Into<String>) -> FormatError {
    FormatError::Syntax {
        line,
        column,
        message: message.into(),
    }
}

/// The whitespace-separated words of a line with their 1-based columns.
fn words(line: &str) -> impl Iterator<Item = (usize, &str)> {
    line.split(|c: char| c.is_ascii_whitespace())
        .scan(0usize, |at, w| {
            let col = *at + 1;
            *at += w.len() + 1;
            Some((col, w))
        })
        .filter(|(_, w)| !w.is_empty())
}
