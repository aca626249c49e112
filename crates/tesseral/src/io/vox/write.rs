//! Writing `.vox`: one model over the bounding box, a palette of the most frequent
//! colours.

use std::collections::HashMap;
use std::path::Path;

use super::DEFAULT_COLOR;
use crate::io::{FormatError, Model};
use crate::Voxel;

/// Writes `model` to `path` as a one-model `.vox`.
///
/// # Errors
/// [`FormatError::Unsupported`] when the bounding box is wider than 256 voxels.
pub fn write_file(path: &Path, model: &Model) -> Result<(), FormatError> {
    let bytes = encode(model).map_err(|m| FormatError::unsupported(m).with_path(path))?;
    crate::io::write_atomic(path, |w| std::io::Write::write_all(w, &bytes))
}

/// Encodes `model` as `.vox` bytes (version 150, one model over the bounding box).
///
/// # Errors
/// A message when the bounding box is wider than 256 voxels on some axis.
///
/// ```
/// use tesseral::io::{vox, Model};
/// use tesseral::linear::LinearOctree;
/// let tree = LinearOctree::from_voxels(2, [0, 0, 0], [[0, 0, 0], [3, 1, 2]]).unwrap();
/// let back = vox::decode(&vox::encode(&Model::new(tree.clone())).unwrap()).unwrap();
/// assert_eq!(back.tree.voxels().collect::<Vec<_>>(), tree.voxels().collect::<Vec<_>>());
/// ```
pub fn encode(model: &Model) -> Result<Vec<u8>, String> {
    let tree = &model.tree;
    let (lo, hi) = tree.bbox().unwrap_or(([0; 3], [0; 3]));
    // Keep coordinates as they are when they already fit 0..256.
    let base = if lo.iter().all(|&c| c >= 0) && hi.iter().all(|&c| c < 256) {
        [0; 3]
    } else {
        lo
    };
    let size: Vec<i64> = (0..3).map(|a| hi[a] - base[a] + 1).collect();
    if size.iter().any(|&s| s > 256) {
        return Err(format!(
            "the octree spans {}×{}×{} voxels; MagicaVoxel models are at most 256 per axis",
            size[0], size[1], size[2]
        ));
    }
    let count = tree.voxel_count();
    // Palette: the 255 most frequent colours.
    let colour_of = |v: &Voxel| -> [u8; 4] {
        model
            .colors
            .as_ref()
            .and_then(|m| m.get(*v))
            .unwrap_or(DEFAULT_COLOR)
    };
    let mut freq: HashMap<[u8; 4], u64> = HashMap::new();
    for v in tree.voxels() {
        *freq.entry(colour_of(&v)).or_default() += 1;
    }
    let mut by_freq: Vec<([u8; 4], u64)> = freq.into_iter().collect();
    by_freq.sort_unstable_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    by_freq.truncate(255);
    let palette: Vec<[u8; 4]> = by_freq.iter().map(|e| e.0).collect();
    let index: HashMap<[u8; 4], u8> = palette
        .iter()
        .enumerate()
        .map(|(i, c)| (*c, (i + 1) as u8))
        .collect();
    let nearest = |c: [u8; 4]| -> u8 {
        if let Some(&i) = index.get(&c) {
            return i;
        }
        let d = |p: &[u8; 4]| {
            (0..4)
                .map(|k| (i32::from(p[k]) - i32::from(c[k])).pow(2))
                .sum::<i32>()
        };
        (palette
            .iter()
            .enumerate()
            .min_by_key(|(_, p)| d(p))
            .map_or(0, |(i, _)| i)
            + 1) as u8
    };
    let mut xyzi = Vec::with_capacity(4 + 4 * count as usize);
    xyzi.extend_from_slice(&(count as u32).to_le_bytes());
    for v in tree.voxels() {
        xyzi.extend_from_slice(&[
            (v[0] - base[0]) as u8,
            (v[1] - base[1]) as u8,
            (v[2] - base[2]) as u8,
            nearest(colour_of(&v)),
        ]);
    }
    let mut size_c = Vec::new();
    for s in &size {
        size_c.extend_from_slice(&(*s as u32).to_le_bytes());
    }
    let mut rgba = Vec::with_capacity(1024);
    for i in 0..256 {
        rgba.extend_from_slice(&palette.get(i).copied().unwrap_or([0, 0, 0, 255]));
    }
    let mut children = Vec::new();
    for (id, body) in [(b"SIZE", &size_c), (b"XYZI", &xyzi), (b"RGBA", &rgba)] {
        children.extend_from_slice(id);
        children.extend_from_slice(&(body.len() as u32).to_le_bytes());
        children.extend_from_slice(&0u32.to_le_bytes());
        children.extend_from_slice(body);
    }
    let mut out = Vec::with_capacity(children.len() + 20);
    out.extend_from_slice(b"VOX ");
    out.extend_from_slice(&150u32.to_le_bytes());
    out.extend_from_slice(b"MAIN");
    out.extend_from_slice(&0u32.to_le_bytes());
    out.extend_from_slice(&(children.len() as u32).to_le_bytes());
    out.extend_from_slice(&children);
    Ok(out)
}
