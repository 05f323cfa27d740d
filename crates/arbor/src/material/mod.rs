//! Materials: the Blinn-Phong terms every material has ([`blinn_phong`]), and the perfectly specular
//! lobes that mirrors, conductors and dielectrics add ([`specular_lobes`]), each in the file named after
//! its scene-file `type`.

mod blinn_phong;
mod conductor;
mod dielectric;
mod mirror;

use crate::math::{Color, Vec3};
use crate::scene::MaterialKind;

pub use blinn_phong::blinn_phong;
pub use conductor::fresnel_conductor;
pub use dielectric::{beer, fresnel_dielectric, refract};

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

/// Up to three specular lobes of a material hit by unit direction `d` at a surface with unit outward
/// normal `n` (the side the normal faces is "outside" for refraction).
pub fn specular_lobes(kind: &MaterialKind, d: Vec3, n: Vec3) -> Vec<Lobe> {
    match kind {
        MaterialKind::BlinnPhong => Vec::new(),
        MaterialKind::Mirror { reflectance } => vec![mirror::lobe(*reflectance, d, n)],
        MaterialKind::Conductor { reflectance, eta, k } => vec![conductor::lobe(*reflectance, *eta, *k, d, n)],
        MaterialKind::Dielectric { eta, .. } => dielectric::lobes(*eta, Color::ONE, d, n),
        MaterialKind::Transparent { eta, transparency, mirror: m } => {
            let mut lobes = dielectric::lobes(*eta, *transparency, d, n);
            if *m != Color::ZERO {
                lobes.push(mirror::lobe(*m, d, n));
            }
            lobes
        }
    }
}
