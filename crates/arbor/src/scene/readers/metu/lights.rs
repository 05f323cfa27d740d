//! METU lights: point, area, directional, spot and the environment (`SphericalDirectionalLight`, whose
//! image is a file name or an image of `Textures/Images`).

use super::Reader;
use crate::scene::desc::LightDesc;
use crate::scene::readers::tree::Node;
use crate::{Error, Result};

impl Reader<'_> {
    pub(super) fn lights(&mut self, l: &Node) -> Result<()> {
        let p = self.path;
        if let Some(a) = self.one(l, "AmbientLight") {
            self.desc.ambient = a.vec3(p)?;
        }
        for n in &l.children {
            let light = match n.name.as_str() {
                "PointLight" => LightDesc::Point {
                    position: self.req(n, "Position")?.vec3(p)?,
                    // A negative intensity would subtract light, which no renderer of the course does.
                    intensity: self.non_negative(n, "Intensity", || light_name(n))?,
                },
                "AreaLight" => self.area_light(n)?,
                "SpotLight" => self.spot_light(n)?,
                "DirectionalLight" => LightDesc::Directional {
                    direction: self.unit(n, "Direction")?,
                    radiance: self.req(n, "Radiance")?.vec3(p)?,
                },
                "SphericalDirectionalLight" => {
                    // Before 2022 the light names its file (`EnvMapName`); from 2022 on an image
                    // of `Textures/Images` (`ImageId`).
                    let (name_node, name) = match (self.one(n, "EnvMapName"), self.one(n, "ImageId")) {
                        (Some(e), _) => (e, e.trimmed().to_string()),
                        (None, Some(i)) => {
                            let id = i.trimmed();
                            let file = self.images.get(id).ok_or_else(|| {
                                self.err(i, format!("<ImageId>: no <Image id=\"{id}\"> in <Textures><Images>"))
                            })?;
                            (i, file.clone())
                        }
                        (None, None) => {
                            let msg = "<SphericalDirectionalLight>: missing <EnvMapName> or <ImageId>";
                            return Err(self.err(n, msg));
                        }
                    };
                    self.desc.environment_loc = Some(name_node.loc(p));
                    if self.desc.environment.is_some() {
                        let msg = "duplicate environment light; the last one wins".to_string();
                        self.notes.plain(n.loc(p), msg);
                    }
                    self.desc.environment = Some(self.dir.join(name));
                    self.desc.environment_probe = match n.attr("type").map(|a| (a, a.trimmed())) {
                        None | Some((_, "latlong")) => false,
                        Some((_, "probe")) => true,
                        Some((a, other)) => {
                            let msg = format!(
                                "<SphericalDirectionalLight>: unknown type '{other}' (expected latlong or probe)"
                            );
                            return Err(Error::input(a.loc(p), msg));
                        }
                    };
                    n.mark_used();
                    n.attr("id");
                    continue;
                }
                _ => continue,
            };
            n.mark_used();
            n.attr("id");
            self.desc.lights.push(light);
        }
        Ok(())
    }

    /// An `AreaLight`: a square of positive side whose area is a finite number, facing a non-zero
    /// normal (the number reader already refuses non-finite coordinates and radiance).
    fn area_light(&mut self, n: &Node) -> Result<LightDesc> {
        let p = self.path;
        let position = self.req(n, "Position")?.vec3(p)?;
        let normal = self.unit(n, "Normal")?;
        let s = self.req(n, "Size")?;
        let size = s.float(p)?;
        let name = || light_name(n);
        if size <= 0.0 {
            return Err(self.err(s, format!("{}: Size {size} must be positive", name())));
        }
        if !(size * size).is_finite() {
            return Err(self.err(s, format!("{}: Size {size} is too large (its area is not a finite number)", name())));
        }
        let radiance = self.req(n, "Radiance")?.vec3(p)?;
        Ok(LightDesc::Area { position, normal, size, radiance })
    }

    /// A `SpotLight`: full cone angles in degrees with `0 < FalloffAngle <= CoverageAngle <= 360` (the
    /// fall-off cone lies inside the coverage cone; a cone's half angle is at most 180°).
    fn spot_light(&mut self, n: &Node) -> Result<LightDesc> {
        let p = self.path;
        let position = self.req(n, "Position")?.vec3(p)?;
        let direction = self.unit(n, "Direction")?;
        let intensity = self.non_negative(n, "Intensity", || light_name(n))?;
        let (cov_node, fall_node) = (self.req(n, "CoverageAngle")?, self.req(n, "FalloffAngle")?);
        let (coverage_deg, falloff_deg) = (cov_node.float(p)?, fall_node.float(p)?);
        let name = || light_name(n);
        if !(coverage_deg > 0.0 && coverage_deg <= 360.0) {
            let msg = format!("{}: CoverageAngle {coverage_deg} must be in (0, 360] degrees", name());
            return Err(self.err(cov_node, msg));
        }
        if !(falloff_deg > 0.0 && falloff_deg <= coverage_deg) {
            let msg = format!("{}: FalloffAngle {falloff_deg} must be in (0, CoverageAngle {coverage_deg}]", name());
            return Err(self.err(fall_node, msg));
        }
        Ok(LightDesc::Spot { position, direction, intensity, coverage_deg, falloff_deg })
    }
}

/// A light element as errors name it: its kind and id (`SpotLight 2`).
fn light_name(n: &Node) -> String {
    format!("{} {}", n.name, n.attr("id").map_or("(no id)", |a| a.trimmed()))
}
