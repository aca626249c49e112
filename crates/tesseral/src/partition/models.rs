//! The steps of a partitioned run on models (tree, frame and colours), for a
//! distributed engine's tasks (`tesseral.dask`): a scene's code range built with its
//! colours, a set operation of two parts (the first operand's colour wins, as
//! [`Model::set_op`]), a part cut into ranges or moved into another space and cut,
//! and the pieces that land in one range joined. Each colour region goes through
//! the same cuts and moves as the tree, so a part's colours stay on its voxels.
//!
//! Parts carry no known-free space or log-odds (scenes and datasets have none); a
//! part that does is refused.

use std::collections::HashMap;

use super::shuffle::{join_pieces, set_op_part};
use super::{Partition, PartitionError, PartitionedOctree};
use crate::csg::{Csg, Scene};
use crate::linear::{push_merging, Leaf, LinearOctree, SetOp};
use crate::model::{Frame, Layer, Model, Rgba};
use crate::Voxel;

/// `tree` made canonical (eight black siblings merged), as a merge of two clipped
/// parts may leave it.
fn canonical(tree: &LinearOctree) -> LinearOctree {
    let mut leaves = Vec::with_capacity(tree.leaf_count());
    for &l in tree.leaves() {
        push_merging(&mut leaves, l);
    }
    LinearOctree::from_parts(tree.depth(), tree.origin(), leaves)
}

/// A model of `tree` with `frame` and the colour `regions` (in the tree's space,
/// disjoint, canonical): no colour layer when no region has a voxel.
fn assemble(
    tree: LinearOctree,
    frame: Frame,
    regions: Vec<(Rgba, LinearOctree)>,
) -> Result<Model, PartitionError> {
    let (depth, origin) = (tree.depth(), tree.origin());
    let colors = if regions.iter().all(|(_, t)| t.is_empty()) {
        None
    } else {
        Some(Layer::from_regions(depth, origin, regions)?)
    };
    Ok(Model {
        colors,
        ..Model::new(tree).with_frame(frame)
    })
}

fn plain(m: &Model, what: &str) -> Result<(), PartitionError> {
    if m.free.is_some() || m.log_odds.is_some() {
        return Err(PartitionError::Ranges(format!(
            "{what} has known-free space or log-odds, which partitioned runs do not carry"
        )));
    }
    Ok(())
}

fn regions(m: &Model) -> &[(Rgba, LinearOctree)] {
    m.colors.as_ref().map_or(&[], |l| l.regions())
}

/// The part of `scene` in the codes `range`, with the scene's frame and colours:
/// the leaves and colours that the streamed `tesseral build --parts` writes for the
/// range (each colour's part built in the same work cells,
/// [`crate::csg::StreamPlan::run_coloured`]), `window` work cells at a time.
///
/// # Errors
/// [`PartitionError::Ranges`] for a scene that does not compile.
pub fn build_scene_range(
    scene: &Scene,
    range: Partition,
    window: usize,
) -> Result<Model, PartitionError> {
    let scene_err = |e: crate::csg::SceneError| PartitionError::Ranges(e.to_string());
    let (csg, plan) = scene.stream_plan(range.range()).map_err(scene_err)?;
    let colours = scene.colour_csgs().map_err(scene_err)?;
    let csgs: Vec<Csg> = colours.iter().map(|(_, c)| c.clone()).collect();
    let mut leaves: Vec<Leaf> = Vec::new();
    let mut coloured: Vec<Vec<Leaf>> = vec![Vec::new(); colours.len()];
    plan.run_coloured::<std::convert::Infallible>(
        &csg,
        &csgs,
        window,
        &mut |ls, cs| {
            for &l in ls {
                push_merging(&mut leaves, l);
            }
            for (out, c) in coloured.iter_mut().zip(cs) {
                for &l in c {
                    push_merging(out, l);
                }
            }
            Ok(())
        },
        &mut |_| {},
    )
    .unwrap_or_else(|e| match e {});
    let (depth, origin) = (scene.depth, [0, 0, 0]);
    let regions = colours
        .iter()
        .zip(coloured)
        .map(|((c, _), l)| (*c, LinearOctree::from_parts(depth, origin, l)))
        .collect();
    assemble(
        LinearOctree::from_parts(depth, origin, leaves),
        scene.frame(),
        regions,
    )
}

