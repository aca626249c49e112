//! A scene's colours as regions: the solid cut into one solid per colour.
//!
//! A point's colour is found by walking the solid from the root (see
//! [`super::Csg::colour_at`]): a union takes its *last* child holding the point, an
//! intersection or difference its first child, and an inner colour overrides an outer
//! one. The same rules, written as set operations, cut the solid into disjoint parts
//! of one colour each, and each part builds with the ordinary top-down builder. So
//! the colour layer is exact, voxel for voxel, and costs one build per colour.

use std::collections::HashMap;
use std::ops::ControlFlow;

use super::index::{Bounds, BoxIndex};
use super::{Colour, Solid};

/// The solid's points that have a colour, as one solid per colour; the parts are
/// disjoint and together hold exactly the coloured points.
///
/// # Runtime
/// O(size of the solid × union children whose boxes overlap) to write the
/// expressions (a union child is cut only by the later children whose boxes meet
/// its own: 10,000 separate boxes no longer write 50 million differences); the
/// cost is in building them.
#[must_use]
pub fn colour_parts(solid: &Solid) -> Vec<(Colour, Solid)> {
    let mut parts = Vec::new();
    collect(solid, None, &mut parts);
    let mut by_colour: HashMap<Colour, Vec<Solid>> = HashMap::new();
    let mut order = Vec::new();
    for (c, s) in parts {
        let entry = by_colour.entry(c).or_insert_with(|| {
            order.push(c);
            Vec::new()
        });
        entry.push(s);
    }
    order
        .into_iter()
        .map(|c| {
            let mut group = by_colour.remove(&c).unwrap_or_default();
            let solid = if group.len() == 1 {
                group.pop().expect("one part")
            } else {
                Solid::Union(group)
            };
            (c, solid)
        })
        .collect()
}

/// Appends the coloured parts of `solid` (whose inherited colour is `colour`).
fn collect(solid: &Solid, colour: Option<Colour>, out: &mut Vec<(Colour, Solid)>) {
    match solid {
        Solid::Primitive(_) | Solid::Not(_) => {
            if let Some(c) = colour {
                out.push((c, solid.clone()));
            }
        }
        Solid::Coloured(inner, c) => collect(inner, Some(*c), out),
        Solid::Transformed(inner, t) => {
            let mut inner_parts = Vec::new();
            collect(inner, colour, &mut inner_parts);
            out.extend(
                inner_parts
                    .into_iter()
                    .map(|(c, s)| (c, Solid::Transformed(Box::new(s), *t))),
            );
        }
        Solid::Union(kids) => {
            // The last child holding a point gives its colour: child i keeps the
            // points that no later child holds. Only a later child whose box meets
            // child i's can hold one of its points.
            let boxes: Vec<(u32, Option<Bounds>)> = kids
                .iter()
                .enumerate()
                .map(|(j, k)| (j as u32, k.compile().ok().and_then(|c| c.bbox())))
                .collect();
            let index = BoxIndex::new(&boxes);
            for (i, kid) in kids.iter().enumerate() {
                let mut kid_parts = Vec::new();
                collect(kid, colour, &mut kid_parts);
                let later: Vec<Solid> = match &boxes[i].1 {
                    Some(b) => {
                        let mut js = Vec::new();
                        let _ = index.for_each_meeting(b, |j| {
                            if j as usize > i {
                                js.push(j as usize);
                            }
                            ControlFlow::Continue(())
                        });
                        js.sort_unstable();
                        js.into_iter().map(|j| kids[j].clone()).collect()
                    }
                    None => kids[i + 1..].to_vec(),
                };
                for (c, s) in kid_parts {
                    let s = if later.is_empty() {
                        s
                    } else {
                        let mut v = vec![s];
                        v.extend(later.iter().cloned());
                        Solid::Difference(v)
                    };
                    out.push((c, s));
                }
            }
        }
        Solid::Intersection(kids) | Solid::Difference(kids) => {
            let Some(first) = kids.first() else {
                // An empty intersection is all space, coloured as inherited.
                if let (Some(c), Solid::Intersection(_)) = (colour, solid) {
                    out.push((c, solid.clone()));
                }
                return;
            };
            let mut first_parts = Vec::new();
            collect(first, colour, &mut first_parts);
            let is_inter = matches!(solid, Solid::Intersection(_));
            for (c, s) in first_parts {
                let mut v = vec![s];
                v.extend(kids[1..].iter().cloned());
                out.push((
                    c,
                    if is_inter {
                        Solid::Intersection(v)
                    } else {
                        Solid::Difference(v)
                    },
                ));
            }
        }
    }
}

