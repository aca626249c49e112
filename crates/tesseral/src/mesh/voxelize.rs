//! Voxelizing a triangle mesh into a solid linear octree, top-down.
//!
//! Everything after reading is exact. Vertices are snapped to a fixed-point lattice of
//! `2^-20` voxel, and every predicate runs in `i128`:
//!
//! - **Inside/outside** by ray parity along +z through voxel centres. Each triangle is
//!   rasterized onto the columns whose centre its xy-projection covers; ties on a
//!   shared edge or vertex are broken by symbolic perturbation of the column
//!   (Edelsbrunner & Mücke's simulation of simplicity, with the point moved by
//!   `(ε, ε²)`), so every column crosses a closed surface an even number of times and
//!   nothing is counted twice. The crossing height is an exact rational; it becomes
//!   the index of the first voxel whose centre lies above it (a "flip").
//! - **Watertightness** first: after welding vertices on the lattice, every edge must
//!   belong to an even number of triangles, else [`VoxelizeError::NotWatertight`]
//!   (use `surface_only`).
//! - **Surface cells** by the exact triangle/box separating-axis test of
//!   Akenine-Möller (2001) on integers, over a uniform grid of triangle bins with a
//!   summed-volume table, so a cell far from the surface is answered in O(1).
//!
//! The octree is built by [`LinearOctree::from_classifier`]: a cell whose hull of
//! voxel centres meets no triangle is uniform and costs one parity lookup; only cells
//! near the surface are split, so the cost follows the surface.

use std::collections::HashMap;

use rayon::prelude::*;

use super::TriMesh;
use crate::linear::{CellClass, Classifier, LinearOctree};
use crate::model::{Frame, Model};
use crate::Voxel;

/// What can go wrong voxelizing a mesh.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum VoxelizeError {
    /// The mesh itself is malformed (a triangle names a missing vertex).
    #[error("{0}")]
    BadMesh(String),
    /// The grid would exceed a limit (depth, extent, ray crossings); the message
    /// names it.
    #[error("{0}")]
    TooLarge(String),
    /// An option cannot be used (a voxel size that is not positive).
    #[error("{0}")]
    Unsupported(String),
    /// A mesh that should bound a solid has open edges, so inside and outside are not
    /// defined.
    #[error("mesh is not watertight: {open_edges} edge(s) are not shared by an even number of triangles (first near {example:?}); use --surface-only to voxelize the surface")]
    NotWatertight {
        /// How many edges have an odd number of triangles.
        open_edges: usize,
        /// The coordinates of one end of one open edge.
        example: [f64; 3],
    },
    /// The octree could not be built.
    #[error(transparent)]
    Octree(#[from] crate::linear::OctreeError),
}

impl VoxelizeError {
    fn corrupt(m: impl Into<String>) -> Self {
        Self::BadMesh(m.into())
    }
    fn too_large(m: impl Into<String>) -> Self {
        Self::TooLarge(m.into())
    }
    fn unsupported(m: impl Into<String>) -> Self {
        Self::Unsupported(m.into())
    }
}

/// The deepest voxelization we attempt (16384 voxels per axis).
pub const MAX_VOXELIZE_DEPTH: u8 = 14;
/// Fixed-point bits below one voxel.
const FRAC_BITS: u32 = 20;
const ONE: i64 = 1 << FRAC_BITS;
const HALF: i64 = ONE / 2;
/// The default budget of column crossings held in memory (8 bytes each, 1 GiB).
pub const MAX_CROSSINGS: usize = 1 << 27;
/// The most triangle references held by the bin grid.
const MAX_BIN_ENTRIES: u64 = 1 << 25;

/// The resolution of a voxelization.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Resolution {
    /// `2^depth` voxels along the longest side of the mesh's bounding box; the grid
    /// starts at the box's lowest corner.
    Depth(u8),
    /// Voxels of this side in mesh units, on a grid aligned to the mesh's origin
    /// (voxel `i` spans `[i·size, (i+1)·size)`).
    VoxelSize(f64),
}

/// How a mesh is voxelized.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VoxelizeOptions {
    /// The grid.
    pub resolution: Resolution,
    /// Keep only voxels whose closed cube meets a triangle (no inside test, so the
    /// mesh need not be watertight).
    pub surface_only: bool,
    /// The most ray crossings (8 bytes each) a solid voxelization may hold; bounded
    /// from the triangles before any work.
    pub max_crossings: usize,
    /// The most leaves the octree may have, estimated from the surface area before
    /// any work (a surface leaf per unit of area: the leaves of a voxelized surface
    /// are about 1–1.4 times its area in voxels).
    pub max_leaves: usize,
}

impl Default for VoxelizeOptions {
    fn default() -> Self {
        Self {
            resolution: Resolution::Depth(8),
            surface_only: false,
            max_crossings: MAX_CROSSINGS,
            max_leaves: crate::csg::DEFAULT_MAX_LEAVES,
        }
    }
}

type Tri = [[i64; 3]; 3];

