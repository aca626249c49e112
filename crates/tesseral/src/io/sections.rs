//! The sections of a `.tess` file that follow the leaves: the frame, colours,
//! known-free space and occupancy log-odds (see [`super::native`] for the layout).
//! Versions 1 and 2 share them; version 1 keeps their flags in the header, version 2
//! just before them.

use super::leafstream::{put_leaves, read_leaves, Reader};
use crate::linear::LinearOctree;
use crate::model::{Frame, Layer, LayerValue, Model, Rgba};

pub(crate) const FLAG_FRAME: u16 = 1;
pub(crate) const FLAG_COLORS: u16 = 2;
pub(crate) const FLAG_COLOR_LAYER: u16 = 4;
pub(crate) const FLAG_FREE: u16 = 8;
pub(crate) const FLAG_LOG_ODDS: u16 = 16;
pub(crate) const KNOWN_FLAGS: u16 =
    FLAG_FRAME | FLAG_COLORS | FLAG_COLOR_LAYER | FLAG_FREE | FLAG_LOG_ODDS;

/// What a model carries besides its black leaves.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct Extras {
    pub(crate) frame: Frame,
    pub(crate) colors: Option<Layer<Rgba>>,
    pub(crate) free: Option<LinearOctree>,
    pub(crate) log_odds: Option<Layer<f32>>,
}

/// The sections to write after a tree, borrowed from a model: writing a model
/// copies none of its layers.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Sections<'a> {
    pub(crate) frame: Frame,
    pub(crate) colors: Option<&'a Layer<Rgba>>,
    pub(crate) free: Option<&'a LinearOctree>,
    pub(crate) log_odds: Option<&'a Layer<f32>>,
}

impl<'a> Sections<'a> {
    /// The sections of `model`.
    pub(crate) fn of(model: &'a Model) -> Self {
        Self {
            frame: model.frame,
            colors: model.colors.as_ref(),
            free: model.free.as_ref(),
            log_odds: model.log_odds.as_ref(),
        }
    }

    /// A frame and no layers.
    pub(crate) fn frame(frame: Frame) -> Self {
        Self {
            frame,
            ..Self::default()
        }
    }
}

impl Extras {
    /// A model's parts besides its tree, and the tree.
    pub(crate) fn split(model: Model) -> (Self, LinearOctree) {
        let Model {
            tree,
            frame,
            colors,
            free,
            log_odds,
        } = model;
        (
            Self {
                frame,
                colors,
                free,
                log_odds,
            },
            tree,
        )
    }

    pub(crate) fn into_model(self, tree: LinearOctree) -> Model {
        Model {
            tree,
            frame: self.frame,
            colors: self.colors,
            free: self.free,
            log_odds: self.log_odds,
        }
    }
}

/// Appends the sections of `x` (frame always, then the optional layers) and returns
/// their flags.
pub(crate) fn put_sections(tail: &mut Vec<u8>, x: &Sections<'_>) -> u16 {
    let mut flags = FLAG_FRAME;
    tail.extend_from_slice(&x.frame.voxel_size.to_le_bytes());
    for t in x.frame.translate {
        tail.extend_from_slice(&t.to_le_bytes());
    }
    if let Some(colors) = x.colors {
        flags |= FLAG_COLOR_LAYER;
        put_layer(tail, colors, |c| c.to_vec());
    }
    if let Some(free) = x.free {
        flags |= FLAG_FREE;
        put_stream(tail, free);
    }
    if let Some(odds) = x.log_odds {
        flags |= FLAG_LOG_ODDS;
        put_layer(tail, odds, |v| v.to_le_bytes().to_vec());
    }
    flags
}

