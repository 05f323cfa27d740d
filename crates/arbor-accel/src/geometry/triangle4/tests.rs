//! Tests of the four-triangle test: lane by lane the scalar watertight test's result, bit for bit, on
//! hand-made and random cases (culling rays, fallback lanes, scaled and subnormal inputs included).

use super::*;
use crate::geometry::TriHit;
use crate::math::Ray;
use crate::test_rng::Rng;

fn int(rng: &mut Rng, n: usize) -> usize {
    ((rng.f32() * n as f32) as usize).min(n - 1)
}

fn range(rng: &mut Rng, lo: f32, hi: f32) -> f32 {
    lo + (hi - lo) * rng.f32()
}

/// A point on the quarter grid in `[-2, 2]^3`.
fn grid(rng: &mut Rng) -> Vec3 {
    Vec3::new(int(rng, 17) as f32 - 8.0, int(rng, 17) as f32 - 8.0, int(rng, 17) as f32 - 8.0) * 0.25
}

/// A small integer vector (each component in -2..=2), not zero.
fn small_int_dir(rng: &mut Rng) -> Vec3 {
    loop {
        let d = Vec3::new(int(rng, 5) as f32 - 2.0, int(rng, 5) as f32 - 2.0, int(rng, 5) as f32 - 2.0);
        if d != Vec3::ZERO {
            return d;
        }
    }
}

const SPECIAL: [f32; 8] = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, f32::MAX, -f32::MAX, 1e-45, 0.0, -0.0];

/// A ray: random, axis-aligned (either sign), or on the grid with a small integer direction, the
/// last two being where edge functions come out exactly zero.
fn random_ray(rng: &mut Rng) -> Ray {
    let (origin, dir) = match int(rng, 4) {
        0 => (rng.vec3() * 4.0 - 2.0, rng.vec3() * 2.0 - 1.0),
        1 => {
            let mut d = Vec3::ZERO;
            d[int(rng, 3)] = if rng.f32() < 0.5 { -1.0 } else { 1.0 } * [1.0, 0.5, 3.0][int(rng, 3)];
            (grid(rng), d)
        }
        _ => (grid(rng), small_int_dir(rng)),
    };
    let dir = match int(rng, 12) {
        0 => dir * 1e-30,
        1 => dir * 1e30,
        2 => dir * 1e-38,
        _ => dir,
    };
    Ray::new(origin, dir)
}

/// A triangle near the ray: random around a point of the ray, with a vertex or an edge exactly
/// through such a point, on the grid, degenerate, with special-valued coordinates, sharing an edge
/// with `prev`, or close to the origin.
fn random_triangle(rng: &mut Rng, ray: &Ray, prev: Option<[Vec3; 3]>) -> [Vec3; 3] {
    // A point of the ray at a small integer (on-grid for grid rays) or random parameter.
    let s = if rng.f32() < 0.5 { int(rng, 4) as f32 } else { range(rng, -0.5, 3.0) };
    let q = ray.origin + s * ray.dir;
    let off = |rng: &mut Rng| {
        if rng.f32() < 0.5 {
            grid(rng)
        } else {
            rng.vec3() * 2.0 - 1.0
        }
    };
    match int(rng, 15) {
        0 => [q + off(rng), q + off(rng), q + off(rng)],
        13 | 14 => {
            // Grazing: nearly parallel to the ray, reaching far along it both ways, crossing it at a
            // t of the order of its own error bound (log-uniform around it), which decides there.
            let a = [1.0, 30.0, 1e3][int(rng, 3)];
            let t0 = a * f32::EPSILON * (2.0f32).powi(int(rng, 12) as i32 - 2);
            let h = ray.origin + t0 * ray.dir;
            let (w1, w2) = (rng.vec3() * 2.0 - 1.0, rng.vec3() * 2.0 - 1.0);
            [h + a * ray.dir + w1, h - a * ray.dir + w2, h - w1 - w2]
        }
        10..=12 => {
            // q is the centroid: a hit unless degenerate or behind.
            let (u, v) = (rng.vec3() * 2.0 - 1.0, rng.vec3() * 2.0 - 1.0);
            [q + u, q + v, q - u - v]
        }
        1 => [q, q + off(rng), q + off(rng)],
        2 => {
            let u = off(rng);
            [q + u, q - u, q + off(rng)]
        }
        3 => [grid(rng), grid(rng), grid(rng)],
        4 => {
            let (p, u) = (q + off(rng), off(rng));
            match int(rng, 3) {
                0 => [p, p, q + off(rng)],
                1 => [p, p + u, p + 2.0 * u],
                _ => [p, p, p],
            }
        }
        5 => {
            let mut t = [q + off(rng), q + off(rng), q + off(rng)];
            t[int(rng, 3)][int(rng, 3)] = SPECIAL[int(rng, SPECIAL.len())];
            t
        }
        6 | 7 if prev.is_some() => {
            let [p0, p1, _] = prev.unwrap();
            [p1, p0, q + off(rng)]
        }
        8 => {
            let tiny = [0.0, 1e-7, -1e-7, 1e-30, 1e-20, f32::MIN_POSITIVE, 1e-44][int(rng, 7)];
            let q = ray.origin + tiny * ray.dir;
            let u = off(rng);
            [q + u, q - u + off(rng) * 0.01, q + off(rng)]
        }
        _ => [ray.origin + range(rng, 0.0, 3.0) * ray.dir + off(rng) * 0.01, q + off(rng), q + off(rng)],
    }
}

