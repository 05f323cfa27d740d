//! Emissive spheres (`LightSphere`, CENG 795 hw6): a sphere object that also emits `radiance` from its
//! outside, possibly under a transform (a non-uniform scale makes it an ellipsoid).
//!
//! A sphere that is still round in the world (its transform a similarity) is sampled, from a point
//! outside it, uniformly over the cone of directions it subtends (Pharr, Jakob and Humphreys, *Physically
//! Based Rendering*, 4th ed., section 6.2.4): density `1 / (2π (1 - cos θ_max))` with
//! `sin θ_max = r / d`, and every direction sees the near side. Otherwise (an ellipsoid) it is sampled by
//! area: a point uniform on the object-space sphere, carried by the transform, whose world-area density
//! is `1 / (4π r² J)` with `J = |det M| |M⁻ᵀ n|` the transform's area stretch at the point's object-space
//! normal `n`; the solid-angle density is that times `d² / |cos θ_l|`. A point on the far side emits
//! nothing towards the receiver and gives no sample; a receiver inside gets no light.
//!
//! Power: `π L A`, a one-sided Lambertian emitter of area `A` (`4π r²`, or for an ellipsoid the
//! integral of the stretch `J` by the midpoint rule).

use std::f32::consts::{PI, TAU};

use super::{Light, LightSample};
use crate::geometry::Sphere;
use crate::math::{orthonormal_basis, Color, Mat3, Ray, Vec2, Vec3};
use crate::tonemap::luminance;

/// A sphere light.
#[derive(Debug, Clone, PartialEq)]
pub struct EmissiveSphere {
    /// Emitted radiance (scene units), the same in every outward direction.
    pub radiance: Color,
    /// The object the light is, in scene-file order.
    pub object: u32,
    sphere: Sphere,
    /// World centre and radius while the sphere is round in the world.
    round: Option<(Vec3, f32)>,
    area: f32,
}

impl EmissiveSphere {
    /// The light of object `object`, the sphere `sphere` (with its transform); `None` when it has no
    /// area.
    pub fn new(sphere: Sphere, radiance: Color, object: u32) -> Option<Self> {
        let round = world_round(&sphere);
        let area = match round {
            Some((_, r)) => 2.0 * TAU * r * r,
            None => ellipsoid_area(&sphere),
        };
        (area > 0.0 && area.is_finite()).then_some(EmissiveSphere { radiance, object, sphere, round, area })
    }

    /// World-space surface area.
    pub fn area(&self) -> f32 {
        self.area
    }

    /// The world-area density of the point whose object-space unit normal is `n`.
    fn area_pdf(&self, n: Vec3) -> f32 {
        1.0 / (2.0 * TAU * self.sphere.radius * self.sphere.radius * stretch(&self.sphere, n))
    }

    /// The solid-angle density at `p` of the sphere's point `q` of object-space unit normal `n_obj`,
    /// and the unit direction and distance to it; `None` when `q` faces away from `p`.
    fn by_area(&self, p: Vec3, q: Vec3, n_obj: Vec3) -> Option<(Vec3, f32, f32)> {
        let n = self.sphere.transform.normal(n_obj).normalize_or_zero();
        super::towards_area_point(p, q, n, self.area_pdf(n_obj))
    }

    /// The round sphere's cone seen from `p`: centre direction, `1 - cos θ_max` and `sin² θ_max`;
    /// `None` from inside.
    fn cone(&self, p: Vec3) -> Option<(Vec3, f32, f32)> {
        let (c, r) = self.round?;
        let dc2 = (c - p).length_squared();
        if dc2 <= r * r {
            return None;
        }
        let sin2_max = r * r / dc2;
        let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
        // For a tiny cone 1 - cos θ_max cancels: its Taylor term instead (pbrt-v4).
        let one_minus = if sin2_max < 0.000_685_23 { sin2_max / 2.0 } else { 1.0 - cos_max };
        Some(((c - p) / dc2.sqrt(), one_minus, sin2_max))
    }
}