impl super::Scene {
    /// The frame of the scene's octree: voxels of [`Scene::voxel`](super::Scene)
    /// world units, voxel `(0, 0, 0)` at [`Scene::bounds_min`](super::Scene).
    #[must_use]
    pub fn frame(&self) -> crate::model::Frame {
        crate::model::Frame::new(self.voxel, self.bounds_min)
    }

    /// The scene's colours as a layer over `tree` (the scene's built octree): one
    /// build per colour of the part of the solid that has it ([`colour_parts`]),
    /// each stopped past `max_leaves`. `None` when no object has a colour.
    ///
    /// # Errors
    /// [`super::SceneError::Build`] when a part exceeds `max_leaves`.
    pub fn colour_layer(
        &self,
        tree: &crate::linear::LinearOctree,
        max_leaves: usize,
    ) -> Result<Option<crate::model::Layer<crate::model::Rgba>>, super::SceneError> {
        let parts = self.colour_csgs()?;
        if parts.is_empty() {
            return Ok(None);
        }
        let mut regions = Vec::with_capacity(parts.len());
        for (c, part) in parts {
            let region = part
                .build_limited(self.depth, [0, 0, 0], max_leaves)
                .map_err(|source| super::SceneError::Build {
                    path: self.path.clone(),
                    source,
                })?;
            regions.push((c, region));
        }
        let layer = crate::model::Layer::from_regions(self.depth, [0, 0, 0], regions)
            .and_then(|l| l.restrict(tree))
            .map_err(|e| super::SceneError::Build {
                path: self.path.clone(),
                source: e.into(),
            })?;
        Ok(Some(layer))
    }

    /// The colour parts ([`colour_parts`]) in voxel coordinates, compiled, with their
    /// colours (opaque): what [`Scene::colour_layer`](super::Scene::colour_layer)
    /// builds, and what a streamed build builds cell by cell.
    ///
    /// # Errors
    /// [`super::SceneError::Build`] when a part does not compile.
    pub fn colour_csgs(&self) -> Result<Vec<(crate::model::Rgba, super::Csg)>, super::SceneError> {
        let to_voxels = self.world_to_voxel();
        colour_parts(&self.solid)
            .into_iter()
            .map(|(c, part)| {
                let csg = part.transform(to_voxels).compile().map_err(|source| {
                    super::SceneError::Build {
                        path: self.path.clone(),
                        source,
                    }
                })?;
                Ok(([c.0[0], c.0[1], c.0[2], 255], csg))
            })
            .collect()
    }

    /// The scene as a model: its octree, its frame and its colours, within
    /// `max_leaves` per build.
    ///
    /// # Errors
    /// As [`Scene::build_limited`](super::Scene::build_limited) and
    /// [`Scene::colour_layer`](super::Scene::colour_layer).
    pub fn build_model_limited(
        &self,
        max_leaves: usize,
    ) -> Result<crate::model::Model, super::SceneError> {
        let tree = self.build_limited(max_leaves)?;
        let colors = self.colour_layer(&tree, max_leaves)?;
        Ok(crate::model::Model {
            colors,
            ..crate::model::Model::new(tree).with_frame(self.frame())
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::csg::Scene;

    /// Every voxel's colour in the layer is the one `Csg::colour_at` gives at its
    /// centre, on every example scene (built coarser), with overlapping coloured
    /// objects, nested colours and uncoloured parts.
    #[test]
    fn colour_layer_matches_colour_at_voxel_for_voxel() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        let extra = "depth 5\nbounds [0, 0, 0] [32, 32, 32]\nunion { box(size = 20) at [12, 12, 12] colour \"red\" sphere(r = 9) at [18, 18, 18] } colour \"blue\"\nsphere(r = 6) at [8, 8, 8]\n";
        let mut scenes = vec![Scene::parse(extra, "extra.tss".as_ref()).unwrap()];
        for entry in std::fs::read_dir(dir).unwrap() {
            // scenes/ also holds octree files (bar.xyz, l-corridor.xyz) for the motion tests.
            let path = entry.unwrap().path();
            if path.extension().is_none_or(|e| e != "tss") {
                continue;
            }
            let mut scene = Scene::read(&path).unwrap();
            let old = scene.depth;
            scene.depth = 5;
            scene.voxel *= f64::from(1u32 << (old - 5));
            scenes.push(scene);
        }
        for scene in scenes {
            let m = scene.build_model_limited(1 << 24).unwrap();
            m.assert_valid();
            let csg = scene.csg().unwrap();
            let colors = m.colors.as_ref().expect("every test scene has colours");
            assert!(!colors.is_empty());
            for v in m.tree.voxels() {
                let p = v.map(|c| c as f64 + 0.5);
                let want = csg.colour_at(p).map(|c| [c.0[0], c.0[1], c.0[2], 255]);
                assert_eq!(
                    colors.get(v),
                    want,
                    "voxel {v:?} of {}",
                    scene.path.display()
                );
            }
        }
    }
}
