//! The build step, the one way from a description to a runtime scene ([`Scene::build`]): it loads the
//! assets (mesh files, each distinct file once and in parallel; the environment map), gives every mesh
//! object its own acceleration structure (in parallel), resolves instances to the mesh they show, puts
//! the objects under one top-level structure ([`super::geometry`]), and turns the description's
//! materials, lights and cameras into their runtime types. Asset errors name the scene element that
//! asked for the file. Nothing after this step reads the description.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use rayon::prelude::*;

use super::desc::{
    BrdfDesc, BrdfKind, CameraDesc, LightDesc, MaterialDesc, MaterialKind, MeshSource, ObjectDesc, OffsetRule,
    SceneDesc, ShapeDesc,
};
use super::geometry::{
    prim_count, world_box, MeshShape, SceneCounts, SceneGeometry, SceneObject, SceneObjects, ScenePlane, Shape,
};
use super::runtime::{RayOffset, Scene};
use crate::accel::{AccelConfig, Primitives};
use crate::camera::{Camera, ImagePlane, Projection};
use crate::geometry::{Plane, Sphere, TriangleMesh};
use crate::image_io::ImageLimits;
use crate::light::environment::EnvMap;
use crate::light::{AreaLight, DirectionalLight, Light, PointLight, SphericalDirectionalLight, SpotLight};
use crate::material::{Brdf, BrdfModel, Conductor, Dielectric, Material, Mirror, SpecularLayer, Transparent, DEGAMMA};
use crate::math::{Aabb, Vec3};
use crate::texture::Decal;
use crate::{Error, Location, Result};

mod emitters;
mod textures;

impl Scene {
    /// Loads the assets of `desc` and builds its runtime scene, with the structure `spec` describes at
    /// both levels. `environment` overrides the scene's own map. A map the scene names
    /// (`SphericalDirectionalLight`) also lights it; one given only by `environment` is background only.
    /// The images the scene reads are held to the default budget, [`ImageLimits::DEFAULT`].
    pub fn build(desc: SceneDesc, spec: &AccelConfig, environment: Option<EnvMap>) -> Result<Scene> {
        Scene::build_within(desc, spec, environment, &ImageLimits::DEFAULT)
    }

    /// [`Scene::build`] with every image the scene reads (textures, its environment map or cube faces)
    /// held to `images`.
    pub fn build_within(
        desc: SceneDesc,
        spec: &AccelConfig,
        environment: Option<EnvMap>,
        images: &ImageLimits,
    ) -> Result<Scene> {
        let environment = match environment {
            Some(env) => Some(env),
            None => load_environment(&desc, images)?,
        };
        let start = Instant::now();
        let geometry = build_geometry(&desc, spec)?;
        let textures = textures::build_textures(&desc, images)?;
        let build_time = start.elapsed().saturating_sub(geometry.counts.mesh_load);
        // The radius of the bounded objects' bounding sphere, for the power of lights at infinity.
        let bounds = geometry.top.bounds();
        let radius = if bounds.min.cmple(bounds.max).all() { 0.5 * (bounds.max - bounds.min).length() } else { 0.0 };
        let mut lights: Vec<Box<dyn Light>> = desc.lights.iter().map(|l| build_light(l, radius)).collect();
        let mut environment_light = None;
        if let (Some(map), true) = (&environment, desc.environment.is_some()) {
            let units = 1.0 / desc.radiance_scale;
            environment_light = Some(lights.len());
            let light = SphericalDirectionalLight::new(map.clone(), units).map_err(|e| environment_error(&desc, e))?;
            lights.push(Box::new(light.with_scene_radius(radius)));
        }
        let (object_lights, object_emission) = emitters::build_emitters(&desc, &geometry, &mut lights)?;
        let offset = match desc.offset {
            OffsetRule::ShadowEpsilon => RayOffset::ShadowEpsilon(desc.shadow_epsilon),
            OffsetRule::ErrorBound => RayOffset::ErrorBound,
        };
        Ok(Scene {
            geometry,
            materials: desc.materials.iter().map(build_material).collect(),
            object_materials: desc.objects.iter().map(|o| o.material).collect(),
            background_texture: textures.iter().position(|t| t.decal == Decal::ReplaceBackground),
            object_textures: desc.objects.iter().map(|o| o.textures.clone()).collect(),
            footprints: textures.iter().any(|t| t.wants_footprint()),
            textures,
            lights,
            environment_light,
            object_lights,
            object_emission,
            // Tone mapping sees the film in the scene's radiance units (its log-average's δ is in them).
            cameras: desc
                .cameras
                .iter()
                .map(|c| {
                    let mut camera = build_camera(c);
                    camera.tonemap = c.tonemap.map(|t| t.in_units(desc.radiance_scale));
                    camera
                })
                .collect(),
            environment,
            background: desc.background,
            ambient: desc.ambient,
            radiance_scale: desc.radiance_scale,
            max_depth: desc.max_depth,
            shadows: desc.shadows,
            flip_back_faces: desc.flip_back_faces,
            cull_backfaces: desc.cull_backfaces,
            offset,
            build_time,
        })
    }
}

