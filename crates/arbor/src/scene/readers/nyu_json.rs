//! The NYU Computer Graphics `scene.json` (Assignment 4), read into a [`SceneDesc`]; the schema and the
//! starter code's conventions are in `shared/scenes/README.md` section (iii).
//!
//! What the file leaves to the starter code is fixed here: a 640x480 image named after the scene file,
//! colours on a 0-1 scale, a camera looking down -z with
//! +y up whose `FieldOfView` (radians) is taken as vertical. The depth-of-field lens is ignored (the
//! reference images show no blur). A `Parallelogram` is `Origin` plus the edge vectors `u` and `v`
//! (the starter leaves it a TODO; `U`/`V` are accepted too), made of two triangles. Semantic errors
//! carry the line of the offending key, thanks to the positions kept by [`super::json`].
//!
//! Shading is local, as the assignment's reference renderer does it: ambient plus Blinn-Phong from every
//! light, with no shadow rays and no reflection, whatever `Mirror` says, and on both sides of a surface
//! (no back-face culling). The reference `bunny.png`
//! matches this to within one level in every pixel, and differs in 4% of its pixels once shadows or
//! mirror bounces are added.

use std::path::Path;
use std::sync::Arc;

use super::json::{self, Member, Spanned, Value};
use crate::geometry::TriangleMesh;
use crate::math::{Color, Transform, Vec3};
use crate::scene::desc::{
    CameraDesc, LightDesc, MaterialDesc, MaterialKind, MeshSource, ObjectDesc, OffsetRule, SceneDesc, ShapeDesc, Window,
};
use crate::{Error, Location, Result};

const WIDTH: u32 = 640;
const HEIGHT: u32 = 480;

/// True when `text` has the NYU layout: top-level `Camera` or `Objects` keys (a METU JSON scene has
/// everything inside a top-level `Scene`). Scans the top-level keys only; never fails.
pub fn looks_like_nyu(text: &str) -> bool {
    json::top_level_keys(text).is_some_and(|keys| keys.iter().any(|k| matches!(k.as_str(), "Camera" | "Objects")))
}

/// Reads an NYU `scene.json`.
pub fn parse(text: &str, path: &Path) -> Result<SceneDesc> {
    let doc = json::parse_value(text, path)?;
    let top = Obj::new(&doc, "the scene", path)?;
    let mut desc = SceneDesc::new(path);
    desc.radiance_scale = 1.0;
    // The format gives no epsilon: offsets follow the hit point's error bound (shadow_epsilon stays
    // the 1e-4 reported before, unused).
    desc.shadow_epsilon = 1e-4;
    desc.offset = OffsetRule::ErrorBound;
    desc.max_depth = 0;
    desc.shadows = false;
    desc.flip_back_faces = true;
    // Nor does it cull: camera rays see back faces (no warning suggests `--cull` either).
    desc.cull_backfaces = Some(false);
    let mut warn = Vec::new();
    if let Some(scene) = top.get("Scene") {
        let scene = Obj::new(&scene.value, "Scene", path)?;
        desc.background = scene.vec3("Background")?;
        desc.ambient = scene.vec3("Ambient")?;
        scene.unknown(&["Background", "Ambient"], &mut warn);
    }
    let cam = top.required("Camera")?;
    desc.cameras.push(camera(&Obj::new(&cam.value, "Camera", path)?, cam, &mut warn)?);
    for (i, m) in top.array("Materials")?.iter().enumerate() {
        desc.materials.push(material(&Obj::new(m, "a material", path)?, i, &mut warn)?);
    }
    for l in top.array("Lights")? {
        let l = Obj::new(l, "a light", path)?;
        let position = l.vec3("Position")?;
        let intensity = l.vec3("Color")?;
        l.unknown(&["Position", "Color"], &mut warn);
        desc.lights.push(LightDesc::Point { position, intensity });
    }
    for (i, o) in top.array("Objects")?.iter().enumerate() {
        let obj = object(&Obj::new(o, "an object", path)?, i, &desc, &mut warn)?;
        desc.objects.push(obj);
    }
    top.unknown(&["Scene", "Camera", "Materials", "Lights", "Objects"], &mut warn);
    desc.warnings = warn;
    Ok(desc)
}

