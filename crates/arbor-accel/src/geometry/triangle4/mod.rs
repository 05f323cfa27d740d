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
mod tests;
