//! The build step for geometry: loads the mesh files of a description (each distinct file once, in
//! parallel), gives every mesh object its own acceleration structure (in parallel), resolves instances
//! to the mesh they show, and puts the objects under one top-level structure ([`super::geometry`]).
//! Asset errors name the scene element that asked for the file.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use rayon::prelude::*;

use super::desc::{MeshSource, ObjectDesc, SceneDesc, ShapeDesc};
use super::geometry::{prim_count, world_box, MeshShape, SceneCounts, SceneGeometry, SceneObject, SceneObjects, Shape};
use crate::accel::{self, AccelSpec, Primitives};
use crate::geometry::{Plane, Sphere, TriangleMesh};
use crate::{Error, Result};

/// Loads the meshes of `desc` and builds its geometry under the structure `spec` describes, at both
/// levels.
pub fn build_geometry(desc: &SceneDesc, spec: &AccelSpec) -> Result<SceneGeometry> {
    spec.check().map_err(Error::Invalid)?;
    let start = Instant::now();
    let files = load_mesh_files(desc)?;
    let mesh_load = start.elapsed();

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
                planes.push((Plane { point, normal }, index as u32));
                continue;
            }
            ShapeDesc::Instance { .. } => unreachable!("resolve_instance never returns an instance"),
        };
        let bounds = match &shape {
            Shape::Mesh(m) => world_box(&m.accel.bounds(), transform.as_ref()),
            Shape::Sphere(s) => s.bounds(),
        };
        match &shape {
            Shape::Mesh(m) => counts.triangles += m.mesh.len(),
            Shape::Sphere(_) => counts.spheres += 1,
        }
        let object = SceneObject {
            transform: if matches!(shape, Shape::Sphere(_)) { None } else { transform },
            shape,
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
    let top = accel::build_with(spec, &objects).map_err(Error::Invalid)?;
    Ok(SceneGeometry { objects, top, meshes: shapes, planes, counts })
}

/// A mesh ready for rendering: smooth meshes get vertex normals (from the file, or averaged from the
/// faces), flat ones none (the shader then uses the face normal).
fn mesh_shape(mesh: &TriangleMesh, smooth: bool, spec: &AccelSpec) -> MeshShape {
    let mut mesh = TriangleMesh { uvs: None, ..mesh.clone() };
    if smooth {
        match &mut mesh.normals {
            Some(n) => n.iter_mut().for_each(|v| *v = v.normalize_or_zero()),
            None => mesh.compute_vertex_normals(),
        }
    } else {
        mesh.normals = None;
    }
    let accel = match accel::build_with(spec, &mesh) {
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
            Ok(((*path).clone(), Arc::new(mesh)))
        })
        .collect()
}
