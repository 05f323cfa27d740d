//! Watertightness of the triangle test at shared vertices and edges: oblique rays aimed exactly at the
//! vertices and edges of an integer grid, and at the centre of a fan of triangles, each cross the
//! surface exactly once, for the scalar test, the four-lane test and every structure.
//!
//! A crossing: the hits of one ray, grouped when they lie on the same edge or vertex. A hit's support
//! is the set of its triangle's corners with nonzero weight (a weight is exactly zero exactly when its
//! edge function is): three for a face, two for an edge, one for a vertex. Two hits are one crossing
//! when neither is a face and one's support holds the other's.
//!
//! These failed before each edge function's double-precision fallback was decided edge by edge: about
//! 1% of the grid's vertex-aimed rays hit nothing (`geometry/triangle.rs`).

use super::{build, AccelKind};
use crate::geometry::{intersect_triangle_in, intersect_triangles4, RayFrame, Tri4, TriHit, TriangleMesh};
use crate::math::{Ray, Vec3};
use crate::test_rng::Rng;

/// An `n` x `n` grid of unit squares in `z = 0`, two triangles each, vertices on the integers.
pub(super) fn grid(n: u32) -> TriangleMesh {
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            positions.push([i as f32, j as f32, 0.0]);
        }
    }
    let mut triangles = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i;
            let (b, c, d) = (a + 1, a + n + 2, a + n + 1);
            triangles.extend([[a, b, c], [a, c, d]]);
        }
    }
    TriangleMesh::from_arrays(positions, triangles).unwrap()
}

