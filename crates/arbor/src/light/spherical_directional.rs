//! Environment lights (`SphericalDirectionalLight`, CENG 795 hw5): the environment map lights the scene
//! from every direction. Each call draws one direction and returns the map's radiance there divided by
//! the direction's probability density, a Monte Carlo estimate the pixel's samples average. A lat-long
//! map is importance-sampled by its luminance ([`super::latlong_sampling`]), so a small bright sun is
//! found by most samples; other maps are sampled uniformly on the hemisphere around the normal (density
//! `1 / 2π`), the assignment's estimator. Not cosine-weighted: the Blinn-Phong specular term carries no
//! cosine, so dividing by a cosine density would turn grazing directions into fireflies.
//!
//! [`Light::pdf`] cannot know the normal the uniform estimator sampled around: it gives `1 / 2π` for
//! every direction, the density of any direction above that normal (the only ones that contribute).
//! The power is pbrt-v4's for an infinite light, `4π · π r² · L̄`: the mean radiance `L̄` over the
//! sphere of directions, crossing the disc of the scene's bounding sphere from every direction.

use std::f32::consts::{PI, TAU};

use super::environment::EnvMap;
use super::latlong_sampling::LatLongSampler;
use super::{Light, LightSample};
use crate::math::{orthonormal_basis, Vec2, Vec3};
use crate::tonemap::luminance;
use crate::Result;

/// The environment map as a light.
#[derive(Debug, Clone, PartialEq)]
pub struct SphericalDirectionalLight {
    map: EnvMap,
    units: f32,
    sampler: Option<LatLongSampler>,
    /// Mean luminance over the sphere of directions, in scene units.
    mean: f32,
    scene_radius: f32,
}

impl SphericalDirectionalLight {
    /// The light of `map` (radiance in display units, as [`EnvMap::eval`] gives it); `units` is the
    /// scene's radiance per display unit (the inverse of its radiance scale), so that the light agrees
    /// with what camera rays that miss see. [`crate::Error::OutOfMemory`] when a lat-long map's sampling
    /// table cannot be allocated.
    pub fn new(map: EnvMap, units: f32) -> Result<Self> {
        let sampler = match map.latlong() {
            Some(film) => LatLongSampler::new(film)?,
            None => None,
        };
        let mean = mean_luminance(&map) * units;
        Ok(SphericalDirectionalLight { map, units, sampler, mean, scene_radius: 1.0 })
    }

    /// The light with the radius of the scene's bounding sphere, for [`Light::power`].
    pub fn with_scene_radius(self, scene_radius: f32) -> Self {
        SphericalDirectionalLight { scene_radius, ..self }
    }
}

/// The mean luminance of `map` over the sphere of directions, by the midpoint rule on a (θ, φ) grid.
fn mean_luminance(map: &EnvMap) -> f32 {
    let (nt, np) = (64, 128);
    let (mut sum, mut weight) = (0.0f64, 0.0f64);
    for t in 0..nt {
        let theta = (t as f32 + 0.5) / nt as f32 * PI;
        for p in 0..np {
            let phi = (p as f32 + 0.5) / np as f32 * TAU;
            let d = Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
            sum += (luminance(map.eval(d)) * theta.sin()) as f64;
            weight += theta.sin() as f64;
        }
    }
    (sum / weight) as f32
}

impl Light for SphericalDirectionalLight {
    fn sample(&self, _p: Vec3, n: Vec3, u: Vec2) -> Option<LightSample> {
        let n = n.try_normalize()?;
        if let Some(sampler) = &self.sampler {
            let (wi, pdf) = sampler.sample(u)?;
            // Below the surface the light contributes nothing: no shadow ray needed.
            if wi.dot(n) <= 0.0 || pdf <= 0.0 {
                return None;
            }
            let irradiance = self.map.eval(wi) * (self.units / pdf);
            return Some(LightSample { wi, dist: f32::INFINITY, irradiance, pdf });
        }
        let (t, b) = orthonormal_basis(n);
        // The cosine to the normal is uniform in [0, 1] for directions uniform on the hemisphere.
        let cos = u.x;
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let phi = TAU * u.y;
        let wi = (t * phi.cos() * sin + b * phi.sin() * sin + n * cos).normalize();
        let irradiance = self.map.eval(wi) * (self.units * TAU);
        Some(LightSample { wi, dist: f32::INFINITY, irradiance, pdf: 1.0 / TAU })
    }

    fn pdf(&self, _p: Vec3, wi: Vec3) -> f32 {
        match &self.sampler {
            Some(sampler) => sampler.pdf(wi),
            None => 1.0 / TAU,
        }
    }

    fn power(&self) -> f32 {
        4.0 * PI * PI * self.scene_radius * self.scene_radius * self.mean
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::Film;
    use crate::math::Color;

    impl SphericalDirectionalLight {
        fn without_importance(self) -> Self {
            SphericalDirectionalLight { sampler: None, ..self }
        }
    }

    #[test]
    fn spherical_directional_light_power_is_that_of_its_mean_radiance() {
        let light = uniform(Color::splat(0.5)).with_scene_radius(2.0);
        assert!((light.power() / (4.0 * PI * PI * 4.0 * 127.5) - 1.0).abs() < 1e-4, "{}", light.power());
    }

    fn uniform(c: Color) -> SphericalDirectionalLight {
        let film = Film { width: 4, height: 2, pixels: vec![c; 8] };
        SphericalDirectionalLight::new(EnvMap::from_film_latlong(film), 255.0).unwrap().without_importance()
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
        // mean of the estimates times the cosine, over a stratified grid, sampling uniformly or by
        // the map's luminance.
        let film = Film { width: 64, height: 32, pixels: vec![Color::ONE; 64 * 32] };
        let importance = SphericalDirectionalLight::new(EnvMap::from_film_latlong(film), 255.0).unwrap();
        assert!(importance.sampler.is_some());
        for light in [uniform(Color::ONE), importance] {
            for n in [Vec3::Y, Vec3::Z, Vec3::new(0.3, -0.5, 0.8).normalize()] {
                let k = 128;
                let mut sum = 0.0f64;
                for i in 0..k {
                    for j in 0..k {
                        let u = Vec2::new((i as f32 + 0.5) / k as f32, (j as f32 + 0.5) / k as f32);
                        if let Some(s) = light.sample(Vec3::ZERO, n, u) {
                            sum += (s.irradiance.x * s.wi.dot(n)) as f64;
                        }
                    }
                }
                let mean = sum / (k * k) as f64;
                assert!((mean / (255.0 * std::f64::consts::PI) - 1.0).abs() < 5e-3, "{mean} for {n}");
            }
        }
    }
}
