//! Textures at render time (CENG 795 2022 hw4): image textures ([`TexImage`], nearest, bilinear or
//! trilinear over a mipmap), Perlin noise ([`perlin`]) and a 3D checkerboard ([`Checkerboard`]), each
//! with the decal mode that says what its value replaces; [`apply`] applies an object's textures to its
//! shading terms and normal, in one place. The build step makes them from the description; nothing here
//! knows the scene file.

mod checker;
mod image;
mod mipmap;
pub mod perlin;

use std::sync::Arc;

use crate::math::{Color, Vec2, Vec3};

pub use checker::Checkerboard;
pub use image::TexImage;

/// What a texture's value replaces.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Decal {
    /// k_d.
    ReplaceKd,
    /// k_d, averaged with the material's.
    BlendKd,
    /// k_s.
    ReplaceKs,
    /// The shaded colour.
    ReplaceAll,
    /// The background of camera rays that miss.
    ReplaceBackground,
    /// The shading normal (tangent space).
    ReplaceNormal,
    /// The shading normal, through a height field.
    BumpNormal,
}

/// How an image is sampled.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Filter {
    /// The texel the point falls in.
    Nearest,
    /// The four texels around the point.
    Bilinear,
    /// Bilinear in the two mipmap levels around the footprint's level of detail, blended (the image
    /// must hold its mipmap, [`TexImage::with_mipmaps`]).
    Trilinear,
}

/// Where a texture's value comes from.
#[derive(Debug)]
pub enum Source {
    /// An image, sampled at (u, v); texels are divided by `normalizer`.
    Image {
        /// The image (shared).
        image: Arc<TexImage>,
        /// Sampling.
        filter: Filter,
        /// Texel divisor.
        normalizer: f32,
        /// Coordinates outside [0, 1] take the edge texels (else the image repeats).
        clamp: bool,
    },
    /// Perlin noise at the point [`TexPoint::p`] times `scale`, made [0, 1] by `|n|` or `(n + 1) / 2`.
    Perlin {
        /// `|n|` (else linear).
        absval: bool,
        /// Frequency.
        scale: f32,
    },
    /// A checkerboard at the object-space point.
    Checker(Checkerboard),
}

/// A texture map ready for shading.
#[derive(Debug)]
pub struct Texture {
    /// Its values.
    pub source: Source,
    /// What they replace.
    pub decal: Decal,
    /// Multiplies the height field of a bump map.
    pub bump_factor: f32,
}

/// Where a surface is sampled: texture coordinates, the point, the shading normal and the derivatives of
/// the point along u and v, in the surface's texture frame; and the width of the pixel's footprint there.
///
/// The frame is a mesh's or plane's object space, and a sphere's world space: so the course's renderer
/// textures them (its Perlin noise reads a sphere's world point, hw4 `ellipsoids_texture`; its bump maps
/// displace a transformed sphere along the world normal, `bump_mapping_transformed`), while a mesh's
/// bump heights scale with its transform (`bump_mapping_transformed`'s floor).
#[derive(Debug, Clone, Copy)]
pub struct TexPoint {
    /// Texture coordinates.
    pub uv: Vec2,
    /// The point, where the object is at time 0; procedural textures read it.
    pub p: Vec3,
    /// Unit shading normal.
    pub n: Vec3,
    /// ∂p/∂u.
    pub dpdu: Vec3,
    /// ∂p/∂v.
    pub dpdv: Vec3,
    /// Side of the pixel's footprint in (u, v) units, for trilinear filtering; 0 when not known (the
    /// finest level).
    pub footprint: f32,
}

impl Texture {
    /// The texture's value at `at`, normalised (images divided by their normalizer).
    pub fn eval(&self, at: &TexPoint) -> Color {
        match &self.source {
            Source::Image { image, filter, normalizer, clamp } => {
                let uv = if *clamp { at.uv.clamp(Vec2::ZERO, Vec2::splat(1.0 - f32::EPSILON)) } else { at.uv };
                let c = match filter {
                    Filter::Nearest => image.nearest(uv),
                    Filter::Bilinear => image.bilinear(uv),
                    Filter::Trilinear => image.trilinear(uv, at.footprint),
                };
                c / *normalizer
            }
            Source::Perlin { absval, scale } => Color::splat(convert(perlin::noise(at.p * *scale), *absval)),
            Source::Checker(c) => c.eval(at.p),
        }
    }

    /// The value at texture coordinates `uv` alone (a background): procedural textures see the point
    /// (u, v, 0).
    pub fn eval_uv(&self, uv: Vec2) -> Color {
        let at = TexPoint { uv, p: uv.extend(0.0), n: Vec3::Z, dpdu: Vec3::X, dpdv: Vec3::Y, footprint: 0.0 };
        self.eval(&at)
    }

