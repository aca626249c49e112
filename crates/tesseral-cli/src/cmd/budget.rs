//! Work budgets, checked before the work: `--memory` and, when given, `--max-leaves`.
//!
//! A scene build is estimated first (`Scene::estimate_leaves`, a build three levels
//! coarser), and refused at once when the estimate is over budget; the real build
//! then stops at the same budget if the estimate was low. A model held whole (a
//! scene built in memory, a file read whole) may hold `--memory` / 48 bytes leaves,
//! fewer when the command's work on it takes more a leaf ([`Budget::for_work`]:
//! a mesh written, a viewer's page); there is no fixed leaf limit. A `.tess` file
//! or dataset is checked from its header before it is read, another file once read,
//! before the work. A streamed build's memory is estimated from its plan instead
//! (`build/stream.rs`). `plan` estimates its configuration space from the region's
//! box (`motion::estimate_plan_bytes`).

use std::path::Path;

use anyhow::{bail, Result};
use tesseral::csg::{Scene, DEFAULT_MAX_LEAVES};
use tesseral::linear::LinearOctree;

use super::output::{human_bytes, parse_bytes};

/// Memory per leaf of a model held whole: a scene built in memory (the leaf, its
/// copy in the per-thread chunks before they are joined, the colour regions) or a
/// file read whole. Peak resident memory measured: 41 bytes a leaf for the
/// showcase at depth 10 (1.69 M leaves), 46 for the spheroid of
/// `fig4c-spheroid.tss` at depth 10 and 44 at depth 11 (3.6 M); reading either
/// from a `.tess` the same.
pub const MODEL_BYTES_PER_LEAF: u64 = 48;

/// Memory per leaf that writing a model in format `ext` takes beside the model:
/// the boundary mesh of `.stl`, `.obj`, `.ply`, `.glb` (its lattice and
/// triangles), the OctoMap tree of `.bt`, `.ot`, the runs of `.binvox`; nothing for
/// the formats written leaf by leaf. Measured as the peak beyond
/// [`MODEL_BYTES_PER_LEAF`] on the showcase and the spheroid at depth 10 (the
/// spheroid also at 11, for meshes): 195–293 bytes (meshes; 300–355 with the hash
/// maps the mesher had before its lattice), 38–48 (`.bt`), 54–58 (`.ot`), 66–68
/// (`.binvox`).
pub fn write_bytes_per_leaf(ext: &str) -> u64 {
    match ext {
        "stl" | "obj" | "ply" | "glb" => 340,
        "binvox" => 80,
        "ot" => 64,
        "bt" => 48,
        _ => 0,
    }
}

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
    /// Memory per leaf of the command's work on the model, beside the model itself
    /// (not a flag: see [`Budget::for_work`]).
    #[arg(skip)]
    pub work_per_leaf: u64,
}

impl Default for Budget {
    fn default() -> Self {
        Self {
            max_leaves: None,
            memory: 8 << 30,
            work_per_leaf: 0,
        }
    }
}

impl Budget {
    /// This budget for a command whose work on the model takes `bytes_per_leaf`
    /// bytes a leaf beside it (a mesh written: [`write_bytes_per_leaf`]), so that
    /// a model too large for the work is refused before it is built or read.
    #[must_use]
    pub fn for_work(self, bytes_per_leaf: u64) -> Self {
        Self {
            work_per_leaf: bytes_per_leaf,
            ..self
        }
    }

    /// The bytes a leaf of a model held whole and worked on.
    fn bytes_per_leaf(&self) -> u64 {
        MODEL_BYTES_PER_LEAF.saturating_add(self.work_per_leaf)
    }

    /// The leaf cap: `--max-leaves`, or fewer if `--memory` cannot hold that many.
    pub fn leaf_cap(&self) -> usize {
        self.max_leaves
            .unwrap_or(usize::MAX)
            .min(self.memory_leaf_cap())
    }

    /// The error for `leaves` over the cap (`u64::MAX`: over, by an unmeasured
    /// amount), naming the flag that binds.
    pub fn refuse(&self, what: &str, leaves: u64) -> anyhow::Error {
        self.refuse_at(what, leaves, self.leaf_cap())
    }

    /// The leaf cap of a world's bodies (`simulate`): `--max-leaves`, by default
    /// the library's [`DEFAULT_MAX_LEAVES`] (a body costs far more than a leaf's
    /// 48 bytes once collision structures are built), or fewer if `--memory`
    /// cannot hold that many.
    pub fn world_leaf_cap(&self) -> usize {
        self.max_leaves
            .unwrap_or(DEFAULT_MAX_LEAVES)
            .min(self.memory_leaf_cap())
    }

    fn memory_leaf_cap(&self) -> usize {
        usize::try_from(self.memory / self.bytes_per_leaf()).unwrap_or(usize::MAX)
    }

    /// Whether `--memory` binds the leaf cap `cap` (it allows no more), rather
    /// than `--max-leaves`.
    fn memory_binds_at(&self, cap: usize) -> bool {
        cap >= self.memory_leaf_cap()
    }

    /// Whether `--memory`, not `--max-leaves`, binds this budget's leaf cap.
    pub fn memory_binds(&self) -> bool {
        self.memory_binds_at(self.leaf_cap())
    }

    /// Refuses a model of `leaves` leaves (`what`: the input) over the leaf cap:
    /// a file to be read whole, from its header, or one just read, before the work.
    ///
    /// # Errors
    /// An error naming the input and the flag that binds.
    pub fn check_leaves(&self, what: &str, leaves: u64) -> Result<()> {
        if leaves > self.leaf_cap() as u64 {
            return Err(self.refuse(what, leaves));
        }
        Ok(())
    }

    /// As [`Budget::refuse`], for the cap `cap`: `--memory` binds when it allows no
    /// more than `cap`, else `--max-leaves` (given, or its default).
    pub fn refuse_at(&self, what: &str, leaves: u64, cap: usize) -> anyhow::Error {
        let (flag, limit) = if self.memory_binds_at(cap) {
            ("--memory", human_bytes(self.memory))
        } else {
            ("--max-leaves", cap.to_string())
        };
        // The bytes a leaf, when the command's work on the model counts.
        let rate = if flag == "--memory" && self.work_per_leaf > 0 {
            format!(
                " (at {} bytes a leaf with the work on it)",
                self.bytes_per_leaf()
            )
        } else {
            String::new()
        };
        let count = if leaves == u64::MAX {
            format!("more than the {cap} leaves that {flag} {limit} allows{rate}")
        } else {
            format!("about {leaves} leaves, more than the {cap} that {flag} {limit} allows{rate}")
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
