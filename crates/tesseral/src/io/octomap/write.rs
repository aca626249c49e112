//! Writing OctoMap trees: a model moved into key space, cut into pieces of one state,
//! colour and log-odds each, and written in preorder.

use std::path::Path;

use super::{BT_HEADER, KEY_ORIGIN, OCCUPIED_LOG_ODDS, OCTOMAP_DEPTH, OT_HEADER};
use crate::io::{reframe, FormatError};
use crate::linear::{Leaf, LinearOctree};
use crate::model::{Layer, LayerValue, Model, Rgba};

/// The log-odds written for free leaves when the model has none: OctoMap's default
/// lower clamping threshold, probability 0.1192.
pub const FREE_LOG_ODDS: f32 = -1.992_430_1;

/// A model's parts in OctoMap's key space.
struct KeyModel {
    occupied: LinearOctree,
    free: Option<LinearOctree>,
    colors: Option<Layer<Rgba>>,
    log_odds: Option<Layer<f32>>,
    res: f64,
}

/// A maximal cell of one state, colour and log-odds.
#[derive(Debug, Clone, Copy)]
struct Piece {
    leaf: Leaf,
    occupied: bool,
    value: f32,
    rgb: [u8; 3],
}

/// Moves a model into OctoMap's key space. OctoMap keys cannot hold a fraction of a
/// voxel, so the frame's translate must be a whole number of voxels.
fn to_key_space(model: &Model) -> Result<KeyModel, String> {
    let shift = model
        .frame
        .world_to_voxels(model.frame.translate)
        .map_err(|e| format!("OctoMap keys cannot place this frame: its translate {e}"))?;
    let put = |t: &LinearOctree| -> Result<LinearOctree, String> {
        let mut origin = [0i64; 3];
        for (a, o) in origin.iter_mut().enumerate() {
            *o = t.origin()[a]
                .checked_add(shift[a])
                .ok_or("the frame's translate moves the octree out of range")?;
        }
        let shifted =
            LinearOctree::from_sorted_leaves(t.depth(), origin, t.leaves().iter().copied())
                .map_err(|e| e.to_string())?;
        reframe(&shifted, OCTOMAP_DEPTH, [KEY_ORIGIN; 3])
            .map_err(|e| format!("{e}: OctoMap keys reach only voxels −32768..32767 on each axis"))
    };
    fn layer<T: LayerValue>(
        l: &Option<Layer<T>>,
        put: &impl Fn(&LinearOctree) -> Result<LinearOctree, String>,
    ) -> Result<Option<Layer<T>>, String> {
        let Some(l) = l else { return Ok(None) };
        let regions = l
            .regions()
            .iter()
            .map(|(x, t)| Ok((*x, put(t)?)))
            .collect::<Result<Vec<_>, String>>()?;
        // The layer's regions are disjoint (a model's invariant) and moving them
        // keeps them so: no check again.
        Ok(Some(Layer::from_regions_unchecked(
            OCTOMAP_DEPTH,
            [KEY_ORIGIN; 3],
            regions,
        )))
    }
    Ok(KeyModel {
        occupied: put(&model.tree)?,
        free: model.free.as_ref().map(put).transpose()?,
        colors: layer(&model.colors, &put)?,
        log_odds: layer(&model.log_odds, &put)?,
        res: model.frame.voxel_size,
    })
}

/// Cuts `leaf` into maximal cells each inside one leaf of `index` or outside all,
/// calling `out` with each cell and its value. `at` is where the search in `index`
/// starts, moved on as it goes: the leaves of one tree are cut in tesseral order,
/// so the region a leaf meets is never before the one the leaf before it met, and
/// is found by a search from there (mostly one compare) rather than a binary search
/// of the whole index.
fn split<T: Copy>(
    leaf: Leaf,
    index: &[(Leaf, T)],
    at: &mut usize,
    out: &mut impl FnMut(Leaf, Option<T>),
) {
    *at += first_false(&index[*at..], |(r, _)| r.end() <= leaf.code());
    match index.get(*at) {
        None => out(leaf, None),
        Some((r, _)) if r.code() >= leaf.end() => out(leaf, None),
        Some((r, x)) if r.code() <= leaf.code() && r.end() >= leaf.end() => out(leaf, Some(*x)),
        Some(_) => {
            // Region leaves lie strictly inside: canonical leaves nest, so split.
            let k = leaf.size_log2() - 1;
            for c in 0..8u64 {
                let child = Leaf::new(leaf.code() + (c << (3 * u32::from(k))), k);
                split(child, index, at, out);
            }
        }
    }
}

/// The length of the prefix of `s` on which `pred` holds (`pred` holds on a prefix),
/// by an exponential search from the start: O(log d) for a prefix of length d.
fn first_false<T>(s: &[T], pred: impl Fn(&T) -> bool) -> usize {
    let mut hi = 1;
    while hi <= s.len() && pred(&s[hi - 1]) {
        hi *= 2;
    }
    // `pred` holds on `s[..lo]` (its last element was tested).
    let lo = hi / 2;
    lo + s[lo..hi.min(s.len())].partition_point(pred)
}