fn camera(c: &Obj<'_>, at: &Member, warn: &mut Vec<String>) -> Result<CameraDesc> {
    let focal = c.number("FocalLength")?;
    let fov = c.number("FieldOfView")?;
    // The image plane must lie in front of the eye and its window must be neither empty nor turned over:
    // either would render a wrong image without a word.
    if focal <= 0.0 {
        return Err(c.bad(c.required("FocalLength")?, &format!("{focal} must be positive")));
    }
    if !(fov > 0.0 && fov < std::f32::consts::PI) {
        return Err(c.bad(c.required("FieldOfView")?, &format!("{fov} must be in (0, π) radians")));
    }
    let top = focal * (fov / 2.0).tan();
    let right = top * WIDTH as f32 / HEIGHT as f32;
    let orthographic = match c.get("IsPerspective") {
        Some(m) => match m.value.value {
            Value::Bool(b) => !b,
            _ => return Err(c.bad(m, "expected true or false")),
        },
        None => false,
    };
    if let Some(m) = c.get("LensRadius") {
        let msg = "depth of field not supported (the reference images show none); lens ignored";
        warn.push(format!("{}: \"LensRadius\": {msg}", c.loc(m)));
    }
    c.unknown(&["IsPerspective", "Position", "FieldOfView", "FocalLength", "LensRadius"], warn);
    let stem = c.path.file_stem().map_or("scene".into(), |s| s.to_string_lossy());
    Ok(CameraDesc {
        id: "Camera".into(),
        position: c.vec3("Position")?,
        gaze: Vec3::NEG_Z,
        up: Vec3::Y,
        window: Window { left: -right, right, bottom: -top, top },
        near_distance: focal,
        orthographic,
        width: WIDTH,
        height: HEIGHT,
        image_name: format!("{stem}.png"),
        name_loc: c.loc(at),
        num_samples: 1,
        transform: Transform::IDENTITY,
        lens: None,
        tonemap: None,
        renderer: Default::default(),
        loc: c.loc(at),
    })
}

fn material(m: &Obj<'_>, i: usize, warn: &mut Vec<String>) -> Result<MaterialDesc> {
    let zero_if_absent = |k: &str| m.get(k).map_or(Ok(Color::ZERO), |_| m.vec3(k));
    let mirror = zero_if_absent("Mirror")?;
    let refraction = zero_if_absent("Refraction")?;
    let kind = if refraction != Color::ZERO {
        MaterialKind::Transparent { eta: m.number("RefractionIndex")?, transparency: refraction, mirror }
    } else if mirror != Color::ZERO {
        MaterialKind::Mirror { reflectance: mirror }
    } else {
        MaterialKind::BlinnPhong
    };
    let known = ["Ambient", "Diffuse", "Specular", "Shininess", "Mirror", "Refraction", "RefractionIndex"];
    m.unknown(&known, warn);
    Ok(MaterialDesc {
        degamma: false,
        id: i.to_string(),
        ambient: m.vec3("Ambient")?,
        diffuse: m.vec3("Diffuse")?,
        specular: m.vec3("Specular")?,
        phong_exponent: m.number("Shininess")?,
        brdf: None,
        roughness: 0.0,
        kind,
    })
}

