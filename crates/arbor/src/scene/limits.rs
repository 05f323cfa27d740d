//! Resource limits on what a scene may ask for, checked after reading and before anything is built or
//! rendered, so that a crafted file cannot exhaust memory (a 100000 x 100000 image) or run for days
//! (a million samples per pixel, a thousand bounces).
//!
//! The defaults are far above every real scene of the courses (at most 1920 x 1080, 900 samples,
//! depth 10) and below what a workstation cannot do: 2^28 pixels of film is 3 GiB of `f32` RGB, 2^34
//! samples are hours of rendering. [`SceneLimits::none`] lifts them all (`arbor render --no-limits`).
//! Every refusal names the limit, the value asked for and where the scene asks for it.
//!
//! The images a scene reads (textures, environment maps, cube faces) have their own budget,
//! [`SceneLimits::images`], checked from each file's header when it is loaded ([`crate::image_io`]);
//! images that `render` writes and `diff` or `merge` read back are held to the film's pixel limit
//! instead ([`SceneLimits::rendered`]), so that whatever `render` may write can be compared and merged.

use super::desc::SceneDesc;
use crate::error::LIFT_LIMITS as LIFT;
use crate::image_io::ImageLimits;
use crate::{Error, Location, Result};

/// The largest images, sample counts, recursion depths and total work a scene may ask for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SceneLimits {
    /// Largest image width and height, in pixels.
    pub max_side: u32,
    /// Largest number of pixels of one image.
    pub max_pixels: u64,
    /// Largest number of samples per pixel.
    pub max_samples: u32,
    /// Largest `MaxRecursionDepth`.
    pub max_depth: u32,
    /// Largest number of camera samples (pixels x samples per pixel) of one image, and of all the
    /// scene's images together.
    pub max_work: u64,
    /// The pixel budget of each image the scene reads (texture, environment map, cube face).
    pub images: ImageLimits,
}

impl Default for SceneLimits {
    fn default() -> Self {
        SceneLimits {
            max_side: 16384,
            max_pixels: 1 << 28,
            max_samples: 65536,
            max_depth: 64,
            max_work: 1 << 34,
            images: ImageLimits::DEFAULT,
        }
    }
}

impl SceneLimits {
    /// No limits at all.
    pub fn none() -> Self {
        SceneLimits {
            max_side: u32::MAX,
            max_pixels: u64::MAX,
            max_samples: u32::MAX,
            max_depth: u32::MAX,
            max_work: u64::MAX,
            images: ImageLimits::NONE,
        }
    }

    /// The budget of an image `render` may write, for the images `diff` and `merge` read: the film's
    /// pixel limit.
    pub fn rendered(&self) -> ImageLimits {
        ImageLimits { max_pixels: self.max_pixels }
    }
}