impl Light for EmissiveSphere {
    fn sample(&self, p: Vec3, _n: Vec3, u: Vec2) -> Option<LightSample> {
        if let Some((axis, one_minus, sin2_max)) = self.cone(p) {
            let (c, r) = self.round?;
            // θ from the axis uniform in cos θ over [cos θ_max, 1]; then the point of the sphere it
            // sees first, by the angle α at the centre (pbrt-v4, which keeps precision for small cones).
            let (cos_t, sin2_t) = if sin2_max < 0.000_685_23 {
                let s2 = sin2_max * u.x;
                ((1.0 - s2).sqrt(), s2)
            } else {
                let cos_t = 1.0 - one_minus * u.x;
                (cos_t, (1.0 - cos_t * cos_t).max(0.0))
            };
            let cos_a = sin2_t / sin2_max.sqrt() + cos_t * (1.0 - sin2_t / sin2_max).max(0.0).sqrt();
            let sin_a = (1.0 - cos_a * cos_a).max(0.0).sqrt();
            let phi = TAU * u.y;
            let (t, b) = orthonormal_basis(-axis);
            let n = (sin_a * phi.cos()) * t + (sin_a * phi.sin()) * b + cos_a * -axis;
            let q = c + r * n;
            let to = q - p;
            let dist = to.length();
            let pdf = 1.0 / (TAU * one_minus);
            return Some(LightSample { wi: to / dist, dist, irradiance: self.radiance / pdf, pdf });
        }
        // Uniform on the object-space sphere: z uniform in [-1, 1], φ uniform.
        let z = 1.0 - 2.0 * u.x;
        let s = (1.0 - z * z).max(0.0).sqrt();
        let phi = TAU * u.y;
        let n_obj = Vec3::new(s * phi.cos(), s * phi.sin(), z);
        let q = self.sphere.transform.point(self.sphere.center + self.sphere.radius * n_obj);
        let (wi, dist, pdf) = self.by_area(p, q, n_obj)?;
        Some(LightSample { wi, dist, irradiance: self.radiance / pdf, pdf })
    }

    fn pdf(&self, p: Vec3, wi: Vec3) -> f32 {
        let Some(t) = self.sphere.intersect(&Ray::new(p, wi), f32::INFINITY) else { return 0.0 };
        if let Some((_, one_minus, _)) = self.cone(p) {
            return 1.0 / (TAU * one_minus);
        }
        let q = p + t * wi;
        let n_obj = (self.sphere.transform.inv.transform_point3(q) - self.sphere.center).normalize_or_zero();
        self.by_area(p, q, n_obj).map_or(0.0, |(_, _, pdf)| pdf)
    }

    fn power(&self) -> f32 {
        PI * luminance(self.radiance) * self.area
    }

    fn object(&self) -> Option<u32> {
        Some(self.object)
    }
}

/// The world centre and radius of `sphere` when its transform keeps it round (a rotation, a uniform
/// scale and a translation: `MᵀM = s² I`).
fn world_round(sphere: &Sphere) -> Option<(Vec3, f32)> {
    let t = &sphere.transform;
    let m = Mat3::from_mat4(t.m);
    let g = m.transpose() * m;
    let s2 = g.x_axis.x;
    let tol = 1e-5 * s2;
    let off = [g.y_axis.y - s2, g.z_axis.z - s2, g.y_axis.x, g.z_axis.x, g.z_axis.y];
    off.iter().all(|d| d.abs() <= tol).then(|| (t.point(sphere.center), sphere.radius * s2.sqrt()))
}

/// The transform's area stretch `|det M| |M⁻ᵀ n|` at object-space unit normal `n`.
fn stretch(sphere: &Sphere, n: Vec3) -> f32 {
    let t = &sphere.transform;
    Mat3::from_mat4(t.m).determinant().abs() * t.normal(n).length()
}