/// The set operation `op` of two parts of one space and frame cut to the same
/// range, with colours as [`Model::set_op`] gives them: the first operand's colour
/// where it has one, else the second's, on the result's voxels.
///
/// # Errors
/// [`PartitionError::Ranges`] when the spaces or frames differ.
pub fn set_op_models(a: &Model, b: &Model, op: SetOp) -> Result<Model, PartitionError> {
    plain(a, "the first operand")?;
    plain(b, "the second operand")?;
    same_frame(a.frame, b.frame)?;
    let tree = set_op_part(&a.tree, &b.tree, op)?;
    let (depth, origin) = (tree.depth(), tree.origin());
    let colors = match (&a.colors, &b.colors) {
        (None, None) => None,
        (Some(x), None) | (None, Some(x)) => Some(x.clone()),
        (Some(x), Some(y)) => Some(x.overlay(y, depth, origin)?),
    };
    let regions = match colors {
        Some(l) => l
            .restrict(&tree)?
            .regions()
            .iter()
            .map(|(c, t)| (*c, canonical(t)))
            .collect(),
        None => Vec::new(),
    };
    assemble(tree, a.frame, regions)
}

fn same_frame(a: Frame, b: Frame) -> Result<(), PartitionError> {
    if a == b {
        return Ok(());
    }
    Err(PartitionError::Ranges(format!(
        "the parts have different frames (voxel size {} at {:?}, voxel size {} at {:?})",
        a.voxel_size, a.translate, b.voxel_size, b.translate
    )))
}

/// The pieces that land in one range (disjoint, of one space and frame) joined,
/// colours with them; an empty model of `(depth, origin)` and `frame` when there
/// are none.
///
/// # Errors
/// [`PartitionError::Ranges`] for a piece of another space or frame.
pub fn join_models(
    depth: u8,
    origin: Voxel,
    frame: Frame,
    pieces: Vec<Model>,
) -> Result<Model, PartitionError> {
    let mut trees = Vec::with_capacity(pieces.len());
    let mut by_colour: HashMap<u64, (Rgba, Vec<LinearOctree>)> = HashMap::new();
    for p in pieces {
        plain(&p, "a piece")?;
        same_frame(frame, p.frame)?;
        for (c, t) in regions(&p) {
            let key = u64::from(u32::from_le_bytes(*c));
            by_colour
                .entry(key)
                .or_insert((*c, Vec::new()))
                .1
                .push(t.clone());
        }
        trees.push(p.tree);
    }
    let tree = join_pieces(depth, origin, trees)?;
    let mut regions = Vec::with_capacity(by_colour.len());
    for (_, (c, ts)) in by_colour {
        regions.push((c, join_pieces(depth, origin, ts)?));
    }
    assemble(tree, frame, regions)
}

/// The ranges tiling the space of `depth` that `subset` (sorted, disjoint ranges)
/// leaves out, merged with it: the tiling and, for each of its ranges, its index in
/// `subset` (`None` for a gap).
fn with_gaps(
    depth: u8,
    subset: &[Partition],
) -> Result<(Vec<Partition>, Vec<Option<usize>>), PartitionError> {
    let end = 1u64 << (3 * u32::from(depth));
    let (mut tiles, mut index) = (Vec::new(), Vec::new());
    let mut at = 0u64;
    for (i, p) in subset.iter().enumerate() {
        if p.lo < at || p.hi <= p.lo || p.hi > end {
            return Err(PartitionError::Ranges(format!(
                "range {i} [{}, {}) is empty, out of order or outside the depth-{depth} space",
                p.lo, p.hi
            )));
        }
        if p.lo > at {
            tiles.push(Partition { lo: at, hi: p.lo });
            index.push(None);
        }
        tiles.push(*p);
        index.push(Some(i));
        at = p.hi;
    }
    if at < end {
        tiles.push(Partition { lo: at, hi: end });
        index.push(None);
    }
    Ok((tiles, index))
}

