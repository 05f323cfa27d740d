//! The METU CENG 795 scene schema (XML, and the 2025 JSON form of it), read from the element tree into
//! a [`SceneDesc`]. The schema, its defaults and its quirks are described in `shared/scenes/README.md`
//! section (ii); the rules that matter here:
//!
//! - ids are 1-based and per kind; materials become indices, inline meshes are compacted to the
//!   vertices they use (0-based), a sphere's `Center` and a plane's `Point` are vertex ids;
//! - `Transformations` lists named transforms (`t1 s2 r1 c1`) applied left to right;
//! - a look-at camera's window is `top = NearDistance·tan(FovY/2)`, `right = top·width/height`;
//! - `NumSamples` is a perfect square in every assignment file; another count becomes the nearest
//!   square with a warning, so that the jittered grid stays square; `ApertureSize` 0 is a pinhole;
//! - untyped (pre-2020) materials: a non-zero `Transparency` means glass, else a non-zero
//!   `MirrorReflectance` means a mirror. Only legacy files follow this rule: XML files in which no
//!   material has a `type` and that use no 2022 texture element (`TextureMap`, `Images`; the 2022
//!   `galactica_static.png` shows no reflection from its untyped mirror). Files that type their
//!   materials, and the 2025 JSON form always, keep
//!   untyped materials plain Blinn-Phong, as the official renderers do (the 2025 `raven.png` reference
//!   shows no reflection from its untyped `MirrorReflectance` at depth 6);
//! - an absent `MaxRecursionDepth` is 0 in XML (the 2024 official parser) and 6 in the 2025 JSON form,
//!   whose `bunny_with_plane.png` reference shows its mirror plane with no depth given;
//! - camera rays cull back faces in the 2025 JSON form unless `BackfaceCulling` says otherwise: its
//!   official images are culled (hw3 `cornellbox_boxes_dynamic.png` shows the boxes through the front
//!   wall's back, which an unculled render shows instead). The XML form does not tell its year (the 2022
//!   references are unculled, the 2021 ones culled), so it leaves the choice to the user (`--cull`);
//! - duplicated single-valued elements: the last one wins, with a warning;
//! - what Arbor does not render (emission, path tracing...) is one warning per
//!   element name, and whatever is never read is reported as ignored ([`Node::unused`]).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use super::tree::{Node, Unused};
use crate::math::{Mat4, Transform, Vec2, Vec3};
use crate::scene::desc::SceneDesc;
use crate::{Error, Location, Result};

/// Which form of the schema a file is written in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Form {
    /// The XML of 2017-2024.
    Xml,
    /// The 2025 JSON conversion.
    Json,
}

/// Reads the scene below the root element `root` of the file `path`, written in `form`.
pub fn read(root: &Node, path: &Path, form: Form) -> Result<SceneDesc> {
    if root.name != "Scene" {
        return Err(Error::input(root.loc(path), format!("root element is <{}>, expected <Scene>", root.name)));
    }
    root.mark_used();
    let mut r = Reader {
        path,
        dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
        desc: SceneDesc {
            max_depth: if form == Form::Json { 6 } else { 0 },
            cull_backfaces: (form == Form::Json).then_some(true),
            ..SceneDesc::new(path)
        },
        legacy: form == Form::Xml && !typed_materials(root) && !texture_maps(root),
        notes: Notes::default(),
        vertices: Vec::new(),
        transforms: HashMap::new(),
        materials: HashMap::new(),
        brdfs: HashMap::new(),
        images: image_table(root),
        texture_ids: HashMap::new(),
        uvs: Vec::new(),
    };
    r.globals(root)?;
    if let Some(v) = r.one(root, "VertexData") {
        r.vertices = vertex_data(v, path)?;
    }
    if let Some(t) = r.one(root, "Transformations") {
        r.transformations(t)?;
    }
    if let Some(b) = r.one(root, "BRDFs") {
        r.read_brdfs(b)?;
    }
    if let Some(m) = r.one(root, "Materials") {
        r.read_materials(m)?;
    }
    if let Some(c) = r.one(root, "Cameras") {
        for (i, node) in c.all("Camera").enumerate() {
            let cam = r.camera(node, i)?;
            // `--camera ID` picks a camera by its id, so two may not share one.
            if r.desc.cameras.iter().any(|c| c.id == cam.id) {
                return Err(r.err(node, format!("duplicate camera id '{}'", cam.id)));
            }
            r.desc.cameras.push(cam);
        }
    }
    if let Some(l) = r.one(root, "Lights") {
        r.lights(l)?;
    }
    if let Some(o) = r.one(root, "Objects") {
        r.objects(o)?;
    }
    for u in root.unused() {
        match u {
            Unused::Element(n, parent) => {
                r.notes.plain(n.loc(path), format!("<{}> in <{parent}> ignored (unknown or unused here)", n.name))
            }
            Unused::Attr(a, elem) => {
                r.notes.plain(a.loc(path), format!("attribute {} of <{elem}> ignored (unknown or unused here)", a.name))
            }
        }
    }
    r.desc.warnings = r.notes.finish();
    Ok(r.desc)
}

/// Warnings: what reading met, in reading order, then what it never read, in file order. An unsupported
/// feature is one line however often it occurs.
#[derive(Default)]
struct Notes {
    lines: Vec<(String, usize)>,
    features: HashMap<String, usize>,
}

