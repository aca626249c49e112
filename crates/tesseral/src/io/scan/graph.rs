//! OctoMap's binary scan graph (`.graph`), the file `log2graph` writes and
//! `graph2tree` reads. All numbers are little-endian:
//!
//! ```text
//! u32 node count, then per node:
//!     u32 point count, then per point: i32 (3), f64 x, f64 y, f64 z
//!     pose: i32 (3), f64 x, f64 y, f64 z; i32 (4), f64 w, f64 x, f64 y, f64 z (a quaternion)
//!     u32 id
//! u32 edge count, then per edge (80 bytes): u32 first id, u32 second id, a pose, f64 weight
//! ```
//!
//! OctoMap keeps points and poses in `f32`, so values are rounded to `f32` on read as
//! OctoMap does; the quaternion becomes roll, pitch, yaw (`Quaternion::toEuler`).
//! Edges are checked for length and otherwise ignored (`graph2tree` ignores them too);
//! a file that ends right after its nodes is read as having no edges, as OctoMap does.

use super::{check_budget, PointFrame, ScanRecord};
use crate::io::FormatError;

/// Bytes of one point: an `i32` dimension and three `f64`.
const POINT_BYTES: usize = 4 + 24;
/// Bytes of one pose: a vector (4 + 24) and a quaternion (4 + 32).
const POSE_BYTES: usize = 28 + 36;
/// Bytes of a node with no points: count, pose, id.
const EMPTY_NODE_BYTES: usize = 4 + POSE_BYTES + 4;
/// Bytes of one edge: two ids, a pose, a weight.
const EDGE_BYTES: usize = 8 + POSE_BYTES + 8;

/// A cursor over the bytes that names the offset where the data ran out.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl Cursor<'_> {
    fn left(&self) -> usize {
        self.bytes.len() - self.pos
    }
    fn take<const N: usize>(&mut self, what: &str) -> Result<[u8; N], FormatError> {
        let b = self.bytes.get(self.pos..self.pos + N).ok_or_else(|| {
            FormatError::corrupt(format!(
                "file ends at byte {} inside {what}",
                self.bytes.len()
            ))
        })?;
        self.pos += N;
        Ok(b.try_into().expect("N bytes"))
    }
    fn u32(&mut self, what: &str) -> Result<u32, FormatError> {
        self.take::<4>(what).map(u32::from_le_bytes)
    }
    fn f64(&mut self, what: &str) -> Result<f64, FormatError> {
        self.take::<8>(what).map(f64::from_le_bytes)
    }
    /// `N` doubles behind their `i32` dimension, each rounded to `f32` as OctoMap
    /// stores them.
    fn vector<const N: usize>(&mut self, what: &str) -> Result<[f64; N], FormatError> {
        self.take::<4>(what)?;
        let mut v = [0.0; N];
        for x in &mut v {
            *x = f64::from(self.f64(what)? as f32);
        }
        Ok(v)
    }
}

