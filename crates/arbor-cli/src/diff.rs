//! `arbor diff`: compares an image with a reference the way the reference-image tests do: pixel by pixel,
//! or, for a render of random samples whose noise cannot match pixel for pixel, by the means of KxK-pixel
//! blocks (`--block K`), or against the noise that a second seed's render measures (`--noise`). Both
//! print the bias, the mean signed difference per channel. High-dynamic-range images (EXR, HDR: radiance)
//! are compared in display levels under one curve their reference fixes (`arbor::image_io::levels`).

use std::path::{Path, PathBuf};

use arbor::film::Film;
use arbor::image_io::levels::{BlockLevels, DisplayCurve};
use arbor::image_io::metrics::{compare_block_levels, compare_blocks_rgb8, compare_rgb8, BlockComparison, Comparison};
use arbor::image_io::noisy::{compare_noisy, compare_noisy_rgb8, compare_noisy_tonemapped, NoisyComparison};
use arbor::image_io::{is_hdr_path, read, read_image_within, ImageLimits};
use arbor::tonemap::Tonemap;
use clap::Args;

use crate::Failure;

/// Block side of `--noise` without `--block`, and of the hint after a failed pixel-by-pixel diff.
const NOISE_BLOCK: u32 = 16;

/// Arguments of `arbor diff`.
#[derive(Args)]
pub struct DiffArgs {
    /// The reference image. An EXR or HDR reference (radiance) fixes one display curve (Reinhard's global
    /// operator at key 0.18 of its log-average luminance, gamma 2.2) under which both images are compared
    /// in 8-bit levels; IMAGE must then be EXR or HDR too.
    pub reference: PathBuf,
    /// The image to check.
    pub image: PathBuf,
    /// A pixel (or block) is "off" when a channel differs by more than this many 8-bit levels.
    #[arg(long, default_value_t = 8)]
    pub threshold: u8,
    /// Fail (exit 1) when more than this percentage of pixels (or blocks) is off.
    #[arg(long, default_value_t = 0.5, value_parser = parse_percent)]
    pub max_off: f64,
    /// Compare the means of KxK-pixel blocks instead of pixels, for noisy renders (blocks at the right and
    /// bottom edges are averaged over the pixels they have; HDR blocks are averaged in radiance, then
    /// put through the curve).
    #[arg(long, value_name = "K", value_parser = parse_block)]
    pub block: Option<u32>,
    /// For a noisy (path-traced) reference: the same render as IMAGE with another --seed, both at the
    /// reference's samples. IMAGE passes when, on the block means (--block, default 16), it is no farther
    /// from the reference than from this second seed plus 1 level, with every channel's mean signed
    /// difference within 2 levels. --threshold and --max-off do not apply.
    #[arg(long, value_name = "IMAGE_OTHER_SEED")]
    pub noise: Option<PathBuf>,
    /// With --noise, for an 8-bit reference written through the course's tone curve (a camera's
    /// `Tonemap`: the photographic operator's key, burn-out percent, saturation and gamma) and IMAGE and
    /// IMAGE_OTHER_SEED as radiance (.exr, .hdr): both are shown through that curve under one exposure,
    /// the one that fits the reference best, since the reference's own came from its renderer's noise.
    #[arg(long, value_name = "KEY,BURN,SATURATION,GAMMA", value_parser = parse_tonemap, requires = "noise")]
    pub tonemap: Option<Tonemap>,
    /// Lift the limit on the pixels of each image (2^28, the most `arbor render` writes by default).
    #[arg(long)]
    pub no_limits: bool,
}

/// Parses `--max-off`: a percentage from 0 to 100 (a NaN limit would pass every image).
fn parse_percent(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(p) if (0.0..=100.0).contains(&p) => Ok(p),
        Ok(_) => Err(format!("'{s}' is not a percentage from 0 to 100")),
        Err(_) => Err(format!("'{s}' is not a number")),
    }
}

/// Parses `--tonemap KEY,BURN,SATURATION,GAMMA` into the photographic operator, in the scene's units.
fn parse_tonemap(s: &str) -> Result<Tonemap, String> {
    let not_four = || format!("'{s}' is not four numbers KEY,BURN,SATURATION,GAMMA (the course's: 0.18,1,1,2.2)");
    let v: Vec<f32> =
        s.split(',').map(|x| x.trim().parse::<f32>()).collect::<Result<_, _>>().map_err(|_| not_four())?;
    match v[..] {
        [key, burn, saturation, gamma]
            if key > 0.0 && (0.0..=100.0).contains(&burn) && saturation >= 0.0 && gamma > 0.0 && v.iter().all(|x| x.is_finite()) =>
        {
            Ok(Tonemap { key, burn_percent: burn, saturation, gamma, ..Tonemap::PREVIEW })
        }
        [_, _, _, _] => Err(format!(
            "'{s}': the key and gamma must be positive, the burn-out a percentage from 0 to 100, the saturation at least 0"
        )),
        _ => Err(not_four()),
    }
}

