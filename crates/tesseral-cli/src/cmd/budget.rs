//! Work budgets, checked before the work: `--memory` and, when given, `--max-leaves`.
//!
//! A scene build is estimated first (`Scene::estimate_leaves`, a build three levels
//! coarser), and refused at once when the estimate is over budget; the real build
//! then stops at the same budget if the estimate was low. An in-memory build may
//! hold `--memory` / 24 bytes leaves (there is no fixed leaf limit); a streamed
//! build's memory is estimated from its plan instead (`build/stream.rs`). `plan` estimates its
//! configuration space from the region's box (`motion::estimate_plan_bytes`).

use std::path::Path;

use anyhow::{bail, Result};
use tesseral::csg::{Scene, DEFAULT_MAX_LEAVES};
use tesseral::linear::LinearOctree;

use super::output::{human_bytes, parse_bytes};

/// Memory per leaf while a scene is built in memory: the leaf itself, its copy in
/// the per-thread chunks before they are joined, and the colour regions (measured:
/// about 21 bytes a leaf for the showcase at depth 12).
const BUILD_BYTES_PER_LEAF: u64 = 24;

/// The budget flags of commands that build scenes or plan.
#[derive(clap::Args, Clone, Copy, Debug)]
pub struct Budget {
    /// Refuse to build an octree of more leaves than this (a scene is estimated before
    /// it is built). Without it, only --memory bounds the leaves.
    #[arg(long, value_name = "N")]
    pub max_leaves: Option<usize>,
    /// The working memory the command may use, estimated before the work: bytes, or a
    /// number with K, M, G or T (powers of 1024).
    #[arg(long, value_name = "SIZE", default_value = "8G", value_parser = parse_bytes)]
    pub memory: u64,
}

impl Default for Budget {
    fn default() -> Self {
        Self {
            max_leaves: None,
            memory: 8 << 30,
        }
    }
}

impl Budget {
    /// The leaf cap: `--max-leaves`, or fewer if `--memory` cannot hold that many.
    pub fn leaf_cap(&self) -> usize {
        let by_memory = usize::try_from(self.memory / BUILD_BYTES_PER_LEAF).unwrap_or(usize::MAX);
        self.max_leaves.unwrap_or(usize::MAX).min(by_memory)
    }

    /// The error for `leaves` over the cap (`u64::MAX`: over, by an unmeasured
    /// amount), naming the flag that binds.
    pub fn refuse(&self, what: &str, leaves: u64) -> anyhow::Error {
        self.refuse_at(what, leaves, self.leaf_cap())
    }

    /// The leaf cap of a world's bodies (`simulate`): `--max-leaves`, by default
    /// the library's [`DEFAULT_MAX_LEAVES`] (a body costs far more than a leaf's
    /// 24 bytes once collision structures are built), or fewer if `--memory`
    /// cannot hold that many.
    pub fn world_leaf_cap(&self) -> usize {
        self.max_leaves
            .unwrap_or(DEFAULT_MAX_LEAVES)
            .min(self.memory_leaf_cap())
    }

    fn memory_leaf_cap(&self) -> usize {
        usize::try_from(self.memory / BUILD_BYTES_PER_LEAF).unwrap_or(usize::MAX)
    }

    /// As [`Budget::refuse`], for the cap `cap`: `--memory` binds when it allows no
    /// more than `cap`, else `--max-leaves` (given, or its default).
    pub fn refuse_at(&self, what: &str, leaves: u64, cap: usize) -> anyhow::Error {
        let (flag, limit) = if cap >= self.memory_leaf_cap() {
            ("--memory", human_bytes(self.memory))
        } else {
            ("--max-leaves", cap.to_string())
        };
        let count = if leaves == u64::MAX {
            format!("more than the {cap} leaves that {flag} {limit} allows")
        } else {
            format!("about {leaves} leaves, more than the {cap} that {flag} {limit} allows")
        };
        anyhow::anyhow!("{what}: the octree would have {count}; raise {flag} or lower the depth")
    }

    /// Builds a scene's octree within the budget: refused before the work when the
    /// estimate is over, stopped during it if the estimate was low.
    ///
    /// # Errors
    /// An error naming the scene and the flag that raises the budget.
    pub fn build_scene(&self, path: &Path, scene: &Scene) -> Result<LinearOctree> {
        self.build_scene_checked(path, scene, |_| Ok(()))
    }

    /// [`Budget::build_scene`], with `check` run on the leaf estimate (once it is
    /// within the leaf cap) before the build: a command whose own memory grows with
    /// the leaves (`render`) refuses there rather than after the build.
    ///
    /// # Errors
    /// As [`Budget::build_scene`], and `check`'s.
    pub fn build_scene_checked(
        &self,
        path: &Path,
        scene: &Scene,
        check: impl FnOnce(u64) -> Result<()>,
    ) -> Result<LinearOctree> {
        let cap = self.leaf_cap();
        let what = format!("{} at depth {}", path.display(), scene.depth);
        let estimate = scene.estimate_leaves(cap)?;
        if estimate > cap as u64 {
            return Err(self.refuse(&what, estimate));
        }
        check(estimate)?;
        match scene.build_limited(cap) {
            Ok(tree) => Ok(tree),
            Err(tesseral::csg::SceneError::Build {
                source: tesseral::csg::CsgError::TooManyLeaves { .. },
                ..
            }) => Err(self.refuse(&what, u64::MAX)),
            Err(e) => Err(e.into()),
        }
    }

    /// Reads a scene and builds it as a model (octree, frame, colours) within the
    /// budget; each colour's part is built under the same leaf cap.
    ///
    /// # Errors
    /// As [`Budget::build_scene`].
    pub fn build_scene_model(&self, path: &Path) -> Result<tesseral::model::Model> {
        let scene = Scene::read(path)?;
        let tree = self.build_scene(path, &scene)?;
        let colors = scene.colour_layer(&tree, self.leaf_cap())?;
        Ok(tesseral::model::Model {
            colors,
            ..tesseral::model::Model::new(tree).with_frame(scene.frame())
        })
    }

    /// Refuses work estimated at `bytes` of memory above `--memory`.
    ///
    /// # Errors
    /// An error naming `what` and `--memory`.
    pub fn check_memory(&self, what: &str, bytes: u64, hint: &str) -> Result<()> {
        if bytes > self.memory {
            bail!(
                "{what}: about {} of memory, more than --memory {} allows; raise --memory{hint}",
                human_bytes(bytes),
                human_bytes(self.memory)
            );
        }
        Ok(())
    }
}
