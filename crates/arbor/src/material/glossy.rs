//! Glossy reflection and refraction as the METU course defines `Roughness` (Cook et al. 1984,
//! "Distributed ray tracing"; the course's distribution ray tracing notes): the ideal direction is
//! moved within a square of side `roughness` spanned by two unit vectors perpendicular to it, then
//! normalised. It is a jitter, not a microfacet distribution: the lobe's weight stays the ideal one's.

use crate::math::{Vec2, Vec3};

/// `dir` (unit) perturbed by `roughness`, with `xi` uniform in `[0, 1)²` choosing the point of the
/// square (centred on `dir`).
pub fn perturb(dir: Vec3, roughness: f32, xi: Vec2) -> Vec3 {
    let (u, v) = course_basis(dir);
    let jitter = xi - Vec2::splat(0.5);
    (dir + roughness * (jitter.x * u + jitter.y * v)).normalize_or(dir)
}

/// Two unit vectors perpendicular to unit `r` and to each other, built the course's way: `r` with its
/// smallest component (in magnitude) set to 1 is not parallel to `r`, so crossing gives `u`.
fn course_basis(r: Vec3) -> (Vec3, Vec3) {
    let a = r.abs();
    let mut r0 = r;
    if a.x <= a.y && a.x <= a.z {
        r0.x = 1.0;
    } else if a.y <= a.z {
        r0.y = 1.0;
    } else {
        r0.z = 1.0;
    }
    let u = r.cross(r0).normalize();
    (u, r.cross(u))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glossy_basis_is_orthonormal_for_any_direction() {
        for r in [Vec3::X, -Vec3::Y, Vec3::Z, Vec3::new(1.0, 2.0, -3.0).normalize(), Vec3::new(0.0, 0.6, 0.8)] {
            let (u, v) = course_basis(r);
            for (a, b) in [(u, v), (u, r), (v, r)] {
                assert!(a.dot(b).abs() < 1e-6, "{r} {u} {v}");
            }
            assert!((u.length() - 1.0).abs() < 1e-6 && (v.length() - 1.0).abs() < 1e-6, "{r}");
        }
    }

    #[test]
    fn glossy_perturbation_is_centred_and_bounded_by_roughness() {
        let r = Vec3::new(0.3, -0.4, 0.866).normalize();
        assert!(perturb(r, 0.7, Vec2::splat(0.5)).abs_diff_eq(r, 1e-6), "the square's centre is the ideal direction");
        assert_eq!(perturb(r, 0.0, Vec2::new(0.1, 0.9)), r);
        // The largest offset is a corner of the square: half its diagonal.
        let max_angle = (0.5f32.sqrt() * 0.7).atan();
        let (mut sum, n) = (Vec3::ZERO, 64);
        for i in 0..n {
            for j in 0..n {
                let xi = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let d = perturb(r, 0.7, xi);
                assert!((d.length() - 1.0).abs() < 1e-5);
                assert!(d.dot(r).clamp(-1.0, 1.0).acos() <= max_angle + 1e-4, "{xi}");
                sum += d;
            }
        }
        assert!((sum / (n * n) as f32).normalize().abs_diff_eq(r, 1e-4), "symmetric jitter keeps the mean direction");
    }
}
