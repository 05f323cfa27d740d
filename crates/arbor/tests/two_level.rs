//! The two-level scene: instances share their base's geometry and structure, transformed objects are hit
//! where their transform puts them, and every structure kind gives the same hits as brute force at both
//! levels on random scenes of transformed meshes and spheres.

use std::sync::Arc;

use arbor::accel::{AccelConfig, AccelKind};
use arbor::geometry::TriangleMesh;
use arbor::math::{Color, Ray, Transform, Vec3};
use arbor::scene::{
    build_geometry, MaterialDesc, MaterialKind, MeshSource, ObjectDesc, SceneDesc, SceneGeometry, ShapeDesc,
};
use arbor::Location;

mod common;
use common::soups::{closed_cube, mesh_of};

fn quad() -> Arc<TriangleMesh> {
    Arc::new(TriangleMesh {
        positions: vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ],
        indices: vec![[0, 1, 2], [0, 2, 3]],
        ..Default::default()
    })
}

fn object(name: &str, shape: ShapeDesc, transform: Transform) -> ObjectDesc {
    ObjectDesc {
        name: name.into(),
        material: 0,
        shape,
        transform,
        motion: Vec3::ZERO,
        textures: Vec::new(),
        emission: None,
        loc: Location::file("test"),
    }
}

fn desc(objects: Vec<ObjectDesc>) -> SceneDesc {
    let mut d = SceneDesc::new("two_level.xml");
    d.materials.push(MaterialDesc {
        degamma: false,
        id: "1".into(),
        ambient: Color::ONE,
        diffuse: Color::ONE,
        specular: Color::ZERO,
        phong_exponent: 1.0,
        brdf: None,
        roughness: 0.0,
        kind: MaterialKind::BlinnPhong,
    });
    d.objects = objects;
    d
}

#[test]
fn two_level_instance_shares_geometry_and_is_hit_through_its_transform() {
    let mesh = ShapeDesc::Mesh { source: MeshSource::Inline(quad()), smooth: false };
    let moved = Transform::translate(Vec3::new(10.0, 0.0, 0.0)).then(&Transform::rotate(90.0, Vec3::Z).unwrap());
    let d = desc(vec![
        object("Mesh 1", mesh, Transform::IDENTITY),
        object("MeshInstance 1", ShapeDesc::Instance { base: 0 }, moved),
    ]);
    let g = build_geometry(&d, &AccelConfig::default()).unwrap();
    assert_eq!(g.meshes.len(), 1, "the instance must not copy the mesh");
    assert_eq!((g.counts.triangles, g.counts.unique_triangles, g.counts.objects), (4, 2, 2));
    // The instance sits around (0, 10, 0) after the rotation of its translation.
    let ray = Ray::new(Vec3::new(0.5, 10.0, 5.0), Vec3::new(0.0, 0.0, -2.0));
    let hit = g.intersect(&ray, f32::INFINITY).unwrap();
    assert_eq!(hit.prim, 1);
    assert!((hit.t - 2.5).abs() < 1e-5, "t is preserved through the transform: {}", hit.t);
    assert_eq!(g.global_prim_id(&hit), 2 + hit.sub);
    assert!(g.intersect(&Ray::new(Vec3::new(10.0, 0.0, 5.0), -Vec3::Z), f32::INFINITY).is_none());
}

/// A small deterministic generator (the tests need no statistical quality).
struct Lcg(u64);

impl Lcg {
    fn f(&mut self) -> f32 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f32) / (1u64 << 24) as f32
    }
    fn v(&mut self, s: f32) -> Vec3 {
        Vec3::new(self.f() - 0.5, self.f() - 0.5, self.f() - 0.5) * s
    }
}

