//! NumPy arrays in: views of any float or integer dtype, C or Fortran order, read in place and never
//! written. Every refusal is a `ValueError` naming the argument and, for a bad value, where it is
//! (`vertices[2, 1]`), in the words of the mesh readers' messages (`non-finite coordinate`,
//! `vertex index -1 out of range`).
//!
//! Floats are read as `f32`, the precision of every structure: a `float64` value is rounded once,
//! and one too large for `f32` is refused as non-finite (the OBJ reader refuses `1e99` so too).
//! Anything that is not an array (a list, a tuple) goes through `numpy.asarray` first.

use arbor::math::{DVec3, Vec3};
use numpy::ndarray::{ArrayView1, ArrayView2};
use numpy::{PyArrayDescrMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyAny;

/// A readonly borrow of a float array of shape `(N, 3)` (or `(N,)`), in its own dtype.
pub enum Floats<'py, const D: usize> {
    /// `float32` (and `float16`, widened by NumPy first).
    F32(FloatBorrow<'py, f32, D>),
    /// `float64`.
    F64(FloatBorrow<'py, f64, D>),
}

/// The borrow of one dtype, by rank.
pub enum FloatBorrow<'py, T: numpy::Element, const D: usize> {
    /// A vector.
    One(PyReadonlyArray1<'py, T>),
    /// A matrix.
    Two(PyReadonlyArray2<'py, T>),
}

/// A view of rows of three coordinates, in the array's dtype; `Send`, so queries read it with the GIL
/// released.
#[derive(Clone, Copy)]
pub enum Rows<'a> {
    /// `float32` rows.
    F32(ArrayView2<'a, f32>),
    /// `float64` rows, rounded to `f32` as they are read.
    F64(ArrayView2<'a, f64>),
}

impl Rows<'_> {
    /// The number of rows.
    pub fn len(&self) -> usize {
        match self {
            Rows::F32(a) => a.nrows(),
            Rows::F64(a) => a.nrows(),
        }
    }
    /// Row `i` as a vector of `f64`, exactly as given (a `float32` row widened).
    #[inline]
    pub fn get_f64(&self, i: usize) -> DVec3 {
        match self {
            Rows::F32(a) => DVec3::new(a[[i, 0]].into(), a[[i, 1]].into(), a[[i, 2]].into()),
            Rows::F64(a) => DVec3::new(a[[i, 0]], a[[i, 1]], a[[i, 2]]),
        }
    }
    /// Row `i` as a vector of `f32`.
    #[inline]
    pub fn get(&self, i: usize) -> Vec3 {
        match self {
            Rows::F32(a) => Vec3::new(a[[i, 0]], a[[i, 1]], a[[i, 2]]),
            Rows::F64(a) => Vec3::new(a[[i, 0]] as f32, a[[i, 1]] as f32, a[[i, 2]] as f32),
        }
    }
    /// Rows `base..base + out.len()` into `out`, in one pass (a C-ordered array as a plain slice).
    #[inline]
    pub fn read(&self, base: usize, out: &mut [Vec3]) {
        fn rows<T: Copy>(a: &ArrayView2<'_, T>, base: usize, out: &mut [Vec3], f: impl Fn(T) -> f32) {
            match a.as_slice() {
                Some(s) => {
                    let s = &s[3 * base..3 * (base + out.len())];
                    for (o, r) in out.iter_mut().zip(s.chunks_exact(3)) {
                        *o = Vec3::new(f(r[0]), f(r[1]), f(r[2]));
                    }
                }
                None => {
                    for (i, o) in (base..).zip(out.iter_mut()) {
                        *o = Vec3::new(f(a[[i, 0]]), f(a[[i, 1]]), f(a[[i, 2]]));
                    }
                }
            }
        }
        match self {
            Rows::F32(a) => rows(a, base, out, |x| x),
            Rows::F64(a) => rows(a, base, out, |x| x as f32),
        }
    }
}

/// A per-ray parameter: one value for every ray, or one each.
#[derive(Clone, Copy)]
pub enum PerRay<'a> {
    /// The same value for every ray.
    Scalar(f32),
    /// `float32` values, one per ray.
    F32(ArrayView1<'a, f32>),
    /// `float64` values, one per ray, rounded to `f32`.
    F64(ArrayView1<'a, f64>),
}

impl PerRay<'_> {
    /// The value for ray `i`.
    #[inline]
    pub fn get(&self, i: usize) -> f32 {
        match self {
            PerRay::Scalar(x) => *x,
            PerRay::F32(a) => a[i],
            PerRay::F64(a) => a[i] as f32,
        }
    }
    /// The values for rays `base..base + out.len()`, into `out`.
    #[inline]
    pub fn read(&self, base: usize, out: &mut [f32]) {
        let range = base..base + out.len();
        match self {
            PerRay::Scalar(x) => out.fill(*x),
            PerRay::F32(a) => out.iter_mut().zip(range).for_each(|(o, i)| *o = a[i]),
            PerRay::F64(a) => out.iter_mut().zip(range).for_each(|(o, i)| *o = a[i] as f32),
        }
    }
}

impl<'py> Floats<'py, 2> {
    /// The rows, for reading.
    pub fn rows(&self) -> Rows<'_> {
        match self {
            Floats::F32(FloatBorrow::Two(a)) => Rows::F32(a.as_array()),
            Floats::F64(FloatBorrow::Two(a)) => Rows::F64(a.as_array()),
            _ => unreachable!("a rank-2 borrow holds a matrix"),
        }
    }
}

impl<'py> Floats<'py, 1> {
    /// The values, for reading.
    pub fn values(&self) -> PerRay<'_> {
        match self {
            Floats::F32(FloatBorrow::One(a)) => PerRay::F32(a.as_array()),
            Floats::F64(FloatBorrow::One(a)) => PerRay::F64(a.as_array()),
            _ => unreachable!("a rank-1 borrow holds a vector"),
        }
    }
}

/// `obj` as an array (through `numpy.asarray` when it is not one).
fn untyped<'py>(obj: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyUntypedArray>> {
    if let Ok(arr) = obj.cast::<PyUntypedArray>() {
        return Ok(arr.clone());
    }
    let arr = obj.py().import("numpy")?.call_method1("asarray", (obj,))?;
    Ok(arr.cast_into::<PyUntypedArray>()?)
}

