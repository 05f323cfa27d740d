//! `arbor diff`: compares an image with a reference the way the reference-image tests do.

use std::path::PathBuf;

use arbor::image_io::metrics::compare_files;
use clap::Args;

use crate::Failure;

/// Arguments of `arbor diff`.
#[derive(Args)]
pub struct DiffArgs {
    /// The reference image.
    pub reference: PathBuf,
    /// The image to check.
    pub image: PathBuf,
    /// A pixel is "off" when a channel differs by more than this many 8-bit levels.
    #[arg(long, default_value_t = 8)]
    pub threshold: u8,
    /// Fail (exit 1) when more than this percentage of pixels is off.
    #[arg(long, default_value_t = 0.5)]
    pub max_off: f64,
}

/// Runs `arbor diff`.
pub fn run(args: DiffArgs) -> Result<(), Failure> {
    let c = compare_files(&args.reference, &args.image, args.threshold)?;
    say!("{}", c.summary());
    if c.share_off * 100.0 > args.max_off {
        say!(
            "FAIL: {:.3}% of pixels off by more than {} levels (limit {}%)",
            c.share_off * 100.0,
            args.threshold,
            args.max_off
        );
        return Err(Failure::TooDifferent);
    }
    say!(
        "OK: {:.3}% of pixels off by more than {} levels (limit {}%)",
        c.share_off * 100.0,
        args.threshold,
        args.max_off
    );
    Ok(())
}
