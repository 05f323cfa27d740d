//! Benchmark inputs and measurements for `arbor bench`: a mesh framed by a default camera, a generated
//! sphere, the primary and diffuse ray sets, and timed parallel tracing.
//!
//! The ray sets follow the peers' benchmark (peerbench): primary rays through every pixel centre, then
//! from each primary hit one cosine-weighted direction about the geometric normal on the side the ray
//! came from, the origin pushed off by `1e-5` of the scene's bounding-box diagonal. Every ray draws from
//! its own random stream seeded by its index, so the sets do not depend on the thread count. The same
//! rays are traced by every structure, and their hits compared exactly (primitive and `t`).
//!
//! [`ray_files`] reads the rays peerbench dumped (`--dump-rays`), to trace exactly the peers' rays.

pub mod ray_files;

use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

use rayon::prelude::*;

use crate::accel::Hit;
use crate::camera::Camera;
use crate::geometry::TriangleMesh;
use crate::math::{orthonormal_basis, Aabb, Color, Ray, Transform, Vec2, Vec3};
use crate::sampler::Rng;
use crate::scene::{
    CameraDesc, MaterialDesc, MaterialKind, MeshSource, ObjectDesc, Scene, SceneDesc, SceneGeometry, ShapeDesc, Window,
};
use crate::Location;

/// Vertical field of view of the default camera, in degrees (peerbench's).
pub const DEFAULT_FOV_DEG: f32 = 40.0;

/// A tessellated unit sphere at the origin with about `n` triangles (at least 8): `r` rings of `2r`
/// quads split in two, fans at the poles, `4r(r - 1)` triangles in all. Deterministic, counter-clockwise
/// seen from outside.
pub fn sphere_mesh(n: usize) -> TriangleMesh {
    let r = ((1.0 + (1.0 + n as f64).sqrt()) / 2.0).round().max(2.0) as u32;
    let cols = 2 * r;
    let mut positions = vec![Vec3::Y];
    for i in 1..r {
        let theta = std::f32::consts::PI * i as f32 / r as f32;
        for j in 0..cols {
            let phi = std::f32::consts::TAU * j as f32 / cols as f32;
            positions.push(Vec3::new(theta.sin() * phi.cos(), theta.cos(), -theta.sin() * phi.sin()));
        }
    }
    positions.push(-Vec3::Y);
    let south = positions.len() as u32 - 1;
    let at = |ring: u32, j: u32| 1 + (ring - 1) * cols + j % cols;
    let mut indices = Vec::with_capacity((4 * r * (r - 1)) as usize);
    for j in 0..cols {
        indices.push([0, at(1, j), at(1, j + 1)]);
        for ring in 1..r - 1 {
            let (a, b, c, d) = (at(ring, j), at(ring + 1, j), at(ring + 1, j + 1), at(ring, j + 1));
            indices.push([a, b, c]);
            indices.push([a, c, d]);
        }
        indices.push([at(r - 1, j), south, at(r - 1, j + 1)]);
    }
    TriangleMesh { positions, indices, normals: None, uvs: None }
}

/// A camera looking at the centre of `bounds` from the +z side, a little from the right and above,
/// far enough that the bounding sphere fits a [`DEFAULT_FOV_DEG`] field of view.
pub fn framing_camera(bounds: Aabb, width: u32, height: u32) -> CameraDesc {
    let (center, radius) = if bounds.is_empty() {
        (Vec3::ZERO, 1.0)
    } else {
        (bounds.center(), (bounds.extent().length() * 0.5).max(1e-6))
    };
    let dir = Vec3::new(0.3, 0.25, 1.0).normalize();
    let half = (DEFAULT_FOV_DEG.to_radians() * 0.5).tan();
    let aspect = width as f32 / height.max(1) as f32;
    // The sphere fits the narrower side of the window.
    let dist = radius / (half * aspect.min(1.0)).atan().sin();
    CameraDesc {
        id: "bench".into(),
        position: center + dir * dist,
        gaze: -dir,
        up: Vec3::Y,
        window: Window { left: -half * aspect, right: half * aspect, bottom: -half, top: half },
        near_distance: 1.0,
        orthographic: false,
        width,
        height,
        image_name: "bench.png".into(),
        name_loc: Location::file("bench"),
        num_samples: 1,
        transform: Transform::IDENTITY,
        lens: None,
        tonemap: None,
        renderer: Default::default(),
        loc: Location::file("bench"),
    }
}

/// A scene of one flat grey mesh seen by `camera`, as if read from `source`.
pub fn mesh_scene(mesh: TriangleMesh, source: &Path, camera: CameraDesc) -> SceneDesc {
    let mut desc = SceneDesc::new(source);
    desc.cameras.push(camera);
    desc.materials.push(MaterialDesc {
        degamma: false,
        id: "grey".into(),
        ambient: Color::splat(0.1),
        diffuse: Color::splat(0.7),
        specular: Color::ZERO,
        phong_exponent: 1.0,
        brdf: None,
        roughness: 0.0,
        kind: MaterialKind::BlinnPhong,
    });
    desc.objects.push(ObjectDesc {
        name: "mesh".into(),
        material: 0,
        shape: ShapeDesc::Mesh { source: MeshSource::Inline(Arc::new(mesh)), smooth: false },
        transform: Transform::IDENTITY,
        motion: Vec3::ZERO,
        textures: Vec::new(),
        emission: None,
        loc: Location::file(source),
    });
    desc
}