/// The dtype's kind letter (`f`, `i`, `u`, `b`, ...) and its size in bytes.
fn kind_of(arr: &Bound<'_, PyUntypedArray>) -> (char, usize) {
    let d = arr.dtype();
    (d.kind() as char, d.itemsize())
}

/// `(3,)` or `(4, 3)`, as NumPy prints shapes.
pub fn shape_text(shape: &[usize]) -> String {
    let parts: Vec<String> = shape.iter().map(|n| n.to_string()).collect();
    if parts.len() == 1 {
        format!("({},)", parts[0])
    } else {
        format!("({})", parts.join(", "))
    }
}

fn dtype_name(arr: &Bound<'_, PyUntypedArray>) -> String {
    arr.dtype().str().map(|s| s.to_string()).unwrap_or_else(|_| "?".to_string())
}

/// A float array of shape `(N, 3)` named `name`, borrowed in `float32` or `float64` (other float
/// sizes and integers are converted to `float64` by NumPy first, into a copy).
pub fn floats_n3<'py>(name: &str, obj: &Bound<'py, PyAny>) -> PyResult<Floats<'py, 2>> {
    let arr = untyped(obj)?;
    let shape = arr.shape().to_vec();
    if shape.len() != 2 || shape[1] != 3 {
        return Err(PyValueError::new_err(format!("{name} must have shape (N, 3), got {}", shape_text(&shape))));
    }
    Ok(match kind_of(&arr) {
        ('f', 4) => Floats::F32(FloatBorrow::Two(arr.extract()?)),
        ('f', 8) => Floats::F64(FloatBorrow::Two(arr.extract()?)),
        ('f' | 'i' | 'u', _) => Floats::F64(FloatBorrow::Two(arr.call_method1("astype", ("float64",))?.extract()?)),
        _ => return Err(PyValueError::new_err(format!("{name} must hold numbers, got dtype {}", dtype_name(&arr)))),
    })
}

/// A per-ray float named `name`: `None` for a Python number (read by [`scalar`]), else a borrowed
/// array of shape `(n,)`.
pub fn per_ray<'py>(name: &str, obj: &Bound<'py, PyAny>, n: usize) -> PyResult<Option<Floats<'py, 1>>> {
    if obj.extract::<f64>().is_ok() && obj.cast::<PyUntypedArray>().is_err() {
        return Ok(None);
    }
    let arr = untyped(obj)?;
    let shape = arr.shape().to_vec();
    if shape.is_empty() {
        return Ok(None);
    }
    if shape != [n] {
        return Err(PyValueError::new_err(format!(
            "{name} must be a number or have shape ({n},), one per ray, got {}",
            shape_text(&shape)
        )));
    }
    Ok(Some(match kind_of(&arr) {
        ('f', 4) => Floats::F32(FloatBorrow::One(arr.extract()?)),
        ('f', 8) => Floats::F64(FloatBorrow::One(arr.extract()?)),
        ('f' | 'i' | 'u', _) => Floats::F64(FloatBorrow::One(arr.call_method1("astype", ("float64",))?.extract()?)),
        _ => return Err(PyValueError::new_err(format!("{name} must hold numbers, got dtype {}", dtype_name(&arr)))),
    }))
}