impl Notes {
    fn plain(&mut self, loc: Location, msg: String) {
        self.lines.push((format!("{loc}: {msg}"), 1));
    }
    /// `label` names what was found (`<Texture>`, `attribute BRDF of <Material>`); `what` says what
    /// Arbor does instead; one line per label.
    fn feature(&mut self, loc: Location, label: &str, what: &str) {
        if let Some(&i) = self.features.get(label) {
            self.lines[i].1 += 1;
            return;
        }
        self.features.insert(label.to_string(), self.lines.len());
        self.lines.push((format!("{loc}: {label}: {what}"), 1));
    }
    fn finish(self) -> Vec<String> {
        let times = |(s, n): (String, usize)| match n {
            1 => s,
            n => format!("{s} ({n} occurrences)"),
        };
        self.lines.into_iter().map(times).collect()
    }
}

/// The scene being read, and what the file has defined so far for later elements to refer to.
struct Reader<'a> {
    path: &'a Path,
    dir: PathBuf,
    desc: SceneDesc,
    notes: Notes,
    vertices: Vec<Vec3>,
    transforms: HashMap<String, Transform>,
    materials: HashMap<String, usize>,
    /// `BRDFs` models by id, for the materials that name them.
    brdfs: HashMap<String, brdfs::BrdfEntry>,
    /// `Textures/Images/Image` by id: the file name as written, for lights that name an image.
    images: HashMap<String, String>,
    /// `TextureMap` (or pre-2022 `Texture`) ids, as indices into the description's textures: one map, or
    /// two for a pre-2022 texture that is also a bump map.
    texture_ids: HashMap<String, Vec<usize>>,
    /// `TexCoordData`, numbered from 1 like the vertices.
    uvs: Vec<Vec2>,
    /// A pre-2020 file: untyped materials take their kind from the elements present.
    legacy: bool,
}

/// True when some material of the scene has a `type` attribute (the post-2020 schema). Looked up
/// without marking anything as read.
fn typed_materials(root: &Node) -> bool {
    root.children
        .iter()
        .filter(|c| c.name == "Materials")
        .flat_map(|m| m.children.iter().filter(|c| c.name == "Material"))
        .any(|m| m.attrs.iter().any(|a| a.name == "type"))
}

/// True when the scene's `Textures` use the 2022 form (`TextureMap`, `Images`). Looked up without marking
/// anything as read.
fn texture_maps(root: &Node) -> bool {
    let textures = root.children.iter().filter(|c| c.name == "Textures").flat_map(|t| &t.children);
    textures.into_iter().any(|c| c.name == "TextureMap" || c.name == "Images")
}

/// The `Image` elements of `Textures/Images` by id (the last one of an id wins), looked up without
/// marking anything as read: textures report themselves.
fn image_table(root: &Node) -> HashMap<String, String> {
    let images = root.children.iter().filter(|c| c.name == "Textures").flat_map(|t| &t.children);
    images
        .filter(|c| c.name == "Images")
        .flat_map(|i| i.children.iter().filter(|c| c.name == "Image"))
        .filter_map(|img| {
            Some((img.attrs.iter().find(|a| a.name == "id")?.trimmed().to_string(), img.trimmed().to_string()))
        })
        .collect()
}

fn vertex_data(v: &Node, path: &Path) -> Result<Vec<Vec3>> {
    if let Some(t) = v.attr("type") {
        if t.trimmed() != "xyz" {
            let msg = format!("<VertexData>: unknown type '{}' (expected xyz)", t.trimmed());
            return Err(Error::input(t.loc(path), msg));
        }
    }
    let f = v.floats(path)?;
    if f.len() % 3 != 0 {
        let msg = format!("<VertexData>: expected x y z triples, found {} numbers", f.len());
        return Err(Error::input(v.loc(path), msg));
    }
    Ok(f.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect())
}

