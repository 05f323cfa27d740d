//! The farm slices of `arbor render`: `--tile I/N`, `--sample-offset K` / `--sample-count N`, and `--crop`
//! with an `.exr` output. A slice renders one camera and writes a partial EXR (`arbor::farm::partial`)
//! to the file `-o` names, which `arbor merge` combines with the other slices.
//!
//! Everything a user can get wrong here is a usage error (exit 2) with the flag's name in the message.
//! The render's identity, stored in every partial so that merge refuses parts of different renders, is a
//! 64-bit FNV-1a hash of the scene file's bytes, the camera id, the samples per pixel, the back-face
//! choice and the environment map's path: everything on the command line that changes pixels.

use std::path::{Path, PathBuf};

use arbor::camera::Camera;
use arbor::render::RenderOptions;
use arbor::sampler::SamplerKind;
use clap::Args;

use crate::Failure;

/// The slice flags of `arbor render`.
#[derive(Args, Clone, Default)]
pub struct SliceArgs {
    /// Render tile I of N (I from 0, as Slurm's SLURM_ARRAY_TASK_ID and Kubernetes' JOB_COMPLETION_INDEX)
    /// of a fixed grid (docs/farm.md) into the partial EXR named by -o.
    #[arg(long, value_name = "I/N", value_parser = parse_tile, conflicts_with = "crop")]
    pub tile: Option<(u32, u32)>,
    /// First sample of a sample range (0-based) of the image's samples per pixel (--spp or NumSamples).
    #[arg(long, value_name = "K")]
    pub sample_offset: Option<u32>,
    /// Number of samples of the range (default: up to the last); the range goes to the partial EXR -o.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    pub sample_count: Option<u32>,
}

/// Parses `--tile I/N`.
pub fn parse_tile(s: &str) -> Result<(u32, u32), String> {
    let (i, n) = s.split_once('/').ok_or_else(|| format!("expected I/N (e.g. 3/16), got '{s}'"))?;
    let num = |v: &str| v.trim().parse::<u32>().map_err(|_| format!("'{v}' is not a whole number"));
    Ok((num(i)?, num(n)?))
}

/// A validated slice request.
pub struct Slice {
    /// The partial EXR to write.
    pub out: PathBuf,
    tile: Option<(u32, u32)>,
    crop: Option<(u32, u32, u32, u32)>,
    offset: Option<u32>,
    count: Option<u32>,
}

impl Slice {
    /// The slice the flags ask for, or `None` for a plain render. `--crop` alone is a slice only when `-o`
    /// names an `.exr` file (otherwise it writes the cropped images into the folder `-o`, as before).
    pub fn from_args(
        a: &SliceArgs,
        crop: Option<(u32, u32, u32, u32)>,
        out: &Path,
        debug: bool,
    ) -> Result<Option<Slice>, Failure> {
        let exr = out.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"));
        let flagged = a.tile.is_some() || a.sample_offset.is_some() || a.sample_count.is_some();
        let slice = flagged || (crop.is_some() && exr);
        if !slice {
            return Ok(None);
        }
        if !exr {
            return Err(Failure::Usage(format!(
                "--tile, --sample-offset and --sample-count write a partial EXR: -o must name a .exr file, got '{}'",
                out.display()
            )));
        }
        if debug {
            return Err(Failure::Usage("--debug views cannot be rendered in slices".into()));
        }
        if let Some((i, n)) = a.tile {
            // Checked again against the frame once the scene is read.
            arbor::farm::tile_window(i, n, u32::MAX, u32::MAX).map_err(Failure::Usage)?;
        }
        Ok(Some(Slice { out: out.to_path_buf(), tile: a.tile, crop, offset: a.sample_offset, count: a.sample_count }))
    }

    /// The window of `cam`'s frame this slice renders.
    pub fn window(&self, cam: &Camera) -> Result<Option<(u32, u32, u32, u32)>, Failure> {
        match self.tile {
            Some((i, n)) => arbor::farm::tile_window(i, n, cam.width, cam.height).map(Some).map_err(Failure::Usage),
            None => Ok(self.crop),
        }
    }

    /// The samples `k0..k1` of `spp` this slice renders.
    pub fn samples(&self, spp: u32) -> Result<(u32, u32), Failure> {
        let k0 = self.offset.unwrap_or(0);
        let k1 = self.count.map_or(spp as u64, |n| k0 as u64 + n as u64);
        if k0 as u64 >= k1.min(spp as u64) || k1 > spp as u64 {
            return Err(Failure::Usage(match self.count {
                Some(n) => format!(
                    "--sample-offset {k0} --sample-count {n}: samples {k0}..{k1} are not inside the image's \
                     {spp} samples per pixel (--spp or the scene's NumSamples)"
                ),
                None => format!(
                    "--sample-offset {k0}: the image has {spp} samples per pixel (--spp or the scene's \
                     NumSamples), numbered from 0"
                ),
            }));
        }
        Ok((k0, k1 as u32))
    }
}

