//! Leaf budgets for scene builds, checked before the work: a scene's leaf count is
//! estimated from a build three levels coarser, which costs about 1/64 of the real
//! one.

use super::{CsgError, Scene, SceneError, Transform};
use crate::linear::LinearOctree;

/// How many levels coarser the estimating build is.
const COARSER: u8 = 3;

/// Leaves multiply by about 4 per level: they follow the surface, whose area in
/// voxels grows fourfold each time the voxel side halves.
const GROWTH_PER_LEVEL: u64 = 4;

impl Scene {
    /// Estimates how many leaves [`Scene::build`] will produce, by building the scene
    /// three levels coarser and multiplying by 4³ (leaves follow the surface). Scenes
    /// of depth below 6 are built outright (at most 32³ voxels), so the estimate is
    /// exact there.
    ///
    /// The estimating build stops once it passes `max_leaves / 64`, and the estimate
    /// is then `u64::MAX`: more than `max_leaves`, by an amount not measured. Thin
    /// features (narrower than eight voxels) may vanish at the coarse level, so the
    /// estimate can be low by a small factor on such scenes; the real build still
    /// enforces `max_leaves` as it goes.
    ///
    /// # Runtime
    /// About 1/64 of [`Scene::build`].
    ///
    /// # Errors
    /// [`SceneError::Build`] when the scene's depth is invalid.
    ///
    /// # Example
    /// ```
    /// use std::path::Path;
    /// use tesseral::csg::Scene;
    /// let scene = Scene::parse("depth 8\nsphere(r = 100) at [128, 128, 128]\n", Path::new("s.tss")).unwrap();
    /// let estimate = scene.estimate_leaves(usize::MAX).unwrap();
    /// let real = scene.build().unwrap().leaf_count() as u64;
    /// assert!(estimate > real / 4 && estimate < real * 4);
    /// ```
    pub fn estimate_leaves(&self, max_leaves: usize) -> Result<u64, SceneError> {
        let wrap = |source| SceneError::Build {
            path: self.path.clone(),
            source,
        };
        if self.depth < 2 * COARSER {
            return match self.build_limited(max_leaves) {
                Ok(tree) => Ok(tree.leaf_count() as u64),
                Err(SceneError::Build {
                    source: CsgError::TooManyLeaves { .. },
                    ..
                }) => Ok(u64::MAX),
                Err(e) => Err(e),
            };
        }
        let factor = GROWTH_PER_LEVEL.pow(u32::from(COARSER));
        let coarse_cap = max_leaves / factor as usize + 1;
        let s = 1.0 / (self.voxel * f64::from(1u32 << COARSER));
        let to_coarse = Transform {
            scale: s,
            at: self.bounds_min.map(|b| -b * s),
            ..Transform::IDENTITY
        };
        let csg = self
            .solid
            .clone()
            .transform(to_coarse)
            .compile()
            .map_err(wrap)?;
        match csg.build_limited(self.depth - COARSER, [0, 0, 0], coarse_cap) {
            Ok(tree) => Ok((tree.leaf_count() as u64).saturating_mul(factor)),
            Err(CsgError::TooManyLeaves { .. }) => Ok(u64::MAX),
            Err(e) => Err(wrap(e)),
        }
    }

    /// Builds the scene's octree as [`Scene::build`] does, stopping with
    /// [`CsgError::TooManyLeaves`] once more than `max_leaves` leaves are produced.
    ///
    /// # Runtime
    /// As [`Scene::build`].
    ///
    /// # Errors
    /// [`SceneError::Build`].
    ///
    /// # Example
    /// ```
    /// use std::path::Path;
    /// use tesseral::csg::Scene;
    /// let scene = Scene::parse("depth 6\nsphere(r = 20) at [32, 32, 32]\n", Path::new("s.tss")).unwrap();
    /// assert!(scene.build_limited(10).is_err());
    /// assert!(scene.build_limited(1 << 20).is_ok());
    /// ```
    pub fn build_limited(&self, max_leaves: usize) -> Result<LinearOctree, SceneError> {
        self.csg()?
            .build_limited(self.depth, [0, 0, 0], max_leaves)
            .map_err(|source| SceneError::Build {
                path: self.path.clone(),
                source,
            })
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;

    /// The estimate against the real build, on every example scene: within a factor
    /// of 4 either way.
    #[test]
    fn estimates_of_the_example_scenes() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        let mut seen = 0;
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_none_or(|e| e != "tss") {
                continue;
            }
            let scene = Scene::read(&path).unwrap();
            let estimate = scene.estimate_leaves(usize::MAX).unwrap();
            let real = scene.build().unwrap().leaf_count() as u64;
            println!("{}: estimate {estimate}, real {real}", path.display());
            assert!(
                estimate >= real / 4 && estimate <= real * 4,
                "{}: estimate {estimate}, real {real}",
                path.display()
            );
            seen += 1;
        }
        assert!(seen >= 5, "only {seen} scenes found");
    }

    #[test]
    fn a_capped_estimate_is_above_the_cap() {
        let scene = Scene::parse(
            "depth 10\nsphere(r = 400) at [512, 512, 512]\n",
            Path::new("s.tss"),
        )
        .unwrap();
        let real = scene.build().unwrap().leaf_count();
        let cap = real / 100;
        assert_eq!(scene.estimate_leaves(cap).unwrap(), u64::MAX);
        assert!(scene.build_limited(cap).is_err());
        assert_eq!(scene.build_limited(real).unwrap().leaf_count(), real);
        // A small scene is built outright: the estimate is exact.
        let small = Scene::parse(
            "depth 4\nbox(size = [5, 6, 7]) at [8, 8, 8]\n",
            Path::new("t.tss"),
        )
        .unwrap();
        assert_eq!(
            small.estimate_leaves(usize::MAX).unwrap(),
            small.build().unwrap().leaf_count() as u64
        );
    }
}
