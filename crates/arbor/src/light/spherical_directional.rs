//! Environment lights (`SphericalDirectionalLight`, CENG 795 hw5): the environment map lights the scene
//! from every direction. Each call picks one direction uniformly on the hemisphere around the surface
//! normal (probability density `1 / 2π`) and returns the map's radiance there divided by that density,
//! the Monte Carlo estimate the assignment gives; the pixel's samples average the estimates. Uniform
//! rather than cosine-weighted, because the Blinn-Phong specular term carries no cosine: dividing by a
//! cosine density would turn grazing directions into fireflies.

use std::f32::consts::TAU;

use super::environment::EnvMap;
use super::{Light, LightSample};
use crate::math::{orthonormal_basis, Vec2, Vec3};

/// The environment map as a light.
#[derive(Debug, Clone, PartialEq)]
pub struct SphericalDirectionalLight {
    /// Radiance by direction, in display units (as [`EnvMap::eval`] gives it).
    pub map: EnvMap,
    /// The scene's radiance per display unit (the inverse of its radiance scale), so that the light
    /// agrees with what camera rays that miss see.
    pub units: f32,
}

impl Light for SphericalDirectionalLight {
    fn sample(&self, _p: Vec3, n: Vec3, u: Vec2) -> Option<LightSample> {
        let n = n.try_normalize()?;
        let (t, b) = orthonormal_basis(n);
        // The cosine to the normal is uniform in [0, 1] for directions uniform on the hemisphere.
        let cos = u.x;
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let phi = TAU * u.y;
        let wi = (t * phi.cos() * sin + b * phi.sin() * sin + n * cos).normalize();
        let irradiance = self.map.eval(wi) * (self.units * TAU);
        Some(LightSample { wi, dist: f32::INFINITY, irradiance })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::Film;
    use crate::math::Color;

    fn uniform(c: Color) -> SphericalDirectionalLight {
        let film = Film { width: 4, height: 2, pixels: vec![c; 8] };
        SphericalDirectionalLight { map: EnvMap::from_film_latlong(film), units: 255.0 }
    }

    #[test]
    fn spherical_directional_light_samples_the_hemisphere_of_the_normal() {
        let light = uniform(Color::splat(0.5));
        let n = Vec3::new(1.0, 2.0, -0.5).normalize();
        for i in 0..64 {
            let u = Vec2::new((i % 8) as f32 / 8.0, (i / 8) as f32 / 8.0);
            let s = light.sample(Vec3::ZERO, n, u).unwrap();
            assert!(s.wi.dot(n) >= -1e-6 && (s.wi.length() - 1.0).abs() < 1e-5);
            assert_eq!(s.dist, f32::INFINITY);
            // Radiance 0.5 display units = 127.5 scene units, over the density 1 / 2π.
            assert!((s.irradiance.x - 127.5 * TAU).abs() < 1e-2, "{}", s.irradiance);
        }
    }

    #[test]
    fn spherical_directional_light_estimates_the_cosine_integral() {
        // A white diffuse surface under a uniform sky of radiance L receives ∫ L cos dω = π L: the
        // mean of the estimates times the cosine, over a stratified grid.
        let light = uniform(Color::ONE);
        let n = Vec3::Y;
        let k = 64;
        let mut sum = 0.0f64;
        for i in 0..k {
            for j in 0..k {
                let u = Vec2::new((i as f32 + 0.5) / k as f32, (j as f32 + 0.5) / k as f32);
                let s = light.sample(Vec3::ZERO, n, u).unwrap();
                sum += (s.irradiance.x * s.wi.dot(n)) as f64;
            }
        }
        let mean = sum / (k * k) as f64;
        assert!((mean / (255.0 * std::f64::consts::PI) - 1.0).abs() < 1e-3, "{mean}");
    }
}
