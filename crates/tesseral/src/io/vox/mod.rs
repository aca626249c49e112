//! MagicaVoxel `.vox`: RIFF-style chunks holding models of up to 256³ voxels, each
//! voxel a palette index, with a 256-entry RGBA palette.
//!
//! Reading keeps every voxel's palette colour in [`Model::colors`]. Files with
//! several models are assembled with the translations of their scene graph (`nTRN`,
//! `nGRP`, `nSHP`), placing model voxel `v` at `t + v − ⌊size/2⌋` as MagicaVoxel
//! does; a rotated model is refused rather than placed wrongly. A file with one model
//! keeps the model's own coordinates. z is up in MagicaVoxel, as in tesseral.
//!
//! Writing emits one model (`SIZE`, `XYZI`) over the bounding box and an `RGBA`
//! palette built from the colours (the 255 most frequent; any others take the
//! nearest of those), or a single grey when the model has no colours.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

#[cfg(test)]
mod tests;
mod write;

pub use write::{encode, write_file};

use super::leafstream::Reader;
use super::{FormatError, Model, MAX_DENSE_VOXELS};
use crate::linear::LinearOctree;
use crate::model::Layer;
use crate::Voxel;

/// The colour given to voxels that have none when written.
pub const DEFAULT_COLOR: [u8; 4] = [200, 200, 200, 255];

/// Reads a `.vox` file.
///
/// # Errors
/// [`FormatError::Corrupt`] naming the chunk at fault; [`FormatError::Unsupported`]
/// for a rotated model in a scene.
pub fn read(path: &Path) -> Result<Model, FormatError> {
    let bytes = super::read_limited(path, super::MAX_FILE_BYTES)?;
    decode(&bytes).map_err(|e| e.with_path(path))
}

struct VoxModel {
    size: [i64; 3],
    voxels: Vec<([u8; 3], u8)>,
}

enum Node {
    Transform { t: [i64; 3], child: i32 },
    Group(Vec<i32>),
    Shape(Vec<i32>),
}