/// The world area of a transformed sphere: `r² ∫ J dω` over the unit sphere, by the midpoint rule in
/// (z, φ), where `dω = dz dφ`.
fn ellipsoid_area(sphere: &Sphere) -> f32 {
    let (nz, np) = (128, 256);
    let mut sum = 0.0f64;
    for i in 0..nz {
        let z = -1.0 + 2.0 * (i as f32 + 0.5) / nz as f32;
        let s = (1.0 - z * z).max(0.0).sqrt();
        for j in 0..np {
            let phi = TAU * (j as f32 + 0.5) / np as f32;
            sum += stretch(sphere, Vec3::new(s * phi.cos(), s * phi.sin(), z)) as f64;
        }
    }
    let cell = (2.0 / nz as f64) * (std::f64::consts::TAU / np as f64);
    (sum * cell) as f32 * sphere.radius * sphere.radius
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Transform;

    fn light(transform: Transform) -> EmissiveSphere {
        let sphere = Sphere { center: Vec3::ZERO, radius: 0.5, transform };
        EmissiveSphere::new(sphere, Color::splat(2.0), 7).unwrap()
    }

    fn grid(k: usize) -> impl Iterator<Item = Vec2> {
        (0..k * k).map(move |i| Vec2::new(((i % k) as f32 + 0.5) / k as f32, ((i / k) as f32 + 0.5) / k as f32))
    }

    /// `∫ pdf dω` over the sphere of directions around `p`, by the midpoint rule in (cos θ, φ).
    fn integral(l: &EmissiveSphere, p: Vec3) -> f64 {
        grid(600).map(|u| l.pdf(p, sphere_dir(u)) as f64).sum::<f64>() * 4.0 * std::f64::consts::PI / 360_000.0
    }

    fn sphere_dir(u: Vec2) -> Vec3 {
        let z = 1.0 - 2.0 * u.x;
        let s = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(s * (TAU * u.y).cos(), s * (TAU * u.y).sin(), z)
    }

    #[test]
    fn emissive_sphere_irradiance_is_pi_l_sin2_alpha() {
        // A plane point 2 below the centre, facing it: E = π L sin² α with sin α = r / d.
        let l = light(Transform::translate(Vec3::new(0.0, 2.0, 0.0)));
        let (p, n) = (Vec3::ZERO, Vec3::Y);
        let k = 64;
        let e: f64 = grid(k)
            .filter_map(|u| l.sample(p, n, u))
            .map(|s| (s.irradiance.x * s.wi.dot(n).max(0.0)) as f64)
            .sum::<f64>()
            / (k * k) as f64;
        let exact = std::f64::consts::PI * 2.0 * (0.25 / 4.0);
        assert!((e / exact - 1.0).abs() < 2e-3, "{e} vs {exact}");
        assert_eq!(l.object(), Some(7));
        assert!((l.power() - PI * 2.0 * PI).abs() < 1e-4, "π L 4π r²");
    }

    #[test]
    fn emissive_sphere_pdf_integrates_to_one_and_matches_its_samples() {
        for t in [Transform::translate(Vec3::new(0.3, 1.5, -0.2)), Transform::scale(Vec3::new(3.0, 1.0, 1.0)).unwrap()]
        {
            let l = light(t.then(&Transform::translate(Vec3::new(0.0, 2.0, 0.0))));
            let p = Vec3::new(0.1, -0.3, 0.2);
            // By area (the ellipsoid) the far side gives no sample: the density covers the samples given.
            let given = grid(200).filter(|&u| l.sample(p, Vec3::Y, u).is_some()).count() as f64 / 40_000.0;
            let total = integral(&l, p);
            assert!((total - given).abs() < 0.01, "∫ pdf = {total}, share of samples given {given}");
            for u in grid(10) {
                let Some(s) = l.sample(p, Vec3::Y, u) else { continue };
                let pdf = l.pdf(p, s.wi);
                // Near the silhouette cos θ_l is small and carries the rounding of the point.
                assert!((pdf / s.pdf - 1.0).abs() < 1e-2, "{pdf} vs {}", s.pdf);
                assert!((s.irradiance.x * s.pdf - 2.0).abs() < 1e-3);
            }
        }
    }

    #[test]
    fn emissive_sphere_ellipsoid_area_matches_the_closed_form_of_a_spheroid() {
        // A prolate spheroid of semi-axes a = 1.5 (x), b = 0.5: A = 2π b² (1 + a e⁻¹ asin(e) / b).
        let l = light(Transform::scale(Vec3::new(3.0, 1.0, 1.0)).unwrap());
        let (a, b) = (1.5f64, 0.5f64);
        let e = (1.0 - b * b / (a * a)).sqrt();
        let exact = 2.0 * std::f64::consts::PI * b * b * (1.0 + a / (b * e) * e.asin());
        assert!((l.area() as f64 / exact - 1.0).abs() < 1e-3, "{} vs {exact}", l.area());
    }
}