/// The environment map the scene names, if any, its images held to `images`. A map that cannot be read
/// (or is above the budget, or does not fit in memory) is the scene's fault, like a missing mesh:
/// located where the file names it.
fn load_environment(desc: &SceneDesc, images: &ImageLimits) -> Result<Option<EnvMap>> {
    let Some(path) = desc.environment.as_deref() else { return Ok(None) };
    let map = if desc.environment_probe { EnvMap::load_probe(path, images) } else { EnvMap::load(path, images) };
    map.map(Some).map_err(|e| environment_error(desc, e))
}

/// An error of the scene's environment map `desc.environment`, at the element that names it.
fn environment_error(desc: &SceneDesc, e: Error) -> Error {
    let Some(path) = desc.environment.as_deref() else { return e };
    let why = match e {
        Error::Io { source, .. } => source.to_string(),
        // An undecodable map file; a face of a cube-map folder keeps its own name in the message.
        Error::Input { loc, msg } if loc.file == path => msg,
        e @ Error::Input { .. } => e.to_string(),
        Error::OutOfMemory(msg) => msg,
        other => return other,
    };
    let loc = desc.environment_loc.clone().unwrap_or_else(|| Location::file(&desc.source));
    Error::input(loc, format!("cannot read environment map '{}': {why}", path.display()))
}

/// The runtime camera of a description: its transform applied to position, gaze and up.
pub fn build_camera(desc: &CameraDesc) -> Camera {
    let t = &desc.transform;
    let w = &desc.window;
    let plane = ImagePlane { left: w.left, right: w.right, bottom: w.bottom, top: w.top, distance: desc.near_distance };
    let projection = match desc.lens {
        _ if desc.orthographic => Projection::Orthographic,
        Some(l) => Projection::ThinLens { aperture: l.aperture, focus_distance: l.focus_distance },
        None => Projection::Pinhole,
    };
    let mut camera = Camera::new(
        t.point(desc.position),
        t.vector(desc.gaze),
        t.vector(desc.up),
        plane,
        projection,
        desc.width,
        desc.height,
    );
    camera.id = desc.id.clone();
    camera.image_name = desc.image_name.clone();
    camera.num_samples = desc.num_samples;
    camera.tonemap = desc.tonemap;
    camera.renderer = desc.renderer;
    camera
}

/// The runtime material of a description.
fn build_material(desc: &MaterialDesc) -> Material {
    let linear = |c: crate::math::Color| if desc.degamma { c.powf(DEGAMMA) } else { c };
    let layer: Option<Box<dyn SpecularLayer>> = match desc.kind {
        MaterialKind::BlinnPhong => None,
        MaterialKind::Mirror { reflectance } => Some(Box::new(Mirror { reflectance: linear(reflectance) })),
        MaterialKind::Conductor { reflectance, eta, k } => {
            Some(Box::new(Conductor { reflectance: linear(reflectance), eta, k }))
        }
        MaterialKind::Dielectric { eta, absorption } => Some(Box::new(Dielectric { eta, absorption })),
        MaterialKind::Transparent { eta, transparency, mirror } => {
            Some(Box::new(Transparent { eta, transparency, mirror }))
        }
    };
    Material {
        ambient: linear(desc.ambient),
        diffuse: linear(desc.diffuse),
        specular: linear(desc.specular),
        phong_exponent: desc.phong_exponent,
        brdf: desc.brdf.as_ref().map(build_brdf),
        roughness: desc.roughness,
        layer,
        degamma: desc.degamma,
    }
}

