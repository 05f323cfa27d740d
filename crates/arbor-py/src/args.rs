//! The arguments of queries, read and checked once per query from what Python passed (`arrays.rs`):
//! rays (origins and directions `(N, 3)`, `t_min` and `t_max` as numbers or `(N,)` arrays), points and
//! their distance bound, thread counts.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyAny;

use crate::arrays::{finite_rows, floats_n3, per_ray, scalar, Floats, PerRay, Rows};
use crate::queries::RaySet;

/// The arguments that describe rays, borrowed for one query.
pub struct RayArgs<'py> {
    origins: Floats<'py, 2>,
    dirs: Floats<'py, 2>,
    t_min: (f32, Option<Floats<'py, 1>>),
    t_max: (f32, Option<Floats<'py, 1>>),
}

impl<'py> RayArgs<'py> {
    pub fn read(
        origins: &Bound<'py, PyAny>,
        directions: &Bound<'py, PyAny>,
        t_min: Option<&Bound<'py, PyAny>>,
        t_max: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Self> {
        let origins = floats_n3("origins", origins)?;
        let dirs = floats_n3("directions", directions)?;
        let n = origins.rows().len();
        if dirs.rows().len() != n {
            return Err(PyValueError::new_err(format!(
                "origins has {n} rows but directions has {}: one of each per ray",
                dirs.rows().len()
            )));
        }
        let interval =
            |name: &str, x: Option<&Bound<'py, PyAny>>, default: f32| -> PyResult<(f32, Option<Floats<'py, 1>>)> {
                match x {
                    None => Ok((default, None)),
                    Some(x) if x.is_none() => Ok((default, None)),
                    Some(x) => match per_ray(name, x, n)? {
                        None => Ok((scalar(name, x)?, None)),
                        Some(a) => Ok((default, Some(a))),
                    },
                }
            };
        let t_min = interval("t_min", t_min, 0.0)?;
        let t_max = interval("t_max", t_max, f32::INFINITY)?;
        Ok(RayArgs { origins, dirs, t_min, t_max })
    }

    pub fn set(&self) -> RaySet<'_> {
        RaySet {
            origins: self.origins.rows(),
            dirs: self.dirs.rows(),
            t_min: per_ray_values(&self.t_min),
            t_max: per_ray_values(&self.t_max),
        }
    }
}

fn per_ray_values<'a>((x, a): &'a (f32, Option<Floats<'_, 1>>)) -> PerRay<'a> {
    a.as_ref().map_or(PerRay::Scalar(*x), |a| a.values())
}

/// Points `(N, 3)` with finite coordinates and a distance bound, borrowed for one closest-point query.
pub struct PointArgs<'py> {
    points: Floats<'py, 2>,
    /// At least 0, maybe infinite.
    pub max_distance: f64,
}

impl<'py> PointArgs<'py> {
    pub fn read(points: &Bound<'py, PyAny>, max_distance: f64) -> PyResult<Self> {
        if max_distance.is_nan() || max_distance < 0.0 {
            let msg = format!("max_distance must be a number >= 0 (inf: no bound), got {max_distance:?}");
            return Err(PyValueError::new_err(msg));
        }
        let points = floats_n3("points", points)?;
        finite_rows("points", &points.rows())?;
        Ok(PointArgs { points, max_distance })
    }

    pub fn rows(&self) -> Rows<'_> {
        self.points.rows()
    }
}

/// `threads` as asked: at least 1 and at most 1024, `None` for every core.
pub fn check_threads(threads: Option<usize>) -> PyResult<Option<usize>> {
    match threads {
        Some(0) => Err(PyValueError::new_err("threads must be at least 1 (None uses every core)")),
        Some(n) if n > 1024 => Err(PyValueError::new_err(format!("threads={n} is more than 1024"))),
        t => Ok(t),
    }
}

/// The outputs of `intersect`, in the order its dict lists them.
const FIELDS: [&str; 6] = ["t", "triangle", "u", "v", "normal", "point"];

/// The fields asked for (every one for `None`), in [`FIELDS`]' order; an unknown name is refused.
pub fn field_names(fields: Option<Vec<String>>) -> PyResult<Vec<&'static str>> {
    let Some(fields) = fields else { return Ok(FIELDS.to_vec()) };
    if let Some(bad) = fields.iter().find(|f| !FIELDS.contains(&f.as_str())) {
        return Err(PyValueError::new_err(format!(
            "fields: unknown field `{bad}` (the fields are t, triangle, u, v, normal, point)"
        )));
    }
    Ok(FIELDS.into_iter().filter(|n| fields.iter().any(|f| f == n)).collect())
}