/// The model's known cells as pieces in tesseral order.
fn pieces(km: &KeyModel) -> Vec<Piece> {
    let colors = km.colors.as_ref().map(Layer::leaves).unwrap_or_default();
    let odds = km.log_odds.as_ref().map(Layer::leaves).unwrap_or_default();
    // OctoMap's "no colour set" is white; its inner nodes average only set colours.
    let default_rgb = [255, 255, 255, 255];
    let mut out = Vec::new();
    let parts = [(&km.occupied, true)]
        .into_iter()
        .chain(km.free.iter().map(|f| (f, false)));
    for (tree, occupied) in parts {
        let (mut color_at, mut odds_at) = (0, 0);
        for &leaf in tree.leaves() {
            split(leaf, &colors, &mut color_at, &mut |l, c: Option<Rgba>| {
                let rgb = c.unwrap_or(default_rgb);
                split(l, &odds, &mut odds_at, &mut |l, v| {
                    let fallback = if occupied {
                        OCCUPIED_LOG_ODDS
                    } else {
                        FREE_LOG_ODDS
                    };
                    out.push(Piece {
                        leaf: l,
                        occupied,
                        value: v.unwrap_or(fallback),
                        rgb: [rgb[0], rgb[1], rgb[2]],
                    });
                });
            });
        }
    }
    // Two runs in order (the occupied pieces, then the free): a stable sort finds
    // them and merges them in one pass.
    out.sort_by_key(|p| p.leaf.code());
    out
}

/// Writes `model` as `.bt` or `.ot` (by extension). Colours make the `.ot` a
/// `ColorOcTree`.
///
/// # Errors
/// [`FormatError::Unsupported`] when a voxel lies outside OctoMap's key range or the
/// frame's translate is not a whole number of voxels.
pub fn write_file(path: &Path, model: &Model) -> Result<(), FormatError> {
    let bytes = if crate::io::extension(path) == "ot" {
        encode_ot(model)
    } else {
        encode_bt(model)
    }
    .map_err(|m| FormatError::unsupported(m).with_path(path))?;
    crate::io::write_atomic(path, |w| std::io::Write::write_all(w, &bytes))
}

/// The pieces inside the cell `[code, code + 8^k)`, split among its eight children.
/// Each child's pieces are found by an exponential search from where the last
/// child's ended (O(log d) for d pieces, not O(log n) over the whole cell's), and
/// the last child takes what is left.
fn children(pieces: &[Piece], code: u64, k: u8) -> [(u64, &[Piece]); 8] {
    let child_cells = 1u64 << (3 * u32::from(k - 1));
    debug_assert!(
        pieces.first().is_none_or(|p| p.leaf.code() >= code)
            && pieces
                .last()
                .is_none_or(|p| p.leaf.code() < code + 8 * child_cells),
        "pieces outside the cell"
    );
    let mut rest = pieces;
    std::array::from_fn(|i| {
        let c = code + i as u64 * child_cells;
        let n = if i == 7 {
            rest.len()
        } else {
            first_false(rest, |p| p.leaf.code() < c + child_cells)
        };
        let (mine, tail) = rest.split_at(n);
        rest = tail;
        (c, mine)
    })
}

/// Whether `pieces` is one piece covering the cell of size `2^k`.
fn covers(pieces: &[Piece], k: u8) -> Option<Piece> {
    match pieces {
        [p] if p.leaf.size_log2() >= k => Some(*p),
        _ => None,
    }
}

/// Encodes `model` as `.bt` bytes: black leaves occupied, free leaves free, the rest
/// unknown.
///
/// # Runtime
/// O(n · 16) for n leaves.
///
/// # Errors
/// A message when a voxel lies outside the key range, or the frame's translate is not
/// a whole number of voxels.
///
/// ```
/// use tesseral::io::{octomap, Model};
/// use tesseral::linear::LinearOctree;
/// let tree = LinearOctree::from_voxels(2, [-2; 3], [[-2, -2, -2], [1, 0, 1]]).unwrap();
/// let bytes = octomap::encode_bt(&Model::new(tree.clone())).unwrap();
/// let back = octomap::decode_bt(&bytes).unwrap();
/// assert_eq!(back.tree.voxels().collect::<Vec<_>>(), tree.voxels().collect::<Vec<_>>());
/// ```
pub fn encode_bt(model: &Model) -> Result<Vec<u8>, String> {
    let km = to_key_space(model)?;
    let pieces = pieces(&km);
    let mut data = Vec::with_capacity(2 * pieces.len() + 16);
    let mut nodes = 0u64;
    if !pieces.is_empty() {
        nodes = 1;
        write_bt_node(&pieces, 0, OCTOMAP_DEPTH, &mut data, &mut nodes);
    }
    let mut out = format!(
        "{BT_HEADER}\n# (feel free to add / change comments, but leave the first line as it is!)\n#\nid OcTree\nsize {nodes}\nres {}\ndata\n",
        km.res
    )
    .into_bytes();
    out.extend_from_slice(&data);
    Ok(out)
}