/// Voxelizes `mesh` into a solid (a voxel is black when its centre is inside) or,
/// with `surface_only`, into the voxels the surface touches. The result carries a [`Frame`] mapping voxels back to mesh units.
///
/// # Runtime
/// O(T + C log C + S) for T triangles, C column crossings (about twice the projected
/// area in voxels) and S cells near the surface.
///
/// # Errors
/// [`VoxelizeError::NotWatertight`]; [`VoxelizeError::TooLarge`] for a grid deeper than
/// [`MAX_VOXELIZE_DEPTH`] or too many crossings; [`VoxelizeError::BadMesh`] for a bad
/// vertex index.
///
/// ```
/// use tesseral::mesh::{voxelize, Resolution, TriMesh, VoxelizeOptions};
/// // A closed tetrahedron-free box: read one from OBJ text.
/// let obj = "v 0 0 0\nv 4 0 0\nv 0 4 0\nv 4 4 0\nv 0 0 4\nv 4 0 4\nv 0 4 4\nv 4 4 4\n\
///            f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
/// let mesh = tesseral::io::mesh::parse_obj(obj.as_bytes()).unwrap();
/// let opts = VoxelizeOptions { resolution: Resolution::VoxelSize(0.5), ..Default::default() };
/// let model = voxelize(&mesh, &opts).unwrap();
/// assert_eq!(model.tree.voxel_count(), 8 * 8 * 8);
/// ```
pub fn voxelize(mesh: &TriMesh, options: &VoxelizeOptions) -> Result<Model, VoxelizeError> {
    let n = mesh.positions.len();
    if let Some(t) = mesh
        .triangles
        .iter()
        .position(|t| t.iter().any(|&i| i as usize >= n))
    {
        return Err(VoxelizeError::corrupt(format!(
            "triangle {t} names a missing vertex"
        )));
    }
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for t in &mesh.triangles {
        for &i in t {
            let p = mesh.positions[i as usize];
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
    }
    if mesh.triangles.is_empty() {
        return Ok(Model::new(LinearOctree::empty(0, [0; 3]).expect("depth 0")));
    }
    let (depth, origin, h, translate) = match options.resolution {
        Resolution::Depth(d) => {
            if d > MAX_VOXELIZE_DEPTH {
                return Err(VoxelizeError::too_large(format!(
                    "depth {d} exceeds the voxelization limit {MAX_VOXELIZE_DEPTH}"
                )));
            }
            let ext = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max);
            if !ext.is_finite() {
                return Err(VoxelizeError::too_large("the mesh's extent overflows"));
            }
            let h = if ext > 0.0 {
                ext / f64::from(1u32 << d)
            } else {
                1.0
            };
            (d, [0i64; 3], h, lo)
        }
        Resolution::VoxelSize(h) => {
            if !(h.is_finite() && h > 0.0) {
                return Err(VoxelizeError::unsupported(format!(
                    "voxel size {h} must be positive"
                )));
            }
            let mut origin = [0i64; 3];
            let mut extent = 1i64;
            for a in 0..3 {
                let (l, u) = ((lo[a] / h).floor(), (hi[a] / h).floor());
                if !(l.abs() < 1e15 && u.abs() < 1e15) {
                    return Err(VoxelizeError::too_large(format!(
                        "voxel size {h} gives a grid too large"
                    )));
                }
                origin[a] = l as i64;
                extent = extent.max(u as i64 - l as i64 + 1);
            }
            let d = (extent as u64).next_power_of_two().trailing_zeros();
            if d > u32::from(MAX_VOXELIZE_DEPTH) {
                return Err(VoxelizeError::too_large(format!(
                    "voxel size {h} needs {extent} voxels per axis, beyond the limit of {}",
                    1u32 << MAX_VOXELIZE_DEPTH
                )));
            }
            (d as u8, origin, h, [0.0; 3])
        }
    };
    let side = 1i64 << depth;
    let quant = |p: [f64; 3]| -> [i64; 3] {
        [0, 1, 2].map(|a| {
            let q = (((p[a] - translate[a]) / h - origin[a] as f64) * ONE as f64).round();
            q.clamp(-(ONE as f64), ((side + 1) * ONE) as f64) as i64
        })
    };
    let q: Vec<[i64; 3]> = mesh.positions.iter().map(|&p| quant(p)).collect();
    let tris: Vec<Tri> = mesh
        .triangles
        .iter()
        .map(|t| t.map(|i| q[i as usize]))
        .collect();
    if !options.surface_only {
        check_watertight(&tris, |p| {
            [0, 1, 2].map(|a| translate[a] + h * (origin[a] as f64 + p[a] as f64 / ONE as f64))
        })?;
    }
    let area = surface_area(&tris);
    if area > options.max_leaves as f64 {
        return Err(VoxelizeError::TooLarge(format!(
            "the surface at depth {depth} is about {area:.0} voxels in area, so the octree would have about that many leaves, more than the budget of {} (raise --max-leaves or --memory, or lower --depth)",
            options.max_leaves
        )));
    }
    if !options.surface_only {
        // The budget is checked before any work, from the triangles alone.
        let bound = crossing_bound(&tris);
        if bound > options.max_crossings as u64 {
            return Err(VoxelizeError::TooLarge(format!(
                "a solid voxelization at depth {depth} needs up to {bound} ray crossings ({} MiB at 8 bytes each), more than the budget of {} (raise --memory, lower --depth, or use --surface-only)",
                bound.saturating_mul(8) >> 20,
                options.max_crossings
            )));
        }
    }
    let bins = Bins::new(&tris, depth);
    let columns = if options.surface_only {
        Columns::default()
    } else {
        Columns::new(&tris, depth, options.max_crossings).map_err(VoxelizeError::too_large)?
    };
    let classifier = MeshClassifier {
        tris,
        bins,
        columns,
        origin,
        side,
        surface_only: options.surface_only,
    };
    let tree =
        LinearOctree::from_classifier(depth, origin, &classifier).map_err(VoxelizeError::Octree)?;
    Ok(Model::new(tree).with_frame(Frame::new(h, translate)))
}

