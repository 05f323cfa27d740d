//! The packet traversal against brute force, bit for bit, on rays that form packets: parallel rays
//! aimed exactly at a grid's vertices and edges (zero direction components, so infinite reciprocals and
//! NaN slab products), a pinhole camera's rays, oblique parallel rays, rays grazing the grid's plane,
//! ties between duplicated triangles, and packets broken by rays that trivially miss or end early.

use super::packet::{packet_len, MIN_PACKET, PACKET};
use super::{intersect_coherent_with, Kernel};
use crate::accel::bvh::tests::{bits, kernels, soup, Opaque};
use crate::accel::bvh::{Bvh, BvhParams};
use crate::accel::watertight_tests::grid;
use crate::accel::{Accel, BruteForce};
use crate::geometry::TriangleMesh;
use crate::math::{Ray, Vec3};

/// A 24 x 24 grid in `z = 0` (vertices on the integers), its first 60 triangles again (ties, the lower
/// index wins), the grid as a wall in `y = 30`, and a soup of 400 triangles above the floor.
fn scene() -> TriangleMesh {
    let mut mesh = grid(24);
    let again: Vec<[u32; 3]> = mesh.indices[..60].to_vec();
    mesh.indices.extend(again);
    // The grid again as a wall in `y = 30` (its vertices on the integers in x and z).
    let wall = grid(24);
    let base = mesh.positions.len() as u32;
    mesh.positions.extend(wall.positions.iter().map(|p| Vec3::new(p.x, 30.0, p.y)));
    mesh.indices.extend(wall.indices.iter().map(|t| t.map(|i| i + base)));
    let above = soup(400, 7);
    let base = mesh.positions.len() as u32;
    mesh.positions.extend(above.positions.iter().map(|p| *p * 2.4 + Vec3::new(0.0, 0.0, 1.0)));
    mesh.indices.extend(above.indices.iter().map(|t| t.map(|i| i + base)));
    mesh
}

/// The ray sets, in the order a scanner or a camera makes them, each with its `t_max`s.
fn sets() -> Vec<(&'static str, Vec<Ray>, Vec<f32>)> {
    // Sixteenths (exact in `f32`): every 16th ray of a row is aimed at the grid's vertices or edges.
    let steps = |n: u32| (0..n).map(move |k| k as f32 / 16.0);
    // Rows of 16 rays from an integer x, so that packets start on the planes of boxes (their extreme
    // origin on a plane, a zero direction component: NaN slab products), as do whole rows at integer y.
    let down: Vec<Ray> = steps(97)
        .flat_map(|y| {
            [0.0, 3.0, 7.0].into_iter().flat_map(move |j| {
                steps(16).map(move |x| Ray::new(Vec3::new(j + x, y, 30.0), Vec3::new(0.0, 0.0, -1.0)))
            })
        })
        .collect();
    // At the wall along +y: x and z components zero, z (the last axis tested) on the wall's planes.
    let ahead: Vec<Ray> = steps(97)
        .flat_map(|z| {
            [0.0, 3.0].into_iter().flat_map(move |j| {
                steps(16).map(move |x| Ray::new(Vec3::new(j + x, -5.0, z), Vec3::new(0.0, 1.0, 0.0)))
            })
        })
        .collect();
    let eye = Vec3::new(12.0, -10.0, 15.0);
    let camera: Vec<Ray> =
        steps(97).flat_map(|y| steps(97).map(move |x| Ray::new(eye, Vec3::new(x, y, 0.0) / 2.0 - eye))).collect();
    let oblique: Vec<Ray> = steps(97)
        .flat_map(|y| steps(97).map(move |x| Ray::new(Vec3::new(x - 3.0, y - 2.0, 10.0), Vec3::new(0.3, 0.2, -1.0))))
        .collect();
    // In the grid's plane (edge-on: no hits) and level through the soup, both with zero y and z.
    let grazing: Vec<Ray> = steps(97).map(|y| Ray::new(Vec3::new(-1.0, y, 0.0), Vec3::new(1.0, 0.0, 0.0))).collect();
    let level: Vec<Ray> =
        steps(385).map(|z| Ray::new(Vec3::new(-1.0, 12.0, 1.0 + z), Vec3::new(1.0, 0.0, 0.0))).collect();
    let far = |n: usize| vec![100.0; n];
    // Every third camera ray ends before the grid; some rays of the scan trivially miss.
    let short: Vec<f32> = (0..camera.len()).map(|i| if i % 3 == 0 { 15.0 } else { 100.0 }).collect();
    let mut broken = down.clone();
    for k in (5..broken.len()).step_by(37) {
        broken[k] = Ray::new(Vec3::NAN, Vec3::X);
    }
    let mut broken_t = far(broken.len());
    broken_t[100] = -1.0;
    vec![
        ("down", down.clone(), far(down.len())),
        ("ahead", ahead.clone(), far(ahead.len())),
        ("camera", camera.clone(), far(camera.len())),
        ("camera, short t_max", camera, short),
        ("oblique", oblique.clone(), far(oblique.len())),
        ("grazing", grazing.clone(), far(grazing.len())),
        ("level", level.clone(), far(level.len())),
        ("down, broken", broken, broken_t),
    ]
}

