//! OctoMap occupancy trees: the compact binary `.bt` (`writeBinary`/`readBinary`)
//! and the full `.ot` (`write`/`read`, with log-odds per node, and colours for
//! `ColorOcTree`).
//!
//! OctoMap addresses voxels by 16-bit keys per axis, centred at 32768: key `k` is the
//! voxel `[(k − 32768)·res, (k − 32767)·res)`. tesseral voxel `i` is key `i + 32768`,
//! so a `.bt` becomes a depth-16 [`LinearOctree`] with origin `(−32768, −32768,
//! −32768)` and a [`Frame`] whose voxel size is the resolution. Its child order
//! (`computeChildIdx`: x = 1, y = 2, z = 4) is ours, so a preorder walk of the file
//! yields leaves in tesseral order with no sorting.
//!
//! Occupied leaves become black, free leaves the model's known-free space, and in
//! `.ot` files every leaf's log-odds goes into the model's log-odds layer bit for bit
//! (and `ColorOcTree` colours into its colour layer), so a round trip keeps the map.
//! Writing emits black voxels as occupied, free ones as free, and the rest unknown.
//!
//! `.bt` stream: a text header (`# Octomap OcTree binary file`, then `id`, `size`,
//! `res`, `data` lines), then per inner node in preorder two bytes holding two bits
//! per child (child `i` in bits `2i, 2i+1`): `00` unknown, `01` (bit `2i+1`)
//! occupied leaf, `10` (bit `2i`) free leaf, `11` inner node, whose own two bytes
//! follow, recursively, after its parent's.
//!
//! `.ot` stream: per node in preorder its data (`f32` log-odds; `ColorOcTree` adds
//! r, g, b bytes; `OcTreeStamped` a `u32` time), then a byte with bit `i` set when
//! child `i` exists. A leaf is occupied when its log-odds is ≥ 0 (probability ≥ ½).

use std::path::Path;

#[cfg(test)]
mod range_tests;
pub(crate) mod stream;
#[cfg(test)]
mod stream_tests;
#[cfg(test)]
mod tests;
mod write;

pub(crate) use write::{bt_file, ot_file};
pub use write::{encode_bt, encode_ot, write_file, FREE_LOG_ODDS};

use super::{FormatError, MAX_COLORED_VOXELS};
use crate::linear::{Leaf, LinearOctree};
use crate::model::{Frame, Layer, Model, Rgba};

/// The depth of every OctoMap tree.
pub const OCTOMAP_DEPTH: u8 = 16;
/// The world voxel of key 0: keys are centred at 32768.
pub const KEY_ORIGIN: i64 = -32768;
/// Whether voxel `cell` has an OctoMap key: −32768..32767 on each axis.
#[must_use]
pub fn in_key_range(cell: crate::Voxel) -> bool {
    cell.iter()
        .all(|c| (KEY_ORIGIN..=-KEY_ORIGIN - 1).contains(c))
}

/// The log-odds written for occupied leaves: OctoMap's default upper clamping
/// threshold, probability 0.971, as OctoMap computes it (`log(p / (1 − p))` rounded
/// to `f32`; what it gives a `.bt`'s occupied cells).
pub const OCCUPIED_LOG_ODDS: f32 = 3.511_030_7;

const BT_HEADER: &str = "# Octomap OcTree binary file";
const OT_HEADER: &str = "# Octomap OcTree file";

/// Reads a `.bt` or `.ot` file (by extension).
///
/// # Errors
/// [`FormatError::Corrupt`] for a malformed header or stream, a node count that
/// disagrees with the header, or a tree deeper than 16.
pub fn read(path: &Path) -> Result<Model, FormatError> {
    let bytes = super::read_limited(path, super::MAX_FILE_BYTES)?;
    if super::extension(path) == "ot" {
        decode_ot(&bytes).map_err(|e| e.with_path(path))
    } else {
        decode_bt(&bytes).map_err(|e| e.with_path(path))
    }
}

