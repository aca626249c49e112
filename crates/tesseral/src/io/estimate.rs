//! Output sizes estimated before anything is written, so a program can refuse an
//! output that would fill the disk (a depth-16 solid as an `.xyz` voxel list runs
//! to 10^14 lines) at once, instead of after hours of writing.
//!
//! The estimates cost O(leaves) at most and are meant to be within a small factor of
//! the truth; for `.xyz` and `.tess` they are upper bounds.

use crate::linear::LinearOctree;
use crate::model::{Layer, LayerValue, Model};

/// Bytes per leaf of a mesh file: a block has six faces of two triangles; binary STL
/// stores 50 bytes per triangle, and OBJ/PLY/glTF spend about as much on shared
/// vertices and indices. Greedy meshing merges faces and hides touching ones, so
/// solids usually come out smaller; faces split by smaller neighbours come out
/// larger.
const MESH_BYTES_PER_LEAF: u64 = 12 * 50;

/// Estimates the size in bytes of `tree` written in the format named by `ext`
/// (lower case, no dot, as [`super::extension`] gives), or `None` for an extension
/// that names no octree format.
///
/// | format | estimate |
/// |---|---|
/// | `.xyz` | one line per voxel, each as long as the widest coordinates allow (an upper bound) |
/// | `.tess` | at most ten bytes per leaf, plus header, chunk headers and index (an upper bound for the voxels; [`estimate_model_bytes`] adds a model's layers) |
/// | `.bt`, `.ot` | OctoMap nodes: at most 16 levels above each leaf, 2 (`.bt`) or 9 (`.ot`) bytes each |
/// | `.binvox` | two bytes per run of the dense grid over the bounding box |
/// | `.vox` | four bytes per voxel, plus the palette |
/// | `.stl`, `.obj`, `.ply`, `.glb` | 600 bytes per leaf (twelve triangles) |
///
/// # Runtime
/// O(n) in the number of leaves (a voxel count and a bounding box).
///
/// # Example
/// ```
/// use tesseral::linear::LinearOctree;
/// let tree = LinearOctree::from_voxels(4, [0, 0, 0], [[1, 2, 3], [4, 5, 6]]).unwrap();
/// let bytes = tesseral::io::estimate_output_bytes(&tree, "xyz").unwrap();
/// // Two lines of `x y z` plus the header line: small.
/// assert!(bytes >= 10 && bytes < 200);
/// assert_eq!(tesseral::io::estimate_output_bytes(&tree, "jpg"), None);
/// ```
#[must_use]
pub fn estimate_output_bytes(tree: &LinearOctree, ext: &str) -> Option<u64> {
    let leaves = tree.leaf_count() as u64;
    let bytes = match ext {
        "xyz" => estimate_xyz_bytes(tree.voxel_count(), tree.bbox()),
        // Header, frame and trailer; ten bytes a leaf at most; 68 bytes a chunk (its
        // header, checksum and index entry).
        "tess" => 200u64
            .saturating_add(leaves.saturating_mul(10))
            .saturating_add((leaves / super::DEFAULT_CHUNK_LEAVES as u64 + 1) * 68),
        "bt" => 200u64.saturating_add(leaves.saturating_mul(16 * 2)),
        "ot" => 200u64.saturating_add(leaves.saturating_mul(16 * 9)),
        "binvox" => {
            let volume = bbox_volume(tree);
            let runs = volume.min(
                tree.voxel_count()
                    .saturating_mul(2)
                    .saturating_add(1)
                    .saturating_add(volume / 255),
            );
            100u64.saturating_add(runs.saturating_mul(2))
        }
        "vox" => 2000u64.saturating_add(tree.voxel_count().saturating_mul(4)),
        "stl" | "obj" | "ply" | "glb" => {
            200u64.saturating_add(leaves.saturating_mul(MESH_BYTES_PER_LEAF))
        }
        _ => return None,
    };
    Some(bytes)
}