/// Reads the sections named by `flags` for a tree in the space `(depth, origin)`.
/// `voxel_of` maps a code to its voxel (for the legacy colour list).
pub(crate) fn read_sections(
    tail: &mut Reader<'_>,
    flags: u16,
    space: &LinearOctree,
) -> Result<Extras, String> {
    let (depth, origin) = (space.depth(), space.origin());
    let frame = if flags & FLAG_FRAME != 0 {
        let voxel_size = tail.f64()?;
        let translate = [tail.f64()?, tail.f64()?, tail.f64()?];
        if !(voxel_size.is_normal() && voxel_size > 0.0) || translate.iter().any(|t| !t.is_finite())
        {
            return Err(format!("frame: voxel size {voxel_size} or translate {translate:?} is not finite and positive"));
        }
        Frame::new(voxel_size, translate)
    } else {
        Frame::default()
    };
    let mut colors = None;
    if flags & FLAG_COLORS != 0 {
        let space_end = 1u64 << (3 * u32::from(depth));
        let count = tail.u64()?;
        let remaining = (tail.bytes.len() - tail.pos) as u64;
        if count > remaining / 5 {
            return Err(format!(
                "colour count {count} cannot fit in {remaining} bytes"
            ));
        }
        let mut pairs = Vec::with_capacity(count as usize);
        let mut code = 0u64;
        for index in 0..count {
            let delta = tail.varint().map_err(|m| format!("colour {index}: {m}"))?;
            code = code
                .checked_add(delta)
                .filter(|&c| c < space_end && (index == 0 || delta > 0))
                .ok_or_else(|| format!("colour {index}: bad voxel code"))?;
            let rgba = tail.take(4)?;
            pairs.push((space.voxel_of(code), [rgba[0], rgba[1], rgba[2], rgba[3]]));
        }
        colors = Some(Layer::from_voxels(depth, origin, pairs).map_err(|e| e.to_string())?);
    }
    if flags & FLAG_COLOR_LAYER != 0 {
        colors = Some(read_layer(tail, depth, origin, "colour", |b| {
            [b[0], b[1], b[2], b[3]]
        })?);
    }
    let free = if flags & FLAG_FREE != 0 {
        Some(read_stream(tail, depth, origin, "free leaf")?)
    } else {
        None
    };
    let log_odds = if flags & FLAG_LOG_ODDS != 0 {
        Some(read_layer(tail, depth, origin, "log-odds", |b| {
            f32::from_le_bytes([b[0], b[1], b[2], b[3]])
        })?)
    } else {
        None
    };
    Ok(Extras {
        frame,
        colors,
        free,
        log_odds,
    })
}

/// Checks what the sections claim against each other: colours on black voxels, free
/// space disjoint from them, log-odds on known voxels.
pub(crate) fn check_parts(m: &Model) -> Result<(), String> {
    use crate::linear::SetOp;
    if let Some(c) = &m.colors {
        if !c
            .domain()
            .set_op_same_space(&m.tree, SetOp::Difference)
            .is_empty()
        {
            return Err("colour section: colours on voxels that are not black".into());
        }
    }
    if let Some(f) = &m.free {
        if !f.set_op_same_space(&m.tree, SetOp::Intersection).is_empty() {
            return Err("free section: free voxels that are also black".into());
        }
    }
    if let Some(l) = &m.log_odds {
        if !l
            .domain()
            .set_op_same_space(&m.known(), SetOp::Difference)
            .is_empty()
        {
            return Err("log-odds section: values on unknown voxels".into());
        }
    }
    Ok(())
}

fn put_stream(out: &mut Vec<u8>, tree: &LinearOctree) {
    out.extend_from_slice(&(tree.leaf_count() as u64).to_le_bytes());
    put_leaves(out, tree.leaves());
}

fn put_layer<T: LayerValue>(out: &mut Vec<u8>, layer: &Layer<T>, bytes: impl Fn(&T) -> Vec<u8>) {
    out.extend_from_slice(&(layer.region_count() as u64).to_le_bytes());
    for (x, t) in layer.regions() {
        out.extend_from_slice(&bytes(x));
        put_stream(out, t);
    }
}

fn read_stream(
    r: &mut Reader<'_>,
    depth: u8,
    origin: crate::Voxel,
    what: &str,
) -> Result<LinearOctree, String> {
    let count = r.u64()?;
    let leaves = read_leaves(r, count, depth, what)?;
    LinearOctree::from_sorted_leaves(depth, origin, leaves).map_err(|e| format!("{what}: {e}"))
}

fn read_layer<T: LayerValue>(
    r: &mut Reader<'_>,
    depth: u8,
    origin: crate::Voxel,
    what: &str,
    value: impl Fn(&[u8]) -> T,
) -> Result<Layer<T>, String> {
    let count = r.u64()?;
    let remaining = (r.bytes.len() - r.pos) as u64;
    // A region takes at least 4 + 8 bytes.
    if count > remaining / 12 {
        return Err(format!(
            "{what} region count {count} cannot fit in {remaining} bytes"
        ));
    }
    let mut regions = Vec::with_capacity(count as usize);
    let mut keys = std::collections::HashSet::new();
    for i in 0..count {
        let x = value(r.take(4)?);
        if !keys.insert(x.key()) {
            return Err(format!("{what} region {i}: repeats a value"));
        }
        regions.push((
            x,
            read_stream(r, depth, origin, &format!("{what} region {i} leaf"))?,
        ));
    }
    // Values are distinct (checked above), so an error here is an overlap.
    Layer::from_regions(depth, origin, regions).map_err(|e| format!("{what} section: {e}"))
}
