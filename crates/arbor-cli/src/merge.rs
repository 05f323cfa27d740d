//! `arbor merge PARTS... -o IMAGE`: partial EXRs of `arbor render` slices (tiles, sample ranges) into the
//! full image, equal byte for byte to a single-process render. The rules and messages are the library's
//! (`arbor::farm::merge`); parts that do not fit exit 3 naming the file.

use std::path::PathBuf;

use clap::Args;

use crate::Failure;

/// Arguments of `arbor merge`.
#[derive(Args)]
pub struct MergeArgs {
    /// Partial EXR files written by `arbor render --tile/--sample-offset/--sample-count` (any order).
    #[arg(required = true, value_name = "PARTS")]
    pub parts: Vec<PathBuf>,
    /// The merged image; the extension picks the format (.png, .ppm, .exr, .hdr, .jpg, .jpeg). An .exr or
    /// .hdr image holds radiance in the scene's units and gets its tone-mapped PNG beside it, which replaces a file of that name; the two are
    /// written together or not at all.
    #[arg(short = 'o', long = "out", value_name = "IMAGE")]
    pub out: PathBuf,
    /// No summary line (`Saved: IMAGE` stays).
    #[arg(short, long)]
    pub quiet: bool,
    /// Lift the limit on the pixels of the frame and of each part (2^28, the most `arbor render` writes
    /// by default).
    #[arg(long)]
    pub no_limits: bool,
}

/// Runs `arbor merge`.
pub fn run(args: MergeArgs, signals: &crate::signals::Signals) -> Result<(), Failure> {
    let start = std::time::Instant::now();
    // Checked before the parts are read: they may be many and large.
    crate::outputs::check_extension(&args.out).map_err(Failure::Usage)?;
    crate::outputs::check_writable(&args.out, true)?;
    // The image, and the PNG beside an HDR one, must not replace a part (they are read first, but a
    // failed or repeated merge would then have lost it).
    for written in crate::outputs::files_written(&args.out, true) {
        if let Some(part) = args.parts.iter().find(|p| same_file(p, &written)) {
            return Err(Failure::Usage(format!(
                "-o {}: merge would write {}, which is the part {}",
                args.out.display(),
                written.display(),
                part.display()
            )));
        }
    }
    let limits = crate::render::limits(args.no_limits).rendered();
    let parts = args
        .parts
        .iter()
        .map(|p| arbor::farm::read_partial(p, &limits).map(|part| (p.clone(), part)))
        .collect::<Result<Vec<_>, _>>()?;
    let film = arbor::farm::merge(&parts)?;
    // Written as the single-process render writes it: the camera's tone mapping, the PNG beside HDR.
    let first = &parts[0].1;
    let tonemap = first.tonemap.or_else(|| crate::outputs::hdr_preview(&args.out, first.sums.scale));
    signals.enter(crate::signals::Stage::Render);
    let written =
        signals.writing(|| arbor::image_io::write_outputs(&args.out, &film, first.sums.scale, tonemap.as_ref()))?;
    signals.check()?;
    if !args.quiet {
        let spp = parts.first().map_or(0, |(_, p)| p.sums.spp);
        say!(
            "{}  {}x{}  {spp} spp  merged {} parts in {:.1} ms",
            args.out.display(),
            film.width,
            film.height,
            parts.len(),
            start.elapsed().as_secs_f64() * 1e3
        );
    }
    for path in written {
        say!("Saved: {}", path.display());
    }
    Ok(())
}

/// True when `a` and `b` name one existing file.
fn same_file(a: &std::path::Path, b: &std::path::Path) -> bool {
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}
