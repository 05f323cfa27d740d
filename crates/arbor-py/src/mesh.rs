//! `Mesh`: a triangle mesh from NumPy arrays, the structure built over it, and its batch queries.
//! Arguments are read here (`arrays.rs`), the work is done with the GIL released on the pool of the
//! threads asked for (`queries.rs`), and the answers go back as NumPy arrays that own the vectors
//! they were computed in (no copy).

use std::sync::{Arc, OnceLock, RwLock};

use arbor::accel::{AccelConfig, Structure};
use arbor::geometry::TriangleMesh;
use numpy::{IntoPyArray, PyArray1, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyAny, PyDict};

use crate::args::{check_threads, field_names, PointArgs, RayArgs};
use crate::arrays::{floats_n3, ints_m3, positions, triangles};
use crate::crossings::Collector;
use crate::queries::{self, in_pool};

/// A structure over the mesh, and the collecting one built from the same configuration when first
/// needed (`crossings.rs`).
struct Built {
    config: AccelConfig,
    main: Structure,
    collect: OnceLock<Structure<Collector>>,
}

/// A triangle mesh and an acceleration structure over it.
///
/// ``Mesh(vertices, faces)``: ``vertices`` (N, 3) float32 or float64 (other numbers are converted),
/// ``faces`` (M, 3) of any integer dtype, 0-based, counter-clockwise around the outward normal; C or
/// Fortran order; read, never written or kept (the mesh holds its own float32 copy). NaN or infinite
/// coordinates, indices out of range and empty arrays raise ValueError. Queries build the default
/// structure (``bvh-sah``) on first use; ``build`` picks another.
#[pyclass(frozen, module = "arbor_rays", name = "Mesh")]
pub struct Mesh {
    mesh: Arc<TriangleMesh>,
    built: RwLock<Option<Arc<Built>>>,
}

fn vec3s<'py, T: numpy::Element>(py: Python<'py>, v: Vec<T>) -> PyResult<Bound<'py, PyAny>> {
    let n = v.len() / 3;
    Ok(PyArray1::from_vec(py, v).reshape([n, 3])?.into_any())
}

impl Mesh {
    /// A mesh of at least one triangle, not yet built.
    pub fn from_mesh(mesh: TriangleMesh) -> PyResult<Mesh> {
        if mesh.is_empty() {
            return Err(PyValueError::new_err("faces is empty: a mesh needs at least one triangle"));
        }
        Ok(Mesh { mesh: Arc::new(mesh), built: RwLock::new(None) })
    }

    /// The structure, built with the default configuration when none was.
    fn built(&self, py: Python<'_>, threads: Option<usize>) -> PyResult<Arc<Built>> {
        if let Some(b) = self.built.read().unwrap_or_else(|e| e.into_inner()).as_ref() {
            return Ok(Arc::clone(b));
        }
        self.rebuild(py, AccelConfig::default(), threads)
    }

    fn rebuild(&self, py: Python<'_>, config: AccelConfig, threads: Option<usize>) -> PyResult<Arc<Built>> {
        let mesh = Arc::clone(&self.mesh);
        let main = py
            .detach(|| in_pool(threads, || Structure::build_shared(&config, mesh)))
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        let built = Arc::new(Built { config, main, collect: OnceLock::new() });
        *self.built.write().unwrap_or_else(|e| e.into_inner()) = Some(Arc::clone(&built));
        Ok(built)
    }

    /// The collecting structure (built on first use, with the GIL released).
    fn collector(&self, py: Python<'_>, threads: Option<usize>) -> PyResult<Arc<Built>> {
        let b = self.built(py, threads)?;
        if b.collect.get().is_none() {
            let collector = Collector { mesh: Arc::clone(&self.mesh) };
            let s = py
                .detach(|| in_pool(threads, || Structure::build(&b.config, collector)))
                .map_err(|e| PyValueError::new_err(e.to_string()))?;
            let _ = b.collect.set(s);
        }
        Ok(b)
    }
}

impl Mesh {
    /// `query` on the closest-hit structure, with the GIL released, on `threads` threads.
    fn on_main<R: Send>(
        &self,
        py: Python<'_>,
        threads: Option<usize>,
        query: impl FnOnce(&Structure) -> R + Send,
    ) -> PyResult<R> {
        let b = self.built(py, threads)?;
        Ok(py.detach(|| in_pool(threads, || query(&b.main))))
    }

    /// `query` on the collecting structure (`crossings.rs`), with the GIL released.
    fn on_collector<R: Send>(
        &self,
        py: Python<'_>,
        threads: Option<usize>,
        query: impl FnOnce(&Structure<Collector>) -> R + Send,
    ) -> PyResult<R> {
        let b = self.collector(py, threads)?;
        let Some(s) = b.collect.get() else { unreachable!("collector() builds it") };
        Ok(py.detach(|| in_pool(threads, || query(s))))
    }
}

