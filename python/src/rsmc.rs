//! `tesseral.rsmc`: Monte Carlo of self-avoiding random surfaces (Libes §6), with the
//! trajectory returned as numpy arrays.

use numpy::IntoPyArray;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tesseral::dynamic::DynamicOctree;
use tesseral::rsmc::{topology, Chain, Counters, DenseLattice, Lattice, Params, Sample};
use tesseral::Voxel;

use crate::args::{Int, U64};
use crate::arrays::{cells, to_array};

const U64_MAX: i128 = u64::MAX as i128;

/// The most rows a trajectory may hold, so that `steps / sample_every` is a budget
/// checked before the run.
const MAX_ROWS: u64 = 10_000_000;

/// The start shape: `"voxel"`, `"box:AxBxC"`, or an N×3 integer array of voxels.
fn start_voxels(start: &Bound<'_, PyAny>) -> PyResult<Vec<Voxel>> {
    match start.extract::<String>() {
        Ok(s) => tesseral::rsmc::parse_start(&s).map_err(|e| PyValueError::new_err(e.to_string())),
        Err(_) => cells(start, "start"),
    }
}

/// Runs the chain for `steps` attempted steps, sampling every `sample_every`.
fn run<L: Lattice>(
    params: Params,
    seed: u64,
    start: &[Voxel],
    steps: u64,
    sample_every: u64,
) -> Result<(Chain<L>, Vec<Sample>), String> {
    let mut chain = Chain::new(L::empty(), params, seed, start).map_err(|e| e.to_string())?;
    let mut rows = Vec::new();
    let mut since = Counters::default();
    rows.push(chain.sample(since));
    while chain.steps() < steps {
        let s = chain.steps();
        let target = steps.min((s / sample_every + 1).saturating_mul(sample_every));
        chain.run(target - s);
        rows.push(chain.sample(since));
        since = chain.counters();
    }
    topology::check_sphere(&chain.voxels())
        .map_err(|e| format!("global topology check of the final surface: {e}"))?;
    Ok((chain, rows))
}

/// Monte Carlo of a self-avoiding random surface of sphere topology (Libes §6), as
/// `tesseral rsmc` runs it: weight exp(−β·A − μ·V), Hastings factor unless
/// `libes=True`. Returns a dict of numpy arrays `step`, `area`, `volume`,
/// `radius_of_gyration`, `acceptance` (the rate since the previous row), one row per
/// `sample_every` steps and one at the start, plus `voxels` (the final N×3 solid),
/// `faces` (its plaquette count), `counters` (a dict) and `seconds`.
#[pyfunction]
#[pyo3(signature = (steps = Int::Fits(100_000), beta = 0.0, mu = 0.0, max_area = None,
    seed = Int::Fits(1), start = None, libes = false, sample_every = Int::Fits(1000),
    backend = "octree"),
    text_signature = "(steps=100000, beta=0.0, mu=0.0, max_area=None, seed=1, start=None, \
    libes=False, sample_every=1000, backend=\"octree\")")]
#[allow(clippy::too_many_arguments)]
pub fn rsmc<'py>(
    py: Python<'py>,
    steps: Int,
    beta: f64,
    mu: f64,
    max_area: Option<Int>,
    seed: Int,
    start: Option<&Bound<'py, PyAny>>,
    libes: bool,
    sample_every: Int,
    backend: &str,
) -> PyResult<Bound<'py, PyDict>> {
    // Checked here, not converted by pyo3, whose OverflowError names neither.
    let steps: u64 = steps.within("steps", U64, "expected 0 to 2**64 - 1")?;
    let seed: u64 = seed.within("seed", U64, "expected 0 to 2**64 - 1")?;
    let sample_every: u64 =
        sample_every.within("sample_every", 1..=U64_MAX, "expected 1 to 2**64 - 1")?;
    let max_area: Option<u64> = max_area
        .map(|m| m.within("max_area", U64, "expected None or 6 to 2**64 - 1 faces"))
        .transpose()?;
    if steps / sample_every > MAX_ROWS {
        return Err(PyValueError::new_err(format!(
            "steps / sample_every gives more than {MAX_ROWS} rows; raise sample_every"
        )));
    }
    let start = match start {
        Some(s) => start_voxels(s)?,
        None => vec![[0, 0, 0]],
    };
    let params = Params {
        beta,
        mu,
        max_area,
        hastings: !libes,
    };
    params
        .validate()
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    let t0 = std::time::Instant::now();
    let result = match backend {
        "octree" => py.allow_threads(|| {
            run::<DynamicOctree>(params, seed, &start, steps, sample_every)
                .map(|(c, r)| (c.voxels(), c.counters(), c.area(), r))
        }),
        "dense" => py.allow_threads(|| {
            run::<DenseLattice>(params, seed, &start, steps, sample_every)
                .map(|(c, r)| (c.voxels(), c.counters(), c.area(), r))
        }),
        other => {
            return Err(PyValueError::new_err(format!(
                "backend {other:?}: expected \"octree\" or \"dense\""
            )))
        }
    };
    let (voxels, k, area, rows) = result.map_err(PyValueError::new_err)?;
    let seconds = t0.elapsed().as_secs_f64();
    let d = PyDict::new(py);
    let col = |f: fn(&Sample) -> u64| rows.iter().map(f).collect::<Vec<u64>>();
    d.set_item("step", col(|r| r.step).into_pyarray(py))?;
    d.set_item("area", col(|r| r.area).into_pyarray(py))?;
    d.set_item("volume", col(|r| r.volume).into_pyarray(py))?;
    let colf = |f: fn(&Sample) -> f64| rows.iter().map(f).collect::<Vec<f64>>();
    d.set_item(
        "radius_of_gyration",
        colf(|r| r.radius_of_gyration).into_pyarray(py),
    )?;
    d.set_item("acceptance", colf(|r| r.acceptance).into_pyarray(py))?;
    d.set_item("voxels", to_array(py, voxels)?)?;
    d.set_item("faces", area)?;
    let c = PyDict::new(py);
    c.set_item("steps", k.steps)?;
    c.set_item("accepted", k.accepted)?;
    c.set_item("grown", k.grown)?;
    c.set_item("illegal", k.illegal)?;
    c.set_item("capped", k.capped)?;
    c.set_item("refused", k.refused)?;
    d.set_item("counters", c)?;
    d.set_item("seconds", seconds)?;
    Ok(d)
}
