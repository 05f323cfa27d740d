//! The textures of a description as runtime types: every image that a map samples is read once, in
//! parallel (within the images' pixel budget), and shared by the maps that name it; an unreadable image,
//! one above the budget or one without the memory it needs, is an error at the `Image` element that
//! names it. An image gets its mipmap when a trilinear map samples it, and only then.

use std::collections::{HashMap, HashSet};
use std::path::Path;
use std::sync::Arc;

use rayon::prelude::*;

use crate::image_io::ImageLimits;
use crate::scene::desc::{DecalMode, Interpolation, NoiseConversion, SceneDesc, TextureDesc, TextureSource};
use crate::texture::{Checkerboard, Decal, Filter, Source, TexImage, Texture};
use crate::{Error, Result};

/// The runtime textures of `desc`, in its order, each image held to `limits`.
pub fn build_textures(desc: &SceneDesc, limits: &ImageLimits) -> Result<Vec<Texture>> {
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
    // By path: two ids of one file share one decoded image below, which a trilinear map of either needs.
    let mipmapped: HashSet<&Path> = desc
        .textures
        .iter()
        .filter_map(|t| match t.source {
            TextureSource::Image { image, interpolation: Interpolation::Trilinear, .. } => {
                Some(desc.images[image].path.as_path())
            }
            _ => None,
        })
        .collect();
    // One decode per file: the first id that names it loads it (and answers for it if it cannot).
    let mut seen: HashSet<&Path> = HashSet::new();
    let files: Vec<usize> = wanted.iter().copied().filter(|&i| seen.insert(desc.images[i].path.as_path())).collect();
    let loaded: HashMap<&Path, Arc<TexImage>> = files
        .par_iter()
        .map(|&i| {
            let img = &desc.images[i];
            let trilinear = mipmapped.contains(img.path.as_path());
            let image = TexImage::load(&img.path, limits);
            let image = image.and_then(|image| if trilinear { image.with_mipmaps() } else { Ok(image) });
            let image = image.map_err(|e| {
                let why = match e {
                    Error::Io { source, .. } => source.to_string(),
                    Error::Input { msg, .. } => msg,
                    other => other.to_string(),
                };
                Error::input(img.loc.clone(), format!("cannot read texture image '{}': {why}", img.path.display()))
            })?;
            Ok((img.path.as_path(), Arc::new(image)))
        })
        .collect::<Result<_>>()?;
    // Maps that name the same file under different ids share its one decoded image.
    let images: HashMap<usize, Arc<TexImage>> =
        wanted.iter().map(|&i| (i, loaded[desc.images[i].path.as_path()].clone())).collect();
    Ok(desc.textures.iter().map(|t| build_texture(t, &images)).collect())
}

fn build_texture(t: &TextureDesc, images: &HashMap<usize, Arc<TexImage>>) -> Texture {
    let source = match t.source {
        TextureSource::Image { image, interpolation, normalizer, clamp, .. } => Source::Image {
            image: images[&image].clone(),
            filter: match interpolation {
                Interpolation::Nearest => Filter::Nearest,
                Interpolation::Bilinear => Filter::Bilinear,
                Interpolation::Trilinear => Filter::Trilinear,
            },
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::desc::ImageDesc;
    use crate::Location;

    fn map(image: usize, interpolation: Interpolation) -> TextureDesc {
        let source = TextureSource::Image { image, interpolation, normalizer: 255.0, clamp: false };
        TextureDesc {
            id: "1".into(),
            source,
            decal: DecalMode::ReplaceKd,
            bump_factor: 1.0,
            loc: Location::file("t.xml"),
        }
    }

    #[test]
    fn build_textures_loads_a_shared_image_once() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.png");
        image::RgbImage::from_raw(1, 1, vec![10, 20, 30]).unwrap().save(&path).unwrap();
        let mut desc = SceneDesc::new("t.xml");
        // Two ids of the same file, three maps over them.
        for _ in 0..2 {
            desc.images.push(ImageDesc { path: path.clone(), loc: Location::file("t.xml") });
        }
        desc.textures =
            vec![map(0, Interpolation::Nearest), map(0, Interpolation::Bilinear), map(1, Interpolation::Nearest)];
        let t = build_textures(&desc, &ImageLimits::DEFAULT).unwrap();
        let image = |t: &Texture| match &t.source {
            Source::Image { image, .. } => image.clone(),
            _ => unreachable!(),
        };
        assert!(Arc::ptr_eq(&image(&t[0]), &image(&t[1])) && Arc::ptr_eq(&image(&t[0]), &image(&t[2])));
        assert!(image(&t[0]).is_8bit());
    }

    #[test]
    fn build_textures_mipmaps_only_images_that_a_trilinear_map_samples() {
        let dir = tempfile::tempdir().unwrap();
        let mut desc = SceneDesc::new("t.xml");
        for name in ["a.png", "b.png"] {
            let path = dir.path().join(name);
            image::RgbImage::from_raw(4, 4, vec![9; 48]).unwrap().save(&path).unwrap();
            desc.images.push(ImageDesc { path, loc: Location::file("t.xml") });
        }
        // a.png under a second id too, sampled nearest there and trilinear through the first id.
        desc.images.push(desc.images[0].clone());
        desc.textures =
            vec![map(2, Interpolation::Nearest), map(0, Interpolation::Trilinear), map(1, Interpolation::Bilinear)];
        let t = build_textures(&desc, &ImageLimits::DEFAULT).unwrap();
        let levels = |t: &Texture| match &t.source {
            Source::Image { image, .. } => image.levels(),
            _ => unreachable!(),
        };
        assert_eq!([levels(&t[0]), levels(&t[1]), levels(&t[2])], [3, 3, 1]);
        assert!(matches!(t[1].source, Source::Image { filter: Filter::Trilinear, .. }));
    }

    #[test]
    fn build_textures_locates_a_missing_image_at_its_element() {
        let mut desc = SceneDesc::new("t.xml");
        let loc = Location { line: Some(3), col: Some(7), ..Location::file("t.xml") };
        desc.images.push(ImageDesc { path: "/nonexistent/a.png".into(), loc });
        desc.textures = vec![map(0, Interpolation::Nearest)];
        let e = build_textures(&desc, &ImageLimits::DEFAULT).unwrap_err().to_string();
        assert!(e.starts_with("t.xml:3:7: cannot read texture image '/nonexistent/a.png': "), "{e}");
    }
}