    /// Whether sampling reads [`TexPoint::footprint`] (only trilinear images do).
    #[inline]
    pub fn wants_footprint(&self) -> bool {
        matches!(self.source, Source::Image { filter: Filter::Trilinear, .. })
    }

    /// The bump-mapped object-space normal at `at`: the surface displaced along its normal by the
    /// texture's height times the bump factor (Blinn 1978), the normal of the displaced surface.
    fn bumped(&self, at: &TexPoint) -> Vec3 {
        let n = at.n;
        let k = self.bump_factor;
        match &self.source {
            Source::Image { image, .. } => {
                // The height is a texel's mean as stored, and its slope the difference between the texel
                // at the point and the next one, whatever the map's interpolation: so a bump factor means
                // the same at any image size, and the slope is constant across a texel.
                let height = |uv: Vec2| {
                    let c = image.nearest(uv);
                    (c.x + c.y + c.z) / 3.0
                };
                let (du, dv) = (1.0 / image.width as f32, 1.0 / image.height as f32);
                let h = height(at.uv);
                let dhdu = height(at.uv + Vec2::new(du, 0.0)) - h;
                let dhdv = height(at.uv + Vec2::new(0.0, dv)) - h;
                let pu = at.dpdu + k * dhdu * n;
                let pv = at.dpdv + k * dhdv * n;
                let m = pu.cross(pv).normalize_or(n);
                if m.dot(n) < 0.0 {
                    -m
                } else {
                    m
                }
            }
            Source::Perlin { absval, scale } => {
                let q = at.p * *scale;
                let nv = perlin::noise(q);
                let slope = if *absval { nv.signum() } else { 0.5 };
                let g = perlin::gradient(q) * (slope * *scale * k);
                (n - (g - g.dot(n) * n)).normalize_or(n)
            }
            Source::Checker(_) => n,
        }
    }
}

/// Noise in [-1, 1] to [0, 1].
fn convert(n: f32, absval: bool) -> f32 {
    if absval {
        n.abs()
    } else {
        (n + 1.0) * 0.5
    }
}

/// Blinn-Phong terms and shading normal after an object's textures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shaded {
    /// k_a.
    pub ambient: Color,
    /// k_d.
    pub diffuse: Color,
    /// k_s.
    pub specular: Color,
    /// Object-space shading normal (unit).
    pub n: Vec3,
    /// The colour that replaces all shading (`replace_all`), if any.
    pub replace_all: Option<Color>,
}

