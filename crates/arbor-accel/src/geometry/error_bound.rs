//! Floating-point error bounds of hit points, and ray origins pushed off a surface by them (pbrt-v4,
//! section 6.8 "Managing Rounding Error": `gamma`, the triangle and sphere `pError`, `Transform`'s error
//! propagation and `OffsetRayOrigin`).
//!
//! A hit point is recomputed from the surface's own parameters (barycentrics for a triangle, reprojection
//! onto a sphere or plane) rather than `o + t d`, because that point has an error bounded by a small
//! multiple of its own magnitude, independent of the distance travelled. The bound `p_error` is
//! per component: the true surface point lies in the box `p ± p_error`. Moving the origin along the
//! geometric normal by `|n| · p_error` (then one more float outwards per component) puts it outside that
//! box on the side the new ray leaves, so the ray cannot re-hit its own surface (no acne), while the
//! offset stays tiny (no light leaking through neighbours, as a fixed epsilon can).

use crate::math::{Transform, Vec3};

/// pbrt's `gamma(n)`: bound on the relative error of `n` chained roundings, `n u / (1 - n u)`.
#[inline]
pub fn gamma(n: u32) -> f32 {
    let u = f32::EPSILON * 0.5;
    n as f32 * u / (1.0 - n as f32 * u)
}

/// The point with barycentrics `(1 - b1 - b2, b1, b2)` on triangle `(p0, p1, p2)` and its error bound.
#[inline]
pub fn triangle_point(p: [Vec3; 3], b1: f32, b2: f32) -> (Vec3, Vec3) {
    let b0 = 1.0 - b1 - b2;
    let point = b0 * p[0] + b1 * p[1] + b2 * p[2];
    let err = gamma(7) * ((b0 * p[0]).abs() + (b1 * p[1]).abs() + (b2 * p[2]).abs());
    (point, err)
}

/// The object-space point `p` near the sphere `(center, radius)` moved onto it, and its error bound
/// (pbrt's `gamma(5) |p|` for a sphere at the origin, plus the rounding of adding the centre back).
#[inline]
pub fn sphere_point(p: Vec3, center: Vec3, radius: f32) -> (Vec3, Vec3) {
    let local = p - center;
    let len = local.length();
    let local = if len > 0.0 { local * (radius / len) } else { local };
    let point = center + local;
    let err = gamma(5) * local.abs() + gamma(2) * (local.abs() + center.abs());
    (point, err)
}

/// The point `p` near the plane through `point` with unit normal `n`, projected onto it, and an error
/// bound: the signed distance costs `gamma(4)` of `|p - point| · |n|`, subtracting it along `n` a few more
/// roundings of the result.
#[inline]
pub fn plane_point(p: Vec3, point: Vec3, n: Vec3) -> (Vec3, Vec3) {
    let d = (p - point).dot(n);
    let projected = p - d * n;
    let dist_err = gamma(4) * ((p.abs() + point.abs()).dot(n.abs()));
    let err = gamma(3) * (projected.abs() + point.abs() + (d * n).abs()) + n.abs() * dist_err;
    (projected, err)
}

/// `p` (with error `err`) taken to world space by `t`, and the error of the result (pbrt's
/// `Transform::operator()(Point3fi)`).
#[inline]
pub fn transform_point(t: &Transform, p: Vec3, err: Vec3) -> (Vec3, Vec3) {
    let m = t.m;
    let world = t.point(p);
    let abs_rows = |v: Vec3| {
        Vec3::new(
            m.x_axis.x.abs() * v.x + m.y_axis.x.abs() * v.y + m.z_axis.x.abs() * v.z,
            m.x_axis.y.abs() * v.x + m.y_axis.y.abs() * v.y + m.z_axis.y.abs() * v.z,
            m.x_axis.z.abs() * v.x + m.y_axis.z.abs() * v.y + m.z_axis.z.abs() * v.z,
        )
    };
    let translation = Vec3::new(m.w_axis.x.abs(), m.w_axis.y.abs(), m.w_axis.z.abs());
    let world_err = (gamma(3) + 1.0) * abs_rows(err) + gamma(3) * (abs_rows(p.abs()) + translation);
    (world, world_err)
}

/// The next float towards +infinity (pbrt's `NextFloatUp`).
#[inline]
pub fn next_float_up(v: f32) -> f32 {
    if v.is_infinite() && v > 0.0 {
        return v;
    }
    let v = if v == -0.0 { 0.0 } else { v };
    let bits = v.to_bits();
    f32::from_bits(if v >= 0.0 { bits + 1 } else { bits - 1 })
}

/// The next float towards -infinity (pbrt's `NextFloatDown`).
#[inline]
pub fn next_float_down(v: f32) -> f32 {
    if v.is_infinite() && v < 0.0 {
        return v;
    }
    let v = if v == 0.0 { -0.0 } else { v };
    let bits = v.to_bits();
    f32::from_bits(if v > 0.0 { bits - 1 } else { bits + 1 })
}

/// pbrt's `OffsetRayOrigin`: `p` (error `err`) moved along the geometric normal `n` to the side of `w`,
/// by `|n| · err`, then rounded one float further away per component.
#[inline]
pub fn offset_ray_origin(p: Vec3, err: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    let d = n.abs().dot(err);
    let mut offset = d * n;
    if w.dot(n) < 0.0 {
        offset = -offset;
    }
    let mut po = p + offset;
    for i in 0..3 {
        if offset[i] > 0.0 {
            po[i] = next_float_up(po[i]);
        } else if offset[i] < 0.0 {
            po[i] = next_float_down(po[i]);
        }
    }
    po
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_bound_gamma_and_next_float() {
        assert!(gamma(7) > 7.0 * f32::EPSILON * 0.5 && gamma(7) < 7.0 * f32::EPSILON);
        assert!(next_float_up(1.0) > 1.0 && next_float_down(1.0) < 1.0);
        assert!(next_float_up(0.0) > 0.0 && next_float_down(0.0) < 0.0);
        assert!(next_float_up(-1.0) > -1.0 && next_float_down(-1.0) < -1.0);
    }

    #[test]
    fn error_bound_offset_leaves_the_error_box_on_the_side_of_w() {
        let p = Vec3::new(1e4, 2.0, -3.0);
        let err = Vec3::new(1e-3, 1e-6, 1e-6);
        let n = Vec3::X;
        let up = offset_ray_origin(p, err, n, Vec3::new(0.5, 1.0, 0.0));
        assert!(up.x > p.x + err.x);
        let down = offset_ray_origin(p, err, n, -Vec3::X);
        assert!(down.x < p.x - err.x);
        assert_eq!((up.y, up.z), (p.y, p.z));
    }

    #[test]
    fn error_bound_triangle_point_is_on_the_triangle() {
        let t = [Vec3::new(1e4, 0.0, 0.0), Vec3::new(1e4, 1.0, 0.0), Vec3::new(1e4, 0.0, 1.0)];
        let (p, err) = triangle_point(t, 0.25, 0.25);
        assert!((p - Vec3::new(1e4, 0.25, 0.25)).abs().max_element() <= err.max_element());
        assert!(err.x > 0.0 && err.x < 1e-2);
    }
}
