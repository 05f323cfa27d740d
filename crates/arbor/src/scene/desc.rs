//! The format-neutral scene description: what every reader (METU XML, METU JSON, NYU JSON) produces and
//! what the build step ([`super::Scene::build`]) turns into a runtime scene; plain data, read by nothing
//! after the build. Everything in it is resolved (ids to indices, look-at cameras to image-plane windows,
//! named transforms to matrices) except assets (mesh files, environment maps), which are loaded at build
//! time; each object keeps the place in the scene file it came from, for error messages.

use std::path::PathBuf;
use std::sync::Arc;

use crate::geometry::TriangleMesh;
use crate::math::{Color, Transform, Vec3};
use crate::renderer::Renderer;
use crate::tonemap::Tonemap;
use crate::Location;

mod brdf;
mod texture;
pub use brdf::{BrdfDesc, BrdfKind};
pub use texture::{DecalMode, ImageDesc, Interpolation, NoiseConversion, TextureDesc, TextureSource};

/// A whole scene as described by its file.
#[derive(Debug, Clone)]
pub struct SceneDesc {
    /// The scene file.
    pub source: PathBuf,
    /// Radiance of primary rays that hit nothing (and have no environment map).
    pub background: Color,
    /// Multiplies the scene's radiance to get display units (1.0 = white): 1/255 for the METU formats,
    /// whose colours are on a 0-255 scale; 1 for NYU.
    pub radiance_scale: f32,
    /// Offset of secondary ray origins along the normal (`ShadowRayEpsilon`), used when [`SceneDesc::offset`]
    /// is [`OffsetRule::ShadowEpsilon`].
    pub shadow_epsilon: f32,
    /// How secondary ray origins leave the surface.
    pub offset: OffsetRule,
    /// `IntersectionTestEpsilon`, kept for reporting; the intersection tests are exact.
    pub intersection_epsilon: f32,
    /// Bounces of mirror, conductor and dielectric rays; 0 means none.
    pub max_depth: u32,
    /// Where the file sets `max_depth` (`MaxRecursionDepth`), for the limit check's message.
    pub max_depth_loc: Option<Location>,
    /// Whether lights are tested for occlusion. The NYU assignment-4 renderer shades without shadow rays.
    pub shadows: bool,
    /// Whether a surface hit from behind has its normals turned towards the ray (shaded as a front).
    /// The METU renderers never turn them: every hit is shaded, and its shadow and mirror rays leave,
    /// on the side of its stored normal (counter-clockwise winding, outward for spheres), so a back face
    /// is lit by the lights in front of it. NYU scenes turn them.
    pub flip_back_faces: bool,
    /// Back-face culling of primary rays as the scene asks for it (`BackfaceCulling`) or its form implies
    /// (the 2025 METU JSON form culls, the NYU form does not); `None` (METU XML) leaves it to the user:
    /// no culling by default.
    pub cull_backfaces: Option<bool>,
    /// One image per camera.
    pub cameras: Vec<CameraDesc>,
    /// Ambient radiance, added as `ambient reflectance * ambient` everywhere, shadowed or not.
    pub ambient: Color,
    /// Lights other than the ambient one.
    pub lights: Vec<LightDesc>,
    /// Materials; objects refer to them by index.
    pub materials: Vec<MaterialDesc>,
    /// Objects, in file order.
    pub objects: Vec<ObjectDesc>,
    /// The environment image of a `SphericalDirectionalLight`: it lights the scene and rays that miss
    /// see it.
    pub environment: Option<PathBuf>,
    /// True when `environment` is a light probe (`type="probe"`), false for a lat-long map.
    pub environment_probe: bool,
    /// Where the file names `environment`, for the message when it cannot be read.
    pub environment_loc: Option<Location>,
    /// Image files of texture maps, each once.
    pub images: Vec<ImageDesc>,
    /// Texture maps; objects refer to them by index.
    pub textures: Vec<TextureDesc>,
    /// Things in the file that Arbor read but does not render (textures, motion blur...), one line each.
    pub warnings: Vec<String>,
}