/// Parses `--block`: a whole number of pixels, at least 1.
fn parse_block(s: &str) -> Result<u32, String> {
    match s.trim().parse::<u32>() {
        Ok(0) => Err("a block is at least 1 pixel wide".into()),
        Ok(k) => Ok(k),
        Err(_) => Err(format!("'{s}' is not a whole number of pixels")),
    }
}

/// The images of one comparison, read alike: 8-bit, or radiance for HDR ones.
enum Images {
    Rgb8 { width: u32, height: u32, reference: Vec<u8>, images: Vec<Vec<u8>> },
    Hdr { reference: Film, images: Vec<Film> },
}

/// One image as read: 8-bit levels, or radiance for an HDR file.
enum Read {
    Rgb8(u32, u32, Vec<u8>),
    Hdr(Film),
}

impl Read {
    fn of(path: &Path, limits: &ImageLimits) -> Result<Read, Failure> {
        Ok(if is_hdr_path(path) {
            Read::Hdr(read_image_within(path, limits)?)
        } else {
            let (w, h, px) = read::<u8>(path, limits)?;
            Read::Rgb8(w, h, px)
        })
    }

    fn size(&self) -> (u32, u32) {
        match self {
            Read::Rgb8(w, h, _) => (*w, *h),
            Read::Hdr(f) => (f.width, f.height),
        }
    }
}

/// An image of size `got` against a reference of size `want`: an error naming `path` when they differ.
fn same_size(path: &Path, got: (u32, u32), want: (u32, u32)) -> Result<(), Failure> {
    if got == want {
        return Ok(());
    }
    let msg = format!("{} is {}x{} but the reference is {}x{}", path.display(), got.0, got.1, want.0, want.1);
    Err(arbor::Error::Invalid(msg).into())
}

/// Reads the reference and `images` (each fails as a file first), then checks that they are all 8-bit or
/// all HDR, and all of one size.
fn read_all(reference: &Path, images: &[&PathBuf], limits: &ImageLimits) -> Result<Images, Failure> {
    let first = Read::of(reference, limits)?;
    let rest = images.iter().map(|p| Read::of(p, limits)).collect::<Result<Vec<_>, _>>()?;
    let want = first.size();
    for (path, read) in images.iter().zip(&rest) {
        let (hdr, other) = (matches!(first, Read::Hdr(_)), matches!(read, Read::Hdr(_)));
        if hdr != other {
            let (what, other) = if hdr { ("an HDR", "an 8-bit") } else { ("an 8-bit", "an HDR") };
            return Err(Failure::Usage(format!(
                "{} is {other} image but the reference {} is {what} one: compare radiance with radiance \
                 (.exr, .hdr) or 8-bit images with 8-bit ones",
                path.display(),
                reference.display()
            )));
        }
        same_size(path, read.size(), want)?;
    }
    Ok(match first {
        Read::Hdr(reference) => Images::Hdr {
            reference,
            images: rest.into_iter().filter_map(|r| if let Read::Hdr(f) = r { Some(f) } else { None }).collect(),
        },
        Read::Rgb8(width, height, reference) => Images::Rgb8 {
            width,
            height,
            reference,
            images: rest
                .into_iter()
                .filter_map(|r| if let Read::Rgb8(_, _, px) = r { Some(px) } else { None })
                .collect(),
        },
    })
}

impl Images {
    /// The first image against the reference, pixel by pixel (HDR ones in the curve's 8-bit levels).
    fn pixels(&self, threshold: u8) -> Comparison {
        match self {
            Images::Rgb8 { width, height, reference, images } => {
                compare_rgb8(reference, &images[0], *width, *height, threshold)
            }
            Images::Hdr { reference, images } => {
                let curve = DisplayCurve::of_reference(reference);
                let (w, h) = (reference.width, reference.height);
                compare_rgb8(&curve.rgb8(reference), &curve.rgb8(&images[0]), w, h, threshold)
            }
        }
    }

    /// Every image's `k` x `k` block means in levels, the reference's first.
    fn block_levels(&self, k: u32) -> Vec<BlockLevels> {
        match self {
            Images::Rgb8 { width, height, reference, images } => std::iter::once(reference)
                .chain(images)
                .map(|px| BlockLevels::of_rgb8(px, *width, *height, k))
                .collect(),
            Images::Hdr { reference, images } => {
                let curve = DisplayCurve::of_reference(reference);
                std::iter::once(reference).chain(images).map(|f| BlockLevels::of_film(f, k, &curve)).collect()
            }
        }
    }

    /// The first image against the reference, block by block.
    fn blocks(&self, k: u32, threshold: u8) -> BlockComparison {
        match self {
            Images::Rgb8 { width, height, reference, images } => {
                compare_blocks_rgb8(reference, &images[0], *width, *height, k, threshold)
            }
            Images::Hdr { reference, .. } => {
                let levels = self.block_levels(k);
                compare_block_levels(&levels[0], &levels[1], reference.width, reference.height, threshold)
            }
        }
    }
}

