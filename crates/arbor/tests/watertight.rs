//! Watertightness: rays from inside a closed mesh never escape through shared edges or vertices, with
//! every structure (Woop, Benthin and Wald 2013: the triangle test is evaluated in a ray-aligned frame in
//! which a shared edge gets the same value from both neighbours).
//!
//! The mesh is a UV sphere of about 10^5 triangles with shared vertices, each vertex displaced radially
//! by a random amount (deterministic seed), so edges are not aligned to anything. Rays start at random
//! points within half the radius, in random directions. Every ray must hit.
//!
//! Ray counts: `ARBOR_WATERTIGHT_RAYS` per structure (default 10^6, so the suite stays fast on 2 cores;
//! the 10^7 is `ARBOR_WATERTIGHT_RAYS=10000000 cargo test --release --test watertight`). Brute
//! force tests every triangle for every ray (10^5 tests per ray), so it gets a sample of 10^4 rays; the
//! first 10^4 rays of every other structure are also compared with it (same closest `t`).
//!
//! NaN and infinite rays hit nothing, in every structure and in a whole scene.

use std::sync::Arc;
use std::time::Instant;

use arbor::accel::{build, AccelKind, Hit};
use arbor::bench::sphere_mesh;
use arbor::geometry::TriangleMesh;
use arbor::math::{Color, Ray, Transform, Vec3};
use arbor::scene::{MaterialDesc, MaterialKind, MeshSource, ObjectDesc, Scene, SceneDesc, ShapeDesc};
use arbor::Location;
use rayon::prelude::*;

const DEFAULT_RAYS: u64 = 1_000_000;
const BRUTE_RAYS: u64 = 10_000;
const CHUNK: u64 = 4096;

/// SplitMix64: a tiny deterministic generator, one stream per chunk of rays.
struct SplitMix(u64);

impl SplitMix {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    fn next_f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
    /// Uniform in the unit ball (rejection sampling).
    fn in_ball(&mut self) -> Vec3 {
        loop {
            let v = Vec3::new(self.next_f32(), self.next_f32(), self.next_f32()) * 2.0 - Vec3::ONE;
            if v.length_squared() <= 1.0 {
                return v;
            }
        }
    }
    /// Uniform on the unit sphere.
    fn direction(&mut self) -> Vec3 {
        loop {
            let v = self.in_ball();
            if v.length_squared() > 1e-4 {
                return v.normalize();
            }
        }
    }
}

/// A closed unit sphere of about `n` triangles, every shared vertex moved radially by up to ±10%.
fn perturbed_sphere(n: usize, seed: u64) -> TriangleMesh {
    let mut mesh = sphere_mesh(n);
    let mut rng = SplitMix(seed);
    for p in &mut mesh.positions {
        *p *= 0.9 + 0.2 * rng.next_f32();
    }
    mesh
}

/// Ray `i` of the test: its chunk's stream, so the rays do not depend on the thread count.
fn rays_of_chunk(chunk: u64, count: u64) -> impl Iterator<Item = Ray> {
    let mut rng = SplitMix(0xA5A5_0000 ^ chunk.wrapping_mul(0x2545_F491_4F6C_DD1D));
    (0..count).map(move |_| Ray::new(rng.in_ball() * 0.5, rng.direction()))
}

fn ray_count() -> u64 {
    std::env::var("ARBOR_WATERTIGHT_RAYS").ok().and_then(|s| s.parse().ok()).unwrap_or(DEFAULT_RAYS)
}

/// Casts `total` rays in parallel; returns the escapes (rays that hit nothing) with an example.
fn escapes(total: u64, intersect: &(dyn Fn(&Ray) -> Option<Hit> + Sync)) -> (u64, Option<Ray>) {
    (0..total.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            let count = CHUNK.min(total - c * CHUNK);
            let mut missed = (0u64, None);
            for ray in rays_of_chunk(c, count) {
                if intersect(&ray).is_none() {
                    missed.0 += 1;
                    missed.1.get_or_insert(ray);
                }
            }
            missed
        })
        .reduce(|| (0, None), |a, b| (a.0 + b.0, a.1.or(b.1)))
}

