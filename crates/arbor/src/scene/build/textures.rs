//! The textures of a description as runtime types: every image that a map samples is read once, in
//! parallel, and shared by the maps that name it; an unreadable image is an error at the `Image`
//! element that names it.

use std::collections::HashMap;
use std::sync::Arc;

use rayon::prelude::*;

use crate::scene::desc::{DecalMode, Interpolation, NoiseConversion, SceneDesc, TextureDesc, TextureSource};
use crate::texture::{Checkerboard, Decal, Source, TexImage, Texture};
use crate::{Error, Result};

/// The runtime textures of `desc`, in its order.
pub fn build_textures(desc: &SceneDesc) -> Result<Vec<Texture>> {
    let mut wanted: Vec<usize> = desc
        .textures
        .iter()
        .filter_map(|t| match t.source {
            TextureSource::Image { image, .. } => Some(image),
            _ => None,
        })
        .collect();
    wanted.sort_unstable();
    wanted.dedup();
    let loaded: HashMap<usize, Arc<TexImage>> = wanted
        .par_iter()
        .map(|&i| {
            let img = &desc.images[i];
            let image = TexImage::load(&img.path).map_err(|e| {
                let why = match e {
                    Error::Io { source, .. } => source.to_string(),
                    Error::Input { msg, .. } => msg,
                    other => other.to_string(),
                };
                Error::input(img.loc.clone(), format!("cannot read texture image '{}': {why}", img.path.display()))
            })?;
            Ok((i, Arc::new(image)))
        })
        .collect::<Result<_>>()?;
    // Share one decoded image between the maps that name the same file under different ids.
    let mut by_path: HashMap<&std::path::Path, Arc<TexImage>> = HashMap::new();
    let images: HashMap<usize, Arc<TexImage>> = wanted
        .iter()
        .map(|&i| (i, by_path.entry(&desc.images[i].path).or_insert_with(|| loaded[&i].clone()).clone()))
        .collect();
    Ok(desc.textures.iter().map(|t| build_texture(t, &images)).collect())
}

fn build_texture(t: &TextureDesc, images: &HashMap<usize, Arc<TexImage>>) -> Texture {
    let source = match t.source {
        TextureSource::Image { image, interpolation, normalizer, clamp, .. } => Source::Image {
            image: images[&image].clone(),
            bilinear: interpolation == Interpolation::Bilinear,
            normalizer,
            clamp,
        },
        TextureSource::Perlin { conversion, scale } => {
            Source::Perlin { absval: conversion == NoiseConversion::AbsVal, scale }
        }
        TextureSource::Checkerboard { scale, offset, black, white } => {
            Source::Checker(Checkerboard { scale, offset, black, white })
        }
    };
    let decal = match t.decal {
        DecalMode::ReplaceKd => Decal::ReplaceKd,
        DecalMode::BlendKd => Decal::BlendKd,
        DecalMode::ReplaceKs => Decal::ReplaceKs,
        DecalMode::ReplaceAll => Decal::ReplaceAll,
        DecalMode::ReplaceBackground => Decal::ReplaceBackground,
        DecalMode::ReplaceNormal => Decal::ReplaceNormal,
        DecalMode::BumpNormal => Decal::BumpNormal,
    };
    Texture { source, decal, bump_factor: t.bump_factor }
}