fn object(o: &Obj<'_>, i: usize, desc: &SceneDesc, warn: &mut Vec<String>) -> Result<ObjectDesc> {
    let ty = o.required("Type")?;
    let Value::Str(kind) = &ty.value.value else {
        return Err(o.bad(ty, "expected a string"));
    };
    let name = format!("{kind} {i}");
    let mat = o.required("Material")?;
    let material = match &mat.value.value {
        Value::Number(n) => n.parse::<usize>().ok().filter(|&m| m < desc.materials.len()),
        _ => None,
    }
    .ok_or_else(|| {
        let n = desc.materials.len();
        o.bad(mat, &format!("{name}: no material {} (the scene has {n}, numbered from 0)", text_of(mat)))
    })?;
    let (shape, known): (ShapeDesc, &[&str]) = match kind.as_str() {
        "Mesh" => {
            let p = o.required("Path")?;
            let Value::Str(file) = &p.value.value else {
                return Err(o.bad(p, "expected a file name"));
            };
            let dir = o.path.parent().unwrap_or(Path::new(""));
            let source = MeshSource::File(dir.join(file));
            (ShapeDesc::Mesh { source, smooth: false }, &["Path"])
        }
        "Sphere" => {
            let radius = o.number("Radius")?;
            if radius < 0.0 {
                let r = o.required("Radius")?;
                return Err(o.bad(r, &format!("{name}: negative radius {radius}")));
            }
            (ShapeDesc::Sphere { center: o.vec3("Position")?, radius }, &["Position", "Radius"])
        }
        "Parallelogram" => {
            let origin = o.vec3("Origin")?;
            let edge = |a: &str, b: &str| o.vec3(if o.get(a).is_some() { a } else { b });
            let (u, v) = (edge("u", "U")?, edge("v", "V")?);
            let mesh = TriangleMesh {
                positions: vec![origin, origin + u, origin + u + v, origin + v],
                indices: vec![[0, 1, 2], [0, 2, 3]],
                ..Default::default()
            };
            let source = MeshSource::Inline(Arc::new(mesh));
            (ShapeDesc::Mesh { source, smooth: false }, &["Origin", "u", "v", "U", "V"])
        }
        other => {
            let msg = format!("unknown object type '{other}' (expected Mesh, Sphere or Parallelogram)");
            return Err(o.bad(ty, &msg));
        }
    };
    let mut all = vec!["Type", "Material"];
    all.extend_from_slice(known);
    o.unknown(&all, warn);
    Ok(ObjectDesc {
        name,
        material,
        shape,
        transform: Transform::IDENTITY,
        motion: Vec3::ZERO,
        textures: Vec::new(),
        emission: None,
        loc: o.loc(ty),
    })
}

fn text_of(m: &Member) -> String {
    match &m.value.value {
        Value::Number(n) => n.clone(),
        Value::Str(s) => format!("\"{s}\""),
        _ => "of that kind".into(),
    }
}

/// A JSON object of the scene, with located accessors.
struct Obj<'a> {
    members: &'a [Member],
    at: &'a Spanned,
    what: &'a str,
    path: &'a Path,
}

impl<'a> Obj<'a> {
    fn new(v: &'a Spanned, what: &'a str, path: &'a Path) -> Result<Self> {
        match &v.value {
            Value::Object(members) => Ok(Obj { members, at: v, what, path }),
            _ => Err(Error::input(Location::at(path, v.line, v.col), format!("{what}: expected a JSON object"))),
        }
    }
    fn loc(&self, m: &Member) -> Location {
        Location::at(self.path, m.line, m.col)
    }
    fn bad(&self, m: &Member, msg: &str) -> Error {
        Error::input(self.loc(m), format!("\"{}\": {msg}", m.key))
    }
    fn get(&self, key: &str) -> Option<&'a Member> {
        self.members.iter().rev().find(|m| m.key == key)
    }
    fn required(&self, key: &str) -> Result<&'a Member> {
        self.get(key).ok_or_else(|| {
            Error::input(
                Location::at(self.path, self.at.line, self.at.col),
                format!("{}: missing \"{key}\"", self.what),
            )
        })
    }
    fn number(&self, key: &str) -> Result<f32> {
        let m = self.required(key)?;
        num(&m.value).ok_or_else(|| self.bad(m, "expected a number"))
    }
    fn vec3(&self, key: &str) -> Result<Vec3> {
        let m = self.required(key)?;
        let v: Option<Vec<f32>> = match &m.value.value {
            Value::Array(items) => items.iter().map(num).collect(),
            _ => None,
        };
        match v.as_deref() {
            Some(&[x, y, z]) => Ok(Vec3::new(x, y, z)),
            _ => Err(self.bad(m, "expected an array of 3 numbers")),
        }
    }
    fn array(&self, key: &str) -> Result<&'a [Spanned]> {
        match self.get(key) {
            None => Ok(&[]),
            Some(m) => match &m.value.value {
                Value::Array(items) => Ok(items),
                _ => Err(self.bad(m, "expected an array")),
            },
        }
    }
    /// Warns about every key not in `known`.
    fn unknown(&self, known: &[&str], warn: &mut Vec<String>) {
        for m in self.members.iter().filter(|m| !known.contains(&m.key.as_str())) {
            let w = format!("{}: \"{}\" in {} ignored (unknown)", self.loc(m), m.key, self.what);
            warn.push(w);
        }
    }
}

