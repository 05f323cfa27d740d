//! One ray against four triangles at once: the leaf test of BVH traversal, with lane by lane the same
//! result, bit for bit, as the scalar watertight test [`intersect_triangle_in`].
//!
//! Why hand-written SIMD: this is the hot loop of every traversal (most of a render's time goes into
//! leaf tests, most of which miss), and the autovectoriser cannot turn the scalar test's early outs
//! and axis permutation into lanes. The triangles are stored structure-of-arrays ([`Tri4`]), so the
//! per-ray axis permutation is only a choice of which axis array to load, and the SSE2 code below
//! repeats the scalar arithmetic operation by operation, in the same order and with the same
//! roundings (no FMA, an exactly rounded division, no reciprocal estimate), so every acceleration
//! structure still returns exactly brute force's hit. The rare lanes the scalar code treats
//! specially (an edge function exactly zero, which takes the double-precision fallback, and
//! back-face culling rays) are handed to the scalar function itself.
//!
//! On targets other than x86_64, and under Miri (which checks the scalar paths), the function is a loop
//! over the lanes calling the scalar test.

use super::triangle::{intersect_triangle_in, RayFrame};
use crate::math::Vec3;

/// Four triangles' corners as structure-of-arrays lanes: `v[corner][axis][lane]` (corner 0,1,2 = p0,p1,p2;
/// axis x,y,z).
#[derive(Debug, Clone, Copy)]
#[repr(C, align(16))]
pub struct Tri4 {
    /// `v[corner][axis][lane]`.
    pub v: [[[f32; 4]; 3]; 3],
}

impl Tri4 {
    /// Up to four triangles; missing lanes are filled with a copy of the last given triangle (callers
    /// mask them off).
    pub fn new(tris: &[[Vec3; 3]]) -> Tri4 {
        assert!(!tris.is_empty() && tris.len() <= 4, "Tri4::new takes 1 to 4 triangles, not {}", tris.len());
        let mut v = [[[0.0f32; 4]; 3]; 3];
        for lane in 0..4 {
            let tri = &tris[lane.min(tris.len() - 1)];
            for (corner, p) in tri.iter().enumerate() {
                for axis in 0..3 {
                    v[corner][axis][lane] = p[axis];
                }
            }
        }
        Tri4 { v }
    }

    /// The corners of lane `l`.
    pub fn lane(&self, l: usize) -> [Vec3; 3] {
        let c = |corner: usize| Vec3::new(self.v[corner][0][l], self.v[corner][1][l], self.v[corner][2][l]);
        [c(0), c(1), c(2)]
    }
}

/// Which lanes hit, and their hits (only lanes whose bit is set in `mask` are meaningful).
#[derive(Debug, Clone, Copy)]
pub struct Tri4Hits {
    /// Bit `l` set when lane `l` hits.
    pub mask: u32,
    /// Ray parameter of each lane's hit.
    pub t: [f32; 4],
    /// Weight of vertex 1 of each lane's hit.
    pub b1: [f32; 4],
    /// Weight of vertex 2 of each lane's hit.
    pub b2: [f32; 4],
}

impl Tri4Hits {
    const NONE: Tri4Hits = Tri4Hits { mask: 0, t: [0.0; 4], b1: [0.0; 4], b2: [0.0; 4] };

    /// Lane `l` from the scalar test.
    #[inline(always)]
    fn set_scalar(&mut self, l: usize, f: &RayFrame, tris: &Tri4, t_max: f32) {
        let [p0, p1, p2] = tris.lane(l);
        if let Some(h) = intersect_triangle_in(f, p0, p1, p2, t_max) {
            self.mask |= 1 << l;
            self.t[l] = h.t;
            self.b1[l] = h.b1;
            self.b2[l] = h.b2;
        }
    }
}