fn random_scene(rng: &mut Lcg) -> SceneDesc {
    let mut objects = Vec::new();
    for m in 0..6 {
        let positions: Vec<Vec3> = (0..60).map(|_| rng.v(4.0)).collect();
        let indices: Vec<[u32; 3]> = (0..40).map(|k| [k * 3 % 60, (k * 3 + 1) % 60, (k * 3 + 2) % 60]).collect();
        let mesh = Arc::new(TriangleMesh { positions, indices, ..Default::default() });
        let t = Transform::translate(rng.v(12.0))
            .then(&Transform::rotate(rng.f() * 360.0, rng.v(1.0) + Vec3::splat(0.01)).unwrap())
            .then(
                &Transform::scale(Vec3::new(1.0 + rng.f(), if m % 3 == 0 { -1.0 } else { 0.5 + rng.f() }, 1.0))
                    .unwrap(),
            );
        objects.push(object("Mesh", ShapeDesc::Mesh { source: MeshSource::Inline(mesh), smooth: false }, t));
        let moved = Transform::translate(rng.v(12.0));
        objects.push(object("MeshInstance", ShapeDesc::Instance { base: objects.len() - 1 }, moved.then(&t)));
        let sphere = ShapeDesc::Sphere { center: rng.v(10.0), radius: 0.5 + rng.f() };
        objects.push(object("Sphere", sphere, Transform::scale(Vec3::new(1.0, 1.0 + rng.f(), 1.0)).unwrap()));
    }
    desc(objects)
}

#[test]
fn two_level_every_structure_matches_brute_force_on_random_transformed_scenes() {
    let mut rng = Lcg(7);
    let mut rays_checked = 0;
    for _ in 0..4 {
        let d = random_scene(&mut rng);
        let brute = build_geometry(&d, &AccelConfig::from(AccelKind::Brute)).unwrap();
        let rays: Vec<Ray> = (0..5_000).map(|_| Ray::new(rng.v(30.0), rng.v(2.0))).collect();
        for &kind in AccelKind::ALL {
            let g = build_geometry(&d, &AccelConfig::from(kind)).unwrap();
            for ray in &rays {
                let (want, got) = (brute.intersect(ray, f32::INFINITY), g.intersect(ray, f32::INFINITY));
                assert_eq!(want.map(|h| (h.prim, h.sub, h.t)), got.map(|h| (h.prim, h.sub, h.t)), "{kind} on {ray:?}");
                let t_max = want.map_or(50.0, |h| h.t * 0.999);
                assert_eq!(brute.occluded(ray, t_max), g.occluded(ray, t_max), "{kind} occluded on {ray:?}");
                rays_checked += 1;
            }
        }
    }
    assert!(rays_checked >= 100_000);
}

#[test]
fn two_level_bvh_top_levels_give_every_object_a_leaf_of_its_own() {
    // An object is a structure of its own: a leaf that grouped objects would send every ray that meets
    // the leaf's box into each of them. Eight flat walls and boxes, as a Cornell box has, are what the
    // SAH's triangle costs would put in one leaf.
    let mut objects = Vec::new();
    for k in 0..8 {
        let t = Transform::translate(Vec3::new(k as f32 * 0.1, 0.0, 0.0));
        objects.push(object("Mesh", ShapeDesc::Mesh { source: MeshSource::Inline(quad()), smooth: false }, t));
    }
    let d = desc(objects);
    for kind in [AccelKind::BvhSah, AccelKind::BvhMedian, AccelKind::BvhBottomUp] {
        let g = build_geometry(&d, &AccelConfig::from(kind)).unwrap();
        let top = g.top.stats();
        assert_eq!((top.primitives, top.leaves), (8, 8), "{kind}: {top:?}");
    }
}

