//! `arbor_rays`: Arbor's exact ray queries and renderer for Python, on NumPy arrays (PyO3 and the
//! `numpy` crate, built by maturin as an abi3 wheel). A thin room over the library: meshes come from
//! arrays (`arrays.rs`) or Arbor's own mesh readers, structures from arbor-accel's one factory and
//! parameter parsing, queries are the structures' batch queries (`queries.rs`, `crossings.rs`) on
//! arguments read by `args.rs`, and `render` is the CLI's path (`render.rs`). The Python package
//! (`python/arbor_rays`) adds the trimesh and Open3D adapters and the type stubs.
//!
//! Every query releases the GIL and runs on a rayon pool of the threads asked for; arrays are read in
//! place (any float or integer dtype, any order) and never written.

mod args;
mod arrays;
mod crossings;
mod errors;
mod mesh;
mod queries;
mod render;

use std::path::PathBuf;

use pyo3::prelude::*;

pub use mesh::Mesh;

/// load_mesh(path) -> Mesh
///
/// Reads a mesh file (.ply, .obj or .off) with Arbor's readers: OSError when it cannot be read,
/// ValueError with the located message (``file:line:col: ...``) when its content is bad.
#[pyfunction]
fn load_mesh(py: Python<'_>, path: PathBuf) -> PyResult<Mesh> {
    let mesh = py.detach(|| arbor::mesh_io::load_mesh(&path)).map_err(errors::to_py)?;
    Mesh::from_mesh(mesh)
}

/// accel_kinds() -> dict
///
/// Every structure ``Mesh.build`` takes, each with its parameters: ``{kind: [(key, range, default,
/// about), ...]}`` (keys as ``build`` takes them, ``_`` for ``-``).
#[pyfunction]
fn accel_kinds(py: Python<'_>) -> PyResult<Bound<'_, pyo3::types::PyDict>> {
    use arbor::accel::{AccelConfig, AccelKind};
    let d = pyo3::types::PyDict::new(py);
    for &k in AccelKind::ALL {
        let defaults = AccelConfig::from(k);
        let params: Vec<(String, String, String, String)> = k
            .params()
            .iter()
            .map(|p| {
                let default = defaults.get(p.key).map(|v| v.to_string()).unwrap_or_default();
                (p.key.replace('-', "_"), p.range.to_string(), default, p.about.to_string())
            })
            .collect();
        d.set_item(k.name(), params)?;
    }
    Ok(d)
}

/// The extension module, `arbor_rays._native`.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // As `arbor` does at start: the kernel would take a typo in the cap as no cap.
    arbor::accel::bvh::Isa::cap_from_env().map_err(pyo3::exceptions::PyValueError::new_err)?;
    m.add_class::<Mesh>()?;
    m.add_function(wrap_pyfunction!(load_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(accel_kinds, m)?)?;
    m.add_function(wrap_pyfunction!(render::render, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