fn check_watertight(
    tris: &[Tri],
    world: impl Fn([i64; 3]) -> [f64; 3],
) -> Result<(), VoxelizeError> {
    let mut ids: HashMap<[i64; 3], u32> = HashMap::with_capacity(tris.len());
    let mut odd: HashMap<(u32, u32), bool> = HashMap::with_capacity(tris.len() * 3 / 2);
    let mut points: Vec<[i64; 3]> = Vec::new();
    for t in tris {
        let w = t.map(|p| {
            let next = ids.len() as u32;
            *ids.entry(p).or_insert_with(|| {
                points.push(p);
                next
            })
        });
        for e in 0..3 {
            let (a, b) = (w[e], w[(e + 1) % 3]);
            if a != b {
                let key = (a.min(b), a.max(b));
                let v = odd.entry(key).or_insert(false);
                *v = !*v;
            }
        }
    }
    let open: Vec<(u32, u32)> = odd.into_iter().filter(|e| e.1).map(|e| e.0).collect();
    if let Some(&(a, _)) = open.iter().min() {
        return Err(VoxelizeError::NotWatertight {
            open_edges: open.len(),
            example: world(points[a as usize]),
        });
    }
    Ok(())
}

/// `orient2d(a, b, p)` in xy, with the symbolic-perturbation sign for exact zeros.
#[inline]
fn edge_sign(a: [i64; 3], b: [i64; 3], px: i64, py: i64) -> (i128, bool) {
    let (bx, by) = (i128::from(b[0] - a[0]), i128::from(b[1] - a[1]));
    let w = bx * i128::from(py - a[1]) - by * i128::from(px - a[0]);
    let positive = if w != 0 {
        w > 0
    } else if by != 0 {
        by < 0
    } else {
        bx > 0
    };
    (w, positive)
}

/// Per-column sorted flip indices: voxel z of column (x, y) is inside when the number
/// of flips ≤ z is odd.
#[derive(Default)]
struct Columns {
    /// Sorted ids of the columns with crossings (sparse form), or empty when
    /// `starts` is indexed by column id directly (dense form).
    cols: Vec<u32>,
    starts: Vec<u32>,
    flips: Vec<u32>,
    side: i64,
    dense: bool,
}

/// Columns up to this many are indexed densely (4 bytes each), beyond it by binary
/// search.
const DENSE_COLUMNS: i64 = 1 << 24;

impl Columns {
    fn new(tris: &[Tri], depth: u8, max_crossings: usize) -> Result<Self, String> {
        let side = 1i64 << depth;
        let parts: Vec<Vec<u64>> = tris
            .par_chunks(4096)
            .map(|chunk| {
                let mut out = Vec::new();
                for t in chunk {
                    rasterize(t, side, &mut out);
                    if out.len() > max_crossings {
                        break;
                    }
                }
                out
            })
            .collect();
        let total: usize = parts.iter().map(Vec::len).sum();
        if total > max_crossings {
            return Err(format!(
                "more than {max_crossings} ray crossings at depth {depth}"
            ));
        }
        let mut entries: Vec<u64> = Vec::with_capacity(total);
        for p in parts {
            entries.extend(p);
        }
        entries.par_sort_unstable();
        let mut c = Columns {
            side,
            dense: side * side <= DENSE_COLUMNS,
            ..Columns::default()
        };
        if c.dense {
            let n = (side * side) as usize;
            c.starts = vec![0u32; n + 1];
            for e in &entries {
                c.starts[(e >> 32) as usize + 1] += 1;
            }
            for i in 0..n {
                c.starts[i + 1] += c.starts[i];
            }
            c.flips = entries.iter().map(|&e| e as u32).collect();
            return Ok(c);
        }
        for e in entries {
            let col = (e >> 32) as u32;
            if c.cols.last() != Some(&col) {
                c.cols.push(col);
                c.starts.push(c.flips.len() as u32);
            }
            c.flips.push(e as u32);
        }
        c.starts.push(c.flips.len() as u32);
        Ok(c)
    }

    #[inline]
    fn column(&self, x: i64, y: i64) -> &[u32] {
        let col = (x + y * self.side) as u32;
        if self.dense {
            let i = col as usize;
            return &self.flips[self.starts[i] as usize..self.starts[i + 1] as usize];
        }
        match self.cols.binary_search(&col) {
            Ok(i) => &self.flips[self.starts[i] as usize..self.starts[i + 1] as usize],
            Err(_) => &[],
        }
    }

    fn inside(&self, v: [i64; 3]) -> bool {
        let f = self.column(v[0], v[1]);
        f.partition_point(|&z| i64::from(z) <= v[2]) % 2 == 1
    }

    /// `Some(inside)` when the whole cell has one state, by scanning its columns.
    fn uniform(&self, rel: [i64; 3], k: u8) -> Option<bool> {
        let s = 1i64 << k;
        let first = self.inside(rel);
        for y in rel[1]..rel[1] + s {
            for x in rel[0]..rel[0] + s {
                let f = self.column(x, y);
                let i = f.partition_point(|&z| i64::from(z) <= rel[2]);
                if (i % 2 == 1) != first {
                    return None;
                }
                if i < f.len() && i64::from(f[i]) < rel[2] + s {
                    return None;
                }
            }
        }
        Some(first)
    }
}

