//! Python bindings of tesseral: the `tesseral._tesseral` extension module, wrapped by
//! the pure-Python package in `pysrc/tesseral`. Arrays cross as numpy arrays (one copy
//! at most), and long calls release the GIL.

use pyo3::prelude::*;

mod args;
mod arrays;
mod calc;
mod dataset;
mod dynamic;
mod errors;
mod motion;
mod occupancy;
mod octree;
mod partition;
mod rsmc;
mod scans;
mod scene;

/// `n` followed by the noun that agrees with it ("1 voxel", "2 voxels"), for the
/// classes' `repr`s.
fn count(n: impl Into<u64>, one: &str, many: &str) -> String {
    let n = n.into();
    format!("{n} {}", if n == 1 { one } else { many })
}

#[pymodule]
fn _tesseral(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("FormatError", py.get_type::<errors::FormatError>())?;
    m.add("SceneError", py.get_type::<errors::SceneError>())?;
    m.add("OctreeError", py.get_type::<errors::OctreeError>())?;
    m.add_class::<octree::Octree>()?;
    m.add_class::<scene::Scene>()?;
    m.add_class::<dynamic::DynamicOctree>()?;
    m.add_class::<occupancy::OccupancyMap>()?;
    m.add_function(wrap_pyfunction!(scans::read_scans, m)?)?;
    m.add_function(wrap_pyfunction!(scene::render, m)?)?;
    m.add_function(wrap_pyfunction!(motion::collide, m)?)?;
    m.add_function(wrap_pyfunction!(motion::plan, m)?)?;
    m.add_function(wrap_pyfunction!(motion::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(rsmc::rsmc, m)?)?;
    m.add_function(wrap_pyfunction!(calc::encode, m)?)?;
    m.add_function(wrap_pyfunction!(calc::decode, m)?)?;
    m.add_function(wrap_pyfunction!(calc::add, m)?)?;
    m.add_function(wrap_pyfunction!(calc::sub, m)?)?;
    partition::register(m)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