impl SceneDesc {
    /// An empty scene read from `source`, with the METU defaults (black background, 0-255 colours,
    /// shadow epsilon 1e-3, no recursion).
    pub fn new(source: impl Into<PathBuf>) -> Self {
        SceneDesc {
            source: source.into(),
            background: Color::ZERO,
            radiance_scale: 1.0 / 255.0,
            shadow_epsilon: 1e-3,
            offset: OffsetRule::ShadowEpsilon,
            intersection_epsilon: 1e-6,
            max_depth: 0,
            max_depth_loc: None,
            shadows: true,
            flip_back_faces: false,
            cull_backfaces: None,
            cameras: Vec::new(),
            ambient: Color::ZERO,
            lights: Vec::new(),
            materials: Vec::new(),
            objects: Vec::new(),
            environment: None,
            environment_probe: false,
            environment_loc: None,
            images: Vec::new(),
            textures: Vec::new(),
            warnings: Vec::new(),
        }
    }
}

/// How far secondary rays (shadow, reflected, refracted) start from the surface they leave.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum OffsetRule {
    /// By [`SceneDesc::shadow_epsilon`] along the geometric normal: the METU formats always give one
    /// (default 1e-3, the official renderer's), and their reference images depend on it.
    #[default]
    ShadowEpsilon,
    /// By the floating-point error bound of the hit point, for scenes that give no epsilon (pbrt-v4's
    /// `OffsetRayOrigin`, [`crate::geometry::error_bound`]).
    ErrorBound,
}

/// The image-plane window `left right bottom top`, at `near_distance` along the gaze.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Window {
    /// Left edge (along `u`).
    pub left: f32,
    /// Right edge.
    pub right: f32,
    /// Bottom edge (along `v`).
    pub bottom: f32,
    /// Top edge.
    pub top: f32,
}

/// A thin-lens aperture for depth of field.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lens {
    /// Side of the square aperture (`ApertureSize`), positive.
    pub aperture: f32,
    /// Distance to the plane in focus (`FocusDistance`), positive.
    pub focus_distance: f32,
}

/// A camera: an eye, a frame and an image-plane window, as in the METU courses.
#[derive(Debug, Clone, PartialEq)]
pub struct CameraDesc {
    /// The camera's id in the file (for messages and `--camera`).
    pub id: String,
    /// Eye point.
    pub position: Vec3,
    /// Viewing direction (need not be unit).
    pub gaze: Vec3,
    /// Up hint (need not be unit or perpendicular to the gaze).
    pub up: Vec3,
    /// Image-plane window.
    pub window: Window,
    /// Distance from the eye to the image plane.
    pub near_distance: f32,
    /// Parallel rays along the gaze instead of rays from the eye.
    pub orthographic: bool,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Output file name, relative to the output folder; its extension picks the format.
    pub image_name: String,
    /// Where the file gives `image_name` (the camera's own location when the format derives the name).
    pub name_loc: Location,
    /// Samples per pixel (`NumSamples`), at least 1; the METU readers give a perfect square.
    pub num_samples: u32,
    /// Camera transform (applied to position, gaze and up).
    pub transform: Transform,
    /// Depth of field, when the file asks for it with a non-zero aperture.
    pub lens: Option<Lens>,
    /// Tone mapping of the image (`Tonemap`); none: radiance written as it is.
    pub tonemap: Option<Tonemap>,
    /// The integrator (`Renderer`, `RendererParams`).
    pub renderer: Renderer,
    /// Where the camera is defined.
    pub loc: Location,
}

/// A light source other than the ambient light.
#[derive(Debug, Clone, PartialEq)]
pub enum LightDesc {
    /// Irradiance `intensity / d²` from a point.
    Point {
        /// Position.
        position: Vec3,
        /// Intensity.
        intensity: Color,
    },
    /// A square of side `size` (positive) centred at `position` facing `normal`, emitting `radiance`.
    Area {
        /// Centre.
        position: Vec3,
        /// Facing direction (unit).
        normal: Vec3,
        /// Side length.
        size: f32,
        /// Emitted radiance.
        radiance: Color,
    },
    /// Parallel light travelling along `direction`.
    Directional {
        /// Direction of travel (unit).
        direction: Vec3,
        /// Irradiance on a surface facing it.
        radiance: Color,
    },
    /// A point light emitting in a cone around `direction` (full angles in degrees,
    /// `0 < falloff_deg <= coverage_deg <= 360`).
    Spot {
        /// Position.
        position: Vec3,
        /// Axis of the cone (unit).
        direction: Vec3,
        /// Intensity inside the fall-off cone.
        intensity: Color,
        /// Full angle of the cone outside which no light leaves.
        coverage_deg: f32,
        /// Full angle of the cone inside which the light is a point light.
        falloff_deg: f32,
    },
}

