//! Materials at render time: the Blinn-Phong terms every material has ([`blinn_phong()`]), or the BRDF
//! model it names instead ([`Brdf`]), and the perfectly specular layer that mirrors, conductors and
//! dielectrics add ([`SpecularLayer`]), each in the file named after its scene-file `type`, made glossy
//! by a roughness ([`perturb`]). The scene's build step makes a [`Material`] from each material of the
//! description; nothing here knows the scene file.
//!
//! A new kind of specular behaviour is a type in its own file implementing [`SpecularLayer`]; the
//! integrator only asks the trait.

mod blinn_phong;
mod brdf;
mod conductor;
mod dielectric;
mod glossy;
mod mirror;
mod transparent;

use std::fmt;

use crate::math::{Color, Vec3};

pub use blinn_phong::blinn_phong;
pub use brdf::{Brdf, BrdfModel};
pub use conductor::{fresnel_conductor, Conductor};
pub use dielectric::{beer, fresnel_dielectric, refract, Dielectric};
pub use glossy::perturb;
pub use mirror::Mirror;
pub use transparent::Transparent;

/// One perfectly specular continuation of a ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lobe {
    /// Unit direction of the new ray.
    pub dir: Vec3,
    /// What the light it brings back is multiplied by.
    pub weight: Color,
    /// True when the ray crosses the surface (refraction), false when it stays on the incoming side.
    pub transmitted: bool,
}

/// What a material adds to its Blinn-Phong terms: perfectly specular lobes, and for glass a medium
/// behind the surface.
pub trait SpecularLayer: fmt::Debug + Send + Sync {
    /// The lobes at a surface with unit outward normal `n` hit by unit direction `d` (the side the
    /// normal faces is "outside" for refraction).
    fn lobes(&self, d: Vec3, n: Vec3) -> Vec<Lobe>;

    /// The most lobes [`SpecularLayer::lobes`] gives (rays a hit spawns).
    fn max_lobes(&self) -> usize {
        1
    }

    /// An upper bound on the sum of the lobes' weights in any channel, over every `d` and `n`.
    fn weight_bound(&self) -> f32;

    /// Whether light crosses the surface. Such a surface hit from inside only refracts and reflects: its
    /// ambient and Blinn-Phong terms belong to its outside.
    fn transmits(&self) -> bool {
        false
    }

    /// The absorption per channel and unit distance (Beer's law) of the medium a transmitted ray
    /// enters when it comes from outside; `None` for a medium that absorbs nothing on its way.
    fn interior_absorption(&self) -> Option<Color> {
        None
    }
}

/// The exponent that turns a display colour into a linear reflectance for a `degamma` material: the
/// course's display gamma (its tone mapping writes PNGs with `Gamma` 2.2).
pub const DEGAMMA: f32 = 2.2;

/// A material ready for shading.
#[derive(Debug)]
pub struct Material {
    /// k_a: multiplies the scene's ambient light.
    pub ambient: Color,
    /// k_d.
    pub diffuse: Color,
    /// k_s.
    pub specular: Color,
    /// Blinn-Phong exponent.
    pub phong_exponent: f32,
    /// The BRDF that replaces the Blinn-Phong terms (with `diffuse` and `specular` as its reflectances);
    /// `None` for Blinn-Phong.
    pub brdf: Option<Brdf>,
    /// How far the layer's rays stray from their ideal directions ([`perturb`]); 0 for none.
    pub roughness: f32,
    /// Mirror, conductor, dielectric...; `None` for Blinn-Phong only (no secondary rays).
    pub layer: Option<Box<dyn SpecularLayer>>,
    /// Its 8-bit colour textures hold display values (`degamma`), made linear by [`DEGAMMA`] as they are
    /// read; its own colours were made linear when it was built.
    pub degamma: bool,
}

impl Material {
    /// The fraction of the irradiance from unit `wi` reflected towards unit `wo` at unit shading normal
    /// `n`: the BRDF times the incidence cosine, Blinn-Phong's terms for a material without a BRDF.
    #[inline]
    pub fn eval_cos(&self, n: Vec3, wi: Vec3, wo: Vec3) -> Color {
        match &self.brdf {
            None => blinn_phong(self, n, wi, wo),
            Some(b) => b.f(self.diffuse, self.specular, wi, wo, n) * n.dot(wi).max(0.0),
        }
    }

    /// The specular lobes at a surface with unit outward normal `n` hit by unit direction `d`; none
    /// for a Blinn-Phong-only material.
    #[inline]
    pub fn specular_lobes(&self, d: Vec3, n: Vec3) -> Vec<Lobe> {
        self.layer.as_ref().map_or_else(Vec::new, |l| l.lobes(d, n))
    }

    /// Whether light crosses the surface ([`SpecularLayer::transmits`]).
    #[inline]
    pub fn transmits(&self) -> bool {
        self.layer.as_ref().is_some_and(|l| l.transmits())
    }

    /// The absorption of the medium a ray travels in after following `lobe` from this surface, when it
    /// travelled in `current` before and arrived from outside if `entering`: a transmitted ray enters the
    /// material's interior from outside and leaves it otherwise; a reflected one stays where it was.
    #[inline]
    pub fn medium_after(&self, lobe: &Lobe, entering: bool, current: Option<Color>) -> Option<Color> {
        match (lobe.transmitted, entering) {
            (false, _) => current,
            (true, true) => self.interior_absorption(),
            (true, false) => None,
        }
    }

    /// The absorption of the medium behind the surface ([`SpecularLayer::interior_absorption`]).
    #[inline]
    pub fn interior_absorption(&self) -> Option<Color> {
        self.layer.as_ref().and_then(|l| l.interior_absorption())
    }
}