/// Checks every camera of `desc` (with `spp`, the command line's samples per pixel, replacing the
/// scene's), all of them together, and the scene's recursion depth against `limits`.
pub fn check_limits(desc: &SceneDesc, spp: Option<u32>, limits: &SceneLimits) -> Result<()> {
    if let Some(spp) = spp.filter(|&s| s > limits.max_samples) {
        let max = limits.max_samples;
        return Err(Error::Invalid(format!("--spp {spp} exceeds the limit of {max} samples per pixel; {LIFT}")));
    }
    if desc.max_depth > limits.max_depth {
        let loc = desc.max_depth_loc.clone().unwrap_or_else(|| Location::file(&desc.source));
        let msg = format!("MaxRecursionDepth {} exceeds the limit of {}; {LIFT}", desc.max_depth, limits.max_depth);
        return Err(Error::input(loc, msg));
    }
    let mut total = 0u64;
    for c in &desc.cameras {
        let fail = |msg: String| Err(Error::input(c.loc.clone(), format!("Camera {}: {msg}; {LIFT}", c.id)));
        let (w, h) = (c.width, c.height);
        let pixels = w as u64 * h as u64;
        if w > limits.max_side || h > limits.max_side {
            let side = limits.max_side;
            return fail(format!("image {w}x{h} exceeds the limit of {side}x{side} pixels"));
        }
        if pixels > limits.max_pixels {
            return fail(format!("image {w}x{h} has {pixels} pixels, more than the limit of {}", limits.max_pixels));
        }
        if c.num_samples > limits.max_samples && spp.is_none() {
            let (n, max) = (c.num_samples, limits.max_samples);
            return fail(format!("NumSamples {n} exceeds the limit of {max} samples per pixel"));
        }
        let samples = spp.unwrap_or(c.num_samples) as u64;
        let work = pixels.saturating_mul(samples);
        if work > limits.max_work {
            let max = limits.max_work;
            return fail(format!("{pixels} pixels x {samples} samples = {work} samples, more than the limit of {max}"));
        }
        total = total.saturating_add(work);
    }
    if total > limits.max_work {
        let (n, max) = (desc.cameras.len(), limits.max_work);
        let msg =
            format!("the scene's {n} cameras ask for {total} samples in all, more than the limit of {max}; {LIFT}");
        return Err(Error::input(Location::file(&desc.source), msg));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::parse_desc;
    use std::path::Path;

    fn scene(res: &str, samples: u32, depth: u32) -> SceneDesc {
        let text = format!(
            "<Scene>\n<MaxRecursionDepth>{depth}</MaxRecursionDepth>\n<Cameras>\n<Camera id=\"c\">\
             <Position>0 0 5</Position><Gaze>0 0 -1</Gaze><Up>0 1 0</Up><NearPlane>-1 1 -1 1</NearPlane>\
             <NearDistance>1</NearDistance><ImageResolution>{res}</ImageResolution>\
             <NumSamples>{samples}</NumSamples><ImageName>a.png</ImageName></Camera></Cameras></Scene>"
        );
        parse_desc(&text, Path::new("s.xml")).unwrap()
    }

    fn err(d: &SceneDesc, spp: Option<u32>) -> String {
        check_limits(d, spp, &SceneLimits::default()).unwrap_err().to_string()
    }

    #[test]
    fn limits_default_accepts_ordinary_scenes() {
        check_limits(&scene("1920 1080", 900, 10), None, &SceneLimits::default()).unwrap();
        check_limits(&scene("16384 16384", 64, 64), Some(64), &SceneLimits::default()).unwrap();
    }

    #[test]
    fn limits_default_refuses_each_excess_with_its_place() {
        let lift = "; --no-limits lifts the limits";
        let e = err(&scene("20000 10", 1, 0), None);
        assert_eq!(e, format!("s.xml:4:1: Camera c: image 20000x10 exceeds the limit of 16384x16384 pixels{lift}"));
        let e = err(&scene("16384 16385", 1, 0), None);
        assert!(e.contains("exceeds the limit of 16384x16384"), "{e}");
        let e = err(&scene("8 8", 66049, 0), None);
        assert_eq!(
            e,
            format!("s.xml:4:1: Camera c: NumSamples 66049 exceeds the limit of 65536 samples per pixel{lift}")
        );
        let e = err(&scene("8 8", 1, 65), None);
        assert_eq!(e, format!("s.xml:2:1: MaxRecursionDepth 65 exceeds the limit of 64{lift}"));
        let e = err(&scene("16384 16384", 81, 0), None);
        assert!(e.contains("268435456 pixels x 81 samples = 21743271936 samples, more than the limit of 17179869184"));
        let e = err(&scene("8 8", 1, 0), Some(65537));
        assert_eq!(e, format!("--spp 65537 exceeds the limit of 65536 samples per pixel{lift}"));
        // The command line's samples replace the scene's, for the total too.
        check_limits(&scene("8 8", 1_000_000, 0), Some(4), &SceneLimits::default()).unwrap();
        assert!(err(&scene("16384 16384", 1, 0), Some(1000)).contains("more than the limit"));
    }

    #[test]
    fn limits_default_bounds_the_work_of_all_cameras_together() {
        let cam = |id: u32| {
            format!(
                "<Camera id=\"{id}\"><Position>0 0 5</Position><Gaze>0 0 -1</Gaze><Up>0 1 0</Up>\
                 <NearPlane>-1 1 -1 1</NearPlane><NearDistance>1</NearDistance>\
                 <ImageResolution>16384 16384</ImageResolution><NumSamples>36</NumSamples>\
                 <ImageName>{id}.png</ImageName></Camera>"
            )
        };
        let text = format!("<Scene><Cameras>{}{}</Cameras></Scene>", cam(1), cam(2));
        let d = parse_desc(&text, Path::new("two.xml")).unwrap();
        let e = err(&d, None);
        assert_eq!(
            e,
            "two.xml: the scene's 2 cameras ask for 19327352832 samples in all, more than the limit of 17179869184; \
             --no-limits lifts the limits"
        );
        check_limits(&d, Some(1), &SceneLimits::default()).unwrap();
    }

    #[test]
    fn limits_none_accepts_everything() {
        let d = scene("4000000000 4000000000", u32::MAX, u32::MAX);
        check_limits(&d, Some(u32::MAX), &SceneLimits::none()).unwrap();
    }
}