#[test]
fn two_level_hits_agree_with_the_same_geometry_flattened_into_world_space() {
    // The same scene with every mesh taken to world space up front: the closest hit lands on the same
    // primitive, at the same distance up to rounding (rays are transformed instead of triangles).
    let mut rng = Lcg(11);
    let d = random_scene(&mut rng);
    let g = build_geometry(&d, &AccelConfig::default()).unwrap();
    let flat_objects: Vec<ObjectDesc> = d
        .objects
        .iter()
        .map(|o| match &o.shape {
            ShapeDesc::Mesh { source: MeshSource::Inline(m), .. } => object(
                &o.name,
                ShapeDesc::Mesh { source: MeshSource::Inline(Arc::new(m.transformed(&o.transform))), smooth: false },
                Transform::IDENTITY,
            ),
            ShapeDesc::Instance { base } => {
                let ShapeDesc::Mesh { source: MeshSource::Inline(m), .. } = &d.objects[*base].shape else {
                    unreachable!()
                };
                let flat = Arc::new(m.transformed(&o.transform));
                object(
                    &o.name,
                    ShapeDesc::Mesh { source: MeshSource::Inline(flat), smooth: false },
                    Transform::IDENTITY,
                )
            }
            _ => o.clone(),
        })
        .collect();
    let flat = build_geometry(&desc(flat_objects), &AccelConfig::default()).unwrap();
    let (mut agree, mut total) = (0, 0);
    for _ in 0..20_000 {
        let ray = Ray::new(rng.v(30.0), rng.v(2.0));
        match (g.intersect(&ray, f32::INFINITY), flat.intersect(&ray, f32::INFINITY)) {
            (None, None) => {}
            (Some(a), Some(b)) => {
                total += 1;
                assert!((a.t - b.t).abs() <= 1e-3 * a.t.max(1.0), "t {} vs {}", a.t, b.t);
                if g.global_prim_id(&a) == flat.global_prim_id(&b) {
                    agree += 1;
                }
            }
            // A ray grazing an edge may hit in one and miss in the other by rounding: counted as disagreeing.
            _ => total += 1,
        }
    }
    assert!(total > 1_000, "too few hits to compare: {total}");
    assert!(agree as f64 >= 0.999 * total as f64, "{agree} of {total} hits on the same primitive");
}

#[test]
fn two_level_batches_give_every_ray_its_own_querys_hit() {
    // One transformed mesh with a plane beside it, a few large objects, one moving (both swept object by
    // object), a few small ones and a random scene of many (each ray walks the top level); invalid rays
    // mixed in.
    let mut rng = Lcg(23);
    let positions: Vec<Vec3> = (0..300).map(|_| rng.v(4.0)).collect();
    let indices: Vec<[u32; 3]> = (0..200).map(|k| [k * 3 % 300, (k * 3 + 1) % 300, (k * 3 + 2) % 300]).collect();
    let mesh = Arc::new(TriangleMesh { positions, indices, ..Default::default() });
    let t = Transform::translate(Vec3::new(1.0, 2.0, 0.5)).then(&Transform::rotate(30.0, Vec3::Y).unwrap());
    let inline = |m: &Arc<TriangleMesh>| ShapeDesc::Mesh { source: MeshSource::Inline(m.clone()), smooth: false };
    let one_mesh = desc(vec![
        object("Mesh", inline(&mesh), t),
        object("Plane", ShapeDesc::Plane { point: Vec3::new(0.0, -1.5, 0.0), normal: Vec3::Y }, Transform::IDENTITY),
    ]);
    // Few large objects: two meshes, an instance in the very place of the first, whose hits tie with it
    // and must go to the first, and a sphere.
    let big = |rng: &mut Lcg| {
        let positions: Vec<Vec3> = (0..1800).map(|_| rng.v(4.0)).collect();
        let indices: Vec<[u32; 3]> = (0..600).map(|k| [k * 3, k * 3 + 1, k * 3 + 2]).collect();
        Arc::new(TriangleMesh { positions, indices, ..Default::default() })
    };
    let u = Transform::translate(Vec3::new(-2.0, 0.0, 1.0));
    // The second one moves over the shutter interval: the sweep culls by its swept box.
    let mut moving = object("Mesh", inline(&big(&mut rng)), u);
    moving.motion = Vec3::new(0.0, 3.0, -1.0);
    let few_large = desc(vec![
        object("Mesh", inline(&big(&mut rng)), t),
        moving,
        object("MeshInstance", ShapeDesc::Instance { base: 0 }, t),
        object("Sphere", ShapeDesc::Sphere { center: Vec3::new(0.0, 1.0, 0.0), radius: 1.5 }, Transform::IDENTITY),
    ]);
    // Few small objects: meshes, instances and spheres, and again an instance where the first mesh is.
    let mut few = random_scene(&mut rng);
    few.objects.truncate(6);
    let same_place = few.objects[0].transform;
    few.objects.push(object("MeshInstance", ShapeDesc::Instance { base: 0 }, same_place));
    let sweeps = [true, true, false, false];
    for (d, sweep) in [one_mesh, few_large, few, random_scene(&mut rng)].into_iter().zip(sweeps) {
        // Aimed at the middle of the scene, where its objects are.
        let mut rays: Vec<Ray> = (0..3_000)
            .map(|_| {
                let o = rng.v(30.0);
                Ray::new(o, rng.v(12.0) - o).with_time(rng.f())
            })
            .collect();
        rays[10] = Ray::new(Vec3::NAN, Vec3::X);
        rays[11] = Ray::new(Vec3::ZERO, Vec3::ZERO);
        for &kind in AccelKind::ALL {
            let g = build_geometry(&d, &AccelConfig::from(kind)).unwrap();
            assert_eq!(g.sweeps(), sweep, "{kind}: {} objects", g.objects.objects.len());
            for t_max in [f32::INFINITY, 20.0] {
                let hits = check_batches(&g, &rays, t_max, &[0, 1, 2, 3, rays.len()], &kind.to_string());
                assert!(hits > 200, "{kind}: the rays must hit");
            }
        }
    }
}