/// `--noise` with `--tonemap`: the 8-bit reference against two seeds' radiance under the fitted exposure.
fn tonemapped(
    args: &DiffArgs,
    tonemap: &Tonemap,
    other: &Path,
    limits: &ImageLimits,
) -> Result<NoisyComparison, Failure> {
    let (w, h, reference) = match Read::of(&args.reference, limits)? {
        Read::Rgb8(w, h, px) => (w, h, px),
        Read::Hdr(_) => {
            return Err(Failure::Usage(format!(
                "--tonemap is for an 8-bit reference, and {} is an HDR one: leave --tonemap out",
                args.reference.display()
            )))
        }
    };
    let mut films = Vec::new();
    for path in [args.image.as_path(), other] {
        let Read::Hdr(film) = Read::of(path, limits)? else {
            return Err(Failure::Usage(format!(
                "{} is an 8-bit image: with --tonemap the two renders are radiance (.exr, .hdr)",
                path.display()
            )));
        };
        same_size(path, (film.width, film.height), (w, h))?;
        films.push(film);
    }
    say!("8-bit reference: the renders' radiance through the tone curve, under the exposure that fits it best");
    Ok(compare_noisy_tonemapped(&reference, tonemap, &films[0], &films[1], args.block.unwrap_or(NOISE_BLOCK)))
}

/// Runs `arbor diff`.
pub fn run(args: DiffArgs) -> Result<(), Failure> {
    let limits = crate::render::limits(args.no_limits).rendered();
    if let (Some(tonemap), Some(other)) = (&args.tonemap, &args.noise) {
        let c = tonemapped(&args, tonemap, other, &limits)?;
        say!("{}", c.summary());
        return if c.passes() { Ok(()) } else { Err(Failure::TooDifferent) };
    }
    let paths: Vec<&PathBuf> = std::iter::once(&args.image).chain(&args.noise).collect();
    let images = read_all(&args.reference, &paths, &limits)?;
    if matches!(images, Images::Hdr { .. }) {
        say!(
            "HDR images: compared in 8-bit levels under the reference's curve (key 0.18 of its log-average, gamma 2.2)"
        );
    }
    if args.noise.is_some() {
        let c = match &images {
            Images::Rgb8 { width, height, reference, images } => compare_noisy_rgb8(
                reference,
                &images[0],
                &images[1],
                *width,
                *height,
                args.block.unwrap_or(NOISE_BLOCK),
            ),
            Images::Hdr { .. } => {
                let levels = images.block_levels(args.block.unwrap_or(NOISE_BLOCK));
                compare_noisy(&levels[0], &levels[1], &levels[2])
            }
        };
        say!("{}", c.summary());
        return if c.passes() { Ok(()) } else { Err(Failure::TooDifferent) };
    }
    let (share_off, what) = match args.block {
        None => {
            let c = images.pixels(args.threshold);
            say!("{}", c.summary());
            say!("{}", c.bias_summary());
            (c.share_off, "pixels".to_string())
        }
        Some(k) => {
            let c = images.blocks(k, args.threshold);
            say!("{}", c.summary());
            say!("{}", c.bias_summary());
            (c.share_off, format!("blocks of {k}x{k} pixels"))
        }
    };
    let failed = share_off * 100.0 > args.max_off;
    say!(
        "{}: {:.3}% of {what} off by more than {} levels (limit {}%)",
        if failed { "FAIL" } else { "OK" },
        share_off * 100.0,
        args.threshold,
        args.max_off
    );
    if failed && args.block.is_none() {
        // A render of random samples fails a pixel-by-pixel diff through its noise alone.
        let b = images.blocks(NOISE_BLOCK, args.threshold);
        say!(
            "hint: {:.3}% of its {k}x{k}-pixel blocks are off; if the image is a render of random samples \
             (path tracing, soft shadows, glossy reflections), compare block means (--block {k}) or measure \
             the noise with a second seed's render (--noise IMAGE_OTHER_SEED)",
            b.share_off * 100.0,
            k = NOISE_BLOCK
        );
    }
    if failed {
        return Err(Failure::TooDifferent);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_block_takes_one_and_more_only() {
        assert_eq!(parse_block("1"), Ok(1));
        assert_eq!(parse_block(" 16 "), Ok(16));
        assert_eq!(parse_block("0"), Err("a block is at least 1 pixel wide".into()));
        assert_eq!(parse_block("-2"), Err("'-2' is not a whole number of pixels".into()));
        assert_eq!(parse_block("4x4"), Err("'4x4' is not a whole number of pixels".into()));
    }

    #[test]
    fn parse_percent_takes_0_to_100_only() {
        assert_eq!(parse_percent("0"), Ok(0.0));
        assert_eq!(parse_percent(" 2.5 "), Ok(2.5));
        assert_eq!(parse_percent("100"), Ok(100.0));
        for bad in ["nan", "NaN", "-1", "100.5", "inf"] {
            assert_eq!(parse_percent(bad), Err(format!("'{bad}' is not a percentage from 0 to 100")));
        }
        assert_eq!(parse_percent("half"), Err("'half' is not a number".into()));
    }
}