fn write_bt_node(pieces: &[Piece], code: u64, k: u8, out: &mut Vec<u8>, nodes: &mut u64) {
    let mut bits = 0u16;
    let mut inner = Vec::with_capacity(8);
    // A piece covering the whole root: eight covered children.
    let whole = covers(pieces, k);
    for (i, (c, mine)) in children(pieces, code, k).into_iter().enumerate() {
        let leaf = whole.or_else(|| covers(mine, k - 1));
        if let Some(p) = leaf {
            bits |= if p.occupied { 0b10 } else { 0b01 } << (2 * i);
            *nodes += 1;
        } else if !mine.is_empty() {
            bits |= 0b11 << (2 * i);
            *nodes += 1;
            inner.push((c, mine));
        }
    }
    out.extend_from_slice(&bits.to_le_bytes());
    for (c, mine) in inner {
        write_bt_node(mine, c, k - 1, out, nodes);
    }
}

/// Encodes `model` as `.ot` bytes: an `OcTree`, or a `ColorOcTree` when the model has
/// colours. Leaves carry the model's log-odds (or OctoMap's clamping thresholds when
/// it has none); inner nodes the maximum of their children's, as OctoMap's
/// `updateInnerOccupancy`, and the mean of their set colours, as
/// `getAverageChildColor` (white is OctoMap's "unset", used for free leaves).
///
/// # Errors
/// As [`encode_bt`].
pub fn encode_ot(model: &Model) -> Result<Vec<u8>, String> {
    let km = to_key_space(model)?;
    let pieces = pieces(&km);
    let colour = km.colors.is_some();
    let mut data = Vec::new();
    let mut nodes = 0u64;
    if !pieces.is_empty() {
        write_ot_node(&pieces, 0, OCTOMAP_DEPTH, colour, &mut data, &mut nodes);
    }
    let id = if colour { "ColorOcTree" } else { "OcTree" };
    let mut out = format!(
        "{OT_HEADER}\n# (feel free to add / change comments, but leave the first line as it is!)\n#\nid {id}\nsize {nodes}\nres {}\ndata\n",
        km.res
    )
    .into_bytes();
    out.extend_from_slice(&data);
    Ok(out)
}

/// Writes the cell at `code` of size `2^k` (which holds some known cell) in `.ot`
/// preorder; returns its log-odds and colour.
fn write_ot_node(
    pieces: &[Piece],
    code: u64,
    k: u8,
    colour: bool,
    out: &mut Vec<u8>,
    nodes: &mut u64,
) -> (f32, [u8; 3]) {
    *nodes += 1;
    let at = out.len();
    let extra = if colour { 3 } else { 0 };
    out.extend(std::iter::repeat_n(0u8, 4 + extra + 1));
    let (value, rgb) = if let Some(p) = covers(pieces, k) {
        (p.value, p.rgb)
    } else {
        let mut mask = 0u8;
        let mut max = f32::NEG_INFINITY;
        let mut sum = [0u32; 3];
        let mut n = 0u32;
        const UNSET: [u8; 3] = [255, 255, 255];
        for (i, (c, mine)) in children(pieces, code, k).into_iter().enumerate() {
            if mine.is_empty() {
                continue;
            }
            mask |= 1 << i;
            let (v, rgb) = write_ot_node(mine, c, k - 1, colour, out, nodes);
            max = max.max(v);
            if rgb != UNSET {
                for j in 0..3 {
                    sum[j] += u32::from(rgb[j]);
                }
                n += 1;
            }
        }
        out[at + 4 + extra] = mask;
        // As OctoMap's `getAverageChildColor`: the mean of the children whose colour
        // is set, or unset (white) when none is.
        let rgb = if n == 0 {
            UNSET
        } else {
            sum.map(|s| (s / n) as u8)
        };
        (max, rgb)
    };
    out[at..at + 4].copy_from_slice(&value.to_le_bytes());
    if colour {
        out[at + 4..at + 7].copy_from_slice(&rgb);
    }
    (value, rgb)
}

#[cfg(test)]
mod tests {
    use super::first_false;

    /// The exponential search finds the prefix a binary search finds, for every
    /// prefix length of slices of every length up to 70.
    #[test]
    fn the_search_from_the_start_finds_the_prefix() {
        for len in 0..70usize {
            let s: Vec<usize> = (0..len).collect();
            for cut in 0..=len {
                let pred = |&x: &usize| x < cut;
                assert_eq!(
                    first_false(&s, pred),
                    s.partition_point(pred),
                    "{len} {cut}"
                );
                assert_eq!(first_false(&s, pred), cut);
            }
        }
    }
}
