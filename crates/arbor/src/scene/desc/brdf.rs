//! BRDF models as a scene file describes them (CENG 795 hw6 `<BRDFs>`, named by a material's `BRDF`
//! attribute), resolved per material: a Torrance-Sparrow model carries the Fresnel indices of the
//! material that uses it.

/// One of the course's BRDF models with its parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BrdfKind {
    /// `OriginalPhong`.
    OriginalPhong,
    /// `ModifiedPhong`, `normalized="true"` or not.
    ModifiedPhong {
        /// `normalized`.
        normalized: bool,
    },
    /// `OriginalBlinnPhong`: the shading of materials without a BRDF.
    OriginalBlinnPhong,
    /// `ModifiedBlinnPhong`, `normalized="true"` or not.
    ModifiedBlinnPhong {
        /// `normalized`.
        normalized: bool,
    },
    /// `TorranceSparrow`.
    TorranceSparrow {
        /// `kdfresnel`: the diffuse term is weighted by one minus the Fresnel reflectance.
        kd_fresnel: bool,
        /// Refraction index of the Fresnel term: the material's `RefractionIndex`, else the 2019
        /// form's `RefractiveIndex` inside the model.
        eta: f32,
        /// Absorption index of the Fresnel term: the material's `AbsorptionIndex`, 0 when absent.
        k: f32,
    },
}

/// A BRDF: its model and the exponent of its specular lobe (`Exponent`, >= 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BrdfDesc {
    /// The model.
    pub kind: BrdfKind,
    /// `Exponent`.
    pub exponent: f32,
}
