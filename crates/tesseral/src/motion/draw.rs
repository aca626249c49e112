//! Pictures of moving objects and planned paths, drawn with [`crate::render`]: the
//! environment and the objects placed where they stand are joined into one octree,
//! and a shader colours each voxel by the body it belongs to, with contacts marked.

use std::collections::HashSet;

use super::interfere::Aabb;
use super::orient::Rotation;
use super::plan::rotated;
use super::world::{Frame, World};
use crate::linear::{LinearOctree, OctreeError};
use crate::render::{render, Image, RenderOptions, Surface};
use crate::Voxel;

/// The colour of the static environment.
pub const ENVIRONMENT_COLOUR: [u8; 3] = [165, 165, 170];
/// The colour of voxels where two bodies overlap, and of objects in contact.
pub const CONTACT_COLOUR: [u8; 3] = [225, 30, 30];
/// The colour of the blocks hit by a contact that only the swept test sees.
pub const SWEPT_COLOUR: [u8; 3] = [235, 40, 235];
/// Moving objects' colours, by index (repeating).
pub const OBJECT_COLOURS: [[u8; 3]; 6] = [
    [40, 110, 230],
    [30, 170, 80],
    [235, 160, 20],
    [150, 70, 210],
    [20, 175, 185],
    [205, 90, 140],
];
/// The colour of a planned path's track.
pub const PATH_COLOUR: [u8; 3] = [250, 205, 0];

fn in_box(b: &Aabb, v: Voxel) -> bool {
    (0..3).all(|a| b.min[a] <= v[a] && v[a] <= b.max[a])
}

fn voxel_at(p: [f64; 3]) -> Voxel {
    p.map(|c| c.floor() as i64)
}

/// Renders one step of a simulation: the environment in grey, each object in its
/// colour (red while it overlaps something), the shared voxels red, and the blocks
/// hit by contacts that begin between this step and the next (`swept`) magenta.
///
/// # Errors
/// [`OctreeError`] when the joined octree would be too deep.
pub fn render_frame(
    world: &World,
    frame: &Frame,
    swept: &[Aabb],
    opts: &RenderOptions,
) -> Result<Image, OctreeError> {
    let mut placed = Vec::with_capacity(world.objects.len());
    let mut all = world.environment.clone();
    for (o, off) in world.objects.iter().zip(&frame.offsets) {
        let t = rotated(&o.tree, o.rotation).translate(*off)?;
        all = all.union(&t)?;
        placed.push(t);
    }
    let touching: HashSet<usize> = frame
        .overlaps
        .iter()
        .map(|&(_, j, _)| j)
        .chain(frame.overlaps.iter().filter_map(|o| o.0))
        .collect();
    let shader = |p: [f64; 3]| {
        let v = voxel_at(p);
        if frame.contact_boxes.iter().any(|b| in_box(b, v)) {
            return CONTACT_COLOUR;
        }
        if swept.iter().any(|b| in_box(b, v)) {
            return SWEPT_COLOUR;
        }
        for (k, t) in placed.iter().enumerate() {
            if t.contains(v) {
                return if touching.contains(&k) {
                    CONTACT_COLOUR
                } else {
                    OBJECT_COLOURS[k % OBJECT_COLOURS.len()]
                };
            }
        }
        ENVIRONMENT_COLOUR
    };
    Ok(render(
        &all,
        Surface {
            colour: Some(&shader),
            normal: None,
        },
        opts,
    ))
}

/// A part of a picture and its colour.
pub type ColouredRegion = ([u8; 3], LinearOctree);

/// One step of a world as coloured parts, for the viewer's animations: the joined
/// octree, and disjoint regions of it with the colours [`render_frame`] gives them
/// (an object in contact red; the environment is what no region holds, drawn in
/// [`ENVIRONMENT_COLOUR`]; the boxes of contacts are not marked).
///
/// # Errors
/// [`OctreeError`] when the joined octree would be too deep.
pub fn frame_regions(
    world: &World,
    frame: &Frame,
) -> Result<(LinearOctree, Vec<ColouredRegion>), OctreeError> {
    let touching: HashSet<usize> = frame
        .overlaps
        .iter()
        .map(|&(_, j, _)| j)
        .chain(frame.overlaps.iter().filter_map(|o| o.0))
        .collect();
    let mut all = world.environment.clone();
    let mut regions = Vec::with_capacity(world.objects.len() + 1);
    for (k, (o, off)) in world.objects.iter().zip(&frame.offsets).enumerate() {
        let t = rotated(&o.tree, o.rotation).translate(*off)?;
        let joined = all.union(&t)?;
        // Voxels shared with what came before keep their first colour.
        let own = t.difference(&all)?;
        let colour = if touching.contains(&k) {
            CONTACT_COLOUR
        } else {
            OBJECT_COLOURS[k % OBJECT_COLOURS.len()]
        };
        regions.push((colour, own));
        all = joined;
    }
    Ok((all, regions))
}

/// Renders a planned path: the environment in grey, the object at the start in
/// green and at the goal in blue, and the track of the centre of the object's box
/// along `waypoints` (if any) in yellow.
///
/// # Errors
/// [`OctreeError`] when the joined octree would be too deep.
pub fn render_plan(
    environment: &LinearOctree,
    object: &LinearOctree,
    rotation: Rotation,
    from: Voxel,
    to: Voxel,
    waypoints: Option<&[Voxel]>,
    opts: &RenderOptions,
) -> Result<Image, OctreeError> {
    let turned = rotated(object, rotation);
    let start = turned.translate(from)?;
    let goal = turned.translate(to)?;
    let mut all = environment.union(&start)?.union(&goal)?;
    let mut track = HashSet::new();
    if let (Some(w), Some((lo, hi))) = (waypoints, turned.bbox()) {
        let c = [0, 1, 2].map(|a| (lo[a] + hi[a]) as f64 / 2.0);
        for pair in w.windows(2) {
            let len = (0..3)
                .map(|a| pair[0][a].abs_diff(pair[1][a]))
                .max()
                .unwrap_or(0);
            let n = (4 * len).max(1);
            for k in 0..=n {
                let s = k as f64 / n as f64;
                let p = [0, 1, 2]
                    .map(|a| pair[0][a] as f64 + (pair[1][a] - pair[0][a]) as f64 * s + c[a]);
                track.insert(voxel_at(p));
            }
        }
        let voxels: Vec<Voxel> = track.iter().copied().collect();
        all = all.union(&LinearOctree::from_voxels_fitted(&voxels)?)?;
    }
    let shader = |p: [f64; 3]| {
        let v = voxel_at(p);
        if start.contains(v) {
            OBJECT_COLOURS[1]
        } else if goal.contains(v) {
            OBJECT_COLOURS[0]
        } else if track.contains(&v) {
            PATH_COLOUR
        } else {
            ENVIRONMENT_COLOUR
        }
    };
    Ok(render(
        &all,
        Surface {
            colour: Some(&shader),
            normal: None,
        },
        opts,
    ))
}