fn bits(h: Option<TriHit>) -> Option<[u32; 3]> {
    h.map(|h| [h.t.to_bits(), h.b1.to_bits(), h.b2.to_bits()])
}

/// Whether the scalar test would take the double-precision fallback on `tri` (for coverage only).
fn takes_fallback(f: &RayFrame, [p0, p1, p2]: [Vec3; 3]) -> bool {
    let shear = |p: Vec3| {
        let q = p - f.origin;
        (q[f.kx] + f.sx * q[f.kz], q[f.ky] + f.sy * q[f.kz])
    };
    let ((ax, ay), (bx, by), (cx, cy)) = (shear(p0), shear(p1), shear(p2));
    bx * cy - by * cx == 0.0 || cx * ay - cy * ax == 0.0 || ax * by - ay * bx == 0.0
}

#[derive(Default, Debug)]
struct Coverage {
    lanes: u64,
    hits: u64,
    fallback_lanes: u64,
    fallback_hits: u64,
    culling_hits: u64,
    t_max_at_hit_kept: u64,
    t_max_at_hit_rejected: u64,
    scaled_hits: u64,
    subnormal_hits: u64,
}

#[test]
fn tri4_lanes_round_trip_and_padding_copies_the_last() {
    let t = |k: f32| [Vec3::splat(k), Vec3::new(k, 1.0, 2.0), Vec3::new(3.0, k, -k)];
    let four = Tri4::new(&[t(1.0), t(2.0), t(3.0), t(4.0)]);
    for l in 0..4 {
        assert_eq!(four.lane(l), t(l as f32 + 1.0));
    }
    let two = Tri4::new(&[t(1.0), t(2.0)]);
    assert_eq!([two.lane(0), two.lane(1), two.lane(2), two.lane(3)], [t(1.0), t(2.0), t(2.0), t(2.0)]);
    assert_eq!(std::mem::size_of::<Tri4>(), 144);
    assert_eq!(std::mem::align_of::<Tri4>(), 16);
}