struct Header {
    id: String,
    size: u64,
    res: f64,
    data_start: usize,
}

/// Parses the header the way OctoMap's `readHeader` does: whitespace-separated
/// tokens, `#` comments to the end of the line, `data` ends it.
fn parse_header(bytes: &[u8], first: &str) -> Result<Header, FormatError> {
    let bad = |m: String| FormatError::corrupt(m);
    let nl = bytes
        .iter()
        .position(|&b| b == b'\n')
        .ok_or_else(|| bad("no header line".into()))?;
    if !bytes[..nl].starts_with(first.as_bytes()) {
        return Err(bad(format!("first line must start with `{first}`")));
    }
    let mut pos = nl + 1;
    let mut id = String::new();
    let mut size: Option<u64> = None;
    let mut res: Option<f64> = None;
    let token = |pos: &mut usize| -> Option<String> {
        while *pos < bytes.len() && bytes[*pos].is_ascii_whitespace() {
            *pos += 1;
        }
        let start = *pos;
        while *pos < bytes.len() && !bytes[*pos].is_ascii_whitespace() && *pos - start < 256 {
            *pos += 1;
        }
        (start < *pos).then(|| String::from_utf8_lossy(&bytes[start..*pos]).into_owned())
    };
    let skip_line = |pos: &mut usize| {
        while *pos < bytes.len() && bytes[*pos] != b'\n' {
            *pos += 1;
        }
        *pos = (*pos + 1).min(bytes.len());
    };
    loop {
        let Some(t) = token(&mut pos) else {
            return Err(bad("header ends without a `data` line".into()));
        };
        match t.as_str() {
            "data" => {
                skip_line(&mut pos);
                break;
            }
            _ if t.starts_with('#') => skip_line(&mut pos),
            "id" => id = token(&mut pos).unwrap_or_default(),
            "size" => {
                let v = token(&mut pos).unwrap_or_default();
                size = Some(
                    v.parse()
                        .map_err(|_| bad(format!("size `{v}` is not a count")))?,
                );
            }
            "res" => {
                let v = token(&mut pos).unwrap_or_default();
                let r: f64 = v
                    .parse()
                    .map_err(|_| bad(format!("res `{v}` is not a number")))?;
                if !(r.is_normal() && r > 0.0) {
                    return Err(bad(format!("res {r} must be finite, positive and normal")));
                }
                res = Some(r);
            }
            _ => skip_line(&mut pos),
        }
    }
    if id == "1" {
        id = "OcTree".into(); // legacy id, as OctoMap reads it
    }
    Ok(Header {
        id,
        size: size.ok_or_else(|| bad("header has no `size`".into()))?,
        res: res.ok_or_else(|| bad("header has no `res`".into()))?,
        data_start: pos,
    })
}

fn octomap_space() -> LinearOctree {
    LinearOctree::empty(OCTOMAP_DEPTH, [KEY_ORIGIN; 3]).expect("depth 16 is valid")
}

/// Decodes `.bt` bytes.
///
/// # Runtime
/// O(nodes): one pass, no sorting.
///
/// # Errors
/// As [`read`].
pub fn decode_bt(bytes: &[u8]) -> Result<Model, FormatError> {
    let header = parse_header(bytes, BT_HEADER)?;
    let frame = Frame::new(header.res, [0.0; 3]);
    if header.size == 0 {
        return Ok(Model::new(octomap_space()).with_frame(frame));
    }
    let data = &bytes[header.data_start..];
    let (leaves, free, nodes, used) = decode_bt_stream(data).map_err(FormatError::corrupt)?;
    if nodes != header.size {
        return Err(FormatError::corrupt(format!(
            "header says {} nodes, the data holds {nodes}",
            header.size
        )));
    }
    let _ = used;
    let tree = LinearOctree::from_sorted_leaves(OCTOMAP_DEPTH, [KEY_ORIGIN; 3], leaves)
        .map_err(FormatError::octree)?;
    let free = LinearOctree::from_sorted_leaves(OCTOMAP_DEPTH, [KEY_ORIGIN; 3], free)
        .map_err(FormatError::octree)?;
    Ok(Model {
        free: Some(free),
        ..Model::new(tree).with_frame(frame)
    })
}