/// `g.intersect_many` over the first `n` of `rays` for each `n` of `batches` gives every ray the very hit
/// its own query gives in `(0, t_max)`; returns how many of `rays` hit.
fn check_batches(g: &SceneGeometry, rays: &[Ray], t_max: f32, batches: &[usize], what: &str) -> usize {
    let single: Vec<_> = rays.iter().map(|r| g.intersect(r, t_max)).collect();
    for &n in batches {
        let mut out = vec![None; n];
        g.intersect_many(&rays[..n], t_max, &mut out);
        for (i, (a, b)) in out.iter().zip(&single).enumerate() {
            assert_eq!(a, b, "{what}, t_max {t_max}, batch of {n}: ray {i} {:?}", rays[i]);
        }
    }
    single.iter().filter(|h| h.is_some()).count()
}

#[test]
fn two_level_swept_batches_turn_away_no_ray_that_grazes_an_objects_box() {
    // The sweep sends an object only the rays that may meet its box before their closest hit so far.
    // Cubes whose faces lie on their boxes, hit on their edges and corners, along their faces and from
    // points on them, near the origin, at 1e5 and scaled by 1e-4: a second cube overlaps the first, and
    // an instance of the first sits in its very place (its hits tie with the first's and go to it).
    for (scale, offset) in [(1.0, 0.0), (1e-4, 0.0), (1.0, 1e5)] {
        let place = |p: Vec3| p * scale + Vec3::splat(offset);
        let cube = |at: Vec3| {
            let tris: Vec<[Vec3; 3]> = closed_cube(8).iter().map(|t| t.map(|p| place(p + at))).collect();
            ShapeDesc::Mesh { source: MeshSource::Inline(Arc::new(mesh_of(&tris))), smooth: false }
        };
        let d = desc(vec![
            object("Mesh", cube(Vec3::ZERO), Transform::IDENTITY),
            object("Mesh", cube(Vec3::new(4.0, 4.0, 0.0)), Transform::IDENTITY),
            object("MeshInstance", ShapeDesc::Instance { base: 0 }, Transform::IDENTITY),
        ]);
        let mut rng = Lcg(41);
        let lattice = |rng: &mut Lcg, n: usize| {
            let mut c = || (rng.f() * (n + 1) as f32).floor();
            place(Vec3::new(c(), c(), c()))
        };
        let mut rays = Vec::new();
        for k in 0..4_000 {
            // Lattice points of both cubes, on and between their edges and faces.
            let target = lattice(&mut rng, 12);
            let origin = match k % 4 {
                // From far away, and from near.
                0 => place(rng.v(60.0) + Vec3::splat(6.0)),
                1 => place(rng.v(16.0) + Vec3::splat(6.0)),
                // From another lattice point: on a face, or along one.
                _ => lattice(&mut rng, 12),
            };
            if origin != target {
                rays.push(Ray::new(origin, target - origin));
            }
        }
        // Along the planes of the first cube's faces, from outside it, to the edges where the faces
        // across meet them: a slab distance of `0 * inf`, NaN, on the axis the ray lies in.
        for (axis, along) in [(0, 1), (1, 2), (2, 0)] {
            for face in [0.0, 8.0] {
                for sign in [1.0, -1.0] {
                    let (mut o, mut dir) = (Vec3::splat(3.5), Vec3::ZERO);
                    o[axis] = face;
                    o[along] = 4.0 - 6.0 * sign;
                    dir[along] = sign;
                    rays.push(Ray::new(place(o), dir));
                }
            }
        }
        for &kind in AccelKind::ALL {
            let g = build_geometry(&d, &AccelConfig::from(kind)).unwrap();
            assert!(g.sweeps(), "{kind}: three cubes of 768 triangles are swept");
            for t_max in [f32::INFINITY, 1.0] {
                let what = format!("{kind}, scale {scale}, offset {offset}");
                let hits = check_batches(&g, &rays, t_max, &[rays.len()], &what);
                assert!(hits > rays.len() / 3, "{what}, t_max {t_max}: only {hits} hits");
            }
        }
    }
}

