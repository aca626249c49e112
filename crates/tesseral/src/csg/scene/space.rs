//! The settings (`depth`, `voxel`, `bounds`) and the objects made into a [`Scene`]:
//! its voxel space, chosen or fitted to the objects.

use super::lexer::Span;
use super::parser::{Parser, Settings};
use super::{Scene, SceneError, MAX_SCENE_DEPTH};
use crate::csg::{Colour, Solid};

impl Parser<'_> {
    pub(super) fn finish(
        &self,
        s: Settings,
        objects: Vec<(Solid, Span)>,
    ) -> Result<Scene, SceneError> {
        let top = Span {
            line: 1,
            col: 1,
            width: 1,
        };
        let Some(first) = objects.first().map(|o| o.1) else {
            return Err(self.err(
                self.peek().span,
                "the scene has no solid",
                Some("add one, e.g. `sphere(r = 10)`".into()),
            ));
        };
        let n = objects.len();
        let solid = Solid::Union(
            objects
                .into_iter()
                .enumerate()
                .map(|(i, (o, _))| match o {
                    Solid::Coloured(..) => o,
                    o => o.colour(Colour::PALETTE[i % Colour::PALETTE.len()]),
                })
                .collect(),
        );
        let (lo, hi) = match s.bounds {
            Some((lo, hi, _)) => (lo, hi),
            None => {
                let csg = solid
                    .compile()
                    .map_err(|e| self.err(first, e.to_string(), None))?;
                match csg.bbox() {
                    Some((lo, hi)) if (0..3).all(|a| hi[a] > lo[a]) => (lo, hi),
                    Some(_) => {
                        return Err(self.err(
                            first,
                            "the scene's solids have an empty bounding box",
                            Some("add `bounds [xmin, ymin, zmin] [xmax, ymax, zmax]`".into()),
                        ))
                    }
                    None => {
                        return Err(self.err(
                            first,
                            "the scene is unbounded (a half-space or `not`), so its space cannot be inferred",
                            Some("add `bounds [xmin, ymin, zmin] [xmax, ymax, zmax]`".into()),
                        ))
                    }
                }
            }
        };
        let extent = (0..3).map(|a| hi[a] - lo[a]).fold(0.0f64, f64::max);
        let (depth, voxel) = match (s.depth, s.voxel) {
            (Some((_, ds)), Some(_)) => return Err(self.err(
                ds,
                "both `depth` and `voxel` are set",
                Some(
                    "keep one: `depth` fits the voxel size to the bounds, `voxel` fits the depth"
                        .into(),
                ),
            )),
            (Some((d, _)), None) => (d, extent / f64::from(1u32 << d)),
            (None, Some((v, vs))) => {
                let cells = (extent / v).max(1.0);
                let d = cells.log2().ceil();
                if d > f64::from(MAX_SCENE_DEPTH) {
                    return Err(self.err(
                        vs,
                        format!(
                            "voxels this small need depth {d}, more than the limit {MAX_SCENE_DEPTH}"
                        ),
                        Some("use a larger voxel size or smaller bounds".into()),
                    ));
                }
                (d as u8, v)
            }
            (None, None) => {
                return Err(self.err(
                    top,
                    "the scene sets neither `depth` nor `voxel`",
                    Some("add a line such as `depth 8` at the top".into()),
                ))
            }
        };
        Ok(Scene {
            solid,
            depth,
            voxel,
            bounds_min: lo,
            objects: n,
            path: self.path.to_owned(),
        })
    }
}