fn num(v: &Spanned) -> Option<f32> {
    match &v.value {
        Value::Number(n) => n.parse::<f32>().ok().filter(|x| x.is_finite()),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nyu_looks_like_nyu_tells_the_forms_apart() {
        assert!(looks_like_nyu("{\"Scene\": {\"Background\": [0, 0, 0]}, \"Camera\": {}}"));
        assert!(looks_like_nyu("{\"Objects\": []}"));
        let metu = "{\"Scene\": {\"Cameras\": {\"Camera\": {}}, \"Objects\": {}}}";
        assert!(!looks_like_nyu(metu));
        assert!(!looks_like_nyu("{\"Scene\": {"));
        assert!(!looks_like_nyu("not json"));
    }

    #[test]
    fn nyu_camera_looks_down_z_with_vertical_fov() {
        let text = "{\"Camera\": {\"IsPerspective\": true, \"Position\": [0, 0, 2], \
                    \"FieldOfView\": 1.5707964, \"FocalLength\": 2.0, \"LensRadius\": 0.1}}";
        let d = parse(text, Path::new("data/scene.json")).unwrap();
        let c = &d.cameras[0];
        assert_eq!((c.gaze, c.up, c.orthographic), (Vec3::NEG_Z, Vec3::Y, false));
        // 90° vertical at focal length 2: top = 2; 640x480 makes right 8/3.
        assert!((c.window.top - 2.0).abs() < 1e-5 && (c.window.right - 8.0 / 3.0).abs() < 1e-5);
        assert_eq!((c.image_name.as_str(), c.near_distance, c.lens), ("scene.png", 2.0, None));
        assert_eq!(d.warnings.len(), 1, "the lens is reported: {:?}", d.warnings);
    }

    #[test]
    fn nyu_errors_name_the_key_and_its_line() {
        let text = "{\n  \"Camera\": {\"Position\": [0, 0], \"FieldOfView\": 1, \"FocalLength\": 1}\n}";
        let e = parse(text, Path::new("s.json")).unwrap_err();
        assert_eq!(e.to_string(), "s.json:2:14: \"Position\": expected an array of 3 numbers");
        let e = parse("{\"Objects\": []}", Path::new("s.json")).unwrap_err();
        assert_eq!(e.to_string(), "s.json:1:1: the scene: missing \"Camera\"");
    }

    #[test]
    fn nyu_camera_needs_a_positive_focal_length_and_a_field_of_view_below_pi() {
        let camera = |fov: &str, focal: &str| {
            let text = format!(
                "{{\"Camera\": {{\"Position\": [0, 0, 2], \"FieldOfView\": {fov}, \"FocalLength\": {focal}}}}}"
            );
            parse(&text, Path::new("s.json")).map(|_| ()).map_err(|e| e.to_string())
        };
        assert_eq!(camera("0.7854", "2"), Ok(()));
        assert_eq!(camera("0.7854", "0"), Err("s.json:1:59: \"FocalLength\": 0 must be positive".into()));
        assert_eq!(camera("0.7854", "-2"), Err("s.json:1:59: \"FocalLength\": -2 must be positive".into()));
        assert_eq!(camera("0", "2"), Err("s.json:1:36: \"FieldOfView\": 0 must be in (0, π) radians".into()));
        assert_eq!(camera("3.2", "2"), Err("s.json:1:36: \"FieldOfView\": 3.2 must be in (0, π) radians".into()));
    }
}