impl Reader<'_> {
    fn err(&self, n: &Node, msg: impl Into<String>) -> Error {
        Error::input(n.loc(self.path), msg)
    }

    /// The child `name` of `parent`, warning about duplicates (the last one wins).
    fn one<'n>(&mut self, parent: &'n Node, name: &str) -> Option<&'n Node> {
        for d in parent.duplicates(name) {
            let msg = format!("duplicate <{name}> in <{}>; the last one wins", parent.name);
            self.notes.plain(d.loc(self.path), msg);
        }
        parent.child(name)
    }

    fn req<'n>(&mut self, parent: &'n Node, name: &str) -> Result<&'n Node> {
        self.one(parent, name);
        parent.required(name, self.path)
    }

    fn globals(&mut self, root: &Node) -> Result<()> {
        let p = self.path;
        if let Some(n) = self.one(root, "BackgroundColor") {
            self.desc.background = n.vec3(p)?;
            if self.desc.background.cmplt(Vec3::ZERO).any() {
                return Err(self.err(n, format!("negative BackgroundColor {}", self.desc.background)));
            }
        }
        // A negative epsilon would move rays into the surfaces they leave, or stop shadow rays past
        // their light.
        let epsilon = |r: &mut Self, name: &str| -> Result<Option<f32>> {
            let Some(n) = r.one(root, name) else { return Ok(None) };
            let e = n.float(p)?;
            if e < 0.0 {
                return Err(r.err(n, format!("negative {name} {e}")));
            }
            Ok(Some(e))
        };
        if let Some(e) = epsilon(self, "ShadowRayEpsilon")? {
            self.desc.shadow_epsilon = e;
        }
        if let Some(e) = epsilon(self, "IntersectionTestEpsilon")? {
            self.desc.intersection_epsilon = e;
        }
        if let Some(n) = self.one(root, "MaxRecursionDepth") {
            self.desc.max_depth = n.uint(p)?;
            self.desc.max_depth_loc = Some(n.loc(p));
        }
        if let Some(n) = self.one(root, "BackfaceCulling") {
            self.desc.cull_backfaces = Some(n.boolean(p)?);
        }
        if let Some(n) = self.one(root, "TexCoordData") {
            self.tex_coord_data(n)?;
        }
        if let Some(t) = self.one(root, "Textures") {
            self.textures(t)?;
        }
        if let Some(n) = self.one(root, "BackgroundTexture") {
            self.background_texture(n);
        }
        Ok(())
    }

    fn transformations(&mut self, t: &Node) -> Result<()> {
        let p = self.path;
        for n in &t.children {
            let prefix = match n.name.as_str() {
                "Translation" => "t",
                "Scaling" => "s",
                "Rotation" => "r",
                "Composite" => "c",
                _ => continue,
            };
            n.mark_used();
            let id = n.attr("id").ok_or_else(|| self.err(n, format!("<{}>: missing attribute id", n.name)))?;
            let (made, why) = match prefix {
                "t" => (Some(Transform::translate(n.vec3(p)?)), String::new()),
                "s" => {
                    let s = n.vec3(p)?;
                    let why = if s.cmpeq(Vec3::ZERO).any() {
                        "a scale factor is zero".to_string()
                    } else {
                        why_singular(&Mat4::from_scale(s))
                    };
                    (Transform::scale(s), why)
                }
                "r" => {
                    let v = n.floats_n(4, false, p)?;
                    let axis = Vec3::new(v[1], v[2], v[3]);
                    (Transform::rotate(v[0], axis), "the rotation axis is zero".to_string())
                }
                _ => {
                    let v = n.floats_n(16, false, p)?;
                    let rows: [f32; 16] = v.try_into().unwrap_or([0.0; 16]);
                    // The file gives rows; glam takes columns.
                    let m = Mat4::from_cols_array(&rows).transpose();
                    (Transform::from_mat4(m), why_singular(&m))
                }
            };
            let made = made.ok_or_else(|| self.err(n, format!("<{}>: {why}", n.name)))?;
            let key = format!("{prefix}{}", id.trimmed());
            if self.transforms.insert(key.clone(), made).is_some() {
                return Err(self.err(n, format!("duplicate transformation '{key}'")));
            }
        }
        Ok(())
    }

    /// The `Transformations` child of `n`, composed left to right; identity when absent.
    fn transform_of(&mut self, n: &Node) -> Result<Transform> {
        let Some(list) = self.one(n, "Transformations") else {
            return Ok(Transform::IDENTITY);
        };
        let mut acc = Transform::IDENTITY;
        for (i, name) in list.trimmed().split_whitespace().enumerate() {
            let t = self
                .transforms
                .get(name)
                .ok_or_else(|| self.err(list, format!("<Transformations>: unknown transformation '{name}'")))?;
            // The first listed is applied first (README (ii), "Mesh/Transformations").
            acc = acc.then(t);
            if !acc.is_finite() {
                let names: Vec<&str> = list.trimmed().split_whitespace().take(i + 1).collect();
                let msg = format!("<Transformations>: composing '{}' {OVERFLOWS}", names.join(" "));
                return Err(self.err(list, msg));
            }
        }
        Ok(acc)
    }

    /// The child `element` of `o` (a `Radiance` or an `Intensity`): required, finite and not negative;
    /// `name` says whose it is in the error (made only then).
    fn non_negative(&mut self, o: &Node, element: &str, name: impl FnOnce() -> String) -> Result<Vec3> {
        let n = self.req(o, element)?;
        let v = n.vec3(self.path)?;
        if v.cmplt(Vec3::ZERO).any() {
            return Err(self.err(n, format!("{}: negative {element} {v}", name())));
        }
        Ok(v)
    }

    /// The child `name` of `n` as a unit vector.
    fn unit(&mut self, n: &Node, name: &str) -> Result<Vec3> {
        let c = self.req(n, name)?;
        let v = c.vec3(self.path)?;
        v.try_normalize().ok_or_else(|| self.err(c, format!("<{name}>: zero vector")))
    }
}

/// What is wrong with a transform whose matrix or inverse has an entry beyond `f32`.
const OVERFLOWS: &str = "overflows to infinity (an entry of the matrix or of its inverse is beyond the range of \
                         32-bit floats)";

/// Why [`Transform::from_mat4`] refuses `m`, whose entries are finite.
fn why_singular(m: &Mat4) -> String {
    let det = m.determinant();
    if !det.is_finite() {
        "the transform cannot be inverted: its determinant overflows to infinity (beyond the range of 32-bit \
         floats)"
            .to_string()
    } else if det == 0.0 {
        "the matrix is not invertible".to_string()
    } else {
        format!("the transform is too close to singular to invert: its determinant {det:e} is below 1e-30")
    }
}