/// [`estimate_output_bytes`] of a whole model: a `.tess` holds its layers too
/// (colours, free space, log-odds: at most ten bytes a leaf and 16 a region, plus
/// 64 bytes a colour region for its index), and OctoMap's `.bt` and `.ot` hold the
/// free space beside the occupied cells (its leaves counted as the tree's). Other
/// formats write the voxels only.
///
/// # Runtime
/// O(n) in the number of leaves.
///
/// # Example
/// ```
/// use tesseral::io::{estimate_model_bytes, estimate_output_bytes};
/// use tesseral::linear::LinearOctree;
/// use tesseral::model::{Frame, Model};
/// let tree = LinearOctree::from_voxels(4, [0, 0, 0], [[1, 2, 3]]).unwrap();
/// let free = LinearOctree::from_voxels(4, [0, 0, 0], [[0, 0, 0], [5, 5, 5]]).unwrap();
/// let model = Model::from_parts(tree.clone(), Frame::default(), None, Some(free), None).unwrap();
/// let alone = estimate_output_bytes(&tree, "tess").unwrap();
/// assert_eq!(estimate_model_bytes(&model, "tess"), Some(alone + 16 + 2 * 10));
/// assert_eq!(estimate_model_bytes(&model, "xyz"), estimate_output_bytes(&tree, "xyz"));
/// ```
#[must_use]
pub fn estimate_model_bytes(model: &Model, ext: &str) -> Option<u64> {
    let base = estimate_output_bytes(&model.tree, ext)?;
    let free = model.free.as_ref().map_or(0, |f| f.leaf_count() as u64);
    fn layer<T: LayerValue>(l: Option<&Layer<T>>, per_region: u64) -> u64 {
        l.map_or(0, |l| {
            l.regions().iter().fold(16, |n: u64, (_, t)| {
                n.saturating_add(per_region)
                    .saturating_add((t.leaf_count() as u64).saturating_mul(10))
            })
        })
    }
    let more = match ext {
        "tess" => (if model.free.is_some() { 16 } else { 0 } + free.saturating_mul(10))
            .saturating_add(layer(model.log_odds.as_ref(), 16))
            .saturating_add(layer(model.colors.as_ref(), 16 + 64)),
        "bt" => free.saturating_mul(16 * 2),
        "ot" => free.saturating_mul(16 * 9),
        _ => 0,
    };
    Some(base.saturating_add(more))
}

/// The `.xyz` estimate of [`estimate_output_bytes`] from the voxel count and the
/// bounding box (lowest and highest voxels, `None` when empty), for a writer that
/// counts them without holding the tree: one line per voxel, each as long as the
/// widest coordinates allow (an upper bound).
///
/// ```
/// assert_eq!(tesseral::io::estimate_xyz_bytes(0, None), 80);
/// assert!(tesseral::io::estimate_xyz_bytes(2, Some(([0; 3], [9; 3]))) >= 2 * 6);
/// ```
#[must_use]
pub fn estimate_xyz_bytes(voxels: u64, bbox: Option<([i64; 3], [i64; 3])>) -> u64 {
    let line = match bbox {
        // Three numbers, two spaces and a newline.
        Some((lo, hi)) => {
            let width = (0..3)
                .map(|a| decimal_width(lo[a]).max(decimal_width(hi[a])))
                .max()
                .unwrap_or(1);
            3 * width + 3
        }
        None => 0,
    };
    80u64.saturating_add(voxels.saturating_mul(line))
}

/// Estimates the size of a PNG image of `width` × `height` RGB pixels: at most
/// its raw size (the encoder falls back to stored blocks) plus the chunk overhead.
///
/// # Runtime
/// O(1).
///
/// # Example
/// ```
/// assert!(tesseral::io::estimate_image_bytes(800, 600) >= 800 * 600 * 3);
/// ```
#[must_use]
pub fn estimate_image_bytes(width: u64, height: u64) -> u64 {
    // One filter byte per row, and deflate's stored blocks add 5 bytes per 64 KiB.
    let raw = width
        .saturating_mul(3)
        .saturating_add(1)
        .saturating_mul(height);
    raw.saturating_add(raw / 13_000).saturating_add(100)
}

/// Characters of `v` in decimal, with its sign.
fn decimal_width(v: i64) -> u64 {
    let digits = u64::from(v.unsigned_abs().checked_ilog10().unwrap_or(0)) + 1;
    digits + u64::from(v < 0)
}