/// `random_scene` with instances of instances (each instance shown again, moved on from where it is)
/// and a translation over the shutter interval on every other object, plus a moving plane.
fn moving_scene(rng: &mut Lcg) -> SceneDesc {
    let mut d = random_scene(rng);
    for i in 0..d.objects.len() {
        if let ShapeDesc::Instance { base } = d.objects[i].shape {
            let on_top = d.objects[i].transform.then(&Transform::translate(rng.v(6.0)));
            d.objects.push(object("MeshInstance", ShapeDesc::Instance { base }, on_top));
        }
    }
    for o in d.objects.iter_mut().step_by(2) {
        o.motion = rng.v(8.0);
    }
    let mut plane =
        object("Plane", ShapeDesc::Plane { point: Vec3::new(0.0, -9.0, 0.0), normal: Vec3::Y }, Transform::IDENTITY);
    plane.motion = Vec3::new(0.0, 4.0, 0.0);
    d.objects.push(plane);
    d
}

/// The scene as it stands at `time`: every motion baked into its object's transform.
fn frozen_at(d: &SceneDesc, time: f32) -> SceneDesc {
    let mut f = d.clone();
    for o in &mut f.objects {
        o.transform = o.transform.then(&Transform::translate(o.motion * time));
        o.motion = Vec3::ZERO;
    }
    f
}

#[test]
fn two_level_moving_objects_match_brute_force_at_random_times() {
    let mut rng = Lcg(31);
    let mut hits = 0;
    for _ in 0..3 {
        let d = moving_scene(&mut rng);
        let brute = build_geometry(&d, &AccelConfig::from(AccelKind::Brute)).unwrap();
        assert!(brute.has_motion());
        let rays: Vec<Ray> = (0..4_000)
            .map(|_| {
                let o = rng.v(30.0);
                Ray::new(o, rng.v(12.0) - o).with_time(rng.f())
            })
            .collect();
        let want: Vec<_> = rays.iter().map(|r| brute.intersect(r, f32::INFINITY)).collect();
        hits += want.iter().filter(|h| h.is_some()).count();
        for &kind in AccelKind::ALL {
            let g = build_geometry(&d, &AccelConfig::from(kind)).unwrap();
            for (ray, want) in rays.iter().zip(&want) {
                let got = g.intersect(ray, f32::INFINITY);
                assert_eq!(want.map(|h| (h.prim, h.sub, h.t)), got.map(|h| (h.prim, h.sub, h.t)), "{kind} on {ray:?}");
                let t_max = want.map_or(50.0, |h| h.t * 0.999);
                assert_eq!(brute.occluded(ray, t_max), g.occluded(ray, t_max), "{kind} occluded on {ray:?}");
            }
            let mut out = vec![None; rays.len()];
            g.intersect_many(&rays, f32::INFINITY, &mut out);
            assert_eq!(out, want, "{kind}: batches at random times");
        }
    }
    assert!(hits > 3_000, "too few hits: {hits}");
}