/// A closed fan of `k` triangles around a centre (vertex 0), all on a grid of 1/64, flat enough that
/// every ray of the test sees all its triangles from the same side (a fan folded over in the ray's view
/// could rightly be crossed twice or not at all). With `compass` (`k` of 4 or 8), the spokes run along
/// the axes and diagonals in the centre's plane, as in the integer grid: sheared corners then land
/// exactly on the lines of a ray's frame most often. Otherwise the rim is at uneven angles, radii and
/// heights.
fn fan(rng: &mut Rng, k: u32, compass: bool) -> TriangleMesh {
    let centre = Vec3::new(1.0, -2.0, 0.5);
    let mut positions = vec![centre.to_array()];
    for i in 0..k {
        let r = 0.5 + rng.f32();
        let p = if compass {
            const DIRS: [[f32; 2]; 8] =
                [[1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [-1.0, 1.0], [-1.0, 0.0], [-1.0, -1.0], [0.0, -1.0], [1.0, -1.0]];
            let [x, y] = DIRS[(i * 8 / k) as usize];
            centre + Vec3::new(r * x, r * y, 0.0)
        } else {
            let angle = (i as f32 + 0.2 + 0.6 * rng.f32()) * std::f32::consts::TAU / k as f32;
            centre + Vec3::new(r * angle.cos(), r * angle.sin(), 0.1 * rng.f32() - 0.05)
        };
        positions.push((p * 64.0).round().to_array().map(|x| x / 64.0));
    }
    let triangles = (0..k).map(|i| [0, 1 + i, 1 + (i + 1) % k]).collect();
    TriangleMesh::from_arrays(positions, triangles).unwrap()
}

/// Uniform in `[0, 1)` with 48 bits, so that origins are not on a float grid of their own.
fn fine(rng: &mut Rng) -> f64 {
    rng.f32() as f64 + rng.f32() as f64 / (1u64 << 24) as f64
}

/// A ray from a random point above `target` (within `spread` sideways) aimed at it: origin and
/// direction are the float32 roundings of the float64 ones.
fn aimed(rng: &mut Rng, target: Vec3, spread: f64) -> Ray {
    let t = target.to_array().map(f64::from);
    let from = [
        t[0] + spread * (2.0 * fine(rng) - 1.0),
        t[1] + spread * (2.0 * fine(rng) - 1.0),
        t[2] + 1.0 + 3.0 * fine(rng),
    ];
    let origin = Vec3::new(from[0] as f32, from[1] as f32, from[2] as f32);
    Ray::new(origin, Vec3::new((t[0] - from[0]) as f32, (t[1] - from[1]) as f32, (t[2] - from[2]) as f32))
}

/// The support of a hit on triangle `tri` (see the module documentation), as a bit set of its corners.
fn support(f: &RayFrame, [p0, p1, p2]: [Vec3; 3], h: &TriHit) -> u32 {
    // The weight of corner 0 is not returned: with the corners rotated, its edge function is the one
    // of the weight of corner 2.
    let rotated = intersect_triangle_in(f, p1, p2, p0, f32::INFINITY).expect("a rotated triangle hits too");
    (rotated.b2 != 0.0) as u32 | ((h.b1 != 0.0) as u32) << 1 | ((h.b2 != 0.0) as u32) << 2
}

/// How many crossings `ray` makes with `mesh` by the scalar test, after checking that the four-lane
/// test gives every triangle the same result, bit for bit.
fn crossings(mesh: &TriangleMesh, ray: &Ray) -> usize {
    let f = RayFrame::new(ray);
    let tris: Vec<[Vec3; 3]> = (0..mesh.len()).map(|i| mesh.triangle(i)).collect();
    let hits: Vec<Option<TriHit>> =
        tris.iter().map(|&[a, b, c]| intersect_triangle_in(&f, a, b, c, f32::INFINITY)).collect();
    let bits = |h: Option<TriHit>| h.map(|h| [h.t, h.b1, h.b2].map(f32::to_bits));
    for (block, chunk) in tris.chunks(4).enumerate() {
        let lanes = intersect_triangles4(&f, &Tri4::new(chunk), (1 << chunk.len()) - 1, f32::INFINITY);
        for l in 0..chunk.len() {
            let lane = (lanes.mask >> l & 1 != 0).then(|| TriHit { t: lanes.t[l], b1: lanes.b1[l], b2: lanes.b2[l] });
            assert_eq!(bits(lane), bits(hits[4 * block + l]), "four-lane test, triangle {}, {ray:?}", 4 * block + l);
        }
    }
    // Supports as sets of mesh vertices, grouped by the module's rule.
    let supports: Vec<Vec<u32>> = (0..mesh.len())
        .filter_map(|i| hits[i].map(|h| (i, h)))
        .map(|(i, h)| {
            let s = support(&f, tris[i], &h);
            (0..3).filter(|k| s >> k & 1 != 0).map(|k| mesh.indices[i][k]).collect()
        })
        .collect();
    let joined = |a: &[u32], b: &[u32]| {
        a.len() < 3 && b.len() < 3 && (a.iter().all(|v| b.contains(v)) || b.iter().all(|v| a.contains(v)))
    };
    let mut group: Vec<usize> = (0..supports.len()).collect();
    for i in 0..supports.len() {
        for j in 0..i {
            if joined(&supports[i], &supports[j]) {
                let (gi, gj) = (group[i], group[j]);
                for x in group.iter_mut().filter(|x| **x == gi || **x == gj) {
                    *x = gi.min(gj);
                }
            }
        }
    }
    (0..group.len()).filter(|&i| group[i] == i).count()
}

/// Every structure returns brute force's hit on `ray`, and there is one.
fn structures_hit(mesh: &TriangleMesh, ray: &Ray) {
    let key = |h: crate::accel::Hit| (h.t.to_bits(), h.prim, h.u.to_bits(), h.v.to_bits());
    let want = build(AccelKind::Brute, mesh).intersect(mesh, ray, f32::INFINITY).map(key);
    assert!(want.is_some(), "brute force: no hit, {ray:?}");
    for &kind in &AccelKind::ALL[1..] {
        let got = build(kind, mesh).intersect(mesh, ray, f32::INFINITY).map(key);
        assert_eq!(got, want, "{kind}, {ray:?}");
    }
}

#[test]
fn oblique_rays_aimed_at_grid_vertices_and_edges_cross_exactly_once() {
    let mesh = grid(16);
    let per_target = if cfg!(miri) { 1 } else { 10 };
    let mut rng = Rng(5);
    let mut failures = Vec::new();
    let mut rays = Vec::new();
    // Vertices, edge midpoints and the midpoints of the squares' diagonals (edges too).
    for j in 2..32 {
        for i in 2..32 {
            for _ in 0..per_target {
                let ray = aimed(&mut rng, Vec3::new(i as f32 * 0.5, j as f32 * 0.5, 0.0), 3.0);
                let n = crossings(&mesh, &ray);
                if n != 1 {
                    failures.push(format!("{n} crossings: {ray:?}"));
                }
                rays.push(ray);
            }
        }
    }
    assert!(failures.is_empty(), "{} of {} rays:\n{}", failures.len(), rays.len(), failures.join("\n"));
    for ray in rays.iter().step_by(if cfg!(miri) { 97 } else { 7 }) {
        structures_hit(&mesh, ray);
    }
}

#[test]
fn oblique_rays_aimed_at_the_centre_of_a_fan_cross_it_exactly_once() {
    let mut rng = Rng(11);
    let (fans, per_fan) = if cfg!(miri) { (2, 10) } else { (40, 250) };
    let mut failures = Vec::new();
    for k in 0..fans {
        let mesh = match k % 4 {
            0 => fan(&mut rng, 4, true),
            2 => fan(&mut rng, 8, true),
            _ => fan(&mut rng, 3 + k as u32 % 10, false),
        };
        let centre = mesh.triangle(0)[0];
        let mut sample = Vec::new();
        for r in 0..per_fan {
            // Aimed at the centre, and at points of the spokes (on the edges up to rounding).
            let target = match r % 3 {
                0 | 1 => centre,
                _ => centre + 0.5 * (mesh.triangle(r % mesh.len())[1] - centre),
            };
            let ray = aimed(&mut rng, target, 1.5);
            let facing = |i: usize| {
                let [a, b, c] = mesh.triangle(i);
                ray.dir.dot((b - a).cross(c - a)) < 0.0
            };
            assert!((0..mesh.len()).all(facing), "the fan is folded in the view of {ray:?}");
            let n = crossings(&mesh, &ray);
            if n != 1 {
                failures.push(format!("fan of {}: {n} crossings: {ray:?}", mesh.len()));
            }
            if r % 25 == 0 {
                sample.push(ray);
            }
        }
        if failures.is_empty() {
            sample.iter().for_each(|ray| structures_hit(&mesh, ray));
        }
    }
    assert!(failures.is_empty(), "{} of {} rays:\n{}", failures.len(), fans * per_fan, failures.join("\n"));
}
