//! Square area lights (CENG 795 hw2): a `size x size` square centred at `position`, facing `normal`,
//! emitting `radiance` from its front side. One point is sampled per shading sample; the solid angle is
//! approximated as in the course notes, `A |n_l · w_i| / d²`, which is exact for small, distant lights.
//! It is not geometry (no ray can hit it), so it counts as a delta light (`pdf` 0); its power is that
//! of a one-sided Lambertian emitter, `π L A`.

use super::{Light, LightSample};
use crate::math::{orthonormal_basis, Color, Vec2, Vec3};
use crate::tonemap::luminance;

/// A square light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AreaLight {
    /// Centre.
    pub position: Vec3,
    /// Facing direction (unit).
    pub normal: Vec3,
    /// Side length.
    pub size: f32,
    /// Emitted radiance.
    pub radiance: Color,
}

impl Light for AreaLight {
    /// The light of the point `u` (in `[0,1)²`) of the square reaching `p`.
    fn sample(&self, p: Vec3, _n: Vec3, u: Vec2) -> Option<LightSample> {
        let AreaLight { position, normal, size, radiance } = *self;
        sample_area(position, normal, size, radiance, p, u)
    }

    /// `L A / d²` with `d` the clearance of the square's centre less its half diagonal: no point of the
    /// square is nearer any surface.
    fn irradiance_bound(&self, clearance: &dyn Fn(Vec3) -> f32) -> Option<f32> {
        let d = clearance(self.position) - self.size * std::f32::consts::FRAC_1_SQRT_2;
        super::point::inverse_square(self.radiance.max_element() * self.size * self.size, d)
    }

    fn power(&self) -> f32 {
        std::f32::consts::PI * luminance(self.radiance) * self.size * self.size
    }
}

fn sample_area(position: Vec3, normal: Vec3, size: f32, radiance: Color, p: Vec3, u: Vec2) -> Option<LightSample> {
    let (a, b) = orthonormal_basis(normal);
    let q = position + (u.x - 0.5) * size * a + (u.y - 0.5) * size * b;
    let to_light = q - p;
    let d2 = to_light.length_squared();
    // Negated so that a NaN distance (a NaN point) gives no light, as a zero one does.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if !(d2 > 0.0) {
        return None;
    }
    let dist = d2.sqrt();
    let wi = to_light / dist;
    let cos_l = normal.dot(-wi).abs();
    Some(LightSample { wi, dist, irradiance: radiance * (size * size * cos_l / d2), pdf: 0.0 })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn area_light_centre_sample_matches_small_square_approximation() {
        let s = sample_area(Vec3::new(0.0, 4.0, 0.0), -Vec3::Y, 0.5, Vec3::splat(64.0), Vec3::ZERO, Vec2::splat(0.5))
            .unwrap();
        assert!(s.wi.abs_diff_eq(Vec3::Y, 1e-6));
        assert!((s.irradiance.x - 64.0 * 0.25 / 16.0).abs() < 1e-5);
    }

    #[test]
    fn area_light_samples_stay_on_the_square() {
        let n = Vec3::new(1.0, 1.0, 0.0).normalize();
        for (x, y) in [(0.0, 0.0), (0.999, 0.0), (0.3, 0.7)] {
            let s = sample_area(Vec3::ZERO, n, 2.0, Vec3::ONE, Vec3::new(5.0, 5.0, 1.0), Vec2::new(x, y)).unwrap();
            let q = Vec3::new(5.0, 5.0, 1.0) + s.wi * s.dist;
            assert!(q.dot(n).abs() < 1e-4, "sample left the light's plane");
            let (a, b) = orthonormal_basis(n);
            assert!(q.dot(a).abs() <= 1.0 + 1e-4 && q.dot(b).abs() <= 1.0 + 1e-4, "sample off the square");
        }
    }
}