/// Decodes a scan graph.
///
/// # Errors
/// [`FormatError::Corrupt`] naming the byte offset and the node at fault (a count
/// the remaining bytes cannot hold, a cut file, a pose that is not finite);
/// [`FormatError::TooLarge`] past [`super::MAX_SCAN_POINTS`].
pub fn decode(bytes: &[u8]) -> Result<Vec<ScanRecord>, FormatError> {
    let mut c = Cursor { bytes, pos: 0 };
    let nodes = c.u32("the node count")? as usize;
    if nodes > c.left() / EMPTY_NODE_BYTES {
        return Err(FormatError::corrupt(format!(
            "byte 0: {nodes} nodes claimed; {} bytes hold at most {}",
            c.left(),
            c.left() / EMPTY_NODE_BYTES
        )));
    }
    let mut scans = Vec::with_capacity(nodes);
    let mut total = 0usize;
    for i in 0..nodes {
        let at = c.pos;
        let what = format!("node {i}");
        let n = c.u32(&what)? as usize;
        if n > c.left().saturating_sub(POSE_BYTES + 4) / POINT_BYTES {
            return Err(FormatError::corrupt(format!(
                "byte {at}: node {i} claims {n} points; the file is too short for them"
            )));
        }
        total += n;
        check_budget(total)?;
        let mut points = Vec::with_capacity(n);
        for _ in 0..n {
            points.push(c.vector::<3>(&what)?);
        }
        let pose_at = c.pos;
        let translation = c.vector::<3>(&what)?;
        let q = c.vector::<4>(&what)?;
        c.u32(&what)?;
        if translation.iter().chain(&q).any(|x| !x.is_finite()) {
            return Err(FormatError::corrupt(format!(
                "byte {pose_at}: the pose of node {i} is not finite"
            )));
        }
        scans.push(ScanRecord {
            translation,
            rpy: quaternion_to_rpy(q),
            points,
            frame: PointFrame::Sensor,
        });
    }
    if c.left() > 0 {
        let at = c.pos;
        let edges = c.u32("the edge count")? as usize;
        if edges > c.left() / EDGE_BYTES {
            return Err(FormatError::corrupt(format!(
                "byte {at}: {edges} edges claimed; {} bytes hold at most {}",
                c.left(),
                c.left() / EDGE_BYTES
            )));
        }
    }
    Ok(scans)
}

/// Roll, pitch, yaw of a quaternion `[w, x, y, z]` (any norm; zero is the identity),
/// as OctoMap's `Quaternion::toEuler`.
#[must_use]
pub fn quaternion_to_rpy([w, x, y, z]: [f64; 4]) -> [f64; 3] {
    let n2 = w * w + x * x + y * y + z * z;
    let s = if n2 > 0.0 { 2.0 / n2 } else { 0.0 };
    let m00 = 1.0 - s * (y * y + z * z);
    let m10 = s * (x * y + w * z);
    let m20 = s * (x * z - w * y);
    let m21 = s * (y * z + w * x);
    let m22 = 1.0 - s * (x * x + y * y);
    [
        m21.atan2(m22),
        (-m20).atan2((m21 * m21 + m22 * m22).sqrt()),
        m10.atan2(m00),
    ]
}

/// The unit quaternion `[w, x, y, z]` of roll, pitch, yaw (the rotation of
/// [`super::rpy_matrix`]).
#[must_use]
pub fn rpy_to_quaternion(rpy: [f64; 3]) -> [f64; 4] {
    let [r, p, y] = rpy.map(|a| a / 2.0);
    let (sr, cr) = r.sin_cos();
    let (sp, cp) = p.sin_cos();
    let (sy, cy) = y.sin_cos();
    [
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    ]
}

/// Encodes scans as a scan graph with no edges. Sensor-frame scans keep their pose;
/// world-frame scans get the identity rotation at their origin, their points moved
/// into that frame (`p − origin`).
#[must_use]
pub fn encode(scans: &[ScanRecord]) -> Vec<u8> {
    let mut out = Vec::new();
    let vector = |out: &mut Vec<u8>, v: &[f64]| {
        out.extend_from_slice(&(v.len() as i32).to_le_bytes());
        for x in v {
            out.extend_from_slice(&x.to_le_bytes());
        }
    };
    out.extend_from_slice(&(scans.len() as u32).to_le_bytes());
    for (id, s) in scans.iter().enumerate() {
        out.extend_from_slice(&(s.points.len() as u32).to_le_bytes());
        for p in &s.points {
            match s.frame {
                PointFrame::Sensor => vector(&mut out, p),
                PointFrame::World => {
                    vector(
                        &mut out,
                        &std::array::from_fn::<f64, 3, _>(|k| p[k] - s.translation[k]),
                    );
                }
            }
        }
        vector(&mut out, &s.translation);
        let rpy = match s.frame {
            PointFrame::Sensor => s.rpy,
            PointFrame::World => [0.0; 3],
        };
        vector(&mut out, &rpy_to_quaternion(rpy));
        out.extend_from_slice(&(id as u32).to_le_bytes());
    }
    out.extend_from_slice(&0u32.to_le_bytes());
    out
}
