//! `arbor diff`: compares an image with a reference the way the reference-image tests do: pixel by pixel,
//! or, for a render of random samples whose noise cannot match pixel for pixel, by the means of KxK-pixel
//! blocks (`--block K`). Both print the bias, the mean signed difference per channel.

use std::path::PathBuf;

use arbor::image_io::metrics::{compare_blocks_files, compare_files};
use arbor::image_io::noisy::compare_noisy_rgb8;
use clap::Args;

use crate::Failure;

/// Arguments of `arbor diff`.
#[derive(Args)]
pub struct DiffArgs {
    /// The reference image.
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
    /// bottom edges are averaged over the pixels they have).
    #[arg(long, value_name = "K", value_parser = parse_block)]
    pub block: Option<u32>,
    /// For a noisy (path-traced) reference: two renders at the reference's samples with different seeds.
    /// IMAGE is then a render at four times the samples, and it passes when, on the block means (--block,
    /// default 16), it is no farther from the reference than the two seeds are from each other plus 1
    /// level, with every channel's mean signed difference within 2 levels.
    #[arg(long, num_args = 2, value_names = ["SEED_A", "SEED_B"])]
    pub noise: Option<Vec<PathBuf>>,
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

/// Parses `--block`: a whole number of pixels, at least 1.
fn parse_block(s: &str) -> Result<u32, String> {
    match s.trim().parse::<u32>() {
        Ok(0) => Err("a block is at least 1 pixel wide".into()),
        Ok(k) => Ok(k),
        Err(_) => Err(format!("'{s}' is not a whole number of pixels")),
    }
}

/// Runs `arbor diff`.
pub fn run(args: DiffArgs) -> Result<(), Failure> {
    let limits = crate::render::limits(args.no_limits).rendered();
    if let Some(seeds) = &args.noise {
        let (w, h, reference) = arbor::image_io::read::<u8>(&args.reference, &limits)?;
        let mut images = Vec::new();
        for path in [&args.image, &seeds[0], &seeds[1]] {
            let (pw, ph, px) = arbor::image_io::read::<u8>(path, &limits)?;
            if (pw, ph) != (w, h) {
                let msg = format!("{} is {pw}x{ph} but the reference is {w}x{h}", path.display());
                return Err(arbor::Error::Invalid(msg).into());
            }
            images.push(px);
        }
        let (image, a, b) = (&images[0], &images[1], &images[2]);
        let c = compare_noisy_rgb8(&reference, image, a, b, w, h, args.block.unwrap_or(16));
        say!("{}", c.summary());
        return if c.passes() { Ok(()) } else { Err(Failure::TooDifferent) };
    }
    let (share_off, what) = match args.block {
        None => {
            let c = compare_files(&args.reference, &args.image, args.threshold, &limits)?;
            say!("{}", c.summary());
            say!("{}", c.bias_summary());
            (c.share_off, "pixels".to_string())
        }
        Some(k) => {
            let c = compare_blocks_files(&args.reference, &args.image, k, args.threshold, &limits)?;
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
