//! The pre-2020 METU and the NYU glass (`Transparency` on a plain material): Fresnel reflection and
//! refraction, the transmitted part weighted by `Transparency`, no Beer's law; a non-zero
//! `MirrorReflectance` adds a Fresnel-free mirror reflection on top.

use super::dielectric::lobes;
use super::{Lobe, Mirror, SpecularLayer};
use crate::math::{Color, Vec3};

/// Legacy glass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transparent {
    /// `RefractionIndex`.
    pub eta: f32,
    /// `Transparency`: weights the refracted lobe.
    pub transparency: Color,
    /// `MirrorReflectance`: the extra mirror lobe (none when black).
    pub mirror: Color,
}

impl SpecularLayer for Transparent {
    fn lobes(&self, d: Vec3, n: Vec3) -> Vec<Lobe> {
        let mut out = lobes(self.eta, self.transparency, d, n);
        if self.mirror != Color::ZERO {
            out.push(Mirror { reflectance: self.mirror }.lobe(d, n));
        }
        out
    }
    fn transmits(&self) -> bool {
        true
    }
    fn max_lobes(&self) -> usize {
        3
    }
    /// `F + (1 - F) t` is at most `max(1, t)`, plus the mirror lobe.
    fn weight_bound(&self) -> f32 {
        self.transparency.max_element().max(1.0) + self.mirror.max_element()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transparent_adds_a_mirror_lobe_only_when_it_has_one() {
        let d = Vec3::new(0.3, -1.0, 0.2).normalize();
        let plain = Transparent { eta: 1.5, transparency: Color::splat(0.5), mirror: Color::ZERO };
        let l = plain.lobes(d, Vec3::Y);
        assert_eq!(l.len(), 2);
        assert!(l[1].transmitted);
        assert!((l[0].weight.x + l[1].weight.x / 0.5 - 1.0).abs() < 1e-6, "refracted part weighted by transparency");
        let shiny = Transparent { mirror: Color::splat(0.25), ..plain };
        let l = shiny.lobes(d, Vec3::Y);
        assert_eq!(l.len(), 3);
        assert_eq!(l[2].weight, Color::splat(0.25));
        assert!(shiny.transmits() && shiny.interior_absorption().is_none());
    }
}