/// Voxels in the bounding box of the black voxels (0 when empty).
fn bbox_volume(tree: &LinearOctree) -> u64 {
    tree.bbox().map_or(0, |(lo, hi)| {
        (0..3)
            .map(|a| hi[a].abs_diff(lo[a]) + 1)
            .fold(1u64, u64::saturating_mul)
    })
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};

    use super::*;
    use crate::io::{random_voxels, Model};

    #[test]
    fn decimal_widths() {
        assert_eq!(decimal_width(0), 1);
        assert_eq!(decimal_width(9), 1);
        assert_eq!(decimal_width(10), 2);
        assert_eq!(decimal_width(-10), 3);
        assert_eq!(decimal_width(i64::MIN), 20);
        assert_eq!(decimal_width(i64::MAX), 19);
    }

    /// Each estimate against the size of the file actually written, on seeded random
    /// solids: `.xyz` and `.tess` are upper bounds within a factor of 2 and 10, the
    /// others within a factor of 20 either way.
    #[test]
    fn estimates_against_written_files() {
        let seed = 0x5eed_e571;
        println!("seed {seed:#x}");
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let dir = tempfile::tempdir().unwrap();
        let mut checked = 0;
        for case in 0..40 {
            let spread = if case % 2 == 0 { 5 } else { 1 << 40 };
            let (origin, voxels) = random_voxels(&mut rng, spread, 32, 400);
            let cube = rng.random_range(0..4) == 0;
            let voxels: Vec<_> = if cube {
                // A solid block, which greedy meshing and RLE shrink most.
                (0..8)
                    .flat_map(|x| (0..8).flat_map(move |y| (0..8).map(move |z| [x, y, z])))
                    .map(|[x, y, z]| [origin[0] + x, origin[1] + y, origin[2] + z])
                    .collect()
            } else {
                voxels
            };
            if voxels.is_empty() {
                continue;
            }
            let tree = LinearOctree::from_voxels(5, origin, voxels).unwrap();
            for ext in [
                "xyz", "tess", "bt", "ot", "binvox", "vox", "stl", "obj", "ply", "glb",
            ] {
                if spread > 5 && ["binvox", "vox", "bt", "ot"].contains(&ext) {
                    // These formats hold a bounded grid: far origins are refused.
                    continue;
                }
                let path = dir.path().join(format!("c.{ext}"));
                let model = Model::new(tree.clone());
                if crate::io::write_model(&path, &model).is_err() {
                    continue;
                }
                let real = std::fs::metadata(&path).unwrap().len();
                let est = estimate_output_bytes(&tree, ext).unwrap();
                let (lo, hi) = match ext {
                    "xyz" => (real, 2 * real),
                    "tess" => (real, 10 * real),
                    _ => (real / 20, 20 * real),
                };
                assert!(
                    (lo..=hi).contains(&est),
                    "case {case} .{ext}: estimated {est}, wrote {real} ({} leaves)",
                    tree.leaf_count()
                );
                checked += 1;
            }
        }
        // Most writes must succeed, or the test checks little.
        assert!(checked > 150, "only {checked} files compared");
    }

    #[test]
    fn images() {
        let tree = LinearOctree::from_voxels(3, [0, 0, 0], [[1, 1, 1]]).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("i.png");
        let opts = crate::render::RenderOptions {
            width: 64,
            height: 48,
            ..Default::default()
        };
        let img = crate::render::render(&tree, crate::render::Surface::default(), &opts);
        img.write_png(&path).unwrap();
        let real = std::fs::metadata(&path).unwrap().len();
        assert!(estimate_image_bytes(64, 48) >= real);
    }

    #[test]
    fn huge_counts_saturate() {
        let tree =
            LinearOctree::from_voxels(21, [0, 0, 0], std::iter::empty::<crate::Voxel>()).unwrap();
        let full = tree.complement();
        assert_eq!(full.voxel_count(), 1 << 63);
        let xyz = estimate_output_bytes(&full, "xyz").unwrap();
        assert!(xyz > 1 << 63);
    }
}