/// The runtime BRDF of a description.
fn build_brdf(desc: &BrdfDesc) -> Brdf {
    let model = match desc.kind {
        BrdfKind::OriginalPhong => BrdfModel::OriginalPhong,
        BrdfKind::ModifiedPhong { normalized } => BrdfModel::ModifiedPhong { normalized },
        BrdfKind::OriginalBlinnPhong => BrdfModel::OriginalBlinnPhong,
        BrdfKind::ModifiedBlinnPhong { normalized } => BrdfModel::ModifiedBlinnPhong { normalized },
        BrdfKind::TorranceSparrow { kd_fresnel, eta, k } => BrdfModel::TorranceSparrow { eta, k, kd_fresnel },
    };
    Brdf { model, exponent: desc.exponent }
}

/// The runtime light of a description; `scene_radius` bounds the scene (for the power of a
/// directional light).
fn build_light(desc: &LightDesc, scene_radius: f32) -> Box<dyn Light> {
    match *desc {
        LightDesc::Point { position, intensity } => Box::new(PointLight { position, intensity }),
        LightDesc::Area { position, normal, size, radiance } => {
            Box::new(AreaLight { position, normal, size, radiance })
        }
        LightDesc::Directional { direction, radiance } => {
            Box::new(DirectionalLight { direction, radiance, scene_radius })
        }
        LightDesc::Spot { position, direction, intensity, coverage_deg, falloff_deg } => {
            match SpotLight::new(position, direction, intensity, coverage_deg, falloff_deg) {
                Some(spot) => Box::new(spot),
                // The readers refuse a zero direction; a description made otherwise gets a dark light.
                None => Box::new(PointLight { position, intensity: crate::math::Color::ZERO }),
            }
        }
    }
}

/// Loads the meshes of `desc` and builds its geometry under the structure `spec` describes, at both
/// levels.
pub fn build_geometry(desc: &SceneDesc, spec: &AccelConfig) -> Result<SceneGeometry> {
    spec.check().map_err(|e| Error::Invalid(e.to_string()))?;
    let start = Instant::now();
    let files = load_mesh_files(desc)?;
    let mesh_load = start.elapsed();
    let build_start = Instant::now();

    // One shape per mesh object, built in parallel; instances point at their base's.
    let mesh_objects: Vec<usize> =
        (0..desc.objects.len()).filter(|&i| matches!(desc.objects[i].shape, ShapeDesc::Mesh { .. })).collect();
    let shapes: Vec<Arc<MeshShape>> = mesh_objects
        .par_iter()
        .map(|&i| {
            let ShapeDesc::Mesh { source, smooth } = &desc.objects[i].shape else { unreachable!() };
            let mesh = match source {
                MeshSource::Inline(m) => m.as_ref(),
                MeshSource::File(path) => files[path].as_ref(),
            };
            Arc::new(mesh_shape(mesh, *smooth, spec))
        })
        .collect();
    let shape_of: HashMap<usize, Arc<MeshShape>> = mesh_objects.iter().copied().zip(shapes.iter().cloned()).collect();

    let mut objects = SceneObjects::default();
    let mut planes = Vec::new();
    let mut counts = SceneCounts { mesh_load, ..SceneCounts::default() };
    let mut first_prim = 0u32;
    for (index, object) in desc.objects.iter().enumerate() {
        let shape_index = match object.shape {
            ShapeDesc::Instance { base } => resolve_instance(desc, index, base)?,
            _ => index,
        };
        let transform = (!object.transform.is_identity()).then_some(object.transform);
        let shape = match &desc.objects[shape_index].shape {
            ShapeDesc::Mesh { .. } => Shape::Mesh(shape_of[&shape_index].clone()),
            ShapeDesc::Sphere { center, radius } => {
                Shape::Sphere(Sphere { center: *center, radius: *radius, transform: object.transform })
            }
            ShapeDesc::Plane { point, normal } => {
                let point = object.transform.point(*point);
                let normal = object.transform.normal(*normal).normalize();
                planes.push(ScenePlane {
                    plane: Plane { point, normal },
                    object: index as u32,
                    motion: moving(object),
                });
                continue;
            }
            ShapeDesc::Instance { .. } => unreachable!("resolve_instance never returns an instance"),
        };
        let bounds = match &shape {
            Shape::Mesh(m) => world_box(&m.accel.bounds(), transform.as_ref()),
            Shape::Sphere(s) => s.bounds(),
        };
        // A translation sweeps the box between its two ends; their union holds every box in between.
        let swept = bounds.union(Aabb::new(bounds.min + object.motion, bounds.max + object.motion));
        if !finite_or_empty(&swept) {
            let how = if finite_or_empty(&bounds) { "its bounds swept by its MotionBlur" } else { "its bounds" };
            let msg = format!("{}: {how} overflow to infinity (beyond the range of 32-bit floats)", object.name);
            return Err(Error::input(object.loc.clone(), msg));
        }
        let bounds = swept;
        match &shape {
            Shape::Mesh(m) => counts.triangles += m.mesh.len(),
            Shape::Sphere(_) => counts.spheres += 1,
        }
        let object = SceneObject {
            transform: if matches!(shape, Shape::Sphere(_)) { None } else { transform },
            shape,
            motion: moving(object),
            bounds,
            object: index as u32,
            first_prim,
        };
        first_prim += prim_count(&object.shape);
        objects.objects.push(object);
    }
    counts.unique_triangles = shapes.iter().map(|s| s.mesh.len()).sum();
    counts.degenerate = shapes.iter().map(|s| s.mesh.check().degenerate).sum();
    counts.planes = planes.len();
    counts.objects = objects.len();
    let top = top_level(spec).build_accel(&objects).map_err(|e| Error::Invalid(e.to_string()))?;
    counts.build = build_start.elapsed();
    Ok(SceneGeometry { objects, top, meshes: shapes, planes, counts })
}