/// The occupied and the free leaves of a `.bt` stream, each in tesseral order.
type BtLeaves = (Vec<Leaf>, Vec<Leaf>, u64, usize);

/// Walks a `.bt` data stream; returns the occupied and free leaves in tesseral order,
/// the node count (root included) and the bytes used.
fn decode_bt_stream(data: &[u8]) -> Result<BtLeaves, String> {
    // Each inner node takes two bytes and adds at most 8 leaves.
    let mut leaves = Vec::with_capacity((data.len() / 2).min(1 << 24));
    let mut free = Vec::new();
    let mut nodes = 1u64;
    let mut pos = 0usize;
    // Explicit stack: (child bits, next child, code of the node's first voxel).
    let mut stack: [(u16, u8, u64); 17] = [(0, 0, 0); 17];
    let read_pair = |pos: &mut usize| -> Result<u16, String> {
        if *pos + 2 > data.len() {
            return Err(format!("data ends at byte {} inside a node", *pos));
        }
        let v = u16::from_le_bytes([data[*pos], data[*pos + 1]]);
        *pos += 2;
        Ok(v)
    };
    stack[0] = (read_pair(&mut pos)?, 0, 0);
    let mut top = 0usize;
    loop {
        let (bits, next, base) = stack[top];
        if next == 8 {
            if top == 0 {
                break;
            }
            top -= 1;
            continue;
        }
        stack[top].1 = next + 1;
        let kind = (bits >> (2 * next)) & 3;
        if kind == 0 {
            continue;
        }
        nodes += 1;
        // A child of a node at depth `top` has depth top + 1 and size 2^(15 - top).
        let child_log2 = (OCTOMAP_DEPTH as usize - 1 - top) as u8;
        let child = base + (u64::from(next) << (3 * u32::from(child_log2)));
        match kind {
            2 => leaves.push(Leaf::new(child, child_log2)),
            1 => free.push(Leaf::new(child, child_log2)),
            _ => {
                if child_log2 == 0 {
                    return Err(format!(
                        "byte {}: a node at depth 16 claims children (OctoMap trees are 16 deep)",
                        pos.saturating_sub(2)
                    ));
                }
                top += 1;
                stack[top] = (read_pair(&mut pos)?, 0, child);
            }
        }
    }
    Ok((leaves, free, nodes, pos))
}