mod brdfs;
mod camera;
mod lights;
mod material;
mod objects;
mod textures;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::desc::{BrdfDesc, BrdfKind, Lens, LightDesc, MaterialKind, MeshSource, ShapeDesc};
    use crate::scene::readers::xml;

    fn read_xml(body: &str) -> Result<SceneDesc> {
        let path = Path::new("t.xml");
        read(&xml::parse(&format!("<Scene>{body}</Scene>"), path)?, path, Form::Xml)
    }

    const MATERIAL: &str = "<Materials><Material id=\"1\"><AmbientReflectance>0 0 0</AmbientReflectance>\
        <DiffuseReflectance>1 1 1</DiffuseReflectance></Material></Materials>";

    #[test]
    fn metu_instance_may_precede_its_base_and_reset_drops_base_transform() {
        let body = format!(
            "{MATERIAL}<VertexData>0 0 0 1 0 0 0 1 0</VertexData>\
             <Transformations><Translation id=\"1\">0 0 5</Translation>\
             <Scaling id=\"1\">3 3 3</Scaling></Transformations><Objects>\
             <MeshInstance id=\"1\" baseMeshId=\"2\" resetTransform=\"true\">\
             <Transformations>s1</Transformations></MeshInstance>\
             <MeshInstance id=\"2\" baseMeshId=\"2\"><Transformations>s1</Transformations></MeshInstance>\
             <Mesh id=\"2\"><Material>1</Material><Transformations>t1</Transformations>\
             <Faces>1 2 3</Faces></Mesh></Objects>"
        );
        let d = read_xml(&body).unwrap();
        assert_eq!(d.objects[0].shape, ShapeDesc::Instance { base: 2 });
        assert_eq!(d.objects[0].material, 0, "inherits the base's material");
        let o = Vec3::ONE;
        assert_eq!(d.objects[0].transform.point(o), Vec3::splat(3.0));
        // Without reset: the base's translation first, then the instance's scale.
        assert_eq!(d.objects[1].transform.point(o), Vec3::new(3.0, 3.0, 18.0));
    }

    #[test]
    fn metu_instance_of_instance_composes_transforms_down_the_chain() {
        // 4 -> 3 -> 2 (mesh); 5 resets on top of 4; 3 has its own material, which 4 inherits.
        let body = format!(
            "{MATERIAL}<VertexData>0 0 0 1 0 0 0 1 0</VertexData>\
             <Transformations><Translation id=\"1\">0 0 5</Translation>\
             <Scaling id=\"1\">3 3 3</Scaling></Transformations><Objects>\
             <MeshInstance id=\"4\" baseMeshId=\"3\"><Transformations>t1</Transformations></MeshInstance>\
             <MeshInstance id=\"5\" baseMeshId=\"4\" resetTransform=\"true\">\
             <Transformations>s1</Transformations></MeshInstance>\
             <Mesh id=\"2\"><Material>1</Material><Transformations>t1</Transformations>\
             <Faces>1 2 3</Faces></Mesh>\
             <MeshInstance id=\"3\" baseMeshId=\"2\"><Material>1</Material>\
             <Transformations>s1</Transformations></MeshInstance></Objects>"
        );
        let d = read_xml(&body).unwrap();
        for i in [0, 1, 3] {
            assert_eq!(d.objects[i].shape, ShapeDesc::Instance { base: 2 }, "object {i}");
        }
        let o = Vec3::ONE;
        // 3: t1 then s1; 4: that, then t1 again; 5: s1 only.
        assert_eq!(d.objects[3].transform.point(o), Vec3::new(3.0, 3.0, 18.0));
        assert_eq!(d.objects[0].transform.point(o), Vec3::new(3.0, 3.0, 23.0));
        assert_eq!(d.objects[1].transform.point(o), Vec3::splat(3.0));
    }

    #[test]
    fn metu_instance_cycles_and_unknown_bases_are_errors() {
        let cycle = format!(
            "{MATERIAL}<Objects><MeshInstance id=\"7\" baseMeshId=\"8\"/>\
             <MeshInstance id=\"8\" baseMeshId=\"7\"/></Objects>"
        );
        let e = read_xml(&cycle).unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:218: MeshInstance 8: base mesh id '7' leads back to this instance");
        let unknown = format!("{MATERIAL}<Objects><MeshInstance id=\"7\" baseMeshId=\"9\"/></Objects>");
        let e = read_xml(&unknown).unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:181: MeshInstance 7: unknown base mesh id '9'");
    }

    /// A camera with `extra` elements, the first of them at column 219.
    fn camera(extra: &str) -> String {
        format!(
            "<Cameras><Camera id=\"1\"><Position>0 0 0</Position><Gaze>0 0 -1</Gaze><Up>0 1 0</Up>\
             <NearPlane>-1 1 -1 1</NearPlane><NearDistance>1</NearDistance><ImageResolution>4 4</ImageResolution>\
             <ImageName>a.png</ImageName>{extra}</Camera></Cameras>"
        )
    }

    #[test]
    fn metu_renderer_and_its_params_are_read_per_camera() {
        use crate::renderer::{PathOptions, Renderer, Roulette};
        let read = |depth: u32, extra: &str| {
            read_xml(&format!("<MaxRecursionDepth>{depth}</MaxRecursionDepth>{}", camera(extra)))
        };
        let d = read(3, "<Renderer>PathTracing</Renderer>").unwrap();
        // The course's renderer splits at refractive surfaces: its cameras do.
        let course = PathOptions { split_refraction: true, ..PathOptions::default() };
        assert_eq!(d.cameras[0].renderer, Renderer::PathTracing(course));
        assert!(d.warnings.is_empty(), "{:?}", d.warnings);
        let all = "<Renderer>PathTracing</Renderer><RendererParams> NextEventEstimation ImportanceSampling \
                   RussianRoulette</RendererParams>";
        let want = PathOptions { next_event: true, importance_sampling: true, roulette: Roulette::Course, ..course };
        assert_eq!(read(3, all).unwrap().cameras[0].renderer, Renderer::PathTracing(want));
        // MIS brings the two samplings it weighs.
        let mis = read(3, "<Renderer>PathTracing</Renderer><RendererParams>MIS</RendererParams>").unwrap();
        assert_eq!(
            mis.cameras[0].renderer,
            Renderer::PathTracing(PathOptions { split_refraction: true, ..PathOptions::DEFAULT })
        );
        assert_eq!(read(3, "").unwrap().cameras[0].renderer, Renderer::Whitted);
        let lone = read(3, "<RendererParams>MIS</RendererParams>").unwrap();
        assert_eq!(
            lone.warnings,
            ["t.xml:1:259: Camera 1: RendererParams without <Renderer>PathTracing</Renderer>; ignored"]
        );
        let flat = read(0, "<Renderer>PathTracing</Renderer>").unwrap();
        assert_eq!(
            flat.warnings,
            ["t.xml:1:259: Camera 1: path tracing with MaxRecursionDepth 0 follows no bounce: emitters and, with \
              NextEventEstimation, direct light only"]
        );
        let e = read(3, "<Renderer>PathTracing</Renderer><RendererParams>Bidirectional</RendererParams>").unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.xml:1:291: Camera 1: unknown RendererParams 'Bidirectional' (expected NextEventEstimation, \
             ImportanceSampling, RussianRoulette or MIS)"
        );
        let e = read(3, "<Renderer>Radiosity</Renderer>").unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:259: Camera 1: unknown Renderer 'Radiosity' (expected PathTracing)");
    }

    #[test]
    fn metu_num_samples_become_the_nearest_square_with_a_warning() {
        for (n, used) in [(1, 1), (4, 4), (9, 9), (900, 900), (2, 1), (3, 4), (10, 9), (12, 9), (13, 16), (14, 16)] {
            let d = read_xml(&camera(&format!("<NumSamples>{n}</NumSamples>"))).unwrap();
            assert_eq!(d.cameras[0].num_samples, used, "NumSamples {n}");
            assert_eq!(d.warnings.is_empty(), n == used, "NumSamples {n}: {:?}", d.warnings);
        }
        let d = read_xml(&camera("<NumSamples>10</NumSamples>")).unwrap();
        assert_eq!(d.warnings, ["t.xml:1:219: Camera 1: NumSamples 10 is not a perfect square; using 9 (3x3)"]);
        let d = read_xml(&camera("<NumSamples>14</NumSamples>")).unwrap();
        assert_eq!(d.warnings, ["t.xml:1:219: Camera 1: NumSamples 14 is not a perfect square; using 16 (4x4)"]);
        // The largest count keeps within u32: 65535² rather than 65536².
        let d = read_xml(&camera(&format!("<NumSamples>{}</NumSamples>", u32::MAX))).unwrap();
        assert_eq!(d.cameras[0].num_samples, 65535 * 65535);
        assert_eq!(read_xml(&camera("")).unwrap().cameras[0].num_samples, 1);
    }

    #[test]
    fn metu_num_samples_below_one_are_errors() {
        let e = read_xml(&camera("<NumSamples>0</NumSamples>")).unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:219: Camera 1: NumSamples 0 must be at least 1");
        let e = read_xml(&camera("<NumSamples>-4</NumSamples>")).unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:219: Camera 1: NumSamples -4 must be at least 1");
        let e = read_xml(&camera("<NumSamples>2.5</NumSamples>")).unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:219: <NumSamples>: malformed integer '2.5'");
    }

    #[test]
    fn metu_lens_must_be_finite_not_negative_and_focus_in_front() {
        let lens = |f: &str, a: &str| {
            read_xml(&camera(&format!("<FocusDistance>{f}</FocusDistance><ApertureSize>{a}</ApertureSize>")))
        };
        let d = lens("21", "1.5").unwrap();
        assert_eq!(d.cameras[0].lens, Some(Lens { aperture: 1.5, focus_distance: 21.0 }));
        // A zero aperture is a pinhole, whatever the focus distance.
        assert_eq!(lens("21", "0").unwrap().cameras[0].lens, None);
        assert_eq!(lens("0", "0").unwrap().cameras[0].lens, None);
        let e = lens("21", "-1.5").unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:252: Camera 1: ApertureSize -1.5 is negative (0 is a pinhole)");
        let e = lens("0", "1.5").unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:219: Camera 1: FocusDistance 0 must be positive");
        let e = lens("-3", "0").unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:219: Camera 1: FocusDistance -3 must be positive");
        let e = lens("inf", "1").unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:219: <FocusDistance>: non-finite number 'inf'");
        let e = lens("5", "NaN").unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:251: <ApertureSize>: non-finite number 'NaN'");
        let e = lens("5", "1e39").unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:251: <ApertureSize>: out-of-range number '1e39'");
    }

    #[test]
    fn metu_area_light_needs_a_positive_size_a_normal_and_finite_radiance() {
        let area = |normal: &str, size: &str, radiance: &str| {
            read_xml(&format!(
                "<Lights><AreaLight id=\"2\"><Position>0 0 0</Position><Normal>{normal}</Normal>\
                 <Size>{size}</Size><Radiance>{radiance}</Radiance></AreaLight></Lights>"
            ))
        };
        let d = area("0 -2 0", "3", "1 2 3").unwrap();
        let want =
            LightDesc::Area { position: Vec3::ZERO, normal: -Vec3::Y, size: 3.0, radiance: Vec3::new(1.0, 2.0, 3.0) };
        assert_eq!(d.lights, [want]);
        let e = area("0 -1 0", "0", "1 1 1").unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:83: AreaLight 2: Size 0 must be positive");
        let e = area("0 -1 0", "-2", "1 1 1").unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:83: AreaLight 2: Size -2 must be positive");
        let e = area("0 -1 0", "1e20", "1 1 1").unwrap_err();
        let msg = "t.xml:1:83: AreaLight 2: Size 100000000000000000000 is too large (its area is not a finite number)";
        assert_eq!(e.to_string(), msg);
        let e = area("0 -1 0", "inf", "1 1 1").unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:83: <Size>: non-finite number 'inf'");
        let e = area("0 0 0", "1", "1 1 1").unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:60: <Normal>: zero vector");
        let e = area("0 nan 0", "1", "1 1 1").unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:60: <Normal>: non-finite number 'nan'");
        let e = area("0 -1 0", "1", "1 Infinity 1").unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:97: <Radiance>: non-finite number 'Infinity'");
    }

    #[test]
    fn metu_legacy_refraction_index_of_an_opaque_material_warns_only_where_it_could_matter() {
        let material = |id: u32, extra: &str| {
            format!(
                "<Material id=\"{id}\"><AmbientReflectance>0 0 0</AmbientReflectance>\
                 <DiffuseReflectance>1 1 1</DiffuseReflectance>{extra}</Material>"
            )
        };
        let body = format!(
            "<Materials>{}{}{}{}</Materials>",
            material(1, "<Transparency>0 0 0</Transparency><RefractionIndex>1.5</RefractionIndex>"),
            material(2, "<RefractionIndex>1</RefractionIndex>"),
            material(3, "<Transparency>0.5 0.5 0.5</Transparency><RefractionIndex>1.5</RefractionIndex>"),
            material(4, "<RefractionIndex>1.5</RefractionIndex>"),
        );
        let brdf = "<Material id=\"5\" BRDF=\"1\"><AmbientReflectance>0 0 0</AmbientReflectance>\
                    <DiffuseReflectance>1 1 1</DiffuseReflectance><RefractionIndex>0.37</RefractionIndex></Material>";
        let body = body.replace("</Materials>", &format!("{brdf}</Materials>"))
            + "<BRDFs><ModifiedPhong id=\"1\"><Exponent>5</Exponent></ModifiedPhong></BRDFs>";
        let d = read_xml(&body).unwrap();
        let kinds: Vec<_> = d.materials.iter().map(|m| m.kind.clone()).collect();
        let glass = MaterialKind::Transparent { eta: 1.5, transparency: Vec3::splat(0.5), mirror: Vec3::ZERO };
        let plain = MaterialKind::BlinnPhong;
        assert_eq!(kinds, [plain.clone(), plain.clone(), glass, plain.clone(), plain]);
        // Material 5's index is left to its BRDF, which (not being Torrance-Sparrow) does not read it.
        assert_eq!(
            d.warnings,
            [
                "t.xml:1:674: Material 4: RefractionIndex 1.5 has no effect without a non-zero <Transparency>",
                "t.xml:1:841: <RefractionIndex> in <Material> ignored (unknown or unused here)",
            ]
        );
        let e = read_xml(&body.replace(">1.5</Refr", ">x</Refr")).unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:162: <RefractionIndex>: malformed number 'x'");
    }

    #[test]
    fn metu_untyped_mirror_reflectance_of_a_typed_file_warns_only_where_it_could_matter() {
        let body = |depth: u32, reflectance: &str| {
            format!(
                "<MaxRecursionDepth>{depth}</MaxRecursionDepth><Materials>{}\
                 <Material id=\"2\"><AmbientReflectance>0 0 0</AmbientReflectance>\
                 <DiffuseReflectance>1 1 1</DiffuseReflectance><MirrorReflectance>{reflectance}</MirrorReflectance>\
                 </Material><Material id=\"3\" type=\"mirror\"><AmbientReflectance>0 0 0</AmbientReflectance>\
                 <DiffuseReflectance>1 1 1</DiffuseReflectance><MirrorReflectance>1 1 1</MirrorReflectance>\
                 </Material></Materials>",
                &MATERIAL["<Materials>".len()..MATERIAL.len() - "</Materials>".len()]
            )
        };
        let d = read_xml(&body(6, "0.5 0.5 0.5")).unwrap();
        assert_eq!(d.materials[1].kind, MaterialKind::BlinnPhong);
        let msg = "t.xml:1:288: <MirrorReflectance>: a material without type=\"mirror\" or \"conductor\" does not \
                   reflect (as in the official renderers); ignored";
        assert_eq!(d.warnings, [msg]);
        assert_eq!(read_xml(&body(6, "0 0 0")).unwrap().warnings, Vec::<String>::new());
        assert_eq!(read_xml(&body(0, "0.5 0.5 0.5")).unwrap().warnings, Vec::<String>::new());
    }

    #[test]
    fn metu_spherical_light_names_a_file_or_an_image_id() {
        let images = "<Textures><Images><Image id=\"1\">a.png</Image><Image id=\"2\">sky.exr</Image></Images>\
                      </Textures>";
        let by_id = format!(
            "{images}<Lights><SphericalDirectionalLight id=\"1\"><ImageId>2</ImageId>\
                             </SphericalDirectionalLight></Lights>"
        );
        assert_eq!(read_xml(&by_id).unwrap().environment, Some(PathBuf::from("sky.exr")));
        let by_name = "<Lights><SphericalDirectionalLight id=\"1\"><EnvMapName>env.hdr</EnvMapName>\
                       </SphericalDirectionalLight></Lights>";
        assert_eq!(read_xml(by_name).unwrap().environment, Some(PathBuf::from("env.hdr")));
        assert!(!read_xml(by_name).unwrap().environment_probe);
        let probe = by_name.replace("id=\"1\">", "id=\"1\" type=\"probe\">");
        assert!(read_xml(&probe).unwrap().environment_probe);
        let e = read_xml(&probe.replace("probe", "cube")).unwrap_err();
        assert!(e.to_string().ends_with("unknown type 'cube' (expected latlong or probe)"), "{e}");
        let missing = by_id.replace(">2<", ">3<");
        let e = read_xml(&missing).unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:144: <ImageId>: no <Image id=\"3\"> in <Textures><Images>");
        let neither = "<Lights><SphericalDirectionalLight id=\"1\"/></Lights>";
        let e = read_xml(neither).unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:16: <SphericalDirectionalLight>: missing <EnvMapName> or <ImageId>");
    }

    #[test]
    fn metu_unsupported_feature_is_one_warning_with_a_count() {
        let untyped = |id: u32| {
            format!(
                "<Material id=\"{id}\"><AmbientReflectance>0 0 0</AmbientReflectance>\
                 <DiffuseReflectance>1 1 1</DiffuseReflectance><MirrorReflectance>1 1 1</MirrorReflectance>\
                 </Material>"
            )
        };
        let body = format!(
            "<MaxRecursionDepth>6</MaxRecursionDepth><Materials>{}{}<Material id=\"3\" type=\"mirror\">\
             <AmbientReflectance>0 0 0</AmbientReflectance><DiffuseReflectance>1 1 1</DiffuseReflectance>\
             <MirrorReflectance>1 1 1</MirrorReflectance></Material></Materials>",
            untyped(1),
            untyped(2)
        );
        let d = read_xml(&body).unwrap();
        let msg = "t.xml:1:168: <MirrorReflectance>: a material without type=\"mirror\" or \"conductor\" does not \
                   reflect (as in the official renderers); ignored (2 occurrences)";
        assert_eq!(d.warnings, [msg]);
    }

    #[test]
    fn metu_light_objects_are_a_mesh_and_a_sphere_with_radiance() {
        let body = format!(
            "{MATERIAL}<VertexData>0 0 0 1 0 0 0 1 0</VertexData><Objects>\
             <LightSphere id=\"1\"><Material>1</Material><Center>1</Center><Radius>1</Radius>\
             <Radiance>1 2 3</Radiance></LightSphere>\
             <LightMesh id=\"1\"><Material>1</Material><Radiance>4 5 6</Radiance><Faces>1 2 3</Faces></LightMesh>\
             <Sphere id=\"2\"><Material>1</Material><Center>1</Center><Radius>1</Radius></Sphere></Objects>"
        );
        let d = read_xml(&body).unwrap();
        assert_eq!(d.warnings, Vec::<String>::new());
        let emission: Vec<_> = d.objects.iter().map(|o| o.emission).collect();
        assert_eq!(emission, [Some(Vec3::new(1.0, 2.0, 3.0)), Some(Vec3::new(4.0, 5.0, 6.0)), None]);
        assert!(matches!(d.objects[0].shape, ShapeDesc::Sphere { radius: 1.0, .. }));
        assert!(matches!(&d.objects[1].shape, ShapeDesc::Mesh { source: MeshSource::Inline(m), .. } if m.len() == 1));
    }

    #[test]
    fn metu_brdfs_are_read_and_resolved_per_material() {
        let brdfs = "<BRDFs><OriginalPhong id=\"1\"><Exponent>5</Exponent></OriginalPhong>\
             <ModifiedPhong id=\"2\" normalized=\"true\"><Exponent>6</Exponent></ModifiedPhong>\
             <OriginalBlinnPhong id=\"3\"><Exponent>7</Exponent></OriginalBlinnPhong>\
             <ModifiedBlinnPhong id=\"4\"><Exponent>8</Exponent></ModifiedBlinnPhong>\
             <TorranceSparrow id=\"5\" kdfresnel=\"true\"><Exponent>9</Exponent></TorranceSparrow>\
             <TorranceSparrow id=\"6\"><Exponent>10</Exponent><RefractiveIndex>0.37</RefractiveIndex>\
             </TorranceSparrow></BRDFs>";
        let material = |id: u32, brdf: &str, extra: &str| {
            format!(
                "<Material id=\"{id}\" BRDF=\"{brdf}\"><AmbientReflectance>0 0 0</AmbientReflectance>\
                 <DiffuseReflectance>1 1 1</DiffuseReflectance>{extra}</Material>"
            )
        };
        let index = "<RefractionIndex>1.5</RefractionIndex><AbsorptionIndex>2</AbsorptionIndex>";
        let materials: String = (1..=4).map(|i| material(i, &i.to_string(), "")).collect();
        let body = format!(
            "<Materials>{materials}{}{}{}</Materials>{brdfs}",
            material(5, "5", index),
            material(6, "6", ""),
            material(7, "6", "<RefractionIndex>2.5</RefractionIndex>"),
        );
        let d = read_xml(&body).unwrap();
        assert!(d.warnings.is_empty(), "{:?}", d.warnings);
        let got: Vec<_> = d.materials.iter().map(|m| m.brdf.unwrap()).collect();
        let ts = |kd_fresnel, eta, k| BrdfKind::TorranceSparrow { kd_fresnel, eta, k };
        let want = [
            (BrdfKind::OriginalPhong, 5.0),
            (BrdfKind::ModifiedPhong { normalized: true }, 6.0),
            (BrdfKind::OriginalBlinnPhong, 7.0),
            (BrdfKind::ModifiedBlinnPhong { normalized: false }, 8.0),
            // The material's indices (2022), else the model's own (2019), the material's first.
            (ts(true, 1.5, 2.0), 9.0),
            (ts(false, 0.37, 0.0), 10.0),
            (ts(false, 2.5, 0.0), 10.0),
        ];
        let want: Vec<_> = want.into_iter().map(|(kind, exponent)| BrdfDesc { kind, exponent }).collect();
        assert_eq!(got, want);
        // An option a model does not have is reported, like any unread attribute.
        let odd = body.replace("<OriginalPhong id=\"1\">", "<OriginalPhong id=\"1\" normalized=\"true\">");
        let d = read_xml(&odd).unwrap();
        assert_eq!(d.warnings.len(), 1);
        assert!(d.warnings[0].ends_with("attribute normalized of <OriginalPhong> ignored (unknown or unused here)"));
    }

    #[test]
    fn metu_motion_blur_and_roughness_are_read() {
        let body = "<Materials><Material id=\"1\" type=\"mirror\"><AmbientReflectance>0 0 0</AmbientReflectance>\
             <DiffuseReflectance>0 0 0</DiffuseReflectance><MirrorReflectance>1 1 1</MirrorReflectance>\
             <Roughness>0.25</Roughness></Material></Materials><VertexData>0 0 0</VertexData><Objects>\
             <Sphere id=\"1\"><Material>1</Material><Center>1</Center><Radius>1</Radius>\
             <MotionBlur>0 0 1.5</MotionBlur></Sphere>\
             <Sphere id=\"2\"><Material>1</Material><Center>1</Center><Radius>1</Radius></Sphere></Objects>";
        let d = read_xml(body).unwrap();
        assert!(d.warnings.is_empty(), "{:?}", d.warnings);
        assert_eq!(d.materials[0].roughness, 0.25);
        assert_eq!(d.objects[0].motion, Vec3::new(0.0, 0.0, 1.5));
        assert_eq!(d.objects[1].motion, Vec3::ZERO);
        let negative = body.replace("0.25", "-0.5");
        assert_eq!(read_xml(&negative).unwrap_err().to_string(), "t.xml:1:186: Material 1: negative roughness -0.5");
        let short = body.replace("0 0 1.5", "0 1.5");
        assert!(read_xml(&short).unwrap_err().to_string().starts_with("t.xml:1:"), "a motion of two numbers");
    }

    #[test]
    fn metu_degenerate_transformations_are_errors() {
        let e = read_xml("<Transformations><Scaling id=\"2\">1 0 1</Scaling></Transformations>").unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:25: <Scaling>: a scale factor is zero");
        let c = "<Transformations><Composite id=\"1\">0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 1</Composite></Transformations>";
        let e = read_xml(c).unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:25: <Composite>: the matrix is not invertible");
        // Factors that are not zero but whose determinant leaves the range of f32.
        let e = read_xml("<Transformations><Scaling id=\"2\">1e30 1e30 1e30</Scaling></Transformations>").unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.xml:1:25: <Scaling>: the transform cannot be inverted: its determinant overflows to infinity (beyond \
             the range of 32-bit floats)"
        );
        let e =
            read_xml("<Transformations><Scaling id=\"2\">1e-11 1e-11 1e-11</Scaling></Transformations>").unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.xml:1:25: <Scaling>: the transform is too close to singular to invert: its determinant 9.999999e-34 \
             is below 1e-30"
        );
    }

    #[test]
    fn metu_composed_transformations_that_overflow_are_errors() {
        let body = |list: &str| {
            format!(
                "{MATERIAL}<VertexData>0 0 0 1 0 0 0 1 0</VertexData><Transformations><Scaling id=\"1\">1e20 1 1\
                 </Scaling><Scaling id=\"2\">1e-20 1 1</Scaling></Transformations><Objects><Mesh id=\"1\">\
                 <Material>1</Material><Faces>1 2 3</Faces><Transformations>{list}</Transformations></Mesh>\
                 </Objects>"
            )
        };
        // Each factor is fine, and so is a product that comes back into range.
        assert!(read_xml(&body("s1 s2 s1")).is_ok());
        for (list, upto) in [("s1 s1 s2", "s1 s1"), ("s2 s2", "s2 s2")] {
            let e = read_xml(&body(list)).unwrap_err().to_string();
            let want = format!(
                "<Transformations>: composing '{upto}' overflows to infinity (an entry of the matrix or of its \
                 inverse is beyond the range of 32-bit floats)"
            );
            assert!(e.starts_with("t.xml:1:") && e.ends_with(&want), "{e}");
        }
    }

    #[test]
    fn metu_root_must_be_scene_and_types_must_be_known() {
        let path = Path::new("t.xml");
        let e = read(&xml::parse("<Scen/>", path).unwrap(), path, Form::Xml).unwrap_err();
        assert_eq!(e.to_string(), "t.xml:1:1: root element is <Scen>, expected <Scene>");
        let body = MATERIAL.replace("id=\"1\"", "id=\"1\" type=\"glass\"");
        let e = read_xml(&body).unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.xml:1:36: Material 1: unknown type 'glass' (expected mirror, conductor or dielectric)"
        );
    }
}