/// How a material reflects beyond its Blinn-Phong terms.
#[derive(Debug, Clone, PartialEq)]
pub enum MaterialKind {
    /// Blinn-Phong only.
    BlinnPhong,
    /// Perfect mirror weighted by `reflectance`, no Fresnel.
    Mirror {
        /// `MirrorReflectance`.
        reflectance: Color,
    },
    /// A metal: complex Fresnel reflectance (index `eta`, extinction `k`) times `reflectance`.
    Conductor {
        /// `MirrorReflectance`.
        reflectance: Color,
        /// `RefractionIndex` (n).
        eta: f32,
        /// `AbsorptionIndex` (k).
        k: f32,
    },
    /// Glass: Fresnel reflection and refraction with index `eta`; Beer's law with `absorption` inside.
    Dielectric {
        /// `RefractionIndex`.
        eta: f32,
        /// `AbsorptionCoefficient`, per channel, per unit distance.
        absorption: Color,
    },
    /// The pre-2020 and NYU glass: Fresnel reflection and refraction, the transmitted part weighted by
    /// `transparency`, no Beer's law; `mirror` adds a Fresnel-free reflection on top.
    Transparent {
        /// `RefractionIndex`.
        eta: f32,
        /// `Transparency`.
        transparency: Color,
        /// `MirrorReflectance`.
        mirror: Color,
    },
}

/// A material: Blinn-Phong terms plus what [`MaterialKind`] adds.
#[derive(Debug, Clone, PartialEq)]
pub struct MaterialDesc {
    /// The material's id in the file.
    pub id: String,
    /// k_a.
    pub ambient: Color,
    /// k_d.
    pub diffuse: Color,
    /// k_s.
    pub specular: Color,
    /// Blinn-Phong exponent (1 when the file gives none).
    pub phong_exponent: f32,
    /// The BRDF model that replaces the Blinn-Phong terms, if the material names one.
    pub brdf: Option<BrdfDesc>,
    /// How far reflected and refracted rays stray from the ideal direction (`Roughness`); 0 is a
    /// perfect mirror or glass.
    pub roughness: f32,
    /// Mirror, conductor, dielectric...
    pub kind: MaterialKind,
    /// The colours are display values (`degamma="true"`): the build raises them to the power
    /// [`DEGAMMA`](crate::material::DEGAMMA) to make them linear reflectances.
    pub degamma: bool,
}

/// Where a mesh's triangles come from.
#[derive(Debug, Clone, PartialEq)]
pub enum MeshSource {
    /// Given in the scene file itself, already 0-based and compacted.
    Inline(Arc<TriangleMesh>),
    /// A mesh file (PLY, OBJ, OFF), resolved relative to the scene file.
    File(PathBuf),
}

/// The geometry of an object, in object space.
#[derive(Debug, Clone, PartialEq)]
pub enum ShapeDesc {
    /// A triangle mesh (a lone `Triangle` is a mesh of one).
    Mesh {
        /// Where its triangles are.
        source: MeshSource,
        /// Interpolate vertex normals (`shadingMode="smooth"`).
        smooth: bool,
    },
    /// A sphere.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f32,
    },
    /// An infinite plane.
    Plane {
        /// A point on it.
        point: Vec3,
        /// Its normal (unit).
        normal: Vec3,
    },
    /// Another object's geometry seen through this object's transform (`MeshInstance`); `base` indexes
    /// [`SceneDesc::objects`], and the transform already includes the base's unless `resetTransform`.
    Instance {
        /// Index of the object whose geometry is reused.
        base: usize,
    },
}

/// One object of the scene.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjectDesc {
    /// Kind and id as the file names it ("Mesh 3"), for messages.
    pub name: String,
    /// Index into [`SceneDesc::materials`].
    pub material: usize,
    /// Geometry in object space.
    pub shape: ShapeDesc,
    /// Object to world.
    pub transform: Transform,
    /// World-space translation over the shutter interval (`MotionBlur`): the object is where `transform`
    /// puts it at time 0 and moved by `motion` at time 1; zero for a still object.
    pub motion: Vec3,
    /// Indices into [`SceneDesc::textures`] of the maps on the object (an instance names its own).
    pub textures: Vec<usize>,
    /// The radiance the object emits (`LightMesh`, `LightSphere`; finite, non-negative), from the front
    /// of its triangles or the outside of its sphere; `None` for an object that does not emit.
    pub emission: Option<Color>,
    /// Where the object is defined.
    pub loc: Location,
}
