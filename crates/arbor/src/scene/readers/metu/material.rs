//! METU materials: Blinn-Phong terms plus the `type` (mirror, conductor, dielectric), or for untyped
//! pre-2020 materials the kind the present elements imply (non-zero `Transparency` is glass, else
//! non-zero `MirrorReflectance` a mirror).
//!
//! An element that a material's kind leaves without effect is accepted in silence where no reading of the
//! file could make it matter, and reported where it could: a legacy opaque material's `RefractionIndex`
//! (the 2019 template writes `Transparency 0 0 0` and `RefractionIndex 1` into every material), and the
//! `MirrorReflectance` of an untyped material in a typed file (zero, or with no recursion).

use super::Reader;
use crate::math::Color;
use crate::scene::desc::{MaterialDesc, MaterialKind};
use crate::scene::readers::tree::Node;
use crate::{Error, Result};

impl Reader<'_> {
    /// Every `Material`, numbered in file order; their ids map to those indices.
    pub(super) fn read_materials(&mut self, ms: &Node) -> Result<()> {
        for (i, m) in ms.all("Material").enumerate() {
            let id = m.attr("id").map_or_else(|| (i + 1).to_string(), |a| a.trimmed().to_string());
            let mat = self.material(m, id.clone())?;
            if self.materials.insert(id.clone(), self.desc.materials.len()).is_some() {
                return Err(self.err(m, format!("duplicate material id '{id}'")));
            }
            self.desc.materials.push(mat);
        }
        Ok(())
    }

    /// One `Material` whose id is `id`.
    fn material(&mut self, m: &Node, id: String) -> Result<MaterialDesc> {
        let p = self.path;
        let color =
            |r: &mut Self, name: &str| -> Result<Option<Color>> { r.one(m, name).map(|n| n.vec3(p)).transpose() };
        let ambient = self.req(m, "AmbientReflectance")?.vec3(p)?;
        let diffuse = self.req(m, "DiffuseReflectance")?.vec3(p)?;
        let specular = color(self, "SpecularReflectance")?.unwrap_or(Color::ZERO);
        let phong_exponent = match self.one(m, "PhongExponent") {
            Some(n) => {
                let e = n.float(p)?;
                if e < 0.0 {
                    return Err(self.err(n, format!("Material {id}: negative PhongExponent {e}")));
                }
                e
            }
            None => 1.0,
        };
        let who = format!("Material {id}");
        let refraction_index = |r: &mut Self| -> Result<f32> {
            let n = r.req(m, "RefractionIndex")?;
            r.refraction_index(n, &who)
        };
        let absorption_index = |r: &mut Self| -> Result<f32> {
            let n = r.req(m, "AbsorptionIndex")?;
            r.absorption_index(n, &who)
        };
        let kind = match m.attr("type").map(|a| (a, a.trimmed().to_string())) {
            Some((_, t)) if t == "mirror" => {
                MaterialKind::Mirror { reflectance: self.req(m, "MirrorReflectance")?.vec3(p)? }
            }
            Some((_, t)) if t == "conductor" => MaterialKind::Conductor {
                reflectance: self.req(m, "MirrorReflectance")?.vec3(p)?,
                eta: refraction_index(self)?,
                k: absorption_index(self)?,
            },
            Some((_, t)) if t == "dielectric" => MaterialKind::Dielectric {
                eta: refraction_index(self)?,
                absorption: color(self, "AbsorptionCoefficient")?.unwrap_or(Color::ZERO),
            },
            Some((a, t)) => {
                let msg = format!("Material {id}: unknown type '{t}' (expected mirror, conductor or dielectric)");
                return Err(Error::input(a.loc(p), msg));
            }
            None if !self.legacy => {
                self.untyped_mirror_reflectance(m)?;
                MaterialKind::BlinnPhong
            }
            None => {
                // Pre-2020 files have no type; the elements present say what the material is.
                let mirror = color(self, "MirrorReflectance")?.unwrap_or(Color::ZERO);
                let transparency_given = m.child("Transparency").is_some();
                let transparency = color(self, "Transparency")?.unwrap_or(Color::ZERO);
                if transparency != Color::ZERO {
                    let eta = refraction_index(self)?;
                    MaterialKind::Transparent { eta, transparency, mirror }
                } else {
                    self.opaque_refraction_index(m, &id, transparency_given)?;
                    if mirror != Color::ZERO {
                        MaterialKind::Mirror { reflectance: mirror }
                    } else {
                        MaterialKind::BlinnPhong
                    }
                }
            }
        };
        let brdf = self.material_brdf(m, &id)?;
        let degamma = match m.attr("degamma").map(|a| (a, a.trimmed())) {
            None | Some((_, "false")) => false,
            Some((_, "true")) => true,
            Some((a, other)) => {
                let msg = format!("Material {id}: degamma must be true or false, not '{other}'");
                return Err(Error::input(a.loc(p), msg));
            }
        };
        let roughness = match self.one(m, "Roughness") {
            Some(n) => {
                let r = n.float(p)?;
                if r < 0.0 {
                    return Err(self.err(n, format!("Material {id}: negative roughness {r}")));
                }
                r
            }
            None => 0.0,
        };
        Ok(MaterialDesc { id, ambient, diffuse, specular, phong_exponent, brdf, roughness, kind, degamma })
    }

    /// The refraction index `n` of `who` (a material's `RefractionIndex`, a Torrance-Sparrow model's
    /// `RefractiveIndex`): positive, as others have no physical reading and make the Fresnel terms NaN
    /// or negative.
    pub(super) fn refraction_index(&self, n: &Node, who: &str) -> Result<f32> {
        match n.float(self.path)? {
            v if v <= 0.0 => Err(self.err(n, format!("{who}: {} {v} must be positive", n.name))),
            v => Ok(v),
        }
    }

    /// The `AbsorptionIndex` `n` of `who`: not negative (a negative one has no physical reading either).
    pub(super) fn absorption_index(&self, n: &Node, who: &str) -> Result<f32> {
        match n.float(self.path)? {
            v if v < 0.0 => Err(self.err(n, format!("{who}: negative AbsorptionIndex {v}"))),
            v => Ok(v),
        }
    }

    /// A legacy opaque material's `RefractionIndex`: it has no effect (only a non-zero `Transparency`
    /// makes a legacy material refract), so it is accepted in silence where it could not matter: beside
    /// an explicit zero `Transparency` (the 2019 files' template), or when it is 1. Otherwise the file
    /// may have meant glass, and is told. A material with a `BRDF` is left alone: a Torrance-Sparrow
    /// model's Fresnel term reads the index, and any other leaves it reported as unused.
    fn opaque_refraction_index(&mut self, m: &Node, id: &str, transparency_given: bool) -> Result<()> {
        if m.attrs.iter().any(|a| a.name == "BRDF") {
            return Ok(());
        }
        let Some(r) = self.one(m, "RefractionIndex") else {
            return Ok(());
        };
        let eta = r.float(self.path)?;
        if !transparency_given && eta != 1.0 {
            let msg = format!("Material {id}: RefractionIndex {eta} has no effect without a non-zero <Transparency>");
            self.notes.plain(r.loc(self.path), msg);
        }
        Ok(())
    }

    /// `MirrorReflectance` on an untyped material of a typed (post-2020) file: the material stays plain
    /// Blinn-Phong, as in the official renderers, so the element has no effect. Silent where it could
    /// not matter (zero reflectance, or no recursion at all); otherwise one warning for the file.
    fn untyped_mirror_reflectance(&mut self, m: &Node) -> Result<()> {
        let Some(r) = self.one(m, "MirrorReflectance") else {
            return Ok(());
        };
        if r.vec3(self.path)? != Color::ZERO && self.desc.max_depth > 0 {
            let what = "a material without type=\"mirror\" or \"conductor\" does not reflect (as in the official \
                        renderers); ignored";
            self.notes.feature(r.loc(self.path), "<MirrorReflectance>", what);
        }
        Ok(())
    }

    /// The material an object names, as an index.
    pub(super) fn material_of(&mut self, o: &Node, name: &str) -> Result<usize> {
        let m = self.req(o, "Material")?;
        let id = m.trimmed();
        self.materials.get(id).copied().ok_or_else(|| self.err(m, format!("{name}: unknown material id '{id}'")))
    }
}
