//! METU `<BRDFs>` (CENG 795 hw6; the 2019 hw5 files too): one element per model, named after it
//! (`OriginalPhong`, `ModifiedPhong`, `OriginalBlinnPhong`, `ModifiedBlinnPhong`, `TorranceSparrow`),
//! with an `id`, an `Exponent`, `normalized` on the modified models and `kdfresnel` on
//! Torrance-Sparrow; a material names one with its `BRDF` attribute.
//!
//! Torrance-Sparrow's Fresnel term takes the material's `RefractionIndex` and `AbsorptionIndex` (the
//! 2022 files), else the model's own `RefractiveIndex` (the 2019 files), with no absorption.
//! A model the course does not define, a negative exponent, a refraction index that is not positive (the
//! model's or the material's, as for any material), a negative absorption index, or a material naming
//! an id no model has is a located error.

use super::Reader;
use crate::scene::desc::{BrdfDesc, BrdfKind};
use crate::scene::readers::tree::Node;
use crate::{Error, Result};

/// The model names of the course, as elements of `<BRDFs>`.
const MODELS: &str = "OriginalPhong, ModifiedPhong, OriginalBlinnPhong, ModifiedBlinnPhong or TorranceSparrow";

/// A model as `<BRDFs>` defines it, before a material resolves it.
#[derive(Debug, Clone, Copy)]
pub(super) struct BrdfEntry {
    desc: BrdfDesc,
    /// A Torrance-Sparrow model's own `RefractiveIndex` (2019).
    eta: Option<f32>,
}

impl Reader<'_> {
    /// Every model of `<BRDFs>`, by id.
    pub(super) fn read_brdfs(&mut self, list: &Node) -> Result<()> {
        let p = self.path;
        for n in &list.children {
            n.mark_used();
            let Some(id) = n.attr("id").map(|a| a.trimmed().to_string()) else {
                return Err(self.err(n, format!("<{}>: missing attribute id", n.name)));
            };
            let exponent_node = self.req(n, "Exponent")?;
            let exponent = exponent_node.float(p)?;
            if exponent < 0.0 {
                return Err(self.err(exponent_node, format!("BRDF {id}: negative exponent {exponent}")));
            }
            let flag = |r: &Self, name: &str| n.attr(name).map_or(Ok(false), |a| a.boolean(r.path));
            let mut eta = None;
            let kind = match n.name.as_str() {
                "OriginalPhong" => BrdfKind::OriginalPhong,
                "ModifiedPhong" => BrdfKind::ModifiedPhong { normalized: flag(self, "normalized")? },
                "OriginalBlinnPhong" => BrdfKind::OriginalBlinnPhong,
                "ModifiedBlinnPhong" => BrdfKind::ModifiedBlinnPhong { normalized: flag(self, "normalized")? },
                "TorranceSparrow" => {
                    let who = format!("BRDF {id}");
                    eta = self.one(n, "RefractiveIndex").map(|r| self.refraction_index(r, &who)).transpose()?;
                    BrdfKind::TorranceSparrow { kd_fresnel: flag(self, "kdfresnel")?, eta: 0.0, k: 0.0 }
                }
                other => {
                    let msg = format!("<BRDFs>: unknown BRDF model <{other}> (expected {MODELS})");
                    return Err(self.err(n, msg));
                }
            };
            let entry = BrdfEntry { desc: BrdfDesc { kind, exponent }, eta };
            if self.brdfs.insert(id.clone(), entry).is_some() {
                return Err(self.err(n, format!("duplicate BRDF id '{id}'")));
            }
        }
        Ok(())
    }

    /// The model a material's `BRDF` attribute names, resolved for the material `m` whose id is `id`.
    pub(super) fn material_brdf(&mut self, m: &Node, id: &str) -> Result<Option<BrdfDesc>> {
        let p = self.path;
        let Some(a) = m.attr("BRDF") else {
            return Ok(None);
        };
        let name = a.trimmed();
        let Some(entry) = self.brdfs.get(name).copied() else {
            return Err(Error::input(a.loc(p), format!("Material {id}: unknown BRDF id '{name}'")));
        };
        let mut desc = entry.desc;
        let who = format!("Material {id}");
        if let BrdfKind::TorranceSparrow { eta, k, .. } = &mut desc.kind {
            *eta = match (self.one(m, "RefractionIndex"), entry.eta) {
                (Some(n), _) => self.refraction_index(n, &who)?,
                (None, Some(e)) => e,
                (None, None) => {
                    let msg = format!(
                        "Material {id}: BRDF '{name}' (TorranceSparrow) needs a <RefractionIndex> for its Fresnel term"
                    );
                    return Err(Error::input(a.loc(p), msg));
                }
            };
            *k = self.one(m, "AbsorptionIndex").map(|n| self.absorption_index(n, &who)).transpose()?.unwrap_or(0.0);
        }
        Ok(Some(desc))
    }
}
