//! Directions over the hemisphere about a unit normal and their densities, for the path tracer's
//! bounces: uniform in solid angle (pdf `1/2π`), or by the cosine (Malley's method, pdf `cos θ/π`).
//! Every direction is a unit vector on the normal's side; cost: a square root and a sine and cosine.

use crate::math::{orthonormal_basis, Vec2, Vec3};

/// A direction over the hemisphere of unit `n`, uniform in solid angle, and its pdf `1/2π`.
pub fn uniform_hemisphere(n: Vec3, u: Vec2) -> (Vec3, f32) {
    let z = u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * std::f32::consts::PI * u.y;
    (local_to_world(n, Vec3::new(r * phi.cos(), r * phi.sin(), z)), 1.0 / (2.0 * std::f32::consts::PI))
}

/// A direction over the hemisphere of unit `n` with density `cos θ / π` (Malley's method: a uniform
/// point of the unit disc lifted to the hemisphere), and that density.
pub fn cosine_hemisphere(n: Vec3, u: Vec2) -> (Vec3, f32) {
    let r = u.x.sqrt();
    let phi = 2.0 * std::f32::consts::PI * u.y;
    let z = (1.0 - u.x).max(0.0).sqrt();
    (local_to_world(n, Vec3::new(r * phi.cos(), r * phi.sin(), z)), z / std::f32::consts::PI)
}

fn local_to_world(n: Vec3, v: Vec3) -> Vec3 {
    let (a, b) = orthonormal_basis(n);
    (a * v.x + b * v.y + n * v.z).normalize_or(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫ g over the sphere of directions, by the midpoint rule in (cos θ, φ).
    fn integrate(g: impl Fn(Vec3) -> f32) -> f32 {
        let (nz, nphi) = (400, 400);
        let mut sum = 0.0;
        for i in 0..nz {
            for j in 0..nphi {
                let z = -1.0 + 2.0 * (i as f32 + 0.5) / nz as f32;
                let phi = 2.0 * std::f32::consts::PI * (j as f32 + 0.5) / nphi as f32;
                let r = (1.0 - z * z).sqrt();
                sum += g(Vec3::new(r * phi.cos(), r * phi.sin(), z));
            }
        }
        sum * 4.0 * std::f32::consts::PI / (nz * nphi) as f32
    }

    #[test]
    fn hemisphere_samplers_stay_above_and_their_pdfs_integrate_to_one() {
        let n = Vec3::new(0.3, -0.5, 0.8).normalize();
        let cos_pdf = |w: Vec3| w.dot(n).max(0.0) / std::f32::consts::PI;
        let uni_pdf = |w: Vec3| if w.dot(n) > 0.0 { 1.0 / (2.0 * std::f32::consts::PI) } else { 0.0 };
        assert!((integrate(cos_pdf) - 1.0).abs() < 2e-3 && (integrate(uni_pdf) - 1.0).abs() < 2e-3);
        let mut rng = crate::sampler::Rng::for_sample(1, 2, 3, 4);
        let (mut mean_cos_c, mut mean_cos_u) = (0.0, 0.0);
        let k = 20_000;
        for _ in 0..k {
            let (c, pc) = cosine_hemisphere(n, rng.next_2d());
            let (u, pu) = uniform_hemisphere(n, rng.next_2d());
            assert!(c.dot(n) >= 0.0 && u.dot(n) >= 0.0);
            assert!((pc - cos_pdf(c)).abs() < 1e-4 && (pu - uni_pdf(u)).abs() < 1e-6);
            mean_cos_c += c.dot(n) / k as f32;
            mean_cos_u += u.dot(n) / k as f32;
        }
        // E[cos θ] is 2/3 under the cosine density, 1/2 under the uniform one.
        assert!((mean_cos_c - 2.0 / 3.0).abs() < 0.01, "{mean_cos_c}");
        assert!((mean_cos_u - 0.5).abs() < 0.01, "{mean_cos_u}");
    }
}
