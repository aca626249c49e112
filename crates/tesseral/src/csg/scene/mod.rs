//! The scene text format (`.tss`, "tesseral scene") and its parser. The format is
//! documented, with its grammar and an example of every construct, in
//! `docs/scenes.md`.
//!
//! ```
//! use tesseral::csg::Scene;
//! let src = "depth 5\nlet r = 8\nsphere(r = r) at [16, 16, 16] colour \"red\"\n\
//!            bounds [0, 0, 0] [32, 32, 32]\n";
//! let scene = Scene::parse(src, "ball.tss".as_ref()).unwrap();
//! let tree = scene.build().unwrap();
//! assert_eq!(tree.depth(), 5);
//! assert!(tree.contains([16, 16, 16]));
//! ```
//!
//! The parser is split by stage: `lexer.rs` (tokens), `parser.rs` (statements and
//! groups), `shapes.rs` (primitive calls), `value.rs` (expressions, `let` values and
//! the work budget), `space.rs` (settings into a voxel space); `error.rs` holds the
//! located diagnostics and `words.rs` the vocabulary and typo suggestions.

mod error;
mod lexer;
mod parser;
mod shapes;
mod space;
mod value;
mod words;

pub use error::{Diagnostic, SceneError};
#[cfg(test)]
pub(crate) use words::closest;

use std::path::{Path, PathBuf};

use super::{Csg, Solid, Transform};
use crate::linear::LinearOctree;
use parser::Parser;

/// The deepest tree a scene may ask for.
pub const MAX_SCENE_DEPTH: u8 = 16;
/// The most primitives a scene may hold.
pub const MAX_PRIMITIVES: usize = 10_000;
/// The deepest nesting of groups and brackets.
pub const MAX_NESTING: usize = 64;
/// The largest scene file, in bytes.
pub const MAX_SCENE_BYTES: usize = 4 << 20;
/// The most numbers and lists one value may hold, counted through shared `let`
/// names: `[a, a]` holds `a` twice.
pub const MAX_VALUE_ELEMENTS: usize = 1 << 20;
/// The most numbers and lists the whole scene may build while it is evaluated (list
/// literals and arithmetic on lists), so that a short file cannot ask for unbounded
/// work by repeating a large computation.
pub const MAX_SCENE_WORK: usize = 1 << 24;
/// The shapes a scene may name.
pub const SHAPES: &[&str] = &[
    "box",
    "prism",
    "sphere",
    "ellipsoid",
    "spheroid",
    "cylinder",
    "cone",
    "torus",
    "capsule",
    "halfspace",
    "polyhedron",
];
/// The set operations a scene may name.
pub const GROUPS: &[&str] = &["union", "intersection", "difference", "not"];
/// The settings.
pub const SETTINGS: &[&str] = &["depth", "voxel", "bounds"];
/// The modifiers that may follow a solid.
pub const MODIFIERS: &[&str] = &["at", "rotate", "scale", "colour", "color"];

/// A parsed scene: the solid in world units and the voxel space it is built in.
///
/// The space is the cube of `2^depth` voxels of side `voxel` whose lowest corner is
/// `bounds_min`; in voxel coordinates (those of the octree, origin `[0, 0, 0]`) a world
/// point `p` is `(p − bounds_min) / voxel`.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The union of the scene's objects, in world units, each with its colour.
    pub solid: Solid,
    /// The tree depth.
    pub depth: u8,
    /// The side of a voxel, in world units.
    pub voxel: f64,
    /// The world position of the space's lowest corner.
    pub bounds_min: [f64; 3],
    /// The number of top-level objects.
    pub objects: usize,
    pub(super) path: PathBuf,
}

impl Scene {
    /// Reads and parses a scene file.
    ///
    /// # Errors
    /// [`SceneError::Io`], or [`SceneError::Parse`] located in the file.
    pub fn read(path: &Path) -> Result<Scene, SceneError> {
        let bytes = std::fs::read(path).map_err(|source| SceneError::Io {
            path: path.to_owned(),
            source,
        })?;
        let text = String::from_utf8(bytes).map_err(|e| {
            let upto = &e.as_bytes()[..e.utf8_error().valid_up_to()];
            let text = String::from_utf8_lossy(upto).into_owned();
            let line = text.matches('\n').count() + 1;
            let col = text.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
            SceneError::Parse(Box::new(Diagnostic {
                path: path.to_owned(),
                line,
                column: col,
                width: 1,
                message: "the file is not valid UTF-8".into(),
                hint: Some("save the scene as UTF-8 text".into()),
                source_line: text.rsplit('\n').next().unwrap_or("").to_owned(),
            }))
        })?;
        Self::parse(&text, path)
    }

    /// Parses scene text; `path` names the file in error messages.
    ///
    /// # Errors
    /// [`SceneError::Parse`] with the line, column, a caret and a hint.
    pub fn parse(text: &str, path: &Path) -> Result<Scene, SceneError> {
        // A UTF-8 byte order mark is skipped; columns count after it.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut p = Parser::new(text, path)?;
        p.file()
    }

    /// The map from world to voxel coordinates.
    #[must_use]
    pub fn world_to_voxel(&self) -> Transform {
        let s = 1.0 / self.voxel;
        Transform {
            scale: s,
            at: self.bounds_min.map(|b| -b * s),
            ..Transform::IDENTITY
        }
    }

    /// The solid compiled in voxel coordinates (the octree's).
    ///
    /// # Errors
    /// [`SceneError::Build`] (cannot happen for a parsed scene, whose solids are checked).
    pub fn csg(&self) -> Result<Csg, SceneError> {
        self.solid
            .clone()
            .transform(self.world_to_voxel())
            .compile()
            .map_err(|source| SceneError::Build {
                path: self.path.clone(),
                source,
            })
    }

    /// Builds the scene's octree: depth [`Scene::depth`], origin `[0, 0, 0]`.
    ///
    /// # Errors
    /// [`SceneError::Build`] when the tree would exceed the leaf limit.
    pub fn build(&self) -> Result<LinearOctree, SceneError> {
        self.csg()?
            .build(self.depth, [0, 0, 0])
            .map_err(|source| SceneError::Build {
                path: self.path.clone(),
                source,
            })
    }
}
