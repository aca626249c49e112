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
//! Occupied leaves become black; free and unknown space is white. Writing emits
//! black leaves as occupied and leaves the rest unknown.
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

use super::{reframe, ColorMap, FormatError, Frame, VoxelModel, MAX_COLORED_VOXELS};
use crate::linear::{Leaf, LinearOctree};

/// The depth of every OctoMap tree.
pub const OCTOMAP_DEPTH: u8 = 16;
/// The world voxel of key 0: keys are centred at 32768.
pub const KEY_ORIGIN: i64 = -32768;
/// The log-odds written for occupied leaves: OctoMap's default upper clamping
/// threshold, probability 0.971.
pub const OCCUPIED_LOG_ODDS: f32 = 3.511_015_4;

const BT_HEADER: &str = "# Octomap OcTree binary file";
const OT_HEADER: &str = "# Octomap OcTree file";

/// Reads a `.bt` or `.ot` file (by extension).
///
/// # Errors
/// [`FormatError::Corrupt`] for a malformed header or stream, a node count that
/// disagrees with the header, or a tree deeper than 16.
pub fn read(path: &Path) -> Result<VoxelModel, FormatError> {
    let bytes = super::read_limited(path, super::MAX_FILE_BYTES)?;
    if super::extension(path) == "ot" {
        decode_ot(&bytes, path)
    } else {
        decode_bt(&bytes, path)
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
fn parse_header(bytes: &[u8], first: &str, path: &Path) -> Result<Header, FormatError> {
    let bad = |m: String| FormatError::corrupt(path, m);
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
                if !(r.is_finite() && r > 0.0) {
                    return Err(bad(format!("res {r} must be finite and positive")));
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
pub fn decode_bt(bytes: &[u8], path: &Path) -> Result<VoxelModel, FormatError> {
    let header = parse_header(bytes, BT_HEADER, path)?;
    let frame = Some(Frame {
        voxel_size: header.res,
        translate: [0.0; 3],
    });
    if header.size == 0 {
        return Ok(VoxelModel {
            tree: octomap_space(),
            frame,
            colors: None,
        });
    }
    let data = &bytes[header.data_start..];
    let (leaves, nodes, used) =
        decode_bt_stream(data).map_err(|m| FormatError::corrupt(path, m))?;
    if nodes != header.size {
        return Err(FormatError::corrupt(
            path,
            format!("header says {} nodes, the data holds {nodes}", header.size),
        ));
    }
    let _ = used;
    let tree = LinearOctree::from_sorted_leaves(OCTOMAP_DEPTH, [KEY_ORIGIN; 3], leaves)
        .map_err(|e| FormatError::octree(path, e))?;
    Ok(VoxelModel {
        tree,
        frame,
        colors: None,
    })
}

/// Walks a `.bt` data stream; returns the occupied leaves in tesseral order, the
/// node count (root included) and the bytes used.
fn decode_bt_stream(data: &[u8]) -> Result<(Vec<Leaf>, u64, usize), String> {
    // Each inner node takes two bytes and adds at most 8 leaves.
    let mut leaves = Vec::with_capacity((data.len() / 2).min(1 << 24));
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
            1 => {}
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
    Ok((leaves, nodes, pos))
}

/// Decodes `.ot` bytes (`OcTree`, `ColorOcTree` or `OcTreeStamped`).
///
/// # Errors
/// As [`read`]; [`FormatError::Unsupported`] for another tree type.
pub fn decode_ot(bytes: &[u8], path: &Path) -> Result<VoxelModel, FormatError> {
    let header = parse_header(bytes, OT_HEADER, path)?;
    let extra = match header.id.as_str() {
        "OcTree" => 0,
        "ColorOcTree" => 3,
        "OcTreeStamped" => 4,
        other => {
            return Err(FormatError::unsupported(
                path,
                format!("tree type `{other}` (we read OcTree, ColorOcTree, OcTreeStamped)"),
            ))
        }
    };
    let color = extra == 3;
    let frame = Some(Frame {
        voxel_size: header.res,
        translate: [0.0; 3],
    });
    let space = octomap_space();
    if header.size == 0 {
        return Ok(VoxelModel {
            tree: space,
            frame,
            colors: color.then(ColorMap::new),
        });
    }
    let data = &bytes[header.data_start..];
    let bad = |m: String| FormatError::corrupt(path, m);
    let node_len = 4 + extra;
    let mut pos = 0usize;
    let mut nodes = 0u64;
    let mut leaves: Vec<Leaf> = Vec::new();
    let mut leaf_colors: Vec<(Leaf, [u8; 4])> = Vec::new();
    let mut coloured_voxels = 0u64;
    // Stack of (children mask, next child, code, depth).
    let mut stack: Vec<(u8, u8, u64, u8)> = Vec::with_capacity(17);
    let mut read_node =
        |pos: &mut usize, code: u64, depth: u8, nodes: &mut u64| -> Result<u8, FormatError> {
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
            if children == 0 && value >= 0.0 {
                let leaf = Leaf::new(code, OCTOMAP_DEPTH - depth);
                leaves.push(leaf);
                if color {
                    coloured_voxels += leaf.voxel_count();
                    if coloured_voxels > MAX_COLORED_VOXELS {
                        return Err(FormatError::too_large(
                            path,
                            "too many coloured voxels".to_string(),
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
        .map_err(|e| FormatError::octree(path, e))?;
    let colors = color.then(|| {
        let mut map = ColorMap::new();
        for (leaf, c) in leaf_colors {
            for code in leaf.code()..leaf.end() {
                map.insert(space.voxel_of(code), c);
            }
        }
        map
    });
    Ok(VoxelModel {
        tree,
        frame,
        colors,
    })
}

/// Moves a model into OctoMap's key space, rounding the frame's translate to whole
/// voxels (OctoMap keys cannot hold a fraction of a voxel).
fn to_key_space(model: &VoxelModel) -> Result<(LinearOctree, f64, [i64; 3]), String> {
    let frame = model.frame.unwrap_or_default();
    let shift = frame
        .translate
        .map(|t| (t / frame.voxel_size).round() as i64);
    let mut shifted_origin = [0i64; 3];
    for a in 0..3 {
        shifted_origin[a] = model.tree.origin()[a]
            .checked_add(shift[a])
            .ok_or("the frame's translate moves the octree out of range")?;
    }
    let shifted = LinearOctree::from_sorted_leaves(
        model.tree.depth(),
        shifted_origin,
        model.tree.leaves().iter().copied(),
    )
    .map_err(|e| e.to_string())?;
    let tree = reframe(&shifted, OCTOMAP_DEPTH, [KEY_ORIGIN; 3])
        .map_err(|e| format!("{e}: OctoMap keys reach only voxels −32768..32767 on each axis"))?;
    Ok((tree, frame.voxel_size, shift))
}

/// Writes `model` as `.bt` or `.ot` (by extension). Colours make the `.ot` a
/// `ColorOcTree`.
///
/// # Errors
/// [`FormatError::Unsupported`] when a voxel lies outside OctoMap's key range.
pub fn write_file(path: &Path, model: &VoxelModel) -> Result<(), FormatError> {
    let bytes = if super::extension(path) == "ot" {
        encode_ot(model)
    } else {
        encode_bt(model)
    }
    .map_err(|m| FormatError::unsupported(path, m))?;
    super::write_atomic(path, |w| std::io::Write::write_all(w, &bytes))
}

/// Encodes `model` as `.bt` bytes.
///
/// # Runtime
/// O(n · 16) for n leaves.
///
/// # Errors
/// A message when a voxel lies outside the key range.
///
/// ```
/// use tesseral::io::{octomap, VoxelModel};
/// use tesseral::linear::LinearOctree;
/// let tree = LinearOctree::from_voxels(2, [-2; 3], [[-2, -2, -2], [1, 0, 1]]).unwrap();
/// let bytes = octomap::encode_bt(&VoxelModel::new(tree.clone())).unwrap();
/// let back = octomap::decode_bt(&bytes, "t.bt".as_ref()).unwrap();
/// assert_eq!(back.tree.voxels().collect::<Vec<_>>(), tree.voxels().collect::<Vec<_>>());
/// ```
pub fn encode_bt(model: &VoxelModel) -> Result<Vec<u8>, String> {
    let (tree, res, _) = to_key_space(model)?;
    let mut data = Vec::with_capacity(2 * tree.leaf_count() + 16);
    let mut nodes = 0u64;
    if !tree.is_empty() {
        nodes = 1;
        write_bt_node(tree.leaves(), 0, OCTOMAP_DEPTH, &mut data, &mut nodes);
    }
    let mut out = format!(
        "{BT_HEADER}\n# (feel free to add / change comments, but leave the first line as it is!)\n#\nid OcTree\nsize {nodes}\nres {res}\ndata\n"
    )
    .into_bytes();
    out.extend_from_slice(&data);
    Ok(out)
}

/// Splits `leaves` (sorted, all inside the cell) among the eight children of the cell
/// at `code` of size `2^k`, calling `f(child index, child code, its leaves, whether one
/// leaf covers it)`.
fn split_children<'a>(
    leaves: &'a [Leaf],
    code: u64,
    k: u8,
    mut f: impl FnMut(usize, u64, &'a [Leaf], bool),
) {
    let child_cells = 1u64 << (3 * u32::from(k - 1));
    let mut rest = leaves;
    // A leaf covering the whole cell (only possible at the root).
    if let [only] = leaves {
        if only.size_log2() >= k {
            for i in 0..8 {
                f(i, code + i as u64 * child_cells, &[], true);
            }
            return;
        }
    }
    for i in 0..8u64 {
        let c = code + i * child_cells;
        let end = c + child_cells;
        let n = rest.partition_point(|l| l.code() < end);
        let (mine, tail) = rest.split_at(n);
        rest = tail;
        let full = mine.len() == 1 && mine[0].size_log2() == k - 1;
        f(i as usize, c, mine, full);
    }
}

fn write_bt_node(leaves: &[Leaf], code: u64, k: u8, out: &mut Vec<u8>, nodes: &mut u64) {
    let mut bits = 0u16;
    let mut inner: [Option<(u64, &[Leaf])>; 8] = [None; 8];
    split_children(leaves, code, k, |i, c, mine, full| {
        if full {
            bits |= 0b10 << (2 * i);
            *nodes += 1;
        } else if !mine.is_empty() {
            bits |= 0b11 << (2 * i);
            *nodes += 1;
            inner[i] = Some((c, mine));
        }
    });
    out.extend_from_slice(&bits.to_le_bytes());
    for (c, mine) in inner.into_iter().flatten() {
        write_bt_node(mine, c, k - 1, out, nodes);
    }
}

/// Encodes `model` as `.ot` bytes: an `OcTree`, or a `ColorOcTree` when the model has
/// colours (blocks whose voxels differ in colour are split down to single voxels).
///
/// # Errors
/// A message when a voxel lies outside the key range.
pub fn encode_ot(model: &VoxelModel) -> Result<Vec<u8>, String> {
    let (tree, res, shift) = to_key_space(model)?;
    let space = octomap_space();
    let colour = model.colors.as_ref().map(|map| {
        move |code: u64| -> [u8; 3] {
            let v = space.voxel_of(code);
            let v = [v[0] - shift[0], v[1] - shift[1], v[2] - shift[2]];
            let c = map.get(&v).copied().unwrap_or(super::vox::DEFAULT_COLOR);
            [c[0], c[1], c[2]]
        }
    });
    // Split blocks with mixed colours into voxels.
    let leaves: Vec<Leaf> = match &colour {
        None => tree.leaves().to_vec(),
        Some(col) => {
            let mut out = Vec::new();
            for l in tree.leaves() {
                let first = col(l.code());
                if (l.code()..l.end()).all(|c| col(c) == first) {
                    out.push(*l);
                } else {
                    out.extend((l.code()..l.end()).map(|c| Leaf::new(c, 0)));
                }
            }
            out
        }
    };
    let mut data = Vec::new();
    let mut nodes = 0u64;
    if !leaves.is_empty() {
        write_ot_node(&leaves, 0, OCTOMAP_DEPTH, &colour, &mut data, &mut nodes);
    }
    let id = if colour.is_some() {
        "ColorOcTree"
    } else {
        "OcTree"
    };
    let mut out = format!(
        "{OT_HEADER}\n# (feel free to add / change comments, but leave the first line as it is!)\n#\nid {id}\nsize {nodes}\nres {res}\ndata\n"
    )
    .into_bytes();
    out.extend_from_slice(&data);
    Ok(out)
}

/// Writes the cell at `code` of size `2^k` (which holds some black) in `.ot` preorder.
/// Returns its colour (the mean of its children's, as OctoMap's `updateColorChildren`).
fn write_ot_node(
    leaves: &[Leaf],
    code: u64,
    k: u8,
    colour: &Option<impl Fn(u64) -> [u8; 3]>,
    out: &mut Vec<u8>,
    nodes: &mut u64,
) -> [u8; 3] {
    *nodes += 1;
    let at = out.len();
    let extra = if colour.is_some() { 3 } else { 0 };
    out.extend_from_slice(&OCCUPIED_LOG_ODDS.to_le_bytes());
    out.extend(std::iter::repeat_n(0u8, extra + 1));
    let is_leaf = leaves.len() == 1 && leaves[0].size_log2() >= k;
    let rgb = if is_leaf {
        colour.as_ref().map_or([0; 3], |c| c(code))
    } else {
        let mut mask = 0u8;
        let mut children: Vec<(u64, &[Leaf])> = Vec::with_capacity(8);
        split_children(leaves, code, k, |i, c, mine, full| {
            if full || !mine.is_empty() {
                mask |= 1 << i;
                children.push((c, mine));
            }
        });
        out[at + 4 + extra] = mask;
        let mut sum = [0u32; 3];
        let n = children.len() as u32;
        for (c, mine) in children {
            let child_leaves: Vec<Leaf>;
            let mine = if mine.is_empty() {
                child_leaves = vec![Leaf::new(c, k - 1)];
                &child_leaves[..]
            } else {
                mine
            };
            let rgb = write_ot_node(mine, c, k - 1, colour, out, nodes);
            for j in 0..3 {
                sum[j] += u32::from(rgb[j]);
            }
        }
        sum.map(|s| (s / n.max(1)) as u8)
    };
    if extra == 3 {
        out[at + 4..at + 7].copy_from_slice(&rgb);
    }
    rgb
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use std::collections::HashSet;

    fn random_model(seed: u64) -> VoxelModel {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let origin = [
            rng.random_range(-40..40),
            rng.random_range(-40..40),
            rng.random_range(-40..40),
        ];
        let n = rng.random_range(0..400);
        let voxels: Vec<_> = (0..n)
            .map(|_| {
                [
                    origin[0] + rng.random_range(0..16),
                    origin[1] + rng.random_range(0..16),
                    origin[2] + rng.random_range(0..8),
                ]
            })
            .collect();
        let mut tree = LinearOctree::from_voxels(4, origin, voxels).unwrap();
        if seed % 5 == 0 {
            tree = LinearOctree::full(3, [origin[0] & !7, origin[1] & !7, origin[2] & !7]).unwrap();
        }
        VoxelModel {
            tree,
            frame: Some(Frame {
                voxel_size: 0.05,
                translate: [0.0; 3],
            }),
            colors: None,
        }
    }

    fn set(t: &LinearOctree) -> HashSet<crate::Voxel> {
        t.voxels().collect()
    }

    #[test]
    fn bt_and_ot_round_trip_random_trees() {
        for seed in 0..80 {
            let m = random_model(seed);
            let bt = decode_bt(&encode_bt(&m).unwrap(), Path::new("t.bt"))
                .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
            bt.tree.assert_valid();
            assert_eq!(set(&bt.tree), set(&m.tree), "seed {seed}");
            assert_eq!(bt.frame.unwrap().voxel_size, 0.05);
            let ot = decode_ot(&encode_ot(&m).unwrap(), Path::new("t.ot"))
                .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
            ot.tree.assert_valid();
            assert_eq!(set(&ot.tree), set(&m.tree), "seed {seed}");
        }
    }

    #[test]
    fn colour_ot_round_trip() {
        let m = random_model(3);
        let colors: ColorMap = m
            .tree
            .voxels()
            .map(|v| (v, [v[0] as u8, v[1] as u8, 7, 255]))
            .collect();
        let m = VoxelModel {
            colors: Some(colors.clone()),
            ..m
        };
        let back = decode_ot(&encode_ot(&m).unwrap(), Path::new("t.ot")).unwrap();
        assert_eq!(back.colors.unwrap(), colors);
    }

    #[test]
    fn a_hand_made_bt_decodes() {
        // Root with child 0 inner; that child (depth 1) has child 7 occupied: the
        // block of size 2^14 at keys (16384, 16384, 16384), i.e. voxel -16384.
        let mut b = b"# Octomap OcTree binary file\nid OcTree\nsize 3\nres 0.1\ndata\n".to_vec();
        b.extend_from_slice(&[0b0000_0011, 0, 0, 0b1000_0000]);
        let m = decode_bt(&b, Path::new("t.bt")).unwrap();
        assert_eq!(m.tree.leaf_count(), 1);
        let blk = m.tree.blocks().next().unwrap();
        assert_eq!((blk.min, blk.size_log2), ([-16384; 3], 14));
        // Wrong node count, truncation, too deep.
        let mut w = b.clone();
        w[b.len() - 9] = b'4';
        assert!(decode_bt(&w, Path::new("t.bt")).is_err());
        assert!(decode_bt(&b[..b.len() - 1], Path::new("t.bt")).is_err());
        let mut deep =
            b"# Octomap OcTree binary file\nid OcTree\nsize 99\nres 0.1\ndata\n".to_vec();
        deep.extend(std::iter::repeat_n([3u8, 0], 20).flatten());
        assert!(decode_bt(&deep, Path::new("t.bt")).is_err());
    }

    #[test]
    fn out_of_key_range_is_refused() {
        let t = LinearOctree::from_voxels(17, [0; 3], [[40000, 0, 0]]).unwrap();
        assert!(encode_bt(&VoxelModel::new(t)).is_err());
    }
}