/// Decodes `.vox` bytes; `path` names the source in errors.
///
/// # Runtime
/// O(file size + voxels · log voxels).
///
/// # Errors
/// As [`read`].
pub fn decode(bytes: &[u8]) -> Result<Model, FormatError> {
    let bad = |m: String| FormatError::corrupt(m);
    if bytes.len() < 8 || &bytes[..4] != b"VOX " {
        return Err(bad("not a MagicaVoxel file (no `VOX ` magic)".into()));
    }
    let mut r = Reader { bytes, pos: 8 };
    let (id, content, children) = chunk_header(&mut r).map_err(&bad)?;
    if &id != b"MAIN" {
        return Err(bad("the first chunk is not MAIN".into()));
    }
    r.take(content).map_err(&bad)?;
    let end = r
        .pos
        .checked_add(children)
        .filter(|&e| e <= bytes.len())
        .ok_or_else(|| bad("MAIN's children run past the end of the file".into()))?;
    let mut models: Vec<VoxModel> = Vec::new();
    let mut pending_size: Option<[i64; 3]> = None;
    let mut palette: Option<Vec<[u8; 4]>> = None;
    let mut nodes: HashMap<i32, Node> = HashMap::new();
    let mut total_voxels = 0u64;
    while r.pos < end {
        let at = r.pos;
        let (id, content, children) = chunk_header(&mut r).map_err(&bad)?;
        let name = String::from_utf8_lossy(&id).into_owned();
        let body = r
            .take(content)
            .map_err(|m| bad(format!("chunk {name} at byte {at}: {m}")))?;
        r.take(children)
            .map_err(|m| bad(format!("chunk {name} at byte {at}: {m}")))?;
        let mut c = Reader {
            bytes: body,
            pos: 0,
        };
        let in_chunk = |m: String| bad(format!("chunk {name} at byte {at}: {m}"));
        match &id {
            b"SIZE" => {
                let s = [c.u32(), c.u32(), c.u32()];
                let mut size = [0i64; 3];
                for a in 0..3 {
                    let v = s[a].clone().map_err(&in_chunk)?;
                    if v == 0 || v > 256 {
                        return Err(in_chunk(format!("model size {v} is not in 1..=256")));
                    }
                    size[a] = i64::from(v);
                }
                pending_size = Some(size);
            }
            b"XYZI" => {
                let size = pending_size
                    .take()
                    .ok_or_else(|| in_chunk("XYZI without a SIZE before it".into()))?;
                let n = u64::from(c.u32().map_err(&in_chunk)?);
                if n > (body.len() as u64 - 4) / 4 {
                    return Err(in_chunk(format!(
                        "{n} voxels cannot fit in {} bytes",
                        body.len()
                    )));
                }
                total_voxels += n;
                if total_voxels > MAX_DENSE_VOXELS {
                    return Err(FormatError::too_large(format!(
                        "more than {MAX_DENSE_VOXELS} voxels"
                    )));
                }
                let mut voxels = Vec::with_capacity(n as usize);
                for _ in 0..n {
                    let v = c.take(4).map_err(&in_chunk)?;
                    if (0..3).any(|a| i64::from(v[a]) >= size[a]) {
                        return Err(in_chunk(format!(
                            "voxel ({}, {}, {}) lies outside the model size {size:?}",
                            v[0], v[1], v[2]
                        )));
                    }
                    voxels.push(([v[0], v[1], v[2]], v[3]));
                }
                models.push(VoxModel { size, voxels });
            }
            b"RGBA" => {
                let mut p = Vec::with_capacity(256);
                for _ in 0..256 {
                    let e = c.take(4).map_err(&in_chunk)?;
                    p.push([e[0], e[1], e[2], e[3]]);
                }
                palette = Some(p);
            }
            b"nTRN" => {
                let node = c.i32().map_err(&in_chunk)?;
                skip_dict(&mut c).map_err(&in_chunk)?;
                let child = c.i32().map_err(&in_chunk)?;
                c.i32().map_err(&in_chunk)?; // reserved
                c.i32().map_err(&in_chunk)?; // layer
                let frames = c.i32().map_err(&in_chunk)?;
                let mut t = [0i64; 3];
                if frames >= 1 {
                    let dict = read_dict(&mut c).map_err(&in_chunk)?;
                    if let Some(rot) = dict.get("_r") {
                        if rot.trim() != "4" {
                            return Err(FormatError::unsupported(format!("node {node} rotates its model (_r = {rot}); rotated models are not read"),
                            ));
                        }
                    }
                    if let Some(tr) = dict.get("_t") {
                        let parts: Vec<i64> = tr
                            .split_whitespace()
                            .filter_map(|w| w.parse().ok())
                            .collect();
                        if parts.len() != 3 || parts.iter().any(|p| p.abs() > 1 << 30) {
                            return Err(in_chunk(format!("bad translation `{tr}`")));
                        }
                        t = [parts[0], parts[1], parts[2]];
                    }
                }
                nodes.insert(node, Node::Transform { t, child });
            }
            b"nGRP" => {
                let node = c.i32().map_err(&in_chunk)?;
                skip_dict(&mut c).map_err(&in_chunk)?;
                let n = c.u32().map_err(&in_chunk)?;
                let mut kids = Vec::new();
                for _ in 0..n {
                    kids.push(c.i32().map_err(&in_chunk)?);
                }
                nodes.insert(node, Node::Group(kids));
            }
            b"nSHP" => {
                let node = c.i32().map_err(&in_chunk)?;
                skip_dict(&mut c).map_err(&in_chunk)?;
                let n = c.u32().map_err(&in_chunk)?;
                let mut ids = Vec::new();
                for _ in 0..n {
                    ids.push(c.i32().map_err(&in_chunk)?);
                    skip_dict(&mut c).map_err(&in_chunk)?;
                }
                nodes.insert(node, Node::Shape(ids));
            }
            _ => {} // PACK, MATL, LAYR, rOBJ, rCAM, NOTE, IMAP: nothing we keep
        }
    }
    let palette = palette.unwrap_or_else(|| {
        dot_vox::DEFAULT_PALETTE
            .iter()
            .map(|c| [c.r, c.g, c.b, c.a])
            .collect()
    });
    // Place every model: by the scene graph when there is more than one.
    let mut placed: Vec<(Voxel, [u8; 4])> = Vec::new();
    let mut place = |m: &VoxModel, offset: Voxel| {
        for (v, ci) in &m.voxels {
            let colour = palette
                .get(usize::from(ci.wrapping_sub(1)))
                .copied()
                .unwrap_or(DEFAULT_COLOR);
            placed.push((
                [
                    offset[0] + i64::from(v[0]),
                    offset[1] + i64::from(v[1]),
                    offset[2] + i64::from(v[2]),
                ],
                colour,
            ));
        }
    };
    if models.len() > 1 && nodes.contains_key(&0) {
        // Every placement counts against the dense-voxel cap before any is expanded:
        // a small scene graph can place one model many times.
        let mut placed_voxels = 0u64;
        walk_graph(&nodes, &models, &mut |m, _| {
            placed_voxels += m.voxels.len() as u64;
            placed_voxels <= MAX_DENSE_VOXELS
        })
        .map_err(&bad)?;
        if placed_voxels > MAX_DENSE_VOXELS {
            return Err(FormatError::too_large(format!(
                "the scene graph places more than {MAX_DENSE_VOXELS} voxels"
            )));
        }
        walk_graph(&nodes, &models, &mut |m, offset| {
            place(m, offset);
            true
        })
        .map_err(&bad)?;
    } else {
        for m in &models {
            place(m, [0, 0, 0]);
        }
    }
    let voxels: Vec<Voxel> = placed.iter().map(|p| p.0).collect();
    let tree = if voxels.is_empty() {
        let side = models
            .first()
            .map_or(1, |m| m.size.iter().copied().max().unwrap_or(1));
        LinearOctree::empty(
            (side as u64).next_power_of_two().trailing_zeros() as u8,
            [0; 3],
        )
    } else if voxels
        .iter()
        .all(|v| v.iter().all(|&c| (0..256).contains(&c)))
    {
        let side = voxels
            .iter()
            .map(|v| v[0].max(v[1]).max(v[2]) + 1)
            .max()
            .unwrap_or(1)
            .max(models.iter().flat_map(|m| m.size).max().unwrap_or(1));
        LinearOctree::from_voxels(
            (side as u64).next_power_of_two().trailing_zeros() as u8,
            [0; 3],
            voxels,
        )
    } else {
        LinearOctree::from_voxels_fitted(&voxels)
    }
    .map_err(FormatError::octree)?;
    let colors =
        Layer::from_voxels(tree.depth(), tree.origin(), placed).map_err(FormatError::octree)?;
    Ok(Model {
        colors: Some(colors),
        ..Model::new(tree)
    })
}