/// `model` cut into `ranges` (sorted and disjoint, not necessarily tiling the
/// space), one model per range, colours cut with the tree.
///
/// # Errors
/// [`PartitionError::Ranges`] for bad ranges, or leaves outside all of them (a
/// shuffle that sent the part to too few ranges).
pub fn split_model(model: &Model, ranges: &[Partition]) -> Result<Vec<Model>, PartitionError> {
    plain(model, "the part")?;
    let tree = &model.tree;
    let (tiles, index) = with_gaps(tree.depth(), ranges)?;
    let cut = |t: &LinearOctree| -> Result<Vec<LinearOctree>, PartitionError> {
        let p = PartitionedOctree::split(t, &tiles)?;
        let mut mine = Vec::with_capacity(ranges.len());
        for ((r, piece), i) in p.parts.into_iter().zip(&index) {
            match i {
                Some(_) => mine.push(piece),
                None if piece.is_empty() => {}
                None => {
                    return Err(PartitionError::Ranges(format!(
                        "the part has leaves in [{}, {}), outside the ranges it is cut to",
                        r.lo, r.hi
                    )))
                }
            }
        }
        Ok(mine)
    };
    let trees = cut(tree)?;
    let mut colours: Vec<Vec<(Rgba, LinearOctree)>> = vec![Vec::new(); ranges.len()];
    for (c, t) in regions(model) {
        for (j, piece) in cut(t)?.into_iter().enumerate() {
            colours[j].push((*c, piece));
        }
    }
    trees
        .into_iter()
        .zip(colours)
        .map(|(t, c)| assemble(t, model.frame, c))
        .collect()
}

/// `model` moved by `by` into the space `(depth, origin)` (voxels landing outside
/// are dropped when `drop_outside`, else an error) and cut into `ranges` of that
/// space (sorted, disjoint; see [`split_model`]): one half of a shuffle. With `by`
/// zero it re-expresses a part in another space.
///
/// # Errors
/// [`PartitionError::Ranges`] for voxels outside the space (unless dropped) and as
/// [`split_model`].
pub fn move_and_split(
    model: &Model,
    by: [i64; 3],
    depth: u8,
    origin: Voxel,
    ranges: &[Partition],
    drop_outside: bool,
) -> Result<Vec<Model>, PartitionError> {
    plain(model, "the part")?;
    let (tree, dropped) = model.tree.translate_into(by, depth, origin)?;
    if dropped > 0 && !drop_outside {
        return Err(PartitionError::Ranges(format!(
            "{dropped} voxels land outside the space of depth {depth} at {origin:?}"
        )));
    }
    let mut moved_regions = Vec::new();
    for (c, t) in regions(model) {
        moved_regions.push((*c, t.translate_into(by, depth, origin)?.0));
    }
    let moved = assemble(tree, model.frame, moved_regions)?;
    split_model(&moved, ranges)
}

/// The ranges of a space `(depth, origin)` re-expressed in a space grown from it by
/// root expansion (so the old space is one aligned cell of the new, its codes one
/// interval from `base`): each range shifted by `base`, the first extended down to 0
/// and the last up to the end, so that they tile the new space.
///
/// # Errors
/// [`PartitionError::Ranges`] when the old space is not an aligned cell of the new.
pub fn embedded_ranges(
    depth: u8,
    origin: Voxel,
    ranges: &[Partition],
    new_depth: u8,
    new_origin: Voxel,
) -> Result<Vec<Partition>, PartitionError> {
    let new = LinearOctree::empty(new_depth, new_origin)?;
    LinearOctree::empty(depth, origin)?;
    let side = 1i64 << depth;
    let aligned = depth <= new_depth
        && (0..3).all(|a| {
            origin[a]
                .checked_sub(new_origin[a])
                .is_some_and(|d| d >= 0 && d % side == 0)
        });
    let base = new.code_of(origin).filter(|_| aligned).ok_or_else(|| {
        PartitionError::Ranges(format!(
            "the space of depth {depth} at {origin:?} is not an aligned cell of the space of depth {new_depth} at {new_origin:?}"
        ))
    })?;
    let end = 1u64 << (3 * u32::from(new_depth));
    let n = ranges.len();
    Ok(ranges
        .iter()
        .enumerate()
        .map(|(i, p)| Partition {
            lo: if i == 0 { 0 } else { base + p.lo },
            hi: if i + 1 == n { end } else { base + p.hi },
        })
        .collect())
}