impl Mesh {
    /// The closest points of `points` within `max_distance`, the arguments checked first.
    fn closest_points(
        &self,
        py: Python<'_>,
        points: &Bound<'_, PyAny>,
        max_distance: f64,
        threads: Option<usize>,
    ) -> PyResult<queries::ClosestPoints> {
        let threads = check_threads(threads)?;
        let args = PointArgs::read(points, max_distance)?;
        let (rows, max_distance) = (args.rows(), args.max_distance);
        self.on_main(py, threads, |s| queries::closest_points(s, rows, max_distance))?
            .map_err(|e| PyValueError::new_err(e.to_string()))
    }
}

/// A dict of the given items.
fn dict<'py>(py: Python<'py>, items: Vec<(&str, Bound<'py, PyAny>)>) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (k, v) in items {
        d.set_item(k, v)?;
    }
    Ok(d)
}

#[pymethods]
impl Mesh {
    #[new]
    fn new(vertices: &Bound<'_, PyAny>, faces: &Bound<'_, PyAny>) -> PyResult<Self> {
        let v = floats_n3("vertices", vertices)?;
        let f = ints_m3("faces", faces)?;
        let positions = positions(&v)?;
        let tris = triangles(&f, positions.len())?;
        let mesh = TriangleMesh::from_arrays(positions, tris).map_err(|e| PyValueError::new_err(e.to_string()))?;
        Mesh::from_mesh(mesh)
    }

    /// build(kind="bvh-sah", *, threads=None, **params) -> Mesh
    ///
    /// Builds the acceleration structure ``kind`` (brute, octree, kdtree, bvh-median, bvh-sah,
    /// bvh-bottom-up) with build parameters given as keywords: the keys of ``arbor info --accels``
    /// with ``-`` written ``_`` (``leaf=4``, ``traversal_cost=1.5``, ``method="ploc"``). An unknown
    /// kind or key, or a value outside its range, raises ValueError with the CLI's message. Returns
    /// the mesh itself.
    #[pyo3(signature = (kind="bvh-sah", *, threads=None, **params))]
    fn build<'py>(
        slf: &Bound<'py, Self>,
        kind: &str,
        threads: Option<usize>,
        params: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, Self>> {
        let threads = check_threads(threads)?;
        let mut config: AccelConfig =
            kind.parse().map_err(|e: arbor::accel::ConfigError| PyValueError::new_err(e.to_string()))?;
        for (k, v) in params.into_iter().flat_map(|d| d.iter()) {
            let key = k.extract::<String>()?.replace('_', "-");
            let value = v.str()?.to_string();
            config.set(&key, &value).map_err(|e| PyValueError::new_err(e.to_string()))?;
        }
        slf.get().rebuild(slf.py(), config, threads)?;
        Ok(slf.clone())
    }

