//! Build and traversal speed of every acceleration structure (criterion), on two interpenetrating
//! generated spheres of 10,000 triangles each (so that diffuse bounces hit something) seen by the
//! benchmark camera (`arbor::bench`): primary rays through 128x128 pixel centres, then one diffuse
//! bounce from each hit, traced one query per ray and as one batch. Small on purpose, so that `cargo
//! bench` takes a couple of minutes; `arbor bench` and `scripts/peer-compare.sh` measure the large
//! meshes and the peers (see `docs/performance.md`). Brute force is left out: at 20,000 tests per ray it would
//! dominate the run and says nothing new.
//!
//! Throughput is reported in rays (traversal) and triangles (build) per second.

use std::path::Path;

use arbor::accel::{AccelConfig, AccelKind};
use arbor::bench::{diffuse_rays, framing_camera, mesh_scene, primary_rays, sphere_mesh, trace};
use arbor::geometry::TriangleMesh;
use arbor::math::{Ray, Vec3};
use arbor::scene::Scene;
use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};

const TRIANGLES: usize = 20_000;
const SIZE: u32 = 128;

fn kinds() -> impl Iterator<Item = AccelKind> {
    AccelKind::ALL.iter().copied().filter(|&k| k != AccelKind::Brute)
}

/// A unit sphere and one of radius 0.8 centred at x = 1.2, as one mesh.
fn two_spheres() -> TriangleMesh {
    let mut mesh = sphere_mesh(TRIANGLES / 2);
    let other = sphere_mesh(TRIANGLES / 2);
    let base = mesh.positions.len() as u32;
    mesh.positions.extend(other.positions.iter().map(|p| *p * 0.8 + Vec3::new(1.2, 0.0, 0.0)));
    mesh.indices.extend(other.indices.iter().map(|t| t.map(|i| i + base)));
    mesh
}

fn inputs() -> (TriangleMesh, Vec<Ray>, Vec<Ray>) {
    let mesh = two_spheres();
    let camera = framing_camera(mesh.bounds(), SIZE, SIZE);
    let desc = mesh_scene(mesh.clone(), Path::new("sphere"), camera);
    let scene = Scene::build(desc, &AccelConfig::default(), None).expect("the sphere scene builds");
    let primary = primary_rays(&scene.cameras[0]);
    let (hits, _) = trace(&scene.geometry, &primary);
    let diffuse = diffuse_rays(&scene, &primary, &hits);
    (mesh, primary, diffuse)
}

fn build(c: &mut Criterion) {
    let mesh = two_spheres();
    let mut g = c.benchmark_group("build");
    g.sample_size(10).throughput(Throughput::Elements(mesh.len() as u64));
    for kind in kinds() {
        g.bench_function(BenchmarkId::from_parameter(kind), |b| {
            b.iter(|| AccelConfig::from(kind).build_accel(black_box(&mesh)).expect("default parameters"))
        });
    }
    g.finish();
}

fn traverse(c: &mut Criterion) {
    let (mesh, primary, diffuse) = inputs();
    for (set, rays) in [("primary", &primary), ("diffuse", &diffuse)] {
        let mut g = c.benchmark_group(format!("intersect-{set}"));
        g.sample_size(10).throughput(Throughput::Elements(rays.len() as u64));
        for kind in kinds() {
            let accel = AccelConfig::from(kind).build_accel(&mesh).expect("default parameters");
            g.bench_function(BenchmarkId::from_parameter(kind), |b| {
                b.iter(|| rays.iter().filter(|r| accel.intersect(&mesh, r, f32::INFINITY).is_some()).count())
            });
        }
        g.finish();
        // The same rays as one batch (`intersect_many`: the BVH interleaves two rays).
        let mut g = c.benchmark_group(format!("intersect-many-{set}"));
        g.sample_size(10).throughput(Throughput::Elements(rays.len() as u64));
        let t_max = vec![f32::INFINITY; rays.len()];
        let mut hits = vec![None; rays.len()];
        for kind in kinds() {
            let accel = AccelConfig::from(kind).build_accel(&mesh).expect("default parameters");
            g.bench_function(BenchmarkId::from_parameter(kind), |b| {
                b.iter(|| {
                    accel.intersect_many(&mesh, rays, &t_max, &mut hits);
                    hits.iter().filter(|h| h.is_some()).count()
                })
            });
        }
        g.finish();
    }
    let mut g = c.benchmark_group("occluded-diffuse");
    g.sample_size(10).throughput(Throughput::Elements(diffuse.len() as u64));
    for kind in kinds() {
        let accel = AccelConfig::from(kind).build_accel(&mesh).expect("default parameters");
        g.bench_function(BenchmarkId::from_parameter(kind), |b| {
            b.iter(|| diffuse.iter().filter(|r| accel.occluded(&mesh, r, f32::INFINITY)).count())
        });
    }
    g.finish();
}

criterion_group!(benches, build, traverse);
criterion_main!(benches);
