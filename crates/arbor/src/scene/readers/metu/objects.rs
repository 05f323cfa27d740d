//! The `Objects` of a METU scene: meshes (inline or from a PLY file), lone triangles, spheres, planes
//! and mesh instances, each with its material index and object-to-world transform; and the emissive
//! `LightMesh` and `LightSphere` (hw6), read as a mesh and a sphere with a `Radiance`.
//!
//! Inline faces are 1-based `VertexData` ids (plus `vertexOffset`); each mesh is compacted to the
//! vertices it uses, renumbered from 0 in order of first use, so that a scene whose meshes share one
//! big vertex list does not copy that list into every mesh. Instances name their base by id: a mesh or
//! another instance, which may come later in the file, so they are resolved after all objects are read,
//! each base before the instances built on it.

use std::collections::HashMap;
use std::sync::Arc;

use super::Reader;
use crate::geometry::TriangleMesh;
use crate::math::Vec3;
use crate::scene::desc::{MeshSource, ObjectDesc, ShapeDesc};
use crate::scene::readers::tree::{Attr, Node};
use crate::{Error, Result};

/// A `MeshInstance` waiting for its base; its own transform is already in its object.
struct Pending<'n> {
    object: usize,
    base_id: &'n Attr,
    reset: bool,
    has_material: bool,
    has_textures: bool,
}

/// What a `MeshInstance` id names while instances are resolved.
#[derive(Clone, Copy)]
enum Base {
    /// A mesh: the object index.
    Mesh(usize),
    /// An instance: its index in the pending list.
    Instance(usize),
}