/// Applies `textures` in order to the terms `base` at `at`.
///
/// With `degamma`, the texels of 8-bit images that give colours (not normals or heights) are display
/// values: they are raised to that power to make them linear. High-dynamic-range images are linear
/// already.
pub fn apply<'a>(
    textures: impl IntoIterator<Item = &'a Texture>,
    mut base: Shaded,
    at: &TexPoint,
    degamma: Option<f32>,
) -> Shaded {
    for t in textures {
        let colour = || match (&t.source, degamma) {
            (Source::Image { image, .. }, Some(g)) if image.is_8bit() => t.eval(at).powf(g),
            _ => t.eval(at),
        };
        match t.decal {
            Decal::ReplaceKd => base.diffuse = colour(),
            Decal::BlendKd => base.diffuse = (base.diffuse + colour()) * 0.5,
            Decal::ReplaceKs => base.specular = colour(),
            Decal::ReplaceAll => base.replace_all = Some(colour()),
            Decal::ReplaceBackground => {}
            Decal::ReplaceNormal => {
                let c = t.eval(at) * 2.0 - Color::ONE;
                let tu = at.dpdu.normalize_or_zero();
                let tv = at.dpdv.normalize_or_zero();
                base.n = (tu * c.x + tv * c.y + at.n * c.z).normalize_or(at.n);
            }
            Decal::BumpNormal => base.n = t.bumped(at),
        }
    }
    base
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image_texture(decal: Decal, bump_factor: f32, image: TexImage) -> Texture {
        Texture {
            source: Source::Image { image: Arc::new(image), filter: Filter::Nearest, normalizer: 255.0, clamp: false },
            decal,
            bump_factor,
        }
    }

    /// The plane z = 0 with (u, v) = (x, y).
    fn plane_point(uv: Vec2) -> TexPoint {
        TexPoint { uv, p: uv.extend(0.0), n: Vec3::Z, dpdu: Vec3::X, dpdv: Vec3::Y, footprint: 0.0 }
    }

    #[test]
    fn bump_map_of_a_ramp_gives_the_ramps_normal() {
        // Grey texels rising by 10 per texel along x, constant along y.
        let bytes = (0..8u8).flat_map(|_| (0..8u8).flat_map(|x| [10 * x; 3])).collect();
        let t = image_texture(Decal::BumpNormal, 0.5, TexImage::from_rgb8(8, 8, bytes));
        let base =
            Shaded { ambient: Color::ZERO, diffuse: Color::ONE, specular: Color::ZERO, n: Vec3::Z, replace_all: None };
        let out = apply([&t], base, &plane_point(Vec2::new(0.3, 0.5)), None);
        // Height k·h rises by 0.5 · 10 per unit of u: the surface z = 5u has normal (-5, 0, 1)/|.|.
        assert!(out.n.abs_diff_eq(Vec3::new(-5.0, 0.0, 1.0).normalize(), 1e-5), "{}", out.n);
        assert_eq!(out.diffuse, Color::ONE);
    }

    #[test]
    fn image_texture_repeats_or_clamps_outside_the_unit_square() {
        // One row of 4 texels: 0, 51, 102, 153 (0, 0.2, 0.4, 0.6 after the normalizer).
        let row = || TexImage::from_rgb8(4, 1, [0u8, 51, 102, 153].iter().flat_map(|&g| [g; 3]).collect());
        let repeat = image_texture(Decal::ReplaceKd, 1.0, row());
        let mut clamp = image_texture(Decal::ReplaceKd, 1.0, row());
        if let Source::Image { clamp: c, .. } = &mut clamp.source {
            *c = true;
        }
        let at = |t: &Texture, u: f32| (t.eval(&plane_point(Vec2::new(u, 0.5))).x * 5.0).round() as u8;
        for (u, repeated, clamped) in [
            (0.125, 0, 0),
            (0.625, 2, 2),
            (0.0, 0, 0),
            (0.25, 1, 1),
            (1.0, 0, 3),
            (-0.1, 3, 0),
            (1.3, 1, 3),
            (-0.8, 0, 0),
        ] {
            assert_eq!((at(&repeat, u), at(&clamp, u)), (repeated, clamped), "u = {u}");
        }
    }

    #[test]
    fn bump_map_of_a_sine_and_a_ramp_gives_the_analytic_normal() {
        // Float heights H(x, y) = 100 + 80 sin(2πx / 32) + 3y at texel (x, y) of a 32x16 image.
        let (w, h) = (32u32, 16u32);
        let height = |x: f32, y: f32| 100.0 + 80.0 * (std::f32::consts::TAU * x / w as f32).sin() + 3.0 * y;
        let texels = (0..h).flat_map(|y| (0..w).flat_map(move |x| [height(x as f32, y as f32); 3])).collect();
        let image = TexImage::from_texels(w, h, image::Texels::F32(texels));
        let k = 0.05;
        let t = image_texture(Decal::BumpNormal, k, image);
        // A tilted plane: ∂p/∂u = a e1, ∂p/∂v = b e2, normal e1 x e2.
        let (e1, e2) = (Vec3::new(1.0, 1.0, 0.0).normalize(), Vec3::Z);
        let n = e1.cross(e2);
        let (a, b) = (2.0, 0.5);
        let base = Shaded { ambient: Color::ZERO, diffuse: Color::ONE, specular: Color::ZERO, n, replace_all: None };
        for (x, y) in [(0, 0), (3, 2), (7, 5), (12, 9), (20, 14), (31, 3)] {
            let uv = Vec2::new((x as f32 + 0.3) / w as f32, (y as f32 + 0.6) / h as f32);
            let at = TexPoint { uv, p: Vec3::ZERO, n, dpdu: a * e1, dpdv: b * e2, footprint: 0.0 };
            // The surface p + k H n has tangents a e1 + k H_u n and b e2 + k H_v n, so its normal is
            // (-k H_u / a, -k H_v / b, 1) in the frame (e1, e2, n); a height is a texel's, and H_u its
            // difference to the next texel: the derivative halfway between them, per texel.
            let hu =
                80.0 * std::f32::consts::TAU / w as f32 * (std::f32::consts::TAU * (x as f32 + 0.5) / w as f32).cos();
            let hv = 3.0;
            let expected = (-k * hu / a * e1 - k * hv / b * e2 + n).normalize();
            let got = apply([&t], base, &at, None).n;
            // A difference is the derivative times sin(π/32) / (π/32) = 0.9984.
            assert!(got.abs_diff_eq(expected, 2e-3), "texel ({x}, {y}): {got} vs {expected}");
        }
    }

    #[test]
    fn decal_modes_replace_what_they_name() {
        let img = || TexImage::from_rgb8(1, 1, vec![255, 0, 51]);
        let base = Shaded {
            ambient: Color::ONE,
            diffuse: Color::splat(0.5),
            specular: Color::ONE,
            n: Vec3::Z,
            replace_all: None,
        };
        let at = plane_point(Vec2::splat(0.5));
        let kd = apply([&image_texture(Decal::ReplaceKd, 1.0, img())], base, &at, None);
        assert_eq!(kd.diffuse, Color::new(1.0, 0.0, 0.2));
        let blend = apply([&image_texture(Decal::BlendKd, 1.0, img())], base, &at, None);
        assert!(blend.diffuse.abs_diff_eq(Color::new(0.75, 0.25, 0.35), 1e-6));
        let ks = apply([&image_texture(Decal::ReplaceKs, 1.0, img())], base, &at, None);
        assert_eq!((ks.specular, ks.diffuse), (Color::new(1.0, 0.0, 0.2), base.diffuse));
        let all = apply([&image_texture(Decal::ReplaceAll, 1.0, img())], base, &at, None);
        assert_eq!(all.replace_all, Some(Color::new(1.0, 0.0, 0.2)));
        // A tangent-space normal of (1, 0.5, 0.6) after mapping [0, 1] to [-1, 1]: (1, 0, 0.2).
        let normal = apply([&image_texture(Decal::ReplaceNormal, 1.0, img())], base, &at, None);
        assert!(normal.n.abs_diff_eq(Vec3::new(1.0, -1.0, -0.6).normalize(), 1e-6), "{}", normal.n);
    }

    #[test]
    fn degamma_linearizes_8_bit_colour_texels_only() {
        let base =
            Shaded { ambient: Color::ONE, diffuse: Color::ONE, specular: Color::ONE, n: Vec3::Z, replace_all: None };
        let at = plane_point(Vec2::splat(0.5));
        let texel = || TexImage::from_rgb8(1, 1, vec![128, 128, 128]);
        let kd = image_texture(Decal::ReplaceKd, 1.0, texel());
        let shown = apply([&kd], base, &at, None).diffuse.x;
        let linear = apply([&kd], base, &at, Some(2.2)).diffuse.x;
        assert!((shown - 128.0 / 255.0).abs() < 1e-6 && (linear - (128.0_f32 / 255.0).powf(2.2)).abs() < 1e-6);
        // A normal map is not a colour; a float (HDR) image is linear already.
        let normal = image_texture(Decal::ReplaceNormal, 1.0, texel());
        assert_eq!(apply([&normal], base, &at, Some(2.2)).n, apply([&normal], base, &at, None).n);
        let hdr = Texture {
            source: Source::Image {
                image: Arc::new(TexImage::from_texels(1, 1, image::Texels::F32(vec![0.5; 3]))),
                filter: Filter::Nearest,
                normalizer: 1.0,
                clamp: false,
            },
            decal: Decal::ReplaceKd,
            bump_factor: 1.0,
        };
        assert_eq!(apply([&hdr], base, &at, Some(2.2)).diffuse, Color::splat(0.5));
    }

    #[test]
    fn perlin_bump_tilts_the_normal_against_the_noise_slope() {
        let scale = 0.7;
        let t = Texture { source: Source::Perlin { absval: false, scale }, decal: Decal::BumpNormal, bump_factor: 2.0 };
        let p = Vec3::new(0.82, 1.47, 0.6);
        let at = TexPoint { uv: Vec2::ZERO, p, n: Vec3::Z, dpdu: Vec3::X, dpdv: Vec3::Y, footprint: 0.0 };
        let base =
            Shaded { ambient: Color::ONE, diffuse: Color::ONE, specular: Color::ONE, n: Vec3::Z, replace_all: None };
        let out = apply([&t], base, &at, None);
        // The height is 2 · (noise + 1) / 2 = noise(0.7 p): its x and y slopes by differences.
        let h = 1e-3;
        let height = |q: Vec3| perlin::noise(q * scale);
        let dx = (height(p + Vec3::X * h) - height(p - Vec3::X * h)) / (2.0 * h);
        let dy = (height(p + Vec3::Y * h) - height(p - Vec3::Y * h)) / (2.0 * h);
        let want = Vec3::new(-dx, -dy, 1.0).normalize();
        assert!(out.n.abs_diff_eq(want, 2e-2), "{} vs {want}", out.n);
        assert!(dx.abs() + dy.abs() > 0.1, "the point should have a slope");
    }
}