/// The identity of a render: the scene's bytes and every command-line choice that changes pixels (of
/// `opts`, those that every slice of the render shares: not its crop or sample range).
pub fn identity(scene: &[u8], camera: &str, spp: u32, env: Option<&Path>, opts: &RenderOptions) -> String {
    let RenderOptions { seed, cull_backfaces: cull, renderer, sampler, .. } = opts;
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut options =
        format!("\0camera={camera}\0spp={spp}\0seed={seed}\0cull={cull:?}\0env={env:?}\0renderer={renderer:?}");
    if let Some(name) = sampler_name(*sampler) {
        options += &format!("\0sampler={name}");
    }
    for &b in scene.iter().chain(options.as_bytes()) {
        h = (h ^ b as u64).wrapping_mul(0x0100_0000_01b3);
    }
    // Escaped: EXR text attributes hold Latin-1 only, and the identity must survive the trip intact.
    format!("fnv1a64:{h:016x} camera={} spp={spp}", camera.escape_default())
}

/// How the identity names `sampler` and its stream version. The independent sampler's first streams
/// are not named, as before samplers could be chosen, so that the slices of a render made then keep
/// their identity.
fn sampler_name(sampler: SamplerKind) -> Option<String> {
    (sampler != SamplerKind::Independent || sampler.stream_version() != 1)
        .then(|| format!("{sampler:?}/{}", sampler.stream_version()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use arbor::renderer::Renderer;

    #[test]
    fn slice_tile_parses() {
        assert_eq!(parse_tile("3/16"), Ok((3, 16)));
        assert_eq!(parse_tile("3"), Err("expected I/N (e.g. 3/16), got '3'".to_string()));
        assert_eq!(parse_tile("a/2"), Err("'a' is not a whole number".to_string()));
    }

    fn slice(offset: Option<u32>, count: Option<u32>) -> Slice {
        Slice { out: PathBuf::from("p.exr"), tile: None, crop: None, offset, count }
    }

    #[test]
    fn slice_sample_ranges_default_to_the_rest() {
        assert!(matches!(slice(None, None).samples(8), Ok((0, 8))));
        assert!(matches!(slice(Some(3), None).samples(8), Ok((3, 8))));
        assert!(matches!(slice(None, Some(2)).samples(8), Ok((0, 2))));
        assert!(matches!(slice(Some(6), Some(2)).samples(8), Ok((6, 8))));
        for (k, n) in [(Some(8), None), (Some(7), Some(2)), (Some(u32::MAX), Some(u32::MAX))] {
            assert!(matches!(slice(k, n).samples(8), Err(Failure::Usage(_))), "{k:?} {n:?}");
        }
        // The message names the flags that were given.
        let Err(Failure::Usage(msg)) = slice(Some(5), None).samples(4) else { panic!("accepted") };
        let want = "--sample-offset 5: the image has 4 samples per pixel (--spp or the scene's NumSamples), numbered \
                    from 0";
        assert_eq!(msg, want);
    }

    #[test]
    fn slice_identity_is_ascii_for_any_camera_id() {
        assert!(identity(b"s", "kamera-\u{e7}-\u{1f4f7}", 1, None, &RenderOptions::default()).is_ascii());
    }

    #[test]
    fn slice_identity_changes_with_what_changes_pixels() {
        let base = RenderOptions::default();
        let a = identity(b"scene", "1", 4, None, &base);
        assert_eq!(a, identity(b"scene", "1", 4, None, &base));
        assert_ne!(a, identity(b"scene2", "1", 4, None, &base));
        assert_ne!(a, identity(b"scene", "2", 4, None, &base));
        assert_ne!(a, identity(b"scene", "1", 8, None, &base));
        assert_ne!(a, identity(b"scene", "1", 4, None, &RenderOptions { seed: 1, ..base.clone() }));
        assert_ne!(a, identity(b"scene", "1", 4, None, &RenderOptions { cull_backfaces: Some(true), ..base.clone() }));
        let whitted = RenderOptions { renderer: Some(Renderer::Whitted), ..base.clone() };
        assert_ne!(a, identity(b"scene", "1", 4, None, &whitted));
        assert_ne!(
            a,
            identity(b"scene", "1", 4, None, &RenderOptions { sampler: SamplerKind::Independent, ..base.clone() })
        );
        assert_ne!(a, identity(b"scene", "1", 4, Some(Path::new("sky.exr")), &base));
        // Streams of another version are another render.
        assert_eq!(sampler_name(SamplerKind::Independent), None);
        assert_eq!(sampler_name(SamplerKind::Stratified).as_deref(), Some("Stratified/3"));
        assert_eq!(sampler_name(SamplerKind::Sobol).as_deref(), Some("Sobol/1"));
        // What differs between one render's slices does not change it.
        let slice = RenderOptions { crop: Some((0, 0, 8, 8)), samples: Some((0, 2)), ..base.clone() };
        assert_eq!(a, identity(b"scene", "1", 4, None, &slice));
    }
}