impl Reader<'_> {
    /// Every object of `Objects`, in file order, then the instances' bases.
    pub(super) fn objects(&mut self, objects: &Node) -> Result<()> {
        let mut ids: HashMap<String, Base> = HashMap::new();
        let mut pending = Vec::new();
        for o in &objects.children {
            let kind = o.name.as_str();
            if !matches!(kind, "Mesh" | "LightMesh" | "Triangle" | "Sphere" | "LightSphere" | "Plane" | "MeshInstance")
            {
                continue;
            }
            o.mark_used();
            let id = o.attr("id").map(|a| a.trimmed().to_string());
            let name = format!("{kind} {}", id.as_deref().unwrap_or("(no id)"));
            let emission =
                if kind.starts_with("Light") { Some(self.non_negative(o, "Radiance", || name.clone())?) } else { None };
            let textures = self.object_textures(o, &name)?;
            let (material, shape) = if kind == "MeshInstance" {
                let base_id =
                    o.attr("baseMeshId").ok_or_else(|| self.err(o, format!("{name}: missing attribute baseMeshId")))?;
                let reset = match o.attr("resetTransform") {
                    Some(a) => a.boolean(self.path)?,
                    None => false,
                };
                let has_material = o.child("Material").is_some();
                let material = if has_material { self.material_of(o, &name)? } else { 0 };
                let has_textures = o.child("Textures").is_some() || o.child("Texture").is_some();
                pending.push(Pending { object: self.desc.objects.len(), base_id, reset, has_material, has_textures });
                (material, ShapeDesc::Instance { base: 0 })
            } else {
                let material = self.material_of(o, &name)?;
                let shape = self.shape(o, &name)?;
                if let ShapeDesc::Mesh { source: MeshSource::Inline(_), .. } = &shape {
                    self.check_uvs_for_images(o, &name, &textures)?;
                }
                if let (Some(_), ShapeDesc::Mesh { source: MeshSource::Inline(m), .. }) = (emission, &shape) {
                    if m.indices.is_empty() {
                        return Err(self.err(o, format!("{name}: a light mesh needs at least one triangle")));
                    }
                }
                (material, shape)
            };
            let transform = self.transform_of(o)?;
            let motion = match self.one(o, "MotionBlur") {
                Some(n) => n.vec3(self.path)?,
                None => Vec3::ZERO,
            };
            let base = match kind {
                "Mesh" => Some(Base::Mesh(self.desc.objects.len())),
                "MeshInstance" => Some(Base::Instance(pending.len() - 1)),
                _ => None,
            };
            // Before 2022 meshes and instances were numbered apart ("MeshInstance 1" of "Mesh 1"); since,
            // one id space holds both. A mesh of the id is the base whenever there is one.
            if let (Some(id), Some(base)) = (&id, base) {
                if matches!(base, Base::Mesh(_)) || !matches!(ids.get(id), Some(Base::Mesh(_))) {
                    ids.insert(id.clone(), base);
                }
            }
            let loc = o.loc(self.path);
            let object = ObjectDesc { name, material, shape, transform, motion, textures, emission, loc };
            self.desc.objects.push(object);
        }
        self.resolve_instances(&pending, &ids)
    }

    /// Gives every pending instance its mesh, and its base's transform and material where it asks for
    /// them, resolving each base instance first; a chain that comes back to itself is an error.
    fn resolve_instances(&mut self, pending: &[Pending], ids: &HashMap<String, Base>) -> Result<()> {
        // The mesh each resolved instance shows.
        let mut mesh_of: Vec<Option<usize>> = vec![None; pending.len()];
        let mut on_chain = vec![false; pending.len()];
        for start in 0..pending.len() {
            // Walk down to the first base that is resolved (or a mesh), then resolve back up.
            let mut chain = vec![start];
            on_chain[start] = true;
            loop {
                let p = &pending[chain[chain.len() - 1]];
                let id = p.base_id.trimmed();
                let base = *ids.get(id).ok_or_else(|| {
                    let name = &self.desc.objects[p.object].name;
                    Error::input(p.base_id.loc(self.path), format!("{name}: unknown base mesh id '{id}'"))
                })?;
                match base {
                    Base::Instance(b) if mesh_of[b].is_none() => {
                        if on_chain[b] {
                            let name = &self.desc.objects[p.object].name;
                            let msg = format!("{name}: base mesh id '{id}' leads back to this instance");
                            return Err(Error::input(p.base_id.loc(self.path), msg));
                        }
                        chain.push(b);
                        on_chain[b] = true;
                    }
                    _ => break,
                }
            }
            for &i in chain.iter().rev() {
                on_chain[i] = false;
                if mesh_of[i].is_some() {
                    continue;
                }
                let p = &pending[i];
                let (base_object, mesh) = match ids[p.base_id.trimmed()] {
                    Base::Mesh(m) => (m, m),
                    Base::Instance(b) => (pending[b].object, mesh_of[b].unwrap_or_default()),
                };
                let (base_transform, base_material, base_textures) = {
                    let b = &self.desc.objects[base_object];
                    (b.transform, b.material, b.textures.clone())
                };
                let inst = &mut self.desc.objects[p.object];
                inst.shape = ShapeDesc::Instance { base: mesh };
                // Without resetTransform the instance moves its base from where the base put it.
                if !p.reset {
                    inst.transform = base_transform.then(&inst.transform);
                    if !inst.transform.is_finite() {
                        let msg =
                            format!("{}: its base's transform followed by its own {}", inst.name, super::OVERFLOWS);
                        return Err(Error::input(inst.loc.clone(), msg));
                    }
                }
                if !p.has_material {
                    inst.material = base_material;
                }
                if !p.has_textures {
                    inst.textures = base_textures;
                }
                mesh_of[i] = Some(mesh);
            }
        }
        Ok(())
    }

    /// The geometry of `o`, any kind but `MeshInstance`.
    fn shape(&mut self, o: &Node, name: &str) -> Result<ShapeDesc> {
        let p = self.path;
        Ok(match o.name.as_str() {
            "Mesh" | "LightMesh" => {
                let smooth = match o.attr("shadingMode") {
                    Some(a) if a.trimmed() == "smooth" => true,
                    Some(a) if a.trimmed() == "flat" => false,
                    Some(a) => {
                        let msg = format!("{name}: unknown shadingMode '{}'; flat used", a.trimmed());
                        self.notes.plain(a.loc(p), msg);
                        false
                    }
                    None => false,
                };
                let faces = self.req(o, "Faces")?;
                ShapeDesc::Mesh { source: self.faces(faces, name)?, smooth }
            }
            "Triangle" => {
                let ind = self.req(o, "Indices")?;
                let idx = ind.ints(p)?;
                if idx.len() != 3 {
                    let msg = format!("<Indices>: expected 3 vertex ids, found {}", idx.len());
                    return Err(self.err(ind, msg));
                }
                let mesh = self.compact(ind, name, &idx, 0, 0)?;
                ShapeDesc::Mesh { source: MeshSource::Inline(Arc::new(mesh)), smooth: false }
            }
            "Plane" => ShapeDesc::Plane { point: self.vertex_ref(o, "Point", name)?, normal: self.unit(o, "Normal")? },
            _ => {
                let center = self.vertex_ref(o, "Center", name)?;
                let r = self.req(o, "Radius")?;
                let radius = r.float(p)?;
                if radius < 0.0 {
                    return Err(self.err(r, format!("{name}: negative radius {radius}")));
                }
                ShapeDesc::Sphere { center, radius }
            }
        })
    }

    /// A mesh's `Faces`: a PLY file, or inline vertex ids.
    fn faces(&mut self, faces: &Node, name: &str) -> Result<MeshSource> {
        let p = self.path;
        if let Some(t) = faces.attr("type").filter(|t| t.trimmed() != "triangle") {
            let msg = format!("<Faces>: unknown type '{}' (expected triangle)", t.trimmed());
            return Err(Error::input(t.loc(p), msg));
        }
        let tex_offset = match faces.attr("textureOffset") {
            Some(a) => a.int(p)?,
            None => 0,
        };
        if let Some(ply) = faces.attr("plyFile") {
            if !faces.trimmed().is_empty() {
                let msg = format!("{name}: inline faces ignored, the mesh comes from plyFile");
                self.notes.plain(faces.loc(p), msg);
            }
            return Ok(MeshSource::File(self.dir.join(ply.trimmed())));
        }
        let offset = match faces.attr("vertexOffset") {
            Some(a) => a.int(p)?,
            None => 0,
        };
        let idx = faces.ints(p)?;
        if idx.len() % 3 != 0 {
            let msg = format!("<Faces>: expected vertex id triples, found {} ids", idx.len());
            return Err(self.err(faces, msg));
        }
        Ok(MeshSource::Inline(Arc::new(self.compact(faces, name, &idx, offset, tex_offset)?)))
    }

    /// The triangles `idx` (1-based ids, plus `offset`) as a mesh of only the vertices they use; with
    /// `TexCoordData`, each corner's (u, v) is the pair of its id plus `tex_offset`.
    fn compact(&self, at: &Node, name: &str, idx: &[i64], offset: i64, tex_offset: i64) -> Result<TriangleMesh> {
        let mut remap: HashMap<(usize, usize), u32> = HashMap::new();
        let mut mesh = TriangleMesh::default();
        let mut uvs = Vec::new();
        let mut corners = Vec::with_capacity(idx.len());
        for &raw in idx {
            let v = self.vertex_index(at, name, "vertex index", raw, offset)?;
            let t = if self.uvs.is_empty() { 0 } else { self.uv_index(at, name, raw, tex_offset)? };
            let next = mesh.positions.len() as u32;
            let i = *remap.entry((v, t)).or_insert_with(|| {
                mesh.positions.push(self.vertices[v]);
                uvs.extend(self.uvs.get(t).copied());
                next
            });
            corners.push(i);
        }
        mesh.uvs = (!self.uvs.is_empty()).then_some(uvs);
        mesh.indices = corners.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        Ok(mesh)
    }

    /// A 1-based vertex id (plus `offset`) as a 0-based index into the vertex data, or an error.
    fn vertex_index(&self, at: &Node, name: &str, what: &str, raw: i64, offset: i64) -> Result<usize> {
        let id = raw.saturating_add(offset);
        let n = self.vertices.len();
        if id >= 1 && (id as u64) <= n as u64 {
            return Ok(id as usize - 1);
        }
        let shown = match offset {
            0 => raw.to_string(),
            _ => format!("{raw} + vertexOffset {offset} = {id}"),
        };
        let msg = format!("{name}: {what} {shown} out of range (VertexData has {n} vertices, numbered from 1)");
        Err(self.err(at, msg))
    }

    /// A 1-based texture coordinate id (plus `offset`) as a 0-based index into `TexCoordData`.
    fn uv_index(&self, at: &Node, name: &str, raw: i64, offset: i64) -> Result<usize> {
        let id = raw.saturating_add(offset);
        let n = self.uvs.len();
        if id >= 1 && (id as u64) <= n as u64 {
            return Ok(id as usize - 1);
        }
        let shown = if offset == 0 { raw.to_string() } else { format!("{raw} + textureOffset {offset} = {id}") };
        let msg =
            format!("{name}: texture coordinate {shown} out of range (TexCoordData has {n} pairs, numbered from 1)");
        Err(self.err(at, msg))
    }

    /// A child holding one vertex id (`Center`, `Point`), as the vertex.
    fn vertex_ref(&mut self, o: &Node, child: &str, name: &str) -> Result<Vec3> {
        let c = self.req(o, child)?;
        let ids = c.ints(self.path)?;
        let [raw] = ids[..] else {
            let msg = format!("<{child}>: expected one vertex id, found {}", ids.len());
            return Err(self.err(c, msg));
        };
        let what = if child == "Center" { "centre vertex" } else { "point vertex" };
        Ok(self.vertices[self.vertex_index(c, name, what, raw, 0)?])
    }
}