#[test]
fn tri4_matches_scalar_bit_for_bit() {
    let mut rng = Rng(0x7121_4a4e_5eed_0001);
    let mut cov = Coverage::default();
    for case in 0..1_000_000u32 {
        let mut ray = random_ray(&mut rng);
        let n = 1 + int(&mut rng, 4);
        let mut tris: Vec<[Vec3; 3]> = Vec::with_capacity(n);
        for _ in 0..n {
            let prev = tris.last().copied();
            tris.push(random_triangle(&mut rng, &ray, prev));
        }
        // Huge and tiny scenes: scale the origin and the triangles together.
        // The scaled t is cubic in the coordinates: it overflows at 1e13 and is subnormal at 1e-13,
        // so huge and tiny scenes test the non-finite and underflow paths, the others hit. A large
        // translation makes every coordinate difference round.
        let scale = match int(&mut rng, 16) {
            0 => 1e30,
            1 => 1e-30,
            2 => 1e12,
            3 => 1e-12,
            4 => 1e-14,
            5 => 3e-13,
            _ => 1.0,
        };
        let shift = if int(&mut rng, 16) == 0 { Vec3::new(1e6, -3e5, 7e4) } else { Vec3::ZERO };
        if scale != 1.0 || shift != Vec3::ZERO {
            ray = Ray::new(ray.origin * scale + shift, ray.dir);
            for t in &mut tris {
                *t = t.map(|p| p * scale + shift);
            }
        }
        // Hits at subnormal and tiny t: triangles in the plane through 0 across the major axis, the
        // origin a tiny distance off it (their scaled t and `t_max * det` are subnormal).
        if int(&mut rng, 10) == 0 {
            let k = RayFrame::new(&ray).kz;
            let tiny = [1e-40, 3e-42, 1e-44, 2e-38, 1e-30, 1e-7][int(&mut rng, 6)] * range(&mut rng, 0.5, 8.0);
            ray.origin[k] = -ray.dir[k].signum() * tiny;
            let mut o = ray.origin;
            o[k] = 0.0;
            for t in &mut tris {
                let (u, v) = (rng.vec3() * 2.0 - 1.0, rng.vec3() * 2.0 - 1.0);
                *t = [o + u, o + v, o - u - v].map(|mut p| {
                    p[k] = 0.0;
                    p
                });
                if rng.f32() < 0.3 {
                    t[int(&mut rng, 3)][k] = [1e-40, -1e-40, 1e-44, 0.5][int(&mut rng, 4)];
                }
            }
        }
        let cull = int(&mut rng, 8) == 0;
        ray = ray.with_culling(cull);
        let f = RayFrame::new(&ray);
        let tri4 = Tri4::new(&tris);
        let lanes = if rng.f32() < 0.5 { 0xf } else { int(&mut rng, 32) as u32 };
        let scalar = |l: usize, t_max: f32| {
            let [p0, p1, p2] = tri4.lane(l);
            intersect_triangle_in(&f, p0, p1, p2, t_max)
        };
        // t_max: infinite, random, at a hit's t or one ulp either side, or special.
        let probe = scalar(int(&mut rng, 4), f32::INFINITY);
        let t_max = match int(&mut rng, 8) {
            0 | 1 => f32::INFINITY,
            2 => range(&mut rng, 0.0, 4.0) * scale,
            3 | 4 => probe.map_or(f32::INFINITY, |h| h.t),
            5 => probe.map_or(1.0, |h| h.t.next_up()),
            6 => probe.map_or(1.0, |h| f32::from_bits(h.t.to_bits() - 1)),
            _ => [0.0, -1.0, f32::NAN, f32::MAX, 1e-45, f32::MIN_POSITIVE, f32::NEG_INFINITY][int(&mut rng, 7)],
        };

        let got = intersect_triangles4(&f, &tri4, lanes, t_max);
        assert_eq!(got.mask & !lanes & 0xf, 0, "case {case}: hit reported in an unrequested lane");
        assert_eq!(got.mask >> 4, 0, "case {case}: mask bits above lane 3");
        for l in 0..4 {
            let want = if lanes & (1 << l) != 0 { scalar(l, t_max) } else { None };
            let have = (got.mask & (1 << l) != 0).then(|| TriHit { t: got.t[l], b1: got.b1[l], b2: got.b2[l] });
            assert_eq!(
                bits(have),
                bits(want),
                "case {case}, lane {l}: ray {ray:?}, triangle {:?}, t_max {t_max:e}, lanes {lanes:#x}: \
                 4-wide {have:?}, scalar {want:?}",
                tri4.lane(l)
            );
            if lanes & (1 << l) != 0 {
                cov.lanes += 1;
                let fb = takes_fallback(&f, tri4.lane(l));
                cov.fallback_lanes += fb as u64;
                if let Some(w) = want {
                    cov.hits += 1;
                    cov.fallback_hits += fb as u64;
                    cov.culling_hits += cull as u64;
                    cov.subnormal_hits += (w.t < f32::MIN_POSITIVE) as u64;
                    cov.scaled_hits += (scale != 1.0 || shift != Vec3::ZERO) as u64;
                }
                if let (Some(p), Some(w)) = (probe, want) {
                    if w.t == p.t && t_max == p.t.next_up() {
                        cov.t_max_at_hit_kept += 1;
                    }
                }
                if let Some(p) = probe {
                    if t_max == p.t && want.is_none() && scalar(l, f32::INFINITY).map(|h| h.t) == Some(p.t) {
                        cov.t_max_at_hit_rejected += 1;
                    }
                }
            }
        }
    }
    // The generators must reach the cases they are for.
    eprintln!("{cov:?}");
    assert!(cov.hits > 200_000, "{cov:?}");
    assert!(cov.fallback_lanes > 300_000 && cov.fallback_hits > 30_000, "{cov:?}");
    assert!(cov.culling_hits > 15_000 && cov.scaled_hits > 70_000 && cov.subnormal_hits > 20_000, "{cov:?}");
    assert!(cov.t_max_at_hit_kept > 25_000 && cov.t_max_at_hit_rejected > 50_000, "{cov:?}");
}