/// The top level's structure: the scene's kind with one object per leaf (for the BVH kinds). An object
/// is a whole structure of its own, far dearer to enter than the box test that keeps a ray out of it,
/// while the SAH's costs are a triangle's: they would put a Cornell box's eight objects in one leaf, and
/// every ray would enter every object. The octree and kd-tree keep their parameters.
fn top_level(spec: &AccelConfig) -> AccelConfig {
    let mut top = spec.clone();
    match &mut top {
        AccelConfig::BvhSah(p) => {
            p.max_leaf_prims = 1;
            p.leaf_block = 1;
        }
        AccelConfig::BvhMedian(p) => p.max_leaf_prims = 1,
        AccelConfig::BvhBottomUp(p) => p.max_leaf_prims = 1,
        _ => {}
    }
    top
}

/// True for a box of finite corners, or the empty box of an object without primitives: an infinite
/// corner would make the top level's costs and every ray's slab distances infinite or NaN.
fn finite_or_empty(b: &Aabb) -> bool {
    b.is_empty() || (b.min.is_finite() && b.max.is_finite())
}

/// An object's motion over the shutter interval, `None` when it stands still.
fn moving(object: &ObjectDesc) -> Option<Vec3> {
    (object.motion != Vec3::ZERO).then_some(object.motion)
}

/// A mesh ready for rendering: smooth meshes get vertex normals (from the file, or averaged from the
/// faces), flat ones none (the shader then uses the face normal); texture coordinates are kept.
fn mesh_shape(mesh: &TriangleMesh, smooth: bool, spec: &AccelConfig) -> MeshShape {
    let mut mesh = mesh.clone();
    if smooth {
        match &mut mesh.normals {
            Some(n) => n.iter_mut().for_each(|v| *v = v.normalize_or_zero()),
            None => mesh.compute_vertex_normals(),
        }
    } else {
        mesh.normals = None;
    }
    let accel = match spec.build_accel(&mesh) {
        Ok(a) => a,
        Err(e) => unreachable!("parameters were checked before building: {e}"),
    };
    MeshShape { mesh, accel }
}

/// The object an instance draws its geometry from (following chains of instances).
fn resolve_instance(desc: &SceneDesc, index: usize, mut base: usize) -> Result<usize> {
    let me = &desc.objects[index];
    for _ in 0..desc.objects.len() {
        let object = desc
            .objects
            .get(base)
            .ok_or_else(|| Error::input(me.loc.clone(), format!("{}: base object does not exist", me.name)))?;
        match object.shape {
            ShapeDesc::Instance { base: next } => base = next,
            ShapeDesc::Mesh { .. } => return Ok(base),
            _ => return Err(Error::input(me.loc.clone(), format!("{}: base {} is not a mesh", me.name, object.name))),
        }
    }
    Err(Error::input(me.loc.clone(), format!("{}: instances refer to each other in a cycle", me.name)))
}

