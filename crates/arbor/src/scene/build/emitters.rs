//! Emissive objects (`LightMesh`, `LightSphere`) as lights: each object with a non-zero emission gets
//! an [`EmissiveMesh`] or [`EmissiveSphere`] over the same geometry the structures hold (a mesh's
//! triangles are shared, not copied), appended to the scene's lights after the others. A moving emitter
//! is sampled where it is at time 0. An emitter without area cannot be sampled: a located error.

use super::super::desc::SceneDesc;
use super::super::geometry::{SceneGeometry, Shape};
use crate::light::{EmissiveMesh, EmissiveSphere, Light};
use crate::math::Color;
use crate::{Error, Result};

/// Per object, in scene-file order: the index of its light in the scene's lights, and its radiance.
pub(super) type Emitters = (Vec<Option<usize>>, Vec<Option<Color>>);

/// Appends the lights of the emissive objects of `desc` (built into `geometry`) to `lights`; returns,
/// for each object in scene-file order, the index of its light, and its emitted radiance.
pub(super) fn build_emitters(
    desc: &SceneDesc,
    geometry: &SceneGeometry,
    lights: &mut Vec<Box<dyn Light>>,
) -> Result<Emitters> {
    let mut light_of = vec![None; desc.objects.len()];
    let mut emission = vec![None; desc.objects.len()];
    for o in &geometry.objects.objects {
        let d = &desc.objects[o.object as usize];
        let Some(radiance) = d.emission.filter(|r| *r != Color::ZERO) else { continue };
        let light: Option<Box<dyn Light>> = match &o.shape {
            Shape::Mesh(m) => {
                EmissiveMesh::new(m.clone(), o.transform, radiance, o.object).map(|l| Box::new(l) as Box<dyn Light>)
            }
            Shape::Sphere(s) => EmissiveSphere::new(*s, radiance, o.object).map(|l| Box::new(l) as Box<dyn Light>),
        };
        let light = light.ok_or_else(|| Error::input(d.loc.clone(), format!("{}: the light has no area", d.name)))?;
        light_of[o.object as usize] = Some(lights.len());
        emission[o.object as usize] = Some(radiance);
        lights.push(light);
    }
    Ok((light_of, emission))
}