    /// stats() -> dict
    ///
    /// The structure's statistics, as ``arbor info`` prints them: kind, config, primitives, nodes,
    /// leaves, max_depth, mean_depth, refs_per_prim, mean_leaf_prims, sah_cost, bytes and
    /// build_seconds (wall time).
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let b = self.built(py, None)?;
        let s = b.main.stats();
        let d = PyDict::new(py);
        d.set_item("kind", s.kind)?;
        d.set_item("config", b.config.to_string())?;
        d.set_item("primitives", s.primitives)?;
        d.set_item("nodes", s.nodes)?;
        d.set_item("leaves", s.leaves)?;
        d.set_item("max_depth", s.max_depth)?;
        d.set_item("mean_depth", s.mean_depth)?;
        d.set_item("refs_per_prim", s.refs_per_prim)?;
        d.set_item("mean_leaf_prims", s.mean_leaf_prims)?;
        d.set_item("sah_cost", s.sah_cost)?;
        d.set_item("bytes", s.bytes)?;
        d.set_item("build_seconds", s.build_time.as_secs_f64())?;
        Ok(d)
    }

    /// The number of triangles.
    fn __len__(&self) -> usize {
        self.mesh.len()
    }

    /// The vertices, (N, 3) float32 (a copy).
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        vec3s(py, self.mesh.positions.iter().flat_map(|p| p.to_array()).collect())
    }

    /// The faces, (M, 3) int64 (a copy).
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let v: Vec<i64> = self.mesh.indices.iter().flatten().map(|&i| i as i64).collect();
        let m = self.mesh.len();
        Ok(PyArray1::from_vec(py, v).reshape([m, 3])?.into_any())
    }

    /// intersect(origins, directions, t_min=0.0, t_max=inf, *, threads=None, fields=None) -> dict
    ///
    /// The closest hit of each ray ``origins[i] + t * directions[i]``, ``t`` in ``(t_min, t_max)``:
    /// origins and directions (N, 3) float32/float64, directions of any length (``t`` is in units of
    /// it); t_min and t_max numbers or (N,) arrays. Returns a dict of arrays: ``t`` (N,) float32
    /// (inf on a miss), ``triangle`` (N,) int64 (-1), ``u``, ``v`` (N,) float32 barycentric weights of
    /// the triangle's vertices 1 and 2 (0), ``normal`` (N, 3) float32 unit geometric normal on the
    /// counter-clockwise side (0), ``point`` (N, 3) float32 the hit point on the triangle (0). Ties
    /// go to the lowest triangle index. ``fields``, a list of those names, limits the dict to them
    /// and the work to what they need (None: all; ``normal`` and ``point`` cost a read of the
    /// triangle's corners per hit). Runs on ``threads`` threads (None: every core) with the GIL
    /// released.
    #[pyo3(signature = (origins, directions, t_min=None, t_max=None, *, threads=None, fields=None))]
    #[allow(clippy::too_many_arguments)]
    fn intersect<'py>(
        &self,
        py: Python<'py>,
        origins: &Bound<'py, PyAny>,
        directions: &Bound<'py, PyAny>,
        t_min: Option<&Bound<'py, PyAny>>,
        t_max: Option<&Bound<'py, PyAny>>,
        threads: Option<usize>,
        fields: Option<Vec<String>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let threads = check_threads(threads)?;
        let names = field_names(fields)?;
        let asked = |n: &str| names.contains(&n);
        let wanted = queries::Fields {
            t: asked("t"),
            triangle: asked("triangle"),
            uv: asked("u") || asked("v"),
            normal: asked("normal"),
            point: asked("point"),
        };
        let args = RayArgs::read(origins, directions, t_min, t_max)?;
        let rays = args.set();
        let c = self.on_main(py, threads, |s| queries::closest(s, rays, wanted))?;
        let items = vec![
            ("t", c.t.into_pyarray(py).into_any()),
            ("triangle", c.triangle.into_pyarray(py).into_any()),
            ("u", c.u.into_pyarray(py).into_any()),
            ("v", c.v.into_pyarray(py).into_any()),
            ("normal", vec3s(py, c.normal)?),
            ("point", vec3s(py, c.point)?),
        ];
        dict(py, items.into_iter().filter(|(k, _)| asked(k)).collect())
    }

    /// occluded(origins, directions, t_min=0.0, t_max=inf, *, threads=None) -> ndarray
    ///
    /// Whether each ray hits anything in ``(t_min, t_max)``: (N,) bool. An any-hit query (it stops
    /// at the first triangle found), not a closest hit. Arguments as for ``intersect``: origins and
    /// directions (N, 3) float32/float64, ``t`` in units of each direction's length.
    #[pyo3(signature = (origins, directions, t_min=None, t_max=None, *, threads=None))]
    fn occluded<'py>(
        &self,
        py: Python<'py>,
        origins: &Bound<'py, PyAny>,
        directions: &Bound<'py, PyAny>,
        t_min: Option<&Bound<'py, PyAny>>,
        t_max: Option<&Bound<'py, PyAny>>,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let threads = check_threads(threads)?;
        let args = RayArgs::read(origins, directions, t_min, t_max)?;
        let rays = args.set();
        Ok(self.on_main(py, threads, |s| queries::occluded(s, rays))?.into_pyarray(py))
    }

    /// intersect_all(origins, directions, t_min=0.0, t_max=inf, *, max_hits=None, threads=None) -> dict
    ///
    /// Every surface crossing of each ray (origins and directions (N, 3), t_min and t_max numbers or
    /// (N,) arrays, as for ``intersect``) in ``(t_min, t_max)``, in order of ``t``, at most
    /// ``max_hits`` per ray (the closest; None: all). A ray through an edge or a vertex shared by
    /// several triangles crosses the surface once there and is reported once (README: the tie
    /// rule). Returns a dict of flat arrays, one entry per crossing, in ray order: ``ray`` and
    /// ``triangle`` (K,) int64, ``t``, ``u``, ``v`` (K,) float32, ``point`` (K, 3) float32.
    #[pyo3(signature = (origins, directions, t_min=None, t_max=None, *, max_hits=None, threads=None))]
    #[allow(clippy::too_many_arguments)]
    fn intersect_all<'py>(
        &self,
        py: Python<'py>,
        origins: &Bound<'py, PyAny>,
        directions: &Bound<'py, PyAny>,
        t_min: Option<&Bound<'py, PyAny>>,
        t_max: Option<&Bound<'py, PyAny>>,
        max_hits: Option<usize>,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let threads = check_threads(threads)?;
        let args = RayArgs::read(origins, directions, t_min, t_max)?;
        let rays = args.set();
        let cap = max_hits.unwrap_or(usize::MAX);
        let a = self.on_collector(py, threads, |s| queries::all_hits(s, rays, cap))?;
        dict(
            py,
            vec![
                ("ray", a.ray.into_pyarray(py).into_any()),
                ("triangle", a.triangle.into_pyarray(py).into_any()),
                ("t", a.t.into_pyarray(py).into_any()),
                ("u", a.u.into_pyarray(py).into_any()),
                ("v", a.v.into_pyarray(py).into_any()),
                ("point", vec3s(py, a.point)?),
            ],
        )
    }

    /// count_crossings(origins, directions, t_min=0.0, t_max=inf, *, threads=None) -> ndarray
    ///
    /// The number of surface crossings of each ray (origins and directions (N, 3)) in
    /// ``(t_min, t_max)``, (N,) int64: the rows ``intersect_all`` would return for it, without a cap.
    #[pyo3(signature = (origins, directions, t_min=None, t_max=None, *, threads=None))]
    fn count_crossings<'py>(
        &self,
        py: Python<'py>,
        origins: &Bound<'py, PyAny>,
        directions: &Bound<'py, PyAny>,
        t_min: Option<&Bound<'py, PyAny>>,
        t_max: Option<&Bound<'py, PyAny>>,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let threads = check_threads(threads)?;
        let args = RayArgs::read(origins, directions, t_min, t_max)?;
        let rays = args.set();
        Ok(self.on_collector(py, threads, |s| queries::count_crossings(s, rays))?.into_pyarray(py))
    }

    /// contains(points, *, threads=None) -> ndarray
    ///
    /// Whether each point, (N, 3) float32/float64, lies inside the closed mesh: (N,) bool, by the
    /// parity of the crossings of a ray from it, along a direction whose ray meets no edge or vertex
    /// (README: the tie rule). Points on the surface may go either way.
    #[pyo3(signature = (points, *, threads=None))]
    fn contains<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let threads = check_threads(threads)?;
        let p = floats_n3("points", points)?;
        let rows = p.rows();
        Ok(self.on_collector(py, threads, |s| queries::contains_points(s, rows))?.into_pyarray(py))
    }

    /// closest_point(points, *, max_distance=inf, threads=None) -> dict
    ///
    /// The point of the mesh nearest to each point, (N, 3) float32/float64 (read in float64 as
    /// given; NaN, infinite or beyond float32's range raise ValueError). Returns a dict of arrays:
    /// ``point`` (N, 3) float64 on the mesh, ``distance`` (N,) float64 (unsigned, in the mesh's
    /// units), ``triangle`` (N,) int64, ``u``, ``v`` (N,) float64 barycentric weights of the
    /// triangle's vertices 1 and 2. Only triangles within ``max_distance`` (inclusive) count: a point
    /// with none has distance inf, triangle -1 and NaN point, u, v. Exactly what testing every
    /// triangle gives, whatever the structure: the smallest distance, ties (a point nearest to a
    /// shared vertex or edge) to the lowest triangle index. Runs on ``threads`` threads (None: every
    /// core) with the GIL released.
    #[pyo3(signature = (points, *, max_distance=f64::INFINITY, threads=None))]
    fn closest_point<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        max_distance: f64,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let c = self.closest_points(py, points, max_distance, threads)?;
        dict(
            py,
            vec![
                ("point", vec3s(py, c.point)?),
                ("distance", c.distance.into_pyarray(py).into_any()),
                ("triangle", c.triangle.into_pyarray(py).into_any()),
                ("u", c.u.into_pyarray(py).into_any()),
                ("v", c.v.into_pyarray(py).into_any()),
            ],
        )
    }

    /// distance(points, *, max_distance=inf, threads=None) -> ndarray
    ///
    /// The unsigned distance from each point, (N, 3) float32/float64, to the mesh: (N,) float64, the
    /// ``distance`` of ``closest_point`` (inf where no triangle is within ``max_distance``).
    #[pyo3(signature = (points, *, max_distance=f64::INFINITY, threads=None))]
    fn distance<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        max_distance: f64,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(self.closest_points(py, points, max_distance, threads)?.distance.into_pyarray(py))
    }

    fn __repr__(&self) -> String {
        let kind = self.built.read().unwrap_or_else(|e| e.into_inner()).as_ref().map(|b| b.config.to_string());
        format!(
            "Mesh({} vertices, {} triangles, {})",
            self.mesh.positions.len(),
            self.mesh.len(),
            kind.unwrap_or_else(|| "not built".into())
        )
    }
}
