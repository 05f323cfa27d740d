//! Image files in and out, and the numbers that say how far two images are apart.
//!
//! - [`write_image`]: a [`Film`](crate::film::Film) to PNG or binary PPM (8 bits per channel, quantised by
//!   [`Film::to_rgb8`](crate::film::Film::to_rgb8)) or to OpenEXR (32-bit float RGB, unclamped). Writes are
//!   atomic: the image goes to a temporary file in the target's directory which is then renamed over the
//!   target, so a failed run never leaves a half-written image and never destroys the previous one.
//!   Radiance HDR (`.hdr`) too. [`write_outputs`] adds a camera's tone mapping
//!   ([`Tonemap`](crate::tonemap::Tonemap)): a high-dynamic-range image plus a tone-mapped PNG beside it.
//! - [`read_image`]: PNG, JPEG, PNM, OpenEXR, Radiance HDR into a film in display units (integer samples
//!   divided by their maximum, float samples as they are); [`read_rgb8`] for exact 8-bit comparisons;
//!   [`read`](fn@read) and [`decode`] into any [`Texel`]. Every read is held to a pixel budget
//!   ([`ImageLimits`]) checked from the file's header before decoding, and allocates fallibly.
//! - [`metrics`]: PSNR, RMSE, bias and the share of differing pixels (or KxK-pixel block means, for noisy
//!   renders) against a reference image; [`levels`]: images as display levels for comparing them (an HDR
//!   image through one curve its reference fixes); [`noisy`]: the rule for a noisy (path-traced)
//!   reference, against a second seed's render.
//!
//! Codecs are the `image` crate's (OpenEXR: the `exr` crate's); this module only chooses formats,
//! converts samples and handles files.

mod jpeg;
pub mod levels;
mod limits;
pub mod metrics;
pub mod noisy;
mod openexr;
mod png;
mod read;
pub(crate) mod write;

pub(crate) use limits::try_vec;
pub use limits::ImageLimits;
pub use metrics::{
    compare_blocks_files, compare_blocks_rgb8, compare_files, compare_rgb8, diff_image, BlockComparison, Comparison,
};
pub(crate) use openexr::{in_parallel as exr_in_parallel, sort_header_attributes as sort_exr_header};
pub use read::{check_finite, decode, read, read_image, read_image_within, read_rgb8, Texel};
pub use write::{
    encode_outputs, is_hdr_path, tone_mapped_beside, write_files, write_image, write_outputs,
    SUPPORTED_WRITE_EXTENSIONS,
};
