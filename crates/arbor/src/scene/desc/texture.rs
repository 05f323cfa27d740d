//! Textures as a scene file describes them (CENG 795 2022 hw4 `<Textures>`, and the 2019 `<Texture>`
//! form read into the same types): image files by index, and texture maps that sample an image or a
//! procedure and say what the sample replaces (the decal mode).

use std::path::PathBuf;

use crate::math::Color;
use crate::Location;

/// An image file that texture maps sample; several maps may share one.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageDesc {
    /// The file, resolved relative to the scene file.
    pub path: PathBuf,
    /// Where the file names it.
    pub loc: Location,
}

/// How an image is sampled between texel centres (nearest when the file does not say).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interpolation {
    /// The texel the point falls in.
    Nearest,
    /// The four texels around the point, weighted by distance; edge texels repeat.
    Bilinear,
    /// Bilinear in the two mipmap levels around the level of detail of the pixel's footprint, blended.
    Trilinear,
}

/// What a texture's value replaces at a surface point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DecalMode {
    /// The diffuse reflectance.
    ReplaceKd,
    /// The diffuse reflectance, averaged with the material's.
    BlendKd,
    /// The specular reflectance.
    ReplaceKs,
    /// The whole shaded colour (no lighting).
    ReplaceAll,
    /// The background colour of camera rays that miss (the texture spans the image plane).
    ReplaceBackground,
    /// The shading normal, given in tangent space.
    ReplaceNormal,
    /// The shading normal, perturbed by the texture as a height field.
    BumpNormal,
}

/// How Perlin noise in [-1, 1] becomes a value in [0, 1].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NoiseConversion {
    /// `|n|` (vein-like patterns).
    AbsVal,
    /// `(n + 1) / 2` (patches).
    Linear,
}

/// Where a texture's value comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum TextureSource {
    /// An image of [`super::SceneDesc::images`], at the surface's texture coordinates.
    Image {
        /// Index into the scene's images.
        image: usize,
        /// Sampling.
        interpolation: Interpolation,
        /// Texel values are divided by this (255 for 8-bit images), positive.
        normalizer: f32,
        /// Coordinates outside [0, 1] take the edge texels (else the image repeats).
        clamp: bool,
    },
    /// Perlin noise at the object-space point times `scale`.
    Perlin {
        /// Noise to [0, 1].
        conversion: NoiseConversion,
        /// Frequency (`NoiseScale`), positive.
        scale: f32,
    },
    /// A 3D checkerboard at the object-space point.
    Checkerboard {
        /// Squares per unit.
        scale: f32,
        /// Added to the point before scaling.
        offset: f32,
        /// Colour of the odd squares.
        black: Color,
        /// Colour of the even squares.
        white: Color,
    },
}

/// A texture map: a source and what it replaces.
#[derive(Debug, Clone, PartialEq)]
pub struct TextureDesc {
    /// The map's id in the file.
    pub id: String,
    /// Where its value comes from.
    pub source: TextureSource,
    /// What the value replaces.
    pub decal: DecalMode,
    /// Multiplies the height field of a bump map.
    pub bump_factor: f32,
    /// Where the map is defined.
    pub loc: Location,
}