#[test]
fn two_level_a_moving_object_is_where_its_motion_puts_it_at_the_rays_time() {
    // Against the same scene frozen at the ray's time (motion baked into transforms, bounds computed
    // afresh): the same primitive at the same distance up to rounding. Far from their time-0 place,
    // moving objects are only found through the swept boxes.
    let mut rng = Lcg(37);
    let d = moving_scene(&mut rng);
    let g = build_geometry(&d, &AccelConfig::default()).unwrap();
    let (mut agree, mut total, mut moved_hits) = (0, 0, 0);
    for time in [0.0, 0.25, 0.6, 0.999] {
        let frozen = build_geometry(&frozen_at(&d, time), &AccelConfig::default()).unwrap();
        assert!(!frozen.has_motion());
        for _ in 0..5_000 {
            let o = rng.v(30.0);
            let ray = Ray::new(o, rng.v(12.0) - o);
            match (g.intersect(&ray.with_time(time), f32::INFINITY), frozen.intersect(&ray, f32::INFINITY)) {
                (None, None) => {}
                (Some(a), Some(b)) => {
                    total += 1;
                    assert!((a.t - b.t).abs() <= 1e-3 * a.t.max(1.0), "time {time}: t {} vs {}", a.t, b.t);
                    if (a.prim, a.sub) == (b.prim, b.sub) {
                        agree += 1;
                        moved_hits += (time > 0.0 && a.prim % 2 == 0) as usize;
                    }
                }
                _ => total += 1,
            }
        }
    }
    assert!(moved_hits > 1_000, "too few hits on moved objects: {moved_hits}");
    assert!(agree as f64 >= 0.999 * total as f64, "{agree} of {total} hits on the same primitive");
}

/// A bumpy `n` x `n` grid of quads (2n² triangles).
fn grid(n: u32) -> Arc<TriangleMesh> {
    let at = |i: u32, j: u32| Vec3::new(i as f32, j as f32, ((i * 7 + j * 13) % 5) as f32 * 0.3);
    let positions = (0..=n).flat_map(|j| (0..=n).map(move |i| at(i, j))).collect();
    let v = |i: u32, j: u32| j * (n + 1) + i;
    let indices = (0..n)
        .flat_map(|j| {
            (0..n).flat_map(move |i| [[v(i, j), v(i + 1, j), v(i + 1, j + 1)], [v(i, j), v(i + 1, j + 1), v(i, j + 1)]])
        })
        .collect();
    Arc::new(TriangleMesh { positions, indices, ..Default::default() })
}

#[test]
fn two_level_build_time_is_the_wall_time_of_the_parallel_build() {
    // Eight meshes built on four threads: the structures' own build times, summed, exceed the wall
    // time of the whole build. What is reported must not (a consistency check, not a speed check).
    let meshes: Vec<ObjectDesc> = (0..8)
        .map(|k| {
            object(
                &format!("m{k}"),
                ShapeDesc::Mesh { source: MeshSource::Inline(grid(70)), smooth: false },
                Transform::translate(Vec3::new(0.0, 0.0, k as f32)),
            )
        })
        .collect();
    let d = desc(meshes);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(4).build().unwrap();
    for kind in [AccelKind::KdTree, AccelKind::BvhSah, AccelKind::Octree] {
        let start = std::time::Instant::now();
        let g = pool.install(|| build_geometry(&d, &AccelConfig::from(kind))).unwrap();
        let elapsed = start.elapsed();
        let built = g.accel_stats().build_time;
        assert!(
            built > std::time::Duration::ZERO && built <= elapsed,
            "{kind}: built in {built:?}, {elapsed:?} in all"
        );
    }
}
