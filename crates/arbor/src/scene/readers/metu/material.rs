//! METU materials: Blinn-Phong terms plus the `type` (mirror, conductor, dielectric), or for untyped
//! pre-2020 materials the kind the present elements imply (non-zero `Transparency` is glass, else
//! non-zero `MirrorReflectance` a mirror).

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
            Some(n) => n.float(p)?,
            None => 1.0,
        };
        let float = |r: &mut Self, name: &str| -> Result<f32> { r.req(m, name)?.float(p) };
        let kind = match m.attr("type").map(|a| (a, a.trimmed().to_string())) {
            Some((_, t)) if t == "mirror" => {
                MaterialKind::Mirror { reflectance: self.req(m, "MirrorReflectance")?.vec3(p)? }
            }
            Some((_, t)) if t == "conductor" => MaterialKind::Conductor {
                reflectance: self.req(m, "MirrorReflectance")?.vec3(p)?,
                eta: float(self, "RefractionIndex")?,
                k: float(self, "AbsorptionIndex")?,
            },
            Some((_, t)) if t == "dielectric" => MaterialKind::Dielectric {
                eta: float(self, "RefractionIndex")?,
                absorption: color(self, "AbsorptionCoefficient")?.unwrap_or(Color::ZERO),
            },
            Some((a, t)) => {
                let msg = format!("Material {id}: unknown type '{t}' (expected mirror, conductor or dielectric)");
                return Err(Error::input(a.loc(p), msg));
            }
            None if !self.legacy => MaterialKind::BlinnPhong,
            None => {
                // Pre-2020 files have no type; the elements present say what the material is.
                let mirror = color(self, "MirrorReflectance")?.unwrap_or(Color::ZERO);
                let transparency = color(self, "Transparency")?.unwrap_or(Color::ZERO);
                if transparency != Color::ZERO {
                    let eta = float(self, "RefractionIndex")?;
                    MaterialKind::Transparent { eta, transparency, mirror }
                } else if mirror != Color::ZERO {
                    MaterialKind::Mirror { reflectance: mirror }
                } else {
                    MaterialKind::BlinnPhong
                }
            }
        };
        for (attr, what) in [("BRDF", "BRDF models are"), ("degamma", "degamma is")] {
            if let Some(a) = m.attr(attr) {
                let label = format!("attribute {attr} of <Material>");
                let msg = format!("{what} not supported; ignored");
                self.notes.feature(a.loc(p), &label, &msg);
            }
        }
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
        Ok(MaterialDesc { id, ambient, diffuse, specular, phong_exponent, roughness, kind })
    }

    /// The material an object names, as an index.
    pub(super) fn material_of(&mut self, o: &Node, name: &str) -> Result<usize> {
        let m = self.req(o, "Material")?;
        let id = m.trimmed();
        self.materials.get(id).copied().ok_or_else(|| self.err(m, format!("{name}: unknown material id '{id}'")))
    }
}