#[test]
fn bvh_packets_of_coherent_rays_keep_brute_forces_hits_with_every_kernel_and_leaf_kind() {
    let mesh = scene();
    let opaque = Opaque(&mesh);
    let brute = BruteForce::build(&mesh);
    let with_copy = Bvh::build_sah(&mesh, &BvhParams::default());
    let without = Bvh::build_sah(&opaque, &BvhParams::default());
    let size = (mesh.bounds().max - mesh.bounds().min).length();
    for (name, rays, t_max) in sets() {
        // These rays do form packets: the test below runs the packet traversal.
        let len = packet_len(&rays[8..], &t_max[8..], size);
        assert!((MIN_PACKET..=PACKET).contains(&len), "{name}: a packet of {len}");
        let want: Vec<_> = rays.iter().zip(&t_max).map(|(r, &t)| bits(brute.intersect(&mesh, r, t))).collect();
        let hits = want.iter().filter(|h| h.is_some()).count();
        assert!(name == "grazing" || 8 * hits >= rays.len(), "{name}: the rays must hit ({hits} of {})", rays.len());
        // Through the trait, as the Python module calls it.
        let mut out = vec![None; rays.len()];
        with_copy.intersect_many_coherent(&mesh, &rays, &t_max, &mut out);
        assert_eq!(out.iter().map(|&h| bits(h)).collect::<Vec<_>>(), want, "{name}, intersect_many_coherent");
        for k in kernels().into_iter().chain([Kernel::Scalar]) {
            let mut out = vec![None; rays.len()];
            intersect_coherent_with(k, &with_copy.wide, &with_copy.prim_indices, &mesh, &rays, &t_max, &mut out);
            for (i, h) in out.iter().enumerate() {
                assert_eq!(bits(*h), want[i], "{name}, {k:?}, mesh leaves, ray {i} {:?}", rays[i]);
            }
            intersect_coherent_with(k, &without.wide, &without.prim_indices, &opaque, &rays, &t_max, &mut out);
            for (i, h) in out.iter().enumerate() {
                assert_eq!(bits(*h), want[i], "{name}, {k:?}, primitive leaves, ray {i} {:?}", rays[i]);
            }
        }
    }
}

#[test]
fn bvh_packets_form_only_from_rays_that_agree() {
    let size = 10.0;
    const D: Vec3 = Vec3::new(0.0, 0.0, -1.0);
    let row = |dir: fn(usize) -> Vec3| {
        (0..PACKET).map(|i| Ray::new(Vec3::new(i as f32 * 0.01, 0.0, 5.0), dir(i))).collect::<Vec<_>>()
    };
    let t = vec![10.0; PACKET];
    assert_eq!(packet_len(&row(|_| Vec3::new(0.0, 0.0, -1.0)), &t, size), PACKET);
    // A direction whose x turns from zero (an infinite reciprocal) to a finite one ends the packet.
    assert_eq!(packet_len(&row(|i| Vec3::new(if i < 5 { 0.0 } else { 1e-3 }, 0.0, -1.0)), &t, size), 5);
    // Opposite signs, another major axis, too wide a spread: fewer than the fewest.
    assert_eq!(packet_len(&row(|i| Vec3::new(if i == 2 { -1e-3 } else { 1e-3 }, 0.0, -1.0)), &t, size), 0);
    assert_eq!(packet_len(&row(|i| if i == 3 { Vec3::X } else { D }), &t, size), 0);
    assert_eq!(packet_len(&row(|i| Vec3::new(0.05 * i as f32, 0.0, -1.0)), &t, size), 0);
    let mut far_apart = row(|_| D);
    far_apart[3].origin.x = 3.0;
    assert_eq!(packet_len(&far_apart, &t, size), 0);
    // A first ray that trivially misses starts none.
    assert_eq!(packet_len(&row(|_| D), &[0.0; PACKET], size), 0);
}