/// Appends `(column << 32) | flip` for every column centre that `t`'s xy-projection
/// covers.
/// An upper bound on the ray crossings of a solid voxelization: per triangle, the
/// column centres its projection can hold, at most those of its bounding box and at
/// most `A + P/2 + 1` (Nosarzewska's bound on the lattice points of a convex region
/// of area A and perimeter P). O(triangles).
#[must_use]
fn crossing_bound(tris: &[Tri]) -> u64 {
    let one = ONE as f64;
    tris.iter()
        .map(|t| {
            let p = t.map(|v| [v[0] as f64 / one, v[1] as f64 / one]);
            let area = ((p[1][0] - p[0][0]) * (p[2][1] - p[0][1])
                - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]))
                .abs()
                / 2.0;
            if area == 0.0 {
                return 0;
            }
            let len = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
            let perimeter = len(p[0], p[1]) + len(p[1], p[2]) + len(p[2], p[0]);
            let span = |a: usize| {
                let lo = p.iter().map(|q| q[a]).fold(f64::INFINITY, f64::min);
                let hi = p.iter().map(|q| q[a]).fold(f64::NEG_INFINITY, f64::max);
                (hi - lo).floor() + 2.0
            };
            let convex = area + perimeter / 2.0 + 1.0;
            (span(0) * span(1)).min(convex).ceil() as u64
        })
        .sum()
}