#[test]
fn watertight_no_ray_escapes_a_perturbed_sphere_in_any_structure() {
    let mesh = perturbed_sphere(100_000, 7);
    assert!(mesh.len() >= 95_000, "{} triangles", mesh.len());
    let total = ray_count();
    let brute = build(AccelKind::Brute, &mesh);
    let sample: Vec<Ray> = rays_of_chunk(0, BRUTE_RAYS).collect();
    let expected: Vec<Option<Hit>> = sample.par_iter().map(|r| brute.intersect(&mesh, r, f32::INFINITY)).collect();
    let brute_escapes = expected.iter().filter(|h| h.is_none()).count();
    println!("brute: {BRUTE_RAYS} rays, {brute_escapes} escapes");
    assert_eq!(brute_escapes, 0, "brute force: rays escaped");

    let mut failures = Vec::new();
    for &kind in AccelKind::ALL.iter().filter(|&&k| k != AccelKind::Brute) {
        let accel = build(kind, &mesh);
        for (ray, want) in sample.iter().zip(&expected) {
            let got = accel.intersect(&mesh, ray, f32::INFINITY);
            assert_eq!(got.map(|h| h.t), want.map(|h| h.t), "{kind} differs from brute force on {ray:?}");
        }
        let start = Instant::now();
        let (missed, example) = escapes(total, &|r| accel.intersect(&mesh, r, f32::INFINITY));
        println!(
            "{kind}: {total} rays from inside {} triangles, {missed} escapes, {:.2} s",
            mesh.len(),
            start.elapsed().as_secs_f64()
        );
        if missed > 0 {
            failures.push(format!("{kind}: {missed} of {total} rays escaped, e.g. {example:?}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Rays with a NaN or infinite origin or direction, or a zero direction.
fn bad_rays() -> Vec<Ray> {
    let (nan, inf) = (f32::NAN, f32::INFINITY);
    let o = Vec3::new(0.1, 0.2, 0.05);
    let d = Vec3::new(0.3, -0.5, 0.8);
    vec![
        Ray::new(Vec3::new(nan, 0.0, 0.0), d),
        Ray::new(o, Vec3::new(0.0, nan, 1.0)),
        Ray::new(Vec3::splat(nan), Vec3::splat(nan)),
        Ray::new(Vec3::new(inf, 0.0, 0.0), d),
        Ray::new(Vec3::new(-inf, 0.0, 0.0), Vec3::X),
        Ray::new(o, Vec3::new(inf, 0.0, 0.0)),
        Ray::new(o, Vec3::new(inf, -inf, 1.0)),
        Ray::new(o, Vec3::ZERO),
    ]
}

#[test]
fn watertight_nan_and_infinite_rays_hit_nothing() {
    let mesh = perturbed_sphere(2_000, 11);
    for &kind in AccelKind::ALL {
        let accel = build(kind, &mesh);
        for ray in bad_rays() {
            assert!(accel.intersect(&mesh, &ray, f32::INFINITY).is_none(), "{kind} hit with {ray:?}");
            assert!(!accel.occluded(&mesh, &ray, f32::INFINITY), "{kind} occluded with {ray:?}");
        }
    }

    // A whole scene: the mesh, a sphere and a plane, under every structure.
    let mut desc = SceneDesc::new("bad_rays.xml");
    desc.materials.push(MaterialDesc {
        degamma: false,
        id: "m".into(),
        ambient: Color::ONE,
        diffuse: Color::ONE,
        specular: Color::ZERO,
        phong_exponent: 1.0,
        brdf: None,
        roughness: 0.0,
        kind: MaterialKind::BlinnPhong,
    });
    let object = |shape| ObjectDesc {
        name: "o".into(),
        material: 0,
        shape,
        transform: Transform::IDENTITY,
        motion: Vec3::ZERO,
        textures: Vec::new(),
        emission: None,
        loc: Location::file("test"),
    };
    desc.objects.push(object(ShapeDesc::Mesh { source: MeshSource::Inline(Arc::new(mesh)), smooth: false }));
    desc.objects.push(object(ShapeDesc::Sphere { center: Vec3::new(3.0, 0.0, 0.0), radius: 1.0 }));
    desc.objects.push(object(ShapeDesc::Plane { point: Vec3::new(0.0, -2.0, 0.0), normal: Vec3::Y }));
    for &kind in AccelKind::ALL {
        let scene = Scene::build(desc.clone(), &arbor::accel::AccelConfig::from(kind), None).unwrap();
        for ray in bad_rays() {
            assert!(scene.geometry.intersect(&ray, f32::INFINITY).is_none(), "scene {kind} hit with {ray:?}");
            assert!(!scene.geometry.occluded(&ray, f32::INFINITY), "scene {kind} occluded with {ray:?}");
        }
    }
}