/// Decodes `.ot` bytes (`OcTree`, `ColorOcTree` or `OcTreeStamped`).
///
/// # Errors
/// As [`read`]; [`FormatError::Unsupported`] for another tree type.
pub fn decode_ot(bytes: &[u8]) -> Result<Model, FormatError> {
    let header = parse_header(bytes, OT_HEADER)?;
    let extra = match header.id.as_str() {
        "OcTree" => 0,
        "ColorOcTree" => 3,
        "OcTreeStamped" => 4,
        other => {
            return Err(FormatError::unsupported(format!(
                "tree type `{other}` (we read OcTree, ColorOcTree, OcTreeStamped)"
            )))
        }
    };
    let color = extra == 3;
    let frame = Frame::new(header.res, [0.0; 3]);
    let space = octomap_space();
    if header.size == 0 {
        let colors = color.then(|| Layer::empty(OCTOMAP_DEPTH, [KEY_ORIGIN; 3]));
        return Ok(Model {
            colors,
            free: Some(space.clone()),
            log_odds: Some(Layer::empty(OCTOMAP_DEPTH, [KEY_ORIGIN; 3])),
            ..Model::new(space).with_frame(frame)
        });
    }
    let data = &bytes[header.data_start..];
    let bad = |m: String| FormatError::corrupt(m);
    let node_len = 4 + extra;
    let mut pos = 0usize;
    let mut nodes = 0u64;
    let mut leaves: Vec<Leaf> = Vec::new();
    let mut free: Vec<Leaf> = Vec::new();
    let mut values: Vec<(Leaf, f32)> = Vec::new();
    let mut leaf_colors: Vec<(Leaf, Rgba)> = Vec::new();
    let mut coloured_voxels = 0u64;
    // Stack of (children mask, next child, code, depth).
    let mut stack: Vec<(u8, u8, u64, u8)> = Vec::with_capacity(17);
    let mut read_node = |pos: &mut usize,
                         code: u64,
                         depth: u8,
                         nodes: &mut u64|
     -> Result<u8, FormatError> {
        if *pos + node_len + 1 > data.len() {
            return Err(bad(format!("data ends at byte {} inside a node", *pos)));
        }
        let d = &data[*pos..*pos + node_len + 1];
        *pos += node_len + 1;
        *nodes += 1;
        let value = f32::from_le_bytes([d[0], d[1], d[2], d[3]]);
        let children = d[node_len];
        if children != 0 && depth == OCTOMAP_DEPTH {
            return Err(bad(format!(
                "byte {}: a node at depth 16 claims children",
                *pos - 1
            )));
        }
        if !value.is_finite() {
            return Err(bad(format!(
                "byte {}: log-odds {value} is not finite",
                *pos - node_len - 1
            )));
        }
        if children == 0 {
            values.push((Leaf::new(code, OCTOMAP_DEPTH - depth), value));
        }
        if children == 0 && value < 0.0 {
            free.push(Leaf::new(code, OCTOMAP_DEPTH - depth));
        }
        if children == 0 && value >= 0.0 {
            let leaf = Leaf::new(code, OCTOMAP_DEPTH - depth);
            leaves.push(leaf);
            if color {
                coloured_voxels += leaf.voxel_count();
                if coloured_voxels > MAX_COLORED_VOXELS {
                    return Err(FormatError::too_large(
                            format!("more than {MAX_COLORED_VOXELS} coloured voxels, the budget of a colour layer"),
                        ));
                }
                leaf_colors.push((leaf, [d[4], d[5], d[6], 255]));
            }
        }
        Ok(children)
    };
    let root = read_node(&mut pos, 0, 0, &mut nodes)?;
    stack.push((root, 0, 0, 0));
    while let Some(top) = stack.last_mut() {
        let (mask, next, code, depth) = *top;
        if next == 8 {
            stack.pop();
            continue;
        }
        top.1 += 1;
        if mask & (1 << next) == 0 {
            continue;
        }
        let child_log2 = OCTOMAP_DEPTH - depth - 1;
        let child = code + (u64::from(next) << (3 * u32::from(child_log2)));
        let m = read_node(&mut pos, child, depth + 1, &mut nodes)?;
        if m != 0 {
            stack.push((m, 0, child, depth + 1));
        }
    }
    if nodes != header.size {
        return Err(bad(format!(
            "header says {} nodes, the data holds {nodes}",
            header.size
        )));
    }
    let tree = LinearOctree::from_sorted_leaves(OCTOMAP_DEPTH, [KEY_ORIGIN; 3], leaves)
        .map_err(FormatError::octree)?;
    let oct = FormatError::octree;
    let colors = if color {
        Some(Layer::from_sorted_leaves(OCTOMAP_DEPTH, [KEY_ORIGIN; 3], leaf_colors).map_err(oct)?)
    } else {
        None
    };
    let free =
        LinearOctree::from_sorted_leaves(OCTOMAP_DEPTH, [KEY_ORIGIN; 3], free).map_err(oct)?;
    let log_odds =
        Layer::from_sorted_leaves(OCTOMAP_DEPTH, [KEY_ORIGIN; 3], values).map_err(oct)?;
    let _ = space;
    Ok(Model {
        tree,
        frame,
        colors,
        free: Some(free),
        log_odds: Some(log_odds),
    })
}
