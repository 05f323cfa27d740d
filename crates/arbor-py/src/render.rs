//! `render(scene, camera=None, spp=None, ...)`: one camera of a scene file rendered as `arbor render`
//! renders it, through the same library calls (read the description, check it against the default
//! limits, build the scene, render the camera's film), returning the radiance and the 8-bit image
//! the CLI would write as arrays instead of files.

use std::path::PathBuf;

use arbor::accel::AccelConfig;
use arbor::render::{render as render_film, RenderOptions};
use arbor::scene::{check_limits, load_desc, Scene, SceneLimits};
use numpy::{IntoPyArray, PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyAny;

use crate::errors::to_py;
use crate::queries::in_pool;

/// render(scene, camera=None, spp=None, *, accel="bvh-sah", seed=0, threads=None) -> (radiance, image)
///
/// Renders one camera of a scene file (.xml or .json, as ``arbor render`` reads them): ``camera``
/// is a camera's id (None: the first camera), ``spp`` overrides its samples per pixel, ``seed``
/// picks the noise. Returns ``radiance``, (H, W, 3) float32, in the scene's own radiance units (what
/// ``arbor render -o image.exr`` writes), and ``image``, (H, W, 3) uint8, rows top first (what
/// ``arbor render -o image.png`` writes: tone-mapped when the camera names a tone map). A file that
/// cannot be read raises OSError; a bad scene, ValueError with the CLI's located message. The GIL is
/// released while the scene is built and rendered.
#[pyfunction]
#[pyo3(signature = (scene, camera=None, spp=None, *, accel="bvh-sah", seed=0, threads=None))]
pub fn render<'py>(
    py: Python<'py>,
    scene: PathBuf,
    camera: Option<&str>,
    spp: Option<u32>,
    accel: &str,
    seed: u64,
    threads: Option<usize>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let config: AccelConfig =
        accel.parse().map_err(|e: arbor::accel::ConfigError| to_py(arbor::Error::Invalid(e.to_string())))?;
    let camera = camera.map(str::to_string);
    let (w, h, radiance, rgb) = py
        .detach(|| in_pool(threads, || render_camera(&scene, camera.as_deref(), spp, &config, seed)))
        .map_err(to_py)?;
    let shape = [h as usize, w as usize, 3];
    let radiance = PyArray1::from_vec(py, radiance).reshape(shape)?.into_any();
    let rgb = rgb.into_pyarray(py).reshape(shape)?.into_any();
    Ok((radiance, rgb))
}

type Rendered = (u32, u32, Vec<f32>, Vec<u8>);

fn render_camera(
    path: &std::path::Path,
    camera: Option<&str>,
    spp: Option<u32>,
    config: &AccelConfig,
    seed: u64,
) -> arbor::Result<Rendered> {
    let desc = load_desc(path)?;
    let limits = SceneLimits::default();
    check_limits(&desc, spp, &limits)?;
    let index = match camera {
        None if desc.cameras.is_empty() => {
            return Err(arbor::Error::Invalid(format!("{}: the scene has no camera", path.display())));
        }
        None => 0,
        Some(id) => desc.cameras.iter().position(|c| c.id == id).ok_or_else(|| {
            let ids: Vec<&str> = desc.cameras.iter().map(|c| c.id.as_str()).collect();
            arbor::Error::Invalid(format!("{}: no camera with id '{id}' (cameras: {})", path.display(), ids.join(", ")))
        })?,
    };
    if spp == Some(0) {
        return Err(arbor::Error::Invalid("spp must be at least 1".into()));
    }
    let scene = Scene::build_within(desc, config, None, &limits.images)?;
    let opts = RenderOptions { spp, seed, ..RenderOptions::default() };
    let (film, _) = render_film(&scene, index, &opts, &|_, _| {})?;
    let unit = scene.radiance_scale;
    let radiance = film.pixels.iter().flat_map(|c| (*c / unit).to_array()).collect();
    let rgb = match scene.cameras[index].tonemap {
        Some(tm) => tm.apply(&film).to_rgb8(),
        None => film.to_rgb8(),
    };
    Ok((film.width, film.height, radiance, rgb))
}