/// Reads every distinct mesh file once, in parallel. A failure names the object that asked for the file.
fn load_mesh_files(desc: &SceneDesc) -> Result<HashMap<PathBuf, Arc<TriangleMesh>>> {
    let mut wanted: Vec<(&PathBuf, &ObjectDesc)> = Vec::new();
    for object in &desc.objects {
        if let ShapeDesc::Mesh { source: MeshSource::File(path), .. } = &object.shape {
            if !wanted.iter().any(|(p, _)| *p == path) {
                wanted.push((path, object));
            }
        }
    }
    wanted
        .par_iter()
        .map(|(path, object)| {
            let mesh = crate::mesh_io::load_mesh(path).map_err(|e| match e {
                Error::Io { source, .. } => Error::input(
                    object.loc.clone(),
                    format!("{}: cannot read mesh file '{}': {source}", object.name, path.display()),
                ),
                // A fault of the whole file (its extension, its emptiness) is the scene's reference to
                // it: located at the element that names the file.
                Error::Input { loc, msg } if loc.line.is_none() && loc.byte.is_none() => {
                    Error::input(object.loc.clone(), format!("{}: mesh file '{}': {msg}", object.name, path.display()))
                }
                other => other,
            })?;
            // A file that parses to nothing (an OBJ reader skips lines it does not know, so any text
            // does) is never what the scene meant.
            if mesh.is_empty() {
                let msg = format!("{}: mesh file '{}' holds no triangles", object.name, path.display());
                return Err(Error::input(object.loc.clone(), msg));
            }
            Ok(((*path).clone(), Arc::new(mesh)))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Color, Transform, Vec2, Vec3};
    use crate::scene::desc::{Lens, Window};

    fn camera_desc() -> CameraDesc {
        CameraDesc {
            id: "7".into(),
            position: Vec3::new(0.0, 0.0, 20.0),
            gaze: Vec3::new(0.0, 0.0, -1.0),
            up: Vec3::new(0.0, 1.0, 0.0),
            window: Window { left: -10.0, right: 10.0, bottom: -10.0, top: 10.0 },
            near_distance: 10.0,
            orthographic: false,
            width: 800,
            height: 800,
            image_name: "x.png".into(),
            name_loc: Location::file("x.xml"),
            num_samples: 4,
            transform: Transform::IDENTITY,
            lens: None,
            tonemap: None,
            renderer: Default::default(),
            loc: Location::file("x.xml"),
        }
    }

    #[test]
    fn build_camera_keeps_image_and_applies_transform() {
        let mut d = camera_desc();
        d.transform = Transform::rotate(90.0, Vec3::Y).unwrap();
        let cam = build_camera(&d);
        assert_eq!((cam.id.as_str(), cam.image_name.as_str(), cam.num_samples), ("7", "x.png", 4));
        assert_eq!((cam.width, cam.height), (800, 800));
        let r = cam.ray(400, 400, Vec2::ZERO, Vec2::ZERO);
        assert!(r.origin.abs_diff_eq(Vec3::new(20.0, 0.0, 0.0), 1e-4));
        assert!(r.dir.abs_diff_eq(-Vec3::X, 1e-6));
    }

    #[test]
    fn build_camera_picks_the_projection() {
        let lens = Some(Lens { aperture: 2.0, focus_distance: 15.0 });
        let thin = build_camera(&CameraDesc { lens, ..camera_desc() });
        let a = thin.ray(10, 10, Vec2::splat(0.5), Vec2::new(0.1, 0.9));
        assert_ne!(a.origin, Vec3::new(0.0, 0.0, 20.0), "a thin lens starts rays off the eye");
        // An orthographic camera ignores the lens: parallel rays along the gaze.
        let ortho = build_camera(&CameraDesc { lens, orthographic: true, ..camera_desc() });
        let o = ortho.ray(10, 10, Vec2::splat(0.5), Vec2::new(0.1, 0.9));
        assert_eq!(o.dir, -Vec3::Z);
        let pinhole = build_camera(&camera_desc());
        assert_eq!(pinhole.ray(10, 10, Vec2::splat(0.5), Vec2::new(0.1, 0.9)).origin, Vec3::new(0.0, 0.0, 20.0));
    }

    #[test]
    fn build_material_maps_every_kind() {
        let desc = |kind| MaterialDesc {
            degamma: false,
            id: "m".into(),
            ambient: Color::splat(0.1),
            diffuse: Color::splat(0.2),
            specular: Color::splat(0.3),
            phong_exponent: 5.0,
            brdf: None,
            roughness: 0.0,
            kind,
        };
        let plain = build_material(&desc(MaterialKind::BlinnPhong));
        assert!(plain.layer.is_none() && !plain.transmits());
        assert_eq!(
            (plain.ambient, plain.diffuse, plain.specular, plain.phong_exponent),
            (Color::splat(0.1), Color::splat(0.2), Color::splat(0.3), 5.0)
        );
        let glass = build_material(&desc(MaterialKind::Dielectric { eta: 1.5, absorption: Color::splat(0.25) }));
        assert!(glass.transmits());
        assert_eq!(glass.interior_absorption(), Some(Color::splat(0.25)));
        let legacy =
            build_material(&desc(MaterialKind::Transparent { eta: 1.5, transparency: Color::ONE, mirror: Color::ONE }));
        assert!(legacy.transmits() && legacy.interior_absorption().is_none());
        let d = Vec3::new(0.0, -1.0, 0.0);
        assert_eq!(legacy.specular_lobes(d, Vec3::Y).len(), 3);
        let mirror = build_material(&desc(MaterialKind::Mirror { reflectance: Color::ONE }));
        assert_eq!(mirror.specular_lobes(d, Vec3::Y)[0].dir, Vec3::Y);
        let metal = build_material(&desc(MaterialKind::Conductor { reflectance: Color::ONE, eta: 0.4, k: 2.8 }));
        assert!(!metal.transmits() && metal.specular_lobes(d, Vec3::Y).len() == 1);
        // degamma: display colours become linear by the power 2.2 (0.5 -> 0.2176).
        let shown = MaterialDesc { degamma: true, ..desc(MaterialKind::Mirror { reflectance: Color::splat(0.5) }) };
        let linear = build_material(&shown);
        assert!((linear.diffuse.x - 0.2_f32.powf(2.2)).abs() < 1e-6, "{}", linear.diffuse);
        assert!(
            (linear.ambient.x - 0.1_f32.powf(2.2)).abs() < 1e-6 && (linear.specular.z - 0.3_f32.powf(2.2)).abs() < 1e-6
        );
        let up = linear.specular_lobes(d, Vec3::Y)[0].weight;
        assert!((up.y - 0.217_637_65).abs() < 1e-6, "{up}");
    }

    #[test]
    fn build_brdf_maps_every_model() {
        let cases = [
            (BrdfKind::OriginalPhong, BrdfModel::OriginalPhong),
            (BrdfKind::ModifiedPhong { normalized: true }, BrdfModel::ModifiedPhong { normalized: true }),
            (BrdfKind::OriginalBlinnPhong, BrdfModel::OriginalBlinnPhong),
            (BrdfKind::ModifiedBlinnPhong { normalized: false }, BrdfModel::ModifiedBlinnPhong { normalized: false }),
            (
                BrdfKind::TorranceSparrow { kd_fresnel: true, eta: 0.37, k: 2.82 },
                BrdfModel::TorranceSparrow { eta: 0.37, k: 2.82, kd_fresnel: true },
            ),
        ];
        for (kind, model) in cases {
            assert_eq!(build_brdf(&BrdfDesc { kind, exponent: 50.0 }), Brdf { model, exponent: 50.0 });
        }
    }

    #[test]
    fn build_light_maps_every_kind() {
        let p = Vec3::new(0.0, 0.0, 0.0);
        let point = build_light(&LightDesc::Point { position: Vec3::Y * 2.0, intensity: Color::splat(4.0) }, 1.0);
        assert_eq!(point.sample(p, Vec3::Y, Vec2::ZERO).unwrap().irradiance, Color::ONE);
        let dir = build_light(&LightDesc::Directional { direction: -Vec3::Y, radiance: Color::splat(3.0) }, 1.0);
        assert_eq!(dir.sample(p, Vec3::Y, Vec2::ZERO).unwrap().wi, Vec3::Y);
        let area =
            LightDesc::Area { position: Vec3::Y * 4.0, normal: -Vec3::Y, size: 0.5, radiance: Color::splat(64.0) };
        let s = build_light(&area, 1.0).sample(p, Vec3::Y, Vec2::splat(0.5)).unwrap();
        assert!((s.irradiance.x - 64.0 * 0.25 / 16.0).abs() < 1e-5);
    }
}
