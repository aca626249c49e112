//! Writing OctoMap trees: a model moved into key space, cut into pieces of one state,
//! colour and log-odds each, and written in preorder.

use std::path::Path;

use super::stream::{encode_pieces, Kind, Piece, UNSET_RGB};
use super::{BT_HEADER, KEY_ORIGIN, OCCUPIED_LOG_ODDS, OCTOMAP_DEPTH, OT_HEADER};
use crate::io::{reframe, FormatError};
use crate::linear::{Leaf, LinearOctree};
use crate::model::{Layer, LayerValue, Model, Rgba};

/// The log-odds written for free leaves when the model has none: OctoMap's default
/// lower clamping threshold, probability 0.1192, as OctoMap computes it
/// (`log(p / (1 − p))` rounded to `f32`; what it gives a `.bt`'s free cells).
pub const FREE_LOG_ODDS: f32 = -2.000_028;

/// A model's parts in OctoMap's key space.
pub(super) struct KeyModel {
    occupied: LinearOctree,
    free: Option<LinearOctree>,
    pub(super) colors: Option<Layer<Rgba>>,
    log_odds: Option<Layer<f32>>,
    res: f64,
}

/// Moves a model into OctoMap's key space. OctoMap keys cannot hold a fraction of a
/// voxel, so the frame's translate must be a whole number of voxels.
pub(super) fn to_key_space(model: &Model) -> Result<KeyModel, String> {
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
        // Name the voxels that do not fit, not the space's corner.
        if let Some((lo, hi)) = shifted.bbox() {
            if !(super::in_key_range(lo) && super::in_key_range(hi)) {
                return Err(format!(
                    "the voxels reach {lo:?} to {hi:?} in OctoMap's key space: OctoMap \
                     keys reach only voxels −32768..32767 on each axis"
                ));
            }
        }
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

/// The model's known cells as pieces in tesseral order: cut at its colours' and
/// log-odds' regions when `values` (for `.ot`), by state alone when not (`.bt`).
pub(super) fn pieces(km: &KeyModel, values: bool) -> Vec<Piece> {
    fn layer<T: LayerValue>(l: &Option<Layer<T>>, values: bool) -> Vec<(Leaf, T)> {
        match l {
            Some(l) if values => l.leaves(),
            _ => Vec::new(),
        }
    }
    let colors = layer(&km.colors, values);
    let odds = layer(&km.log_odds, values);
    let mut out = Vec::new();
    let parts = [(&km.occupied, true)]
        .into_iter()
        .chain(km.free.iter().map(|f| (f, false)));
    for (tree, occupied) in parts {
        let (mut color_at, mut odds_at) = (0, 0);
        for &leaf in tree.leaves() {
            split(leaf, &colors, &mut color_at, &mut |l, c: Option<Rgba>| {
                let rgb = c.map_or(UNSET_RGB, |c| [c[0], c[1], c[2]]);
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
                        rgb,
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
    let (data, nodes) = encode_pieces(Kind::Bt, pieces(&km, false));
    Ok(bt_file(km.res, nodes, &data))
}

/// A `.bt` file: the header, then `data` (of `nodes` nodes).
pub(crate) fn bt_file(res: f64, nodes: u64, data: &[u8]) -> Vec<u8> {
    file(BT_HEADER, "OcTree", res, nodes, data)
}

/// An OctoMap file whose first line is `first`, of tree type `id`: the header,
/// then `data` (of `nodes` nodes).
fn file(first: &str, id: &str, res: f64, nodes: u64, data: &[u8]) -> Vec<u8> {
    let mut out = format!(
        "{first}\n# (feel free to add / change comments, but leave the first line as it is!)\n#\nid {id}\nsize {nodes}\nres {res}\ndata\n"
    )
    .into_bytes();
    out.extend_from_slice(data);
    out
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
    let colour = km.colors.is_some();
    let (data, nodes) = encode_pieces(Kind::Ot { colour }, pieces(&km, true));
    Ok(ot_file(colour, km.res, nodes, &data))
}

/// An `.ot` file (of a `ColorOcTree` when `colour`): the header, then `data` (of
/// `nodes` nodes).
pub(crate) fn ot_file(colour: bool, res: f64, nodes: u64, data: &[u8]) -> Vec<u8> {
    let id = if colour { "ColorOcTree" } else { "OcTree" };
    file(OT_HEADER, id, res, nodes, data)
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