/// One ray through each pixel centre of `cam`, row by row from the top.
pub fn primary_rays(cam: &Camera) -> Vec<Ray> {
    let (w, h) = (cam.width, cam.height);
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| cam.ray(x, y, Vec2::splat(0.5), Vec2::splat(0.5)))
        .collect()
}

/// From each hit of `rays`, a cosine-weighted ray about the geometric normal facing the incoming ray.
pub fn diffuse_rays(scene: &Scene, rays: &[Ray], hits: &[Option<Hit>]) -> Vec<Ray> {
    let b = scene.geometry.bounds();
    let eps = if b.is_empty() { 1e-5 } else { 1e-5 * b.extent().length().max(1e-30) };
    rays.par_iter()
        .zip(hits)
        .enumerate()
        .filter_map(|(i, (ray, hit))| {
            let hit = hit.as_ref()?;
            let s = scene.surface(ray, hit);
            let n = if ray.dir.dot(s.ng) < 0.0 { s.ng } else { -s.ng };
            let mut rng = Rng::for_sample(i as u32, (i >> 32) as u32, 0x0d1f, 0);
            let u = rng.next_2d();
            let (t, bt) = orthonormal_basis(n);
            let (r, phi) = (u.x.sqrt(), std::f32::consts::TAU * u.y);
            let dir = t * (r * phi.cos()) + bt * (r * phi.sin()) + n * (1.0 - u.x).max(0.0).sqrt();
            Some(Ray::new(s.p + n * eps, dir))
        })
        .collect()
}

/// Closest hits of every ray, traced in parallel, and the wall time it took.
pub fn trace(geometry: &SceneGeometry, rays: &[Ray]) -> (Vec<Option<Hit>>, Duration) {
    let start = Instant::now();
    let hits = rays.par_iter().with_min_len(256).map(|r| geometry.intersect(r, f32::INFINITY)).collect();
    (hits, start.elapsed())
}

/// Every `k`-th ray, `k` chosen so that at most `max` are kept (a deterministic sample for brute force).
pub fn sample(rays: &[Ray], max: usize) -> (Vec<Ray>, usize) {
    let k = rays.len().div_ceil(max.max(1)).max(1);
    (rays.iter().step_by(k).copied().collect(), k)
}

/// How many hits differ (hit or miss, primitive, or `t` to the bit) between two answers to the same rays.
pub fn mismatches(a: &[Option<Hit>], b: &[Option<Hit>]) -> usize {
    a.iter()
        .zip(b)
        .filter(|(x, y)| match (x, y) {
            (None, None) => false,
            (Some(x), Some(y)) => (x.prim, x.sub) != (y.prim, y.sub) || x.t.to_bits() != y.t.to_bits(),
            _ => true,
        })
        .count()
        + a.len().abs_diff(b.len())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::AccelConfig;

    #[test]
    fn bench_sphere_has_about_n_unit_triangles() {
        for n in [8, 1000, 20_000] {
            let m = sphere_mesh(n);
            let got = m.len() as f64;
            assert!((got - n as f64).abs() <= 0.05 * n as f64 + 8.0, "asked {n}, got {got}");
            assert!(m.positions.iter().all(|p| (p.length() - 1.0).abs() < 1e-5));
            assert_eq!(m.check().degenerate, 0);
            // Counter-clockwise from outside: every face normal points away from the centre.
            assert!((0..m.len()).all(|i| {
                let [a, b, c] = m.triangle(i);
                (b - a).cross(c - a).dot(a + b + c) > 0.0
            }));
        }
    }

    #[test]
    fn bench_framing_camera_sees_the_whole_mesh_and_diffuse_rays_leave_it() {
        let mesh = sphere_mesh(2000);
        let desc = mesh_scene(mesh.clone(), Path::new("sphere"), framing_camera(mesh.bounds(), 48, 32));
        let scene = Scene::build(desc, &AccelConfig::default(), None).unwrap();
        let rays = primary_rays(&scene.cameras[0]);
        assert_eq!(rays.len(), 48 * 32);
        let (hits, _) = trace(&scene.geometry, &rays);
        // The border of the image misses; the centre hits.
        assert!(hits[0].is_none() && hits[47].is_none() && hits[48 * 31].is_none());
        assert!(hits[16 * 48 + 24].is_some());
        let diffuse = diffuse_rays(&scene, &rays, &hits);
        assert_eq!(diffuse.len(), hits.iter().flatten().count());
        // Outward-facing from a convex sphere: nothing to hit.
        let (again, _) = trace(&scene.geometry, &diffuse);
        assert!(again.iter().all(Option::is_none));
        assert_eq!(diffuse_rays(&scene, &rays, &hits)[5].dir, diffuse[5].dir);
    }

    #[test]
    fn bench_sample_and_mismatches_count() {
        let rays = vec![Ray::new(Vec3::ZERO, Vec3::X); 10];
        let (kept, k) = sample(&rays, 3);
        assert_eq!((kept.len(), k), (3, 4));
        let h = |t: f32, prim, sub| Some(Hit { t, prim, u: 0.0, v: 0.0, sub });
        let a = [h(1.0, 1, 0), None, h(2.0, 3, 0), h(3.0, 0, 5)];
        let b = [h(1.0, 1, 0), h(1.0, 1, 0), h(2.0, 4, 0), h(3.0, 0, 6)];
        assert_eq!(mismatches(&a, &b), 3, "another triangle of the same mesh is a mismatch");
    }
}