/// The total area of the triangles in voxel units. O(triangles).
fn surface_area(tris: &[Tri]) -> f64 {
    let one = ONE as f64;
    tris.iter()
        .map(|t| {
            let p = t.map(|v| v.map(|c| c as f64 / one));
            let u = [0, 1, 2].map(|a| p[1][a] - p[0][a]);
            let w = [0, 1, 2].map(|a| p[2][a] - p[0][a]);
            let c = [
                u[1] * w[2] - u[2] * w[1],
                u[2] * w[0] - u[0] * w[2],
                u[0] * w[1] - u[1] * w[0],
            ];
            (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt() / 2.0
        })
        .sum()
}

fn rasterize(t: &Tri, side: i64, out: &mut Vec<u64>) {
    let [a, mut b, mut c] = *t;
    let (w, _) = edge_sign(a, b, c[0], c[1]);
    if w == 0 {
        return; // vertical in projection: no column crosses it
    }
    if w < 0 {
        std::mem::swap(&mut b, &mut c);
    }
    let minx = a[0].min(b[0]).min(c[0]);
    let maxx = a[0].max(b[0]).max(c[0]);
    let miny = a[1].min(b[1]).min(c[1]);
    let maxy = a[1].max(b[1]).max(c[1]);
    // Columns whose centre i·ONE + HALF lies in [min, max].
    let i0 = ((minx - HALF).div_euclid(ONE) + 1).max(0);
    let i1 = (maxx - HALF).div_euclid(ONE).min(side - 1);
    let j0 = ((miny - HALF).div_euclid(ONE) + 1).max(0);
    let j1 = (maxy - HALF).div_euclid(ONE).min(side - 1);
    // Include centres exactly on the bounding box (the perturbation decides).
    let i0 = if (i0 - 1) * ONE + HALF == minx && i0 > 0 {
        i0 - 1
    } else {
        i0
    };
    let j0 = if (j0 - 1) * ONE + HALF == miny && j0 > 0 {
        j0 - 1
    } else {
        j0
    };
    for j in j0..=j1 {
        let py = j * ONE + HALF;
        for i in i0..=i1 {
            let px = i * ONE + HALF;
            let (wa, ia) = edge_sign(b, c, px, py);
            if !ia {
                continue;
            }
            let (wb, ib) = edge_sign(c, a, px, py);
            if !ib {
                continue;
            }
            let (wc, ic) = edge_sign(a, b, px, py);
            if !ic {
                continue;
            }
            let den = wa + wb + wc;
            let num = wa * i128::from(a[2]) + wb * i128::from(b[2]) + wc * i128::from(c[2]);
            let flip = (num - i128::from(HALF) * den).div_euclid(i128::from(ONE) * den) + 1;
            let flip = flip.clamp(0, i128::from(side)) as u64;
            out.push(((i + j * side) as u64) << 32 | flip);
        }
    }
}

/// A uniform grid of triangle references with a summed-volume table of counts.
struct Bins {
    shift: u32,
    n: usize,
    starts: Vec<u32>,
    items: Vec<u32>,
    sum: Vec<u32>,
}

impl Bins {
    fn range(t: &Tri, side: i64, shift: u32) -> [[usize; 2]; 3] {
        [0, 1, 2].map(|a| {
            let lo = t.iter().map(|p| p[a]).min().unwrap_or(0) - 1;
            let hi = t.iter().map(|p| p[a]).max().unwrap_or(0) + 1;
            let v0 = lo.div_euclid(ONE).clamp(0, side - 1);
            let v1 = hi.div_euclid(ONE).clamp(0, side - 1);
            [(v0 >> shift) as usize, (v1 >> shift) as usize]
        })
    }

    fn new(tris: &[Tri], depth: u8) -> Self {
        let side = 1i64 << depth;
        let mut shift = u32::from(depth.saturating_sub(7));
        loop {
            let total: u64 = tris
                .iter()
                .map(|t| {
                    let r = Self::range(t, side, shift);
                    r.iter().map(|[a, b]| (b - a + 1) as u64).product::<u64>()
                })
                .sum();
            if total <= MAX_BIN_ENTRIES || shift >= u32::from(depth) {
                break;
            }
            shift += 1;
        }
        let n = (side >> shift) as usize;
        let idx = |x: usize, y: usize, z: usize| (z * n + y) * n + x;
        let mut counts = vec![0u32; n * n * n + 1];
        for t in tris {
            let r = Self::range(t, side, shift);
            for z in r[2][0]..=r[2][1] {
                for y in r[1][0]..=r[1][1] {
                    for x in r[0][0]..=r[0][1] {
                        counts[idx(x, y, z)] += 1;
                    }
                }
            }
        }
        // Summed-volume table over (n+1)^3.
        let m = n + 1;
        let sidx = |x: usize, y: usize, z: usize| (z * m + y) * m + x;
        let mut sum = vec![0u32; m * m * m];
        for z in 0..n {
            for y in 0..n {
                for x in 0..n {
                    let c = counts[idx(x, y, z)].min(1);
                    sum[sidx(x + 1, y + 1, z + 1)] = c
                        .wrapping_add(sum[sidx(x, y + 1, z + 1)])
                        .wrapping_add(sum[sidx(x + 1, y, z + 1)])
                        .wrapping_add(sum[sidx(x + 1, y + 1, z)])
                        .wrapping_sub(sum[sidx(x, y, z + 1)])
                        .wrapping_sub(sum[sidx(x, y + 1, z)])
                        .wrapping_sub(sum[sidx(x + 1, y, z)])
                        .wrapping_add(sum[sidx(x, y, z)]);
                }
            }
        }
        let mut starts = vec![0u32; n * n * n + 1];
        let mut acc = 0u32;
        for (i, c) in counts.iter().enumerate().take(n * n * n) {
            starts[i] = acc;
            acc += c;
        }
        starts[n * n * n] = acc;
        let mut fill = starts.clone();
        let mut items = vec![0u32; acc as usize];
        for (ti, t) in tris.iter().enumerate() {
            let r = Self::range(t, side, shift);
            for z in r[2][0]..=r[2][1] {
                for y in r[1][0]..=r[1][1] {
                    for x in r[0][0]..=r[0][1] {
                        let b = idx(x, y, z);
                        items[fill[b] as usize] = ti as u32;
                        fill[b] += 1;
                    }
                }
            }
        }
        Bins {
            shift,
            n,
            starts,
            items,
            sum,
        }
    }

    /// The bin ranges covering voxels `[lo, hi]` (inclusive), and whether any holds a
    /// triangle.
    fn query(&self, lo: [i64; 3], hi: [i64; 3]) -> Option<[[usize; 2]; 3]> {
        let r = [0, 1, 2].map(|a| {
            [
                (lo[a] >> self.shift) as usize,
                (hi[a] >> self.shift) as usize,
            ]
        });
        let m = self.n + 1;
        let s = |x: usize, y: usize, z: usize| self.sum[(z * m + y) * m + x];
        let (x0, x1, y0, y1, z0, z1) = (
            r[0][0],
            r[0][1] + 1,
            r[1][0],
            r[1][1] + 1,
            r[2][0],
            r[2][1] + 1,
        );
        let total = s(x1, y1, z1)
            .wrapping_sub(s(x0, y1, z1))
            .wrapping_sub(s(x1, y0, z1))
            .wrapping_sub(s(x1, y1, z0))
            .wrapping_add(s(x0, y0, z1))
            .wrapping_add(s(x0, y1, z0))
            .wrapping_add(s(x1, y0, z0))
            .wrapping_sub(s(x0, y0, z0));
        (total > 0).then_some(r)
    }

    fn any(&self, r: [[usize; 2]; 3], mut hit: impl FnMut(u32) -> bool) -> bool {
        let n = self.n;
        for z in r[2][0]..=r[2][1] {
            for y in r[1][0]..=r[1][1] {
                for x in r[0][0]..=r[0][1] {
                    let b = (z * n + y) * n + x;
                    let items = &self.items[self.starts[b] as usize..self.starts[b + 1] as usize];
                    if items.iter().any(|&t| hit(t)) {
                        return true;
                    }
                }
            }
        }
        false
    }
}

/// Exact triangle/box overlap (closed box `[lo, hi]`), by the separating-axis theorem
/// (Akenine-Möller 2001), on integers doubled so the box centre is integral.
fn tri_box_overlap(lo: [i64; 3], hi: [i64; 3], t: &Tri) -> bool {
    // Cheap rejection on the bounding boxes first, in i64.
    for a in 0..3 {
        if t[0][a].min(t[1][a]).min(t[2][a]) > hi[a] || t[0][a].max(t[1][a]).max(t[2][a]) < lo[a] {
            return false;
        }
    }
    let c: [i128; 3] = [0, 1, 2].map(|a| i128::from(lo[a]) + i128::from(hi[a]));
    let e: [i128; 3] = [0, 1, 2].map(|a| i128::from(hi[a]) - i128::from(lo[a]));
    let v: [[i128; 3]; 3] = t.map(|p| [0, 1, 2].map(|a| 2 * i128::from(p[a]) - c[a]));
    for a in 0..3 {
        let mn = v[0][a].min(v[1][a]).min(v[2][a]);
        let mx = v[0][a].max(v[1][a]).max(v[2][a]);
        if mn > e[a] || mx < -e[a] {
            return false;
        }
    }
    let sub = |p: [i128; 3], q: [i128; 3]| [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
    let dot = |p: [i128; 3], q: [i128; 3]| p[0] * q[0] + p[1] * q[1] + p[2] * q[2];
    let f = [sub(v[1], v[0]), sub(v[2], v[1]), sub(v[0], v[2])];
    let radius = |ax: [i128; 3]| e[0] * ax[0].abs() + e[1] * ax[1].abs() + e[2] * ax[2].abs();
    for fj in f {
        for ax in [[0, -fj[2], fj[1]], [fj[2], 0, -fj[0]], [-fj[1], fj[0], 0]] {
            let p = v.map(|vi| dot(ax, vi));
            let r = radius(ax);
            if p[0].min(p[1]).min(p[2]) > r || p[0].max(p[1]).max(p[2]) < -r {
                return false;
            }
        }
    }
    let n = [
        f[0][1] * f[1][2] - f[0][2] * f[1][1],
        f[0][2] * f[1][0] - f[0][0] * f[1][2],
        f[0][0] * f[1][1] - f[0][1] * f[1][0],
    ];
    dot(n, v[0]).abs() <= radius(n)
}

struct MeshClassifier {
    tris: Vec<Tri>,
    bins: Bins,
    columns: Columns,
    origin: Voxel,
    side: i64,
    surface_only: bool,
}

impl Classifier for MeshClassifier {
    fn classify(&self, min: Voxel, k: u8) -> CellClass {
        let rel = [0, 1, 2].map(|a| min[a] - self.origin[a]);
        let s = 1i64 << k;
        let last = rel.map(|r| (r + s - 1).min(self.side - 1));
        let state = |inside: bool| {
            if inside {
                CellClass::Inside
            } else {
                CellClass::Outside
            }
        };
        if self.surface_only {
            // Triangle bin ranges carry a one-unit margin, so a triangle that only
            // touches the cell's faces is still among the cell's own bins.
            let lo = rel.map(|r| r * ONE);
            let hi = rel.map(|r| (r + s) * ONE);
            let hit = self.bins.query(rel, last).is_some_and(|r| {
                self.bins
                    .any(r, |t| tri_box_overlap(lo, hi, &self.tris[t as usize]))
            });
            return match (hit, k) {
                (false, _) => CellClass::Outside,
                (true, 0) => CellClass::Inside,
                (true, _) => CellClass::Partial,
            };
        }
        if k == 0 {
            return state(self.columns.inside(rel));
        }
        let Some(r) = self.bins.query(rel, last) else {
            return state(self.columns.inside(rel));
        };
        if k <= 3 {
            return self
                .columns
                .uniform(rel, k)
                .map_or(CellClass::Partial, state);
        }
        // The hull of the cell's voxel centres, padded by one lattice unit.
        let lo = rel.map(|r| r * ONE + HALF - 1);
        let hi = rel.map(|r| (r + s - 1) * ONE + HALF + 1);
        if self
            .bins
            .any(r, |t| tri_box_overlap(lo, hi, &self.tris[t as usize]))
        {
            CellClass::Partial
        } else {
            state(self.columns.inside(rel))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// A closed axis-aligned box mesh, outward-facing.
    fn box_mesh(lo: [f64; 3], hi: [f64; 3]) -> TriMesh {
        let p = |x: usize, y: usize, z: usize| {
            [
                if x == 1 { hi[0] } else { lo[0] },
                if y == 1 { hi[1] } else { lo[1] },
                if z == 1 { hi[2] } else { lo[2] },
            ]
        };
        let positions: Vec<[f64; 3]> = (0..8)
            .map(|i| p(i & 1, (i >> 1) & 1, (i >> 2) & 1))
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let triangles = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        TriMesh {
            positions,
            triangles,
            colors: Vec::new(),
        }
    }

    fn model_count(lo: [f64; 3], hi: [f64; 3], h: f64) -> u64 {
        (0..3)
            .map(|a| {
                // Centres (i + 0.5) h strictly inside, or on the surface counted by the
                // perturbation rule (not needed for these tests: no centre on a face).
                let first = (lo[a] / h - 0.5).ceil() as i64;
                let last = (hi[a] / h - 0.5).floor() as i64;
                (last - first + 1).max(0) as u64
            })
            .product()
    }

    #[test]
    fn boxes_voxelize_to_the_exact_count() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
        for case in 0..60 {
            let lo = [
                rng.random_range(-5.0..5.0),
                rng.random_range(-5.0..5.0),
                rng.random_range(-5.0..5.0),
            ];
            let hi = [
                lo[0] + rng.random_range(0.1..6.0),
                lo[1] + rng.random_range(0.1..6.0),
                lo[2] + rng.random_range(0.1..6.0),
            ];
            let h = rng.random_range(0.2..1.0);
            let opts = VoxelizeOptions {
                resolution: Resolution::VoxelSize(h),
                surface_only: false,
                ..Default::default()
            };
            let m = voxelize(&box_mesh(lo, hi), &opts).unwrap();
            m.tree.assert_valid();
            assert_eq!(
                m.tree.voxel_count(),
                model_count(lo, hi, h),
                "case {case}: {lo:?} {hi:?} h {h}"
            );
        }
    }

    #[test]
    fn centres_on_faces_are_counted_once() {
        // Box [0.5, 4.5]^3 with unit voxels: every face passes through voxel centres.
        // The perturbation moves a column by (+ε, +ε²) in xy and a centre down in z,
        // so x and y keep voxels 0..=3 and z keeps 1..=4: 64 voxels, not 125 or 27.
        let opts = VoxelizeOptions {
            resolution: Resolution::VoxelSize(1.0),
            surface_only: false,
            ..Default::default()
        };
        let whole = voxelize(&box_mesh([0.5; 3], [4.5; 3]), &opts).unwrap();
        assert_eq!(whole.tree.voxel_count(), 64);
        assert!(whole.tree.contains([0, 0, 4]) && !whole.tree.contains([0, 0, 0]));
        // Two boxes meeting in the plane x = 2.5, which holds the centres of column
        // x = 2: the shared top and bottom edges must not count twice.
        let mut a = box_mesh([0.5, 0.5, 0.5], [2.5, 4.5, 4.5]);
        let b = box_mesh([2.5, 0.5, 0.5], [4.5, 4.5, 4.5]);
        let off = a.positions.len() as u32;
        a.positions.extend(b.positions);
        a.triangles
            .extend(b.triangles.iter().map(|t| t.map(|i| i + off)));
        let halves = voxelize(&a, &opts).unwrap();
        assert_eq!(halves.tree, whole.tree);
    }

    #[test]
    fn random_points_agree_with_the_parity_model() {
        // A closed, non-convex mesh: two boxes joined (a union as one surface).
        let m = {
            let obj = "v 0 0 0\nv 6 0 0\nv 6 2 0\nv 2 2 0\nv 2 6 0\nv 0 6 0\n\
                       v 0 0 3\nv 6 0 3\nv 6 2 3\nv 2 2 3\nv 2 6 3\nv 0 6 3\n\
                       f 1 6 5 4 3 2\nf 7 8 9 10 11 12\n\
                       f 1 2 8 7\nf 2 3 9 8\nf 3 4 10 9\nf 4 5 11 10\nf 5 6 12 11\nf 6 1 7 12\n";
            crate::io::mesh::parse_obj(obj.as_bytes()).unwrap()
        };
        assert_eq!(m.edge_defects(), 0);
        let opts = VoxelizeOptions {
            resolution: Resolution::VoxelSize(0.25),
            surface_only: false,
            ..Default::default()
        };
        let v = voxelize(&m, &opts).unwrap();
        // L-shaped prism: area 6*2 + 2*4 = 20, height 3 → 60 units → 60 * 64 voxels.
        assert_eq!(v.tree.voxel_count(), 60 * 64);
        let shell = VoxelizeOptions {
            resolution: Resolution::VoxelSize(0.25),
            surface_only: true,
            ..Default::default()
        };
        let s = voxelize(&m, &shell).unwrap();
        s.tree.assert_valid();
        // Every surface voxel touches the solid's boundary: it is a solid voxel or a
        // neighbour of one.
        for vox in s.tree.voxels() {
            let near = (-1..=1).any(|dx| {
                (-1..=1).any(|dy| {
                    (-1..=1).any(|dz| v.tree.contains([vox[0] + dx, vox[1] + dy, vox[2] + dz]))
                })
            });
            assert!(near, "{vox:?}");
        }
    }

    #[test]
    fn the_crossing_bound_holds_and_the_budget_is_checked_first() {
        let side = 1i64 << 8;
        let mut x = 0x2545_f491_4f6c_dd1du64;
        let mut next = |m: i64| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x % m as u64) as i64
        };
        for seed in 0..300 {
            let t: Tri =
                std::array::from_fn(|_| [next(side * ONE), next(side * ONE), next(side * ONE)]);
            let mut out = Vec::new();
            rasterize(&t, side, &mut out);
            let bound = crossing_bound(&[t]);
            assert!(
                out.len() as u64 <= bound,
                "seed {seed}: {} > {bound}",
                out.len()
            );
        }
        // A budget below the bound is refused before any work, naming the flag.
        let opts = VoxelizeOptions {
            resolution: Resolution::Depth(6),
            max_crossings: 100,
            ..Default::default()
        };
        let e = voxelize(&box_mesh([0.0; 3], [1.0; 3]), &opts).unwrap_err();
        assert!(
            matches!(e, VoxelizeError::TooLarge(_)) && e.to_string().contains("--memory"),
            "{e}"
        );
    }

    #[test]
    fn open_meshes_are_refused_unless_surface_only() {
        let mut m = box_mesh([0.0; 3], [1.0; 3]);
        m.triangles.pop();
        let opts = VoxelizeOptions::default();
        let err = voxelize(&m, &opts).unwrap_err();
        assert!(
            matches!(err, VoxelizeError::NotWatertight { open_edges: 3, .. }),
            "{err}"
        );
        let ok = voxelize(
            &m,
            &VoxelizeOptions {
                surface_only: true,
                ..opts
            },
        )
        .unwrap();
        assert!(ok.tree.voxel_count() > 0);
    }

    #[test]
    fn tri_box_matches_sampling() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
        for _ in 0..2000 {
            let t: Tri =
                std::array::from_fn(|_| std::array::from_fn(|_| rng.random_range(-20..20)));
            let lo = [
                rng.random_range(-10..5),
                rng.random_range(-10..5),
                rng.random_range(-10..5),
            ];
            let hi = [
                lo[0] + rng.random_range(0..8),
                lo[1] + rng.random_range(0..8),
                lo[2] + rng.random_range(0..8),
            ];
            let overlap = tri_box_overlap(lo, hi, &t);
            // Sampled points of the triangle inside the box imply overlap.
            for i in 0..=20 {
                for j in 0..=(20 - i) {
                    let p: [f64; 3] = std::array::from_fn(|a| {
                        (t[0][a] as f64 * (20 - i - j) as f64
                            + t[1][a] as f64 * i as f64
                            + t[2][a] as f64 * j as f64)
                            / 20.0
                    });
                    if (0..3).all(|a| p[a] >= lo[a] as f64 && p[a] <= hi[a] as f64) {
                        assert!(overlap, "{t:?} {lo:?} {hi:?} {p:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn surface_only_matches_brute_force() {
        for seed in 0..40u64 {
            let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
            let n = rng.random_range(1..12);
            let positions: Vec<[f64; 3]> = (0..3 * n)
                .map(|_| {
                    // Some coordinates on voxel boundaries, to exercise touching.
                    std::array::from_fn(|_| {
                        if rng.random_bool(0.3) {
                            f64::from(rng.random_range(0..8))
                        } else {
                            rng.random_range(0.0..8.0)
                        }
                    })
                })
                .collect();
            let triangles = (0..n as u32)
                .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
                .collect();
            let mesh = TriMesh {
                positions,
                triangles,
                colors: Vec::new(),
            };
            let opts = VoxelizeOptions {
                resolution: Resolution::VoxelSize(1.0),
                surface_only: true,
                ..Default::default()
            };
            let got = voxelize(&mesh, &opts).unwrap();
            got.tree.assert_valid();
            let o = got.tree.origin();
            let side = got.tree.side() as i64;
            let q: Vec<[i64; 3]> = mesh
                .positions
                .iter()
                .map(|p| [0, 1, 2].map(|a| ((p[a] - o[a] as f64) * ONE as f64).round() as i64))
                .collect();
            let tris: Vec<Tri> = mesh
                .triangles
                .iter()
                .map(|t| t.map(|i| q[i as usize]))
                .collect();
            for x in 0..side {
                for y in 0..side {
                    for z in 0..side {
                        let lo = [x * ONE, y * ONE, z * ONE];
                        let hi = [(x + 1) * ONE, (y + 1) * ONE, (z + 1) * ONE];
                        let want = tris.iter().any(|t| tri_box_overlap(lo, hi, t));
                        let v = [x + o[0], y + o[1], z + o[2]];
                        assert_eq!(got.tree.contains(v), want, "seed {seed}, voxel {v:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn solid_matches_brute_force_parity() {
        // A closed but irregular mesh: a jittered sphere, voxelized and compared with
        // a column-by-column parity count over all triangles.
        for seed in 0..6u64 {
            let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
            let (lat, lon) = (7usize, 9usize);
            let mut positions = vec![[4.0, 4.0, 0.6]];
            for i in 1..lat {
                let th = std::f64::consts::PI * i as f64 / lat as f64;
                for j in 0..lon {
                    let ph = 2.0 * std::f64::consts::PI * j as f64 / lon as f64;
                    let r = 3.4 + rng.random_range(-0.4..0.4);
                    positions.push([
                        4.0 + r * th.sin() * ph.cos(),
                        4.0 + r * th.sin() * ph.sin(),
                        4.0 - r * th.cos(),
                    ]);
                }
            }
            positions.push([4.0, 4.0, 7.4]);
            let top = (positions.len() - 1) as u32;
            let at = |i: usize, j: usize| (1 + (i - 1) * lon + j % lon) as u32;
            let mut triangles = Vec::new();
            for j in 0..lon {
                triangles.push([0, at(1, j + 1), at(1, j)]);
                triangles.push([top, at(lat - 1, j), at(lat - 1, j + 1)]);
            }
            for i in 1..lat - 1 {
                for j in 0..lon {
                    triangles.push([at(i, j), at(i, j + 1), at(i + 1, j + 1)]);
                    triangles.push([at(i, j), at(i + 1, j + 1), at(i + 1, j)]);
                }
            }
            let mesh = TriMesh {
                positions,
                triangles,
                colors: Vec::new(),
            };
            let h = 0.25;
            let opts = VoxelizeOptions {
                resolution: Resolution::VoxelSize(h),
                surface_only: false,
                ..Default::default()
            };
            let got = voxelize(&mesh, &opts).unwrap();
            got.tree.assert_valid();
            // Brute force in f64 (no centre lies exactly on the jittered surface).
            let o = got.tree.origin();
            let side = got.tree.side() as i64;
            let mut count = 0u64;
            for x in 0..side {
                for y in 0..side {
                    for z in 0..side {
                        let c = [
                            (x + o[0]) as f64 + 0.5,
                            (y + o[1]) as f64 + 0.5,
                            (z + o[2]) as f64 + 0.5,
                        ]
                        .map(|v| v * h);
                        let mut crossings = 0;
                        for t in &mesh.triangles {
                            let [a, b, d] = t.map(|i| mesh.positions[i as usize]);
                            let e = |p: [f64; 3], q: [f64; 3]| {
                                (q[0] - p[0]) * (c[1] - p[1]) - (q[1] - p[1]) * (c[0] - p[0])
                            };
                            let (w0, w1, w2) = (e(b, d), e(d, a), e(a, b));
                            let inside = (w0 > 0.0 && w1 > 0.0 && w2 > 0.0)
                                || (w0 < 0.0 && w1 < 0.0 && w2 < 0.0);
                            if inside {
                                let zc = (w0 * a[2] + w1 * b[2] + w2 * d[2]) / (w0 + w1 + w2);
                                if zc < c[2] {
                                    crossings += 1;
                                }
                            }
                        }
                        let want = crossings % 2 == 1;
                        let v = [x + o[0], y + o[1], z + o[2]];
                        assert_eq!(got.tree.contains(v), want, "seed {seed}, voxel {v:?}");
                        count += u64::from(want);
                    }
                }
            }
            assert!(count > 1000, "seed {seed}: {count}");
        }
    }
}
