//! Importance sampling of a latitude-longitude environment map: directions drawn in proportion to the
//! map's luminance times `sin θ` (the solid angle of a row), with a piecewise-constant 2D distribution,
//! a marginal over rows and a conditional over each row's pixels (Pharr, Jakob and Humphreys, *Physically
//! Based Rendering*, 4th ed., section 12.5, "Image infinite lights").
//!
//! A pixel's weight is the largest luminance among it and its eight neighbours: lookups are bilinear, so
//! a direction in a black pixel next to a bright one still sees light, and must have a non-zero density
//! for the estimate to stay unbiased. Within a pixel `(u, v)` is uniform, so the density per solid angle
//! is `p(pixel) · W · H / (2π² sin θ)` with the exact `θ` of the direction. The tables take 8 bytes
//! per pixel, allocated fallibly.

use std::f32::consts::PI;

use crate::film::Film;
use crate::math::{Vec2, Vec3};
use crate::tonemap::luminance;
use crate::{Error, Result};

/// The distribution over a map's pixels.
#[derive(Debug, Clone, PartialEq)]
pub struct LatLongSampler {
    width: usize,
    height: usize,
    /// Cumulative row weights, `height + 1` entries from 0.
    rows: Vec<f64>,
    /// Cumulative weights within each row, `width + 1` entries per row from 0.
    cols: Vec<f64>,
}

impl LatLongSampler {
    /// The distribution for `film`; `None` when the map is black (nothing to sample) or empty;
    /// [`Error::OutOfMemory`] when its tables cannot be allocated.
    pub fn new(film: &Film) -> Result<Option<Self>> {
        let (width, height) = (film.width as usize, film.height as usize);
        if width == 0 || height == 0 {
            return Ok(None);
        }
        let lum = |i: isize, j: isize| {
            let x = i.rem_euclid(width as isize) as u32;
            let y = j.clamp(0, height as isize - 1) as u32;
            luminance(film.get(x, y)).max(0.0) as f64
        };
        let (mut cols, mut rows) = (Vec::new(), Vec::new());
        let n = height.saturating_mul(width + 1);
        if cols.try_reserve_exact(n).is_err() || rows.try_reserve_exact(height + 1).is_err() {
            let gib = (n as f64 + height as f64) * 8.0 / (1u64 << 30) as f64;
            return Err(Error::OutOfMemory(format!("not enough memory for its sampling table ({gib:.1} GiB)")));
        }
        rows.push(0.0);
        for j in 0..height {
            let sin = (PI * (j as f32 + 0.5) / height as f32).sin() as f64;
            let mut acc = 0.0;
            cols.push(0.0);
            for i in 0..width {
                let (i, jj) = (i as isize, j as isize);
                let w = (-1..=1).flat_map(|dj| (-1..=1).map(move |di| (di, dj))).map(|(di, dj)| lum(i + di, jj + dj));
                acc += w.fold(0.0, f64::max) * sin;
                cols.push(acc);
            }
            rows.push(rows[j] + acc);
        }
        let total = rows[height];
        Ok((total > 0.0 && total.is_finite()).then_some(LatLongSampler { width, height, rows, cols }))
    }

    /// A unit direction for `u` in `[0,1)²` and its density per unit solid angle; `None` at a pole.
    pub fn sample(&self, u: Vec2) -> Option<(Vec3, f32)> {
        let total = self.rows[self.height];
        let (j, fy) = pick(&self.rows, u.y as f64 * total);
        let row = &self.cols[j * (self.width + 1)..(j + 1) * (self.width + 1)];
        let (i, fx) = pick(row, u.x as f64 * row[self.width]);
        let p_pixel = (row[i + 1] - row[i]) / total;
        let (su, sv) = ((i as f64 + fx) / self.width as f64, (j as f64 + fy) / self.height as f64);
        let theta = (sv * std::f64::consts::PI) as f32;
        let phi = (2.0 * std::f64::consts::PI * (su - 0.5)) as f32;
        let sin = theta.sin();
        if sin <= 1e-6 {
            return None;
        }
        // The inverse of the lookup: u = 0.5 + atan2(x, -z) / 2π, v = acos(y) / π.
        let dir = Vec3::new(sin * phi.sin(), theta.cos(), -sin * phi.cos());
        let pdf = p_pixel * (self.width * self.height) as f64 / (2.0 * std::f64::consts::PI.powi(2) * sin as f64);
        Some((dir, pdf as f32))
    }

    /// The density per unit solid angle with which [`LatLongSampler::sample`] gives the direction `d`
    /// (any length): the density of its pixel, through the same lookup as the map's.
    pub fn pdf(&self, d: Vec3) -> f32 {
        let Some(d) = d.try_normalize() else { return 0.0 };
        let theta = d.y.clamp(-1.0, 1.0).acos();
        let sin = theta.sin();
        if sin <= 1e-6 {
            return 0.0;
        }
        let su = 0.5 + d.x.atan2(-d.z) as f64 / (2.0 * std::f64::consts::PI);
        let sv = theta as f64 / std::f64::consts::PI;
        let i = ((su * self.width as f64) as usize).min(self.width - 1);
        let j = ((sv * self.height as f64) as usize).min(self.height - 1);
        let row = &self.cols[j * (self.width + 1)..(j + 1) * (self.width + 1)];
        let p_pixel = (row[i + 1] - row[i]) / self.rows[self.height];
        (p_pixel * (self.width * self.height) as f64 / (2.0 * std::f64::consts::PI.powi(2) * sin as f64)) as f32
    }
}