/// A per-ray float given as a number (or a 0-d array), as `f32` (NaN stays NaN: every ray misses).
pub fn scalar(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<f32> {
    let x: f64 = obj
        .extract()
        .map_err(|_| PyValueError::new_err(format!("{name} must be a number or an array of one per ray")))?;
    Ok(x as f32)
}

/// Integer rows of shape `(M, 3)` named `name` (any integer dtype), as `i64` or `u64` views (a copy
/// when the dtype is narrower).
pub enum Ints<'py> {
    /// Signed indices.
    Signed(PyReadonlyArray2<'py, i64>),
    /// Unsigned indices.
    Unsigned(PyReadonlyArray2<'py, u64>),
}

/// The faces array: shape `(M, 3)`, an integer dtype.
pub fn ints_m3<'py>(name: &str, obj: &Bound<'py, PyAny>) -> PyResult<Ints<'py>> {
    let arr = untyped(obj)?;
    let shape = arr.shape().to_vec();
    if shape.len() != 2 || shape[1] != 3 {
        return Err(PyValueError::new_err(format!("{name} must have shape (M, 3), got {}", shape_text(&shape))));
    }
    Ok(match kind_of(&arr) {
        ('i', 8) => Ints::Signed(arr.extract()?),
        ('u', 8) => Ints::Unsigned(arr.extract()?),
        ('i', _) => Ints::Signed(arr.call_method1("astype", ("int64",))?.extract()?),
        ('u', _) => Ints::Unsigned(arr.call_method1("astype", ("uint64",))?.extract()?),
        _ => {
            let msg = format!("{name} must hold integer vertex indices, got dtype {}", dtype_name(&arr));
            return Err(PyValueError::new_err(msg));
        }
    })
}

/// The triangles of `faces` as `u32` indices into `vertices` rows; the first index out of range is
/// refused as the PLY reader words it (`faces[4, 1]: vertex index 8 out of range (there are 8
/// vertices)`).
pub fn triangles(faces: &Ints<'_>, vertices: usize) -> PyResult<Vec<[u32; 3]>> {
    let bad = |i: usize, k: usize, idx: i128| {
        PyValueError::new_err(format!(
            "faces[{i}, {k}]: vertex index {idx} out of range (there are {vertices} vertices)"
        ))
    };
    let read = |i: usize, k: usize, idx: i128| -> PyResult<u32> {
        if idx < 0 || idx >= vertices as i128 {
            Err(bad(i, k, idx))
        } else {
            Ok(idx as u32)
        }
    };
    match faces {
        Ints::Signed(a) => rows_of(a.as_array(), read),
        Ints::Unsigned(a) => rows_of(a.as_array(), read),
    }
}

/// The rows of `a`, each index read by `read(row, column, value)`.
fn rows_of<T: Copy + Into<i128>>(
    a: ArrayView2<'_, T>,
    read: impl Fn(usize, usize, i128) -> PyResult<u32>,
) -> PyResult<Vec<[u32; 3]>> {
    let mut out = Vec::with_capacity(a.nrows());
    for i in 0..a.nrows() {
        out.push([read(i, 0, a[[i, 0]].into())?, read(i, 1, a[[i, 1]].into())?, read(i, 2, a[[i, 2]].into())?]);
    }
    Ok(out)
}

/// The vertex positions as `f32`; the first non-finite coordinate (NaN, infinite, or a `float64`
/// beyond `f32`'s range) is refused as the mesh readers word it (`vertices[2, 1]: non-finite
/// coordinate `nan``).
pub fn positions(vertices: &Floats<'_, 2>) -> PyResult<Vec<[f32; 3]>> {
    let rows = vertices.rows();
    finite_rows("vertices", &rows)?;
    Ok((0..rows.len()).map(|i| rows.get(i).to_array()).collect())
}

/// Refuses the first coordinate of `rows` (the array `name`) that is not finite in `f32` (NaN,
/// infinite, or a `float64` beyond `f32`'s range), in the mesh readers' words (`points[2, 1]:
/// non-finite coordinate `nan``).
pub fn finite_rows(name: &str, rows: &Rows<'_>) -> PyResult<()> {
    for i in 0..rows.len() {
        let p = rows.get(i);
        if let Some(k) = (0..3).find(|&k| !p[k].is_finite()) {
            let shown = match rows {
                Rows::F32(a) => format!("{:?}", a[[i, k]]),
                Rows::F64(a) => format!("{:?}", a[[i, k]]),
            };
            return Err(PyValueError::new_err(format!("{name}[{i}, {k}]: non-finite coordinate `{shown}`")));
        }
    }
    Ok(())
}