/// `out` with the lanes in `lanes` replaced by the scalar test's results (culling rays, lanes whose
/// edge function is exactly zero, and every lane on targets without the SIMD code).
#[inline(never)]
#[cold]
fn with_scalar(mut out: Tri4Hits, lanes: u32, f: &RayFrame, tris: &Tri4, t_max: f32) -> Tri4Hits {
    for l in 0..4 {
        if lanes & (1 << l) != 0 {
            out.mask &= !(1 << l);
            out.set_scalar(l, f, tris, t_max);
        }
    }
    out
}

/// The hits of the frame's ray with the lanes of `tris` whose bit is set in `lanes` (bits 0..4), in
/// `(0, t_max)`: lane l hits iff `intersect_triangle_in(f, tris.lane(l)..., t_max)` is Some, with
/// identical t/b1/b2 bits.
#[cfg(any(not(target_arch = "x86_64"), miri))]
#[inline(always)]
pub fn intersect_triangles4(f: &RayFrame, tris: &Tri4, lanes: u32, t_max: f32) -> Tri4Hits {
    with_scalar(Tri4Hits::NONE, lanes & 0xf, f, tris, t_max)
}

/// The hits of the frame's ray with the lanes of `tris` whose bit is set in `lanes` (bits 0..4), in
/// `(0, t_max)`: lane l hits iff `intersect_triangle_in(f, tris.lane(l)..., t_max)` is Some, with
/// identical t/b1/b2 bits.
///
/// SSE2 only (the x86_64 baseline) and no `#[target_feature]`, so it inlines into code compiled for
/// any x86_64 level. Each line below is the scalar line of [`intersect_triangle_in`] it repeats.
#[cfg(all(target_arch = "x86_64", not(miri)))]
#[inline(always)]
pub fn intersect_triangles4(f: &RayFrame, tris: &Tri4, lanes: u32, t_max: f32) -> Tri4Hits {
    use std::arch::x86_64::*;

    let lanes = lanes & 0xf;
    if lanes == 0 {
        return Tri4Hits::NONE;
    }
    if f.cull_backfaces {
        // The culling test is a dot product whose rounding would need its own replica; culling rays
        // are rare (primary rays, when asked for), so they take the scalar test.
        return with_scalar(Tri4Hits::NONE, lanes, f, tris, t_max);
    }
    let (kx, ky, kz) = (f.kx, f.ky, f.kz);
    // SAFETY: SSE and SSE2 are part of the x86_64 baseline; the loads read `[f32; 4]` arrays of a
    // 16-byte aligned `Tri4` (each is at a multiple of 16 bytes from its start).
    unsafe {
        let load = |corner: usize, axis: usize| _mm_load_ps(tris.v[corner][axis].as_ptr());
        let zero = _mm_setzero_ps();
        let sign = _mm_set1_ps(-0.0);
        let abs = |x: __m128| _mm_andnot_ps(sign, x);

        // a = permute(p0 - origin), ...: the permutation picks the axis arrays.
        let o = f.origin.to_array();
        let (ox, oy, oz) = (_mm_set1_ps(o[kx]), _mm_set1_ps(o[ky]), _mm_set1_ps(o[kz]));
        let mut ax = _mm_sub_ps(load(0, kx), ox);
        let mut ay = _mm_sub_ps(load(0, ky), oy);
        let mut az = _mm_sub_ps(load(0, kz), oz);
        let mut bx = _mm_sub_ps(load(1, kx), ox);
        let mut by = _mm_sub_ps(load(1, ky), oy);
        let mut bz = _mm_sub_ps(load(1, kz), oz);
        let mut cx = _mm_sub_ps(load(2, kx), ox);
        let mut cy = _mm_sub_ps(load(2, ky), oy);
        let mut cz = _mm_sub_ps(load(2, kz), oz);

        // a.x += sx * a.z; ...
        let (sx, sy, sz) = (_mm_set1_ps(f.sx), _mm_set1_ps(f.sy), _mm_set1_ps(f.sz));
        ax = _mm_add_ps(ax, _mm_mul_ps(sx, az));
        ay = _mm_add_ps(ay, _mm_mul_ps(sy, az));
        bx = _mm_add_ps(bx, _mm_mul_ps(sx, bz));
        by = _mm_add_ps(by, _mm_mul_ps(sy, bz));
        cx = _mm_add_ps(cx, _mm_mul_ps(sx, cz));
        cy = _mm_add_ps(cy, _mm_mul_ps(sy, cz));

        // e0 = b.x * c.y - b.y * c.x; ...
        let e0 = _mm_sub_ps(_mm_mul_ps(bx, cy), _mm_mul_ps(by, cx));
        let e1 = _mm_sub_ps(_mm_mul_ps(cx, ay), _mm_mul_ps(cy, ax));
        let e2 = _mm_sub_ps(_mm_mul_ps(ax, by), _mm_mul_ps(ay, bx));
        // Lanes with an edge function exactly zero (-0.0 included, NaN not) take the scalar test and
        // its double-precision fallback.
        let any_zero = _mm_or_ps(_mm_or_ps(_mm_cmpeq_ps(e0, zero), _mm_cmpeq_ps(e1, zero)), _mm_cmpeq_ps(e2, zero));
        let fallback = _mm_movemask_ps(any_zero) as u32 & lanes;

        // Rejected when (e0 < 0 || e1 < 0 || e2 < 0) && (e0 > 0 || e1 > 0 || e2 > 0) (false on NaN).
        let any_neg = _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(e0, zero), _mm_cmplt_ps(e1, zero)), _mm_cmplt_ps(e2, zero));
        let any_pos = _mm_or_ps(_mm_or_ps(_mm_cmpgt_ps(e0, zero), _mm_cmpgt_ps(e1, zero)), _mm_cmpgt_ps(e2, zero));
        // det = e0 + e1 + e2; rejected when det == 0.0 || !det.is_finite(): kept iff |det| < inf
        // (false on NaN) and det != 0.
        let det = _mm_add_ps(_mm_add_ps(e0, e1), e2);
        let det_ok = _mm_and_ps(_mm_cmplt_ps(abs(det), _mm_set1_ps(f32::INFINITY)), _mm_cmpneq_ps(det, zero));
        let mut ok = _mm_andnot_ps(_mm_and_ps(any_neg, any_pos), det_ok);
        let simd_lanes = lanes & !fallback;
        if _mm_movemask_ps(ok) as u32 & simd_lanes == 0 {
            // Every lane missed (the common case) or takes the fallback.
            return finish(Tri4Hits::NONE, fallback, f, tris, t_max);
        }

        // a.z *= sz; ...
        az = _mm_mul_ps(az, sz);
        bz = _mm_mul_ps(bz, sz);
        cz = _mm_mul_ps(cz, sz);
        // t_scaled = e0 * a.z + e1 * b.z + e2 * c.z
        let t_scaled = _mm_add_ps(_mm_add_ps(_mm_mul_ps(e0, az), _mm_mul_ps(e1, bz)), _mm_mul_ps(e2, cz));
        // far = t_max * det * (1.0 + 4.0 * f32::EPSILON)
        let tmax = _mm_set1_ps(t_max);
        let far = _mm_mul_ps(_mm_mul_ps(tmax, det), _mm_set1_ps(1.0 + 4.0 * f32::EPSILON));
        // Rejected when det < 0.0 && (t_scaled >= 0.0 || t_scaled < far), and when
        // det > 0.0 && (t_scaled <= 0.0 || t_scaled > far); each comparison false on NaN as in Rust.
        let reject_neg =
            _mm_and_ps(_mm_cmplt_ps(det, zero), _mm_or_ps(_mm_cmpge_ps(t_scaled, zero), _mm_cmplt_ps(t_scaled, far)));
        let reject_pos =
            _mm_and_ps(_mm_cmpgt_ps(det, zero), _mm_or_ps(_mm_cmple_ps(t_scaled, zero), _mm_cmpgt_ps(t_scaled, far)));
        ok = _mm_andnot_ps(_mm_or_ps(reject_neg, reject_pos), ok);
        // inv_det = 1.0 / det (exactly rounded division); t = t_scaled * inv_det; kept iff t < t_max.
        let inv_det = _mm_div_ps(_mm_set1_ps(1.0), det);
        let t = _mm_mul_ps(t_scaled, inv_det);
        ok = _mm_and_ps(ok, _mm_cmplt_ps(t, tmax));
        if _mm_movemask_ps(ok) as u32 & simd_lanes == 0 {
            return finish(Tri4Hits::NONE, fallback, f, tris, t_max);
        }

        // The error bound of t, as in the scalar code. `max_element` is `x.max(y.max(z))` with Rust's
        // NaN-ignoring max, `_mm_max_ps` is not; they agree on every lane that can still hit: there
        // det is finite, so are all of e and the sheared x and y (a NaN or infinite one makes an edge
        // function non-finite), and a NaN z would have made t NaN and failed `t < t_max`.
        let max3 = |x: __m128, y: __m128, z: __m128| _mm_max_ps(abs(x), _mm_max_ps(abs(y), abs(z)));
        let gamma = |n: f32| (n * f32::EPSILON * 0.5) / (1.0 - n * f32::EPSILON * 0.5);
        let (g2, g3, g5) = (_mm_set1_ps(gamma(2.0)), _mm_set1_ps(gamma(3.0)), _mm_set1_ps(gamma(5.0)));
        let max_zt = max3(az, bz, cz);
        let delta_z = _mm_mul_ps(g3, max_zt);
        let max_xt = max3(ax, bx, cx);
        let max_yt = max3(ay, by, cy);
        let delta_x = _mm_mul_ps(g5, _mm_add_ps(max_xt, max_zt));
        let delta_y = _mm_mul_ps(g5, _mm_add_ps(max_yt, max_zt));
        // delta_e = 2.0 * (gamma(2.0) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt)
        let delta_e = _mm_mul_ps(
            _mm_set1_ps(2.0),
            _mm_add_ps(
                _mm_add_ps(_mm_mul_ps(_mm_mul_ps(g2, max_xt), max_yt), _mm_mul_ps(delta_y, max_xt)),
                _mm_mul_ps(delta_x, max_yt),
            ),
        );
        let max_e = max3(e0, e1, e2);
        // delta_t = 3.0 * (gamma(3.0) * max_e * max_zt + delta_e * max_zt + delta_z * max_e) * inv_det.abs()
        let delta_t = _mm_mul_ps(
            _mm_mul_ps(
                _mm_set1_ps(3.0),
                _mm_add_ps(
                    _mm_add_ps(_mm_mul_ps(_mm_mul_ps(g3, max_e), max_zt), _mm_mul_ps(delta_e, max_zt)),
                    _mm_mul_ps(delta_z, max_e),
                ),
            ),
            abs(inv_det),
        );
        // Rejected when t <= delta_t: kept iff !(t <= delta_t) (true on NaN, as in Rust).
        ok = _mm_and_ps(ok, _mm_cmpnle_ps(t, delta_t));

        let mut out = Tri4Hits::NONE;
        out.mask = _mm_movemask_ps(ok) as u32 & simd_lanes;
        _mm_storeu_ps(out.t.as_mut_ptr(), t);
        _mm_storeu_ps(out.b1.as_mut_ptr(), _mm_mul_ps(e1, inv_det));
        _mm_storeu_ps(out.b2.as_mut_ptr(), _mm_mul_ps(e2, inv_det));
        finish(out, fallback, f, tris, t_max)
    }
}

/// `out` with the lanes in `fallback` replaced by the scalar test's results.
#[cfg(all(target_arch = "x86_64", not(miri)))]
#[inline(always)]
fn finish(mut out: Tri4Hits, fallback: u32, f: &RayFrame, tris: &Tri4, t_max: f32) -> Tri4Hits {
    if fallback != 0 {
        out = with_scalar(out, fallback, f, tris, t_max);
    }
    out
}

#[cfg(test)]
mod tests {
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
                5 => probe.map_or(1.0, |h| f32::from_bits(h.t.to_bits() + 1)),
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
                        if w.t == p.t && t_max == f32::from_bits(p.t.to_bits() + 1) {
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
}