/// Visits every placement of a model by the scene graph from node 0, with the
/// model's lowest corner, until `visit` returns false.
fn walk_graph(
    nodes: &HashMap<i32, Node>,
    models: &[VoxModel],
    visit: &mut dyn FnMut(&VoxModel, Voxel) -> bool,
) -> Result<(), String> {
    let mut stack = vec![(0i32, [0i64; 3], 0u32)];
    let mut visits = 0usize;
    while let Some((id, t, depth)) = stack.pop() {
        visits += 1;
        if depth > 64 || visits > 1 << 20 {
            return Err("scene graph is cyclic or too deep".into());
        }
        match nodes.get(&id) {
            Some(Node::Transform { t: dt, child }) => {
                stack.push((
                    *child,
                    [t[0] + dt[0], t[1] + dt[1], t[2] + dt[2]],
                    depth + 1,
                ));
            }
            Some(Node::Group(kids)) => {
                stack.extend(kids.iter().map(|&k| (k, t, depth + 1)));
            }
            Some(Node::Shape(ids)) => {
                for &m in ids {
                    let model = usize::try_from(m)
                        .ok()
                        .and_then(|m| models.get(m))
                        .ok_or_else(|| format!("shape names model {m}, which does not exist"))?;
                    let s = model.size;
                    if !visit(model, [t[0] - s[0] / 2, t[1] - s[1] / 2, t[2] - s[2] / 2]) {
                        return Ok(());
                    }
                }
            }
            None => return Err(format!("scene graph names node {id}, which does not exist")),
        }
    }
    Ok(())
}

fn chunk_header(r: &mut Reader<'_>) -> Result<([u8; 4], usize, usize), String> {
    let id = r.take(4)?;
    let content = r.u32()?;
    let children = r.u32()?;
    if content > i32::MAX as u32 || children > i32::MAX as u32 {
        return Err(format!("chunk sizes {content}/{children} are negative"));
    }
    Ok((
        [id[0], id[1], id[2], id[3]],
        content as usize,
        children as usize,
    ))
}

fn read_string(c: &mut Reader<'_>) -> Result<String, String> {
    let n = c.u32()? as usize;
    Ok(String::from_utf8_lossy(c.take(n)?).into_owned())
}

fn read_dict(c: &mut Reader<'_>) -> Result<BTreeMap<String, String>, String> {
    let n = c.u32()?;
    let mut d = BTreeMap::new();
    for _ in 0..n {
        let k = read_string(c)?;
        let v = read_string(c)?;
        d.insert(k, v);
    }
    Ok(d)
}

fn skip_dict(c: &mut Reader<'_>) -> Result<(), String> {
    read_dict(c).map(|_| ())
}

impl Reader<'_> {
    fn i32(&mut self) -> Result<i32, String> {
        self.u32().map(|v| v as i32)
    }
}
