//! The world file: a JSON description of a static environment and moving objects
//! with trajectories, read by `tesseral simulate`. Paths inside it are relative to
//! the file's folder; octrees are read with [`crate::io::read_octree`], so every
//! octree format works, and `.tss` scene files are built with [`crate::csg`].
//!
//! ```json
//! {
//!   "environment": "room.xyz",
//!   "time_step": 0.5,
//!   "steps": 40,
//!   "objects": [
//!     { "name": "probe", "octree": "probe.xyz", "rotate": "z90",
//!       "start": [0, 4, 4], "velocity": [6, 0, 0] },
//!     { "name": "arm", "octree": "arm.xyz",
//!       "waypoints": [ { "time": 0, "at": [0, 0, 8] }, { "time": 5, "at": [10, 0, 8] } ] }
//!   ]
//! }
//! ```

use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::orient::Rotation;
use super::world::{MovingObject, Trajectory, TranslationMethod, World};
use crate::csg::SceneError;
use crate::io::{read_model, read_octree, FormatError};
use crate::model::{Frame, Model};

/// The most steps a world file may ask for.
pub const MAX_STEPS: u64 = 1_000_000;
/// The most moving objects a world file may hold.
pub const MAX_OBJECTS: usize = 1024;

/// What can go wrong reading a world file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum WorldError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The JSON is malformed or has a field of the wrong type, at a line and column.
    #[error("{path}:{line}:{column}: {message}")]
    Syntax {
        /// The file.
        path: PathBuf,
        /// The line, from 1.
        line: usize,
        /// The column, from 1.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// A value is out of range or inconsistent (named in the message).
    #[error("{path}: {message}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong, naming the object and field.
        message: String,
    },
    /// An octree file the world names could not be read.
    #[error(transparent)]
    Octree(#[from] FormatError),
    /// A scene file the world names could not be read or built.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The environment and objects hold more leaves in total than the budget.
    #[error(
        "{path}: the environment and objects read so far hold {leaves} leaves, more than the budget of {budget}"
    )]
    TooManyLeaves {
        /// The world file.
        path: PathBuf,
        /// The leaves counted when the budget was crossed.
        leaves: u64,
        /// The budget.
        budget: u64,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct WorldSpec {
    environment: String,
    #[serde(default = "one")]
    time_step: f64,
    steps: u64,
    #[serde(default)]
    translation: Option<String>,
    #[serde(default)]
    objects: Vec<ObjectSpec>,
}

fn one() -> f64 {
    1.0
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ObjectSpec {
    #[serde(default)]
    name: Option<String>,
    octree: String,
    #[serde(default)]
    rotate: Option<String>,
    #[serde(default)]
    start: Option<[f64; 3]>,
    #[serde(default)]
    velocity: Option<[f64; 3]>,
    #[serde(default)]
    waypoints: Option<Vec<WaypointSpec>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct WaypointSpec {
    time: f64,
    at: [f64; 3],
}

/// A world read from a file, with how long to run it.
#[derive(Debug, Clone)]
pub struct WorldFile {
    /// The world, in the environment's voxels.
    pub world: World,
    /// The environment's frame: positions, velocities and contacts are in its voxels.
    pub frame: Frame,
    /// The time between steps.
    pub time_step: f64,
    /// How many steps to take.
    pub steps: u64,
}

/// Reads a solid: a `.tss` scene file (built with [`crate::csg::Scene::build`]) or an
/// octree file in any format [`read_octree`] knows. The frame is dropped; see
/// [`read_body`] to keep it.
///
/// # Errors
/// [`WorldError::Scene`] or [`WorldError::Octree`], naming the file and place.
pub fn read_solid(path: &Path) -> Result<crate::linear::LinearOctree, WorldError> {
    if crate::io::extension(path) == "tss" {
        Ok(crate::csg::Scene::read(path)?.build()?)
    } else {
        Ok(read_octree(path)?)
    }
}

/// Reads a solid with its frame: a `.tss` scene (its scene units) or an octree file.
///
/// # Errors
/// As [`read_solid`].
pub fn read_body(path: &Path) -> Result<Model, WorldError> {
    if crate::io::extension(path) == "tss" {
        let scene = crate::csg::Scene::read(path)?;
        let tree = scene.build()?;
        Ok(Model::new(tree).with_frame(scene.frame()))
    } else {
        Ok(read_model(path)?)
    }
}

/// Positions and times must stay where an `i64` offset and an `f64` time are exact.
const MAX_COORD: f64 = (1u64 << 40) as f64;

/// Reads a world file (see the module documentation for the format), with the
/// default budget of [`crate::csg::DEFAULT_MAX_LEAVES`] leaves over all its bodies.
///
/// # Errors
/// As [`read_world_limited`].
pub fn read_world(path: &Path) -> Result<WorldFile, WorldError> {
    read_world_limited(path, crate::csg::DEFAULT_MAX_LEAVES as u64, false)
}

/// Reads a world file, with a budget on the leaves of the environment and all the
/// objects together (1,024 objects that each name a large octree would otherwise
/// hold 1,024 copies of it). The total is checked after each body is read, so at
/// most one body's leaves are read past the budget.
///
/// The octree paths in the file must stay inside its folder (relative, with no
/// `..`), so that a world file from elsewhere cannot make the reader open any file
/// of the machine (`/dev/zero`, another user's data); `allow_outside` lifts this.
/// A symbolic link inside the folder is followed.
///
/// # Errors
/// [`WorldError`] naming the file and the line and column, or the object and field,
/// at fault; or the octree file that could not be read;
/// [`WorldError::TooManyLeaves`] when the bodies hold more than `max_leaves`;
/// [`WorldError::Invalid`] for a path outside the folder without `allow_outside`.
pub fn read_world_limited(
    path: &Path,
    max_leaves: u64,
    allow_outside: bool,
) -> Result<WorldFile, WorldError> {
    let text = std::fs::read_to_string(path).map_err(|source| WorldError::Io {
        path: path.to_owned(),
        source,
    })?;
    // A UTF-8 byte order mark is skipped; columns count after it.
    let json = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let spec: WorldSpec = serde_json::from_str(json).map_err(|e| WorldError::Syntax {
        path: path.to_owned(),
        line: e.line(),
        column: e.column(),
        message: e.to_string(),
    })?;
    let invalid = |message: String| WorldError::Invalid {
        path: path.to_owned(),
        message,
    };
    if !(spec.time_step.is_finite() && spec.time_step > 0.0 && spec.time_step < MAX_COORD) {
        return Err(invalid(format!(
            "time_step must be positive and finite, not {}",
            spec.time_step
        )));
    }
    if spec.steps > MAX_STEPS {
        return Err(invalid(format!("steps {} exceeds {MAX_STEPS}", spec.steps)));
    }
    if spec.objects.len() > MAX_OBJECTS {
        return Err(invalid(format!(
            "{} objects exceed the limit of {MAX_OBJECTS}",
            spec.objects.len()
        )));
    }
    let method = match spec.translation.as_deref() {
        None | Some("offset") => TranslationMethod::Offset,
        Some("linear") => TranslationMethod::Linear,
        Some("labels") => TranslationMethod::Labels,
        Some(other) => {
            return Err(invalid(format!(
                "translation {other:?} is not known (known: \"offset\", \"linear\", \"labels\")"
            )))
        }
    };
    let dir = path.parent().unwrap_or(Path::new(""));
    let inside = |field: &str, p: &str| -> Result<PathBuf, WorldError> {
        let rel = Path::new(p);
        let escapes = rel.components().any(|c| {
            !matches!(
                c,
                std::path::Component::Normal(_) | std::path::Component::CurDir
            )
        });
        if escapes && !allow_outside {
            return Err(invalid(format!(
                "{field} {p:?} leaves the world file's folder (an absolute path or `..`); \
                 move the file beside the world file, or allow it with --allow-outside"
            )));
        }
        Ok(dir.join(rel))
    };
    let env_path = inside("environment", &spec.environment)?;
    let Model {
        tree: environment,
        frame,
        ..
    } = read_body(&env_path)?;
    let mut leaves = environment.leaf_count() as u64;
    let over = |leaves: u64| WorldError::TooManyLeaves {
        path: path.to_owned(),
        leaves,
        budget: max_leaves,
    };
    if leaves > max_leaves {
        return Err(over(leaves));
    }
    let mut objects = Vec::with_capacity(spec.objects.len());
    for (i, o) in spec.objects.into_iter().enumerate() {
        let name = o.name.unwrap_or_else(|| format!("object{i}"));
        let field = |f: &str, m: String| invalid(format!("object {name:?}, {f}: {m}"));
        let rotation = match &o.rotate {
            None => Rotation::IDENTITY,
            Some(s) => s
                .parse()
                .map_err(|e: super::RotationError| field("rotate", e.to_string()))?,
        };
        let finite = |p: &[f64; 3]| p.iter().all(|c| c.is_finite() && c.abs() < MAX_COORD);
        let trajectory = match (o.waypoints, o.start, o.velocity) {
            (Some(points), None, None) => {
                if points.is_empty() {
                    return Err(field("waypoints", "at least one waypoint is needed".into()));
                }
                let mut out = Vec::with_capacity(points.len());
                for w in points {
                    if !finite(&w.at) || !w.time.is_finite() {
                        return Err(field(
                            "waypoints",
                            "positions and times must be finite and below 2^40".into(),
                        ));
                    }
                    if out.last().is_some_and(|&(t, _)| w.time < t) {
                        return Err(field("waypoints", "times must not decrease".into()));
                    }
                    out.push((w.time, w.at));
                }
                Trajectory::Waypoints(out)
            }
            (Some(_), _, _) => {
                return Err(field(
                    "waypoints",
                    "give either waypoints or start and velocity, not both".into(),
                ))
            }
            (None, start, velocity) => {
                let start = start.unwrap_or([0.0; 3]);
                let velocity = velocity.unwrap_or([0.0; 3]);
                if !finite(&start) || !finite(&velocity) {
                    return Err(field(
                        "start/velocity",
                        "must be finite and below 2^40".into(),
                    ));
                }
                Trajectory::Constant { start, velocity }
            }
        };
        let body = read_body(&inside(&format!("object {name:?}, octree"), &o.octree)?)?;
        // The frame rule of `collide`: the object sits where its frame puts it in
        // the environment's lattice, and its trajectory moves it from there.
        let placed = frame
            .offset_to(&body.frame)
            .map_err(|e| field("octree", format!("{e} (against the environment)")))?;
        let tree = body
            .tree
            .translate(placed)
            .map_err(|e| field("octree", e.to_string()))?;
        leaves = leaves.saturating_add(tree.leaf_count() as u64);
        if leaves > max_leaves {
            return Err(over(leaves));
        }
        objects.push(MovingObject {
            name,
            tree,
            rotation,
            trajectory,
        });
    }
    // Every position over the run must stay where offsets are exact.
    let end = spec.time_step * spec.steps as f64;
    for o in &objects {
        let p = o.trajectory.position(end);
        if !p.iter().all(|c| c.abs() < MAX_COORD) {
            return Err(invalid(format!(
                "object {:?} leaves the space of exact coordinates (|x| < 2^40) by time {end}",
                o.name
            )));
        }
    }
    Ok(WorldFile {
        world: World {
            environment,
            objects,
            method,
        },
        frame,
        time_step: spec.time_step,
        steps: spec.steps,
    })
}