/// The cell of the cumulative table `cdf` containing `x` (skipping empty cells) and the position within.
fn pick(cdf: &[f64], x: f64) -> (usize, f64) {
    let n = cdf.len() - 1;
    // The first cell whose upper end exceeds x: never an empty one, as an empty cell's ends are equal.
    let k = cdf[1..].partition_point(|&c| c <= x).min(n - 1);
    let (lo, hi) = (cdf[k], cdf[k + 1]);
    let f = if hi > lo { ((x - lo) / (hi - lo)).clamp(0.0, 1.0 - f64::EPSILON) } else { 0.5 };
    (k, f)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::environment::EnvMap;
    use crate::math::Color;

    #[test]
    fn latlong_pdf_matches_the_density_of_the_sample() {
        let pixels = (0..32 * 16).map(|k| Color::splat(1.0 + (k % 7) as f32 * (k % 5) as f32)).collect();
        let s = LatLongSampler::new(&Film { width: 32, height: 16, pixels }).unwrap().unwrap();
        for k in 0..50 {
            let u = Vec2::new((k % 10) as f32 / 10.0 + 0.037, (k / 10) as f32 / 5.0 + 0.051);
            let (d, pdf) = s.sample(u).unwrap();
            assert!((s.pdf(d) / pdf - 1.0).abs() < 1e-3, "{} vs {pdf} at {d}", s.pdf(d));
        }
    }

    #[test]
    fn latlong_sampling_of_a_uniform_map_is_close_to_uniform_on_the_sphere() {
        let film = Film { width: 64, height: 32, pixels: vec![Color::ONE; 64 * 32] };
        let s = LatLongSampler::new(&film).unwrap().unwrap();
        for k in 0..100 {
            let u = Vec2::new((k % 10) as f32 / 10.0 + 0.03, (k / 10) as f32 / 10.0 + 0.05);
            let (d, pdf) = s.sample(u).unwrap();
            assert!((d.length() - 1.0).abs() < 1e-5);
            // Row weights use the row centre's sin θ: within a row the density departs from 1/4π by the
            // ratio of the two sines, at most a few percent away from the poles.
            if d.y.abs() < 0.9 {
                assert!((pdf * 4.0 * PI - 1.0).abs() < 0.05, "{pdf} at {d}");
            }
        }
        assert!(LatLongSampler::new(&Film { width: 2, height: 1, pixels: vec![Color::ZERO; 2] }).unwrap().is_none());
    }

    #[test]
    fn latlong_sampling_lands_around_the_light() {
        let mut film = Film { width: 32, height: 16, pixels: vec![Color::ZERO; 32 * 16] };
        film.pixels[5 * 32 + 20] = Color::splat(100.0);
        let s = LatLongSampler::new(&film).unwrap().unwrap();
        let map = EnvMap::from_film_latlong(film);
        let mut lit = 0;
        for k in 0..64 {
            let (d, pdf) = s.sample(Vec2::new((k % 8) as f32 / 8.0, (k / 8) as f32 / 8.0)).unwrap();
            // Every sample falls in the bright pixel's 3x3 neighbourhood, the pixels its bilinear
            // footprint reaches.
            let (u, v) = (0.5 + d.x.atan2(-d.z) / (2.0 * PI), d.y.acos() / PI);
            let (i, j) = ((u * 32.0).floor() as i32, (v * 16.0).floor() as i32);
            assert!((19..=21).contains(&i) && (4..=6).contains(&j) && pdf > 0.0, "{d} in pixel ({i}, {j})");
            lit += usize::from(map.eval(d).x > 0.0);
        }
        // The bright pixel's bilinear footprint covers 4 of the 9 pixels' area.
        assert!(lit >= 16, "only {lit} of 64 samples see the light");
    }

    #[test]
    fn latlong_sampling_estimates_the_irradiance_of_a_sun() {
        // A small bright patch and a dim sky: the mean of L cos / pdf over the upper hemisphere equals
        // the same integral computed on a fine grid of directions.
        let (w, h) = (64u32, 32u32);
        let pixels = (0..w * h)
            .map(|k| if (k / w, k % w) == (10, 40) { Color::splat(500.0) } else { Color::splat(0.2) })
            .collect();
        let film = Film { width: w, height: h, pixels };
        let s = LatLongSampler::new(&film).unwrap().unwrap();
        let map = EnvMap::from_film_latlong(film);
        let n = Vec3::Y;
        let k = 256;
        let mut estimate = 0.0f64;
        for a in 0..k {
            for b in 0..k {
                let u = Vec2::new((a as f32 + 0.5) / k as f32, (b as f32 + 0.5) / k as f32);
                if let Some((d, pdf)) = s.sample(u) {
                    estimate += (map.eval(d).x * d.dot(n).max(0.0) / pdf) as f64;
                }
            }
        }
        estimate /= (k * k) as f64;
        // The same integral over (θ, φ) on a grid finer than the map's pixels.
        let (nt, np) = (1024, 2048);
        let mut exact = 0.0f64;
        for t in 0..nt {
            let theta = (t as f64 + 0.5) / nt as f64 * std::f64::consts::FRAC_PI_2;
            for p in 0..np {
                let phi = (p as f64 + 0.5) / np as f64 * 2.0 * std::f64::consts::PI;
                let d =
                    Vec3::new((theta.sin() * phi.cos()) as f32, theta.cos() as f32, (theta.sin() * phi.sin()) as f32);
                exact += map.eval(d).x as f64 * theta.cos() * theta.sin();
            }
        }
        exact *= std::f64::consts::FRAC_PI_2 / nt as f64 * 2.0 * std::f64::consts::PI / np as f64;
        assert!((estimate / exact - 1.0).abs() < 0.01, "{estimate} vs {exact}");
    }
}
