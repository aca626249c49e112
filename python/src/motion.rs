//! `tesseral.collide`, `tesseral.plan` and `tesseral.simulate`.

use std::path::PathBuf;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use tesseral::motion::{self, Placement, PlanOptions, Rotation};

use crate::args::{within3, Int, I64, I64_RULE, ZERO3};
use crate::errors;

const I64_MAX: i128 = i64::MAX as i128;
use crate::octree::Octree;

fn rotation(text: &str) -> PyResult<Rotation> {
    text.parse()
        .map_err(|e: tesseral::motion::RotationError| PyValueError::new_err(e.to_string()))
}

/// Whether B, placed by its frame in A's and moved by `offset` voxels (turned by
/// `turns`, such as "z90"), meets A: a dict with intersects, overlap_voxels and
/// clearance (None when a solid is empty).
#[pyfunction]
#[pyo3(signature = (a, b, offset = ZERO3, turns = ""), text_signature = "(a, b, offset=(0, 0, 0), turns=\"\")")]
pub fn collide<'py>(
    py: Python<'py>,
    a: &Octree,
    b: &Octree,
    offset: (Int, Int, Int),
    turns: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let offset: [i64; 3] = within3(&offset, "offset", I64, I64_RULE)?;
    let framed = a
        .model
        .frame
        .offset_to(&b.model.frame)
        .map_err(errors::octree)?;
    let mut moved = [0; 3];
    for ((m, o), f) in moved.iter_mut().zip(offset).zip(framed) {
        // Refused past int64, not wrapped round.
        *m = o.checked_add(f).ok_or_else(|| {
            PyValueError::new_err(format!(
                "offset {offset:?}: with b's frame offset {framed:?} from a's it lies past int64"
            ))
        })?;
    }
    let place = Placement {
        rotation: rotation(turns)?,
        offset: moved,
    };
    let (ta, tb) = (&a.model.tree, &b.model.tree);
    let (hit, gap) = py.allow_threads(|| {
        (
            motion::interference(ta, tb, place, false),
            motion::clearance(ta, tb, place),
        )
    });
    let d = PyDict::new(py);
    d.set_item("intersects", hit.intersects)?;
    d.set_item("overlap_voxels", hit.overlap_voxels)?;
    d.set_item("clearance", gap)?;
    Ok(d)
}

/// A collision-free path for `obj` through `env` from offset `start` to `goal`
/// (voxels of env); `rotations=True` lets it turn by quarter turns. A dict with
/// found, and waypoints/length/steps (or moves/turns/orientations), or reason.
/// A negative `margin`, or a planning region too large to search (past 2**21
/// voxels a side), raises ValueError.
#[pyfunction]
#[pyo3(signature = (env, obj, start, goal, margin = Int::Fits(0), turns = "", rotations = false),
    text_signature = "(env, obj, start, goal, margin=0, turns=\"\", rotations=False)")]
#[allow(clippy::too_many_arguments)]
pub fn plan<'py>(
    py: Python<'py>,
    env: &Octree,
    obj: &Octree,
    start: (Int, Int, Int),
    goal: (Int, Int, Int),
    margin: Int,
    turns: &str,
    rotations: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let from: [i64; 3] = within3(&start, "start", I64, I64_RULE)?;
    let to: [i64; 3] = within3(&goal, "goal", I64, I64_RULE)?;
    let margin: i64 = margin.within("margin", 0..=I64_MAX, "expected 0 to 2**63 - 1 voxels")?;
    let placed = env
        .model
        .frame
        .offset_to(&obj.model.frame)
        .map_err(errors::octree)?;
    let obj_tree = obj.model.tree.translate(placed).map_err(errors::octree)?;
    let opts = PlanOptions {
        rotation: rotation(turns)?,
        margin,
        ..PlanOptions::default()
    };
    let e = &env.model.tree;
    let d = PyDict::new(py);
    if rotations {
        match py
            .allow_threads(|| motion::plan_with_turns(e, &obj_tree, from, to, opts.rotation, &opts))
        {
            Ok(p) => {
                let w = p.waypoints();
                d.set_item("found", true)?;
                d.set_item("waypoints", w.iter().map(|s| s.0).collect::<Vec<_>>())?;
                d.set_item(
                    "orientations",
                    w.iter().map(|s| s.1.to_string()).collect::<Vec<_>>(),
                )?;
                d.set_item("moves", p.moves)?;
                d.set_item("turns", p.turns)?;
            }
            Err(why) => {
                d.set_item("found", false)?;
                d.set_item("reason", no_path(why, margin)?)?;
            }
        }
        return Ok(d);
    }
    match py.allow_threads(|| motion::plan(e, &obj_tree, from, to, &opts)) {
        Ok(p) => {
            d.set_item("found", true)?;
            d.set_item("waypoints", p.waypoints)?;
            d.set_item("steps", p.steps)?;
            d.set_item("length", p.length)?;
            d.set_item("clearance", p.clearance)?;
        }
        Err(why) => {
            d.set_item("found", false)?;
            d.set_item("reason", no_path(why, margin)?)?;
        }
    }
    Ok(d)
}

/// The reason there is no path, or a ValueError when there is no answer: a
/// planning region wider than an octree holds is a limit of the search, not a
/// finding about the solids (the CLI refuses it before planning).
fn no_path(why: motion::NoPath, margin: i64) -> PyResult<String> {
    match why {
        motion::NoPath::Octree(e) => Err(PyValueError::new_err(format!(
            "the planning region is too large to search: {e} (at most 2**21 voxels a \
             side); it is the bounding box of env and of obj at start and at goal, \
             widened by margin={margin} voxels on every side: lower margin, or plan \
             between nearer start and goal"
        ))),
        other => Ok(other.to_string()),
    }
}

/// Runs a world file (see docs/motion.md): a dict with steps, time_step, objects and
/// contacts (each a dict of time, step, a, b, between_steps). A file the system
/// will not read (the world, or an octree or scene it names) raises the `OSError`
/// of its errno (`FileNotFoundError`, `IsADirectoryError`, ...), as `Octree.read`.
#[pyfunction]
pub fn simulate<'py>(py: Python<'py>, world: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let wf = py
        .allow_threads(|| motion::read_world(&world))
        .map_err(|e| errors::world(py, e))?;
    let contacts = PyList::empty(py);
    let names: Vec<String> = wf.world.objects.iter().map(|o| o.name.clone()).collect();
    let name = |b: &motion::Body| match b {
        motion::Body::Environment => "environment".to_owned(),
        motion::Body::Object { name, .. } => name.clone(),
    };
    let mut found = Vec::new();
    let world_ref = &wf.world;
    py.allow_threads(|| {
        world_ref.simulate_each(wf.time_step, wf.steps, false, |step| {
            for c in &step.contacts {
                found.push((c.time, c.step, name(&c.a), name(&c.b), c.between_steps));
            }
            std::ops::ControlFlow::Continue(())
        })
    })
    .map_err(errors::octree)?;
    for (time, step, a, b, between) in found {
        let c = PyDict::new(py);
        c.set_item("time", time)?;
        c.set_item("step", step)?;
        c.set_item("a", a)?;
        c.set_item("b", b)?;
        c.set_item("between_steps", between)?;
        contacts.append(c)?;
    }
    let d = PyDict::new(py);
    d.set_item("steps", wf.steps)?;
    d.set_item("time_step", wf.time_step)?;
    d.set_item("objects", names)?;
    d.set_item("contacts", contacts)?;
    Ok(d)
}
