//! `arbor`: render scene files (whole or in farm slices), merge slices, describe scenes, benchmark their
//! acceleration structures, compare images, show a scene live in a web page.
//!
//! Exit codes: 0 success, 1 `diff` found the images too different, 2 usage error, 3 bad input,
//! 4 I/O failure or not enough memory, 130 and 143 when stopped by SIGINT or SIGTERM (at any stage;
//! no image written).

/// Prints a line to standard output. A closed pipe (`arbor info | head -1`) ends the program quietly
/// instead of panicking, as command-line tools do.
macro_rules! say {
    ($($arg:tt)*) => { $crate::say_line(format_args!($($arg)*)) };
}

mod bench;
mod diff;
mod info;
mod integrator;
mod memory;
mod merge;
mod outputs;
mod progress;
mod render;
mod signals;
mod slice;
mod threads;
mod view;
mod warnings;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// A ray tracer for triangle meshes built around fast and exactly correct acceleration structures.
#[derive(Parser)]
#[command(
    name = "arbor",
    version,
    about,
    long_about = None,
    after_help = "Environment: ARBOR_MAX_ISA=avx2 (or sse) caps the structures' SIMD kernel below the \
                  processor's best, to measure Arbor as it runs on an older processor; `--stats-json` \
                  and `arbor bench` name the kernel that ran."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render every camera of a scene (METU XML/JSON, NYU scene.json) to the image it names.
    Render(render::RenderArgs),
    /// Describe a scene: cameras, lights, materials, objects, triangle counts, structure statistics.
    Info(info::InfoArgs),
    /// Benchmark the acceleration structures on a scene, a mesh file or a generated sphere: one row per
    /// structure with build statistics, Mrays/s and speedup over brute force; checks every structure's
    /// hits against the default one's (any difference: exit 3).
    Bench(bench::BenchArgs),
    /// Merge partial EXRs of render slices (tiles, sample ranges) into the full image.
    Merge(merge::MergeArgs),
    /// Compare an image with a reference: PSNR, bias and the share of pixels (or, for noisy renders, of
    /// KxK-pixel block means) off by more than a threshold.
    Diff(diff::DiffArgs),
    /// Show a scene live in a web page: the render (orbit, pan, zoom), the structure's boxes and cost
    /// heatmap, a pixel's rays, two structures side by side and a benchmark chart. Prints the address
    /// to open (with its token) and serves until Ctrl-C.
    View(view::ViewArgs),
}

/// How a command ended, when not in success.
pub enum Failure {
    /// The comparison was above its threshold (exit 1).
    TooDifferent,
    /// Options that do not make sense together (exit 2, like clap's own usage errors).
    Usage(String),
    /// An error from the library (exit 3 for bad input, 4 for I/O).
    Arbor(arbor::Error),
    /// An error about a file, after where the scene names it (`s.xml:9:13: Camera 1: ImageName 'x.png'`):
    /// exit 3 or 4, as the error's.
    At(String, arbor::Error),
    /// Stopped by a signal: 130 for SIGINT, 143 for SIGTERM (128 + the signal number, as shells report).
    Interrupted(u8),
    /// A buffer could not be allocated (exit 4, like other failures of the machine rather than the input).
    OutOfMemory(String),
}

impl From<arbor::Error> for Failure {
    fn from(e: arbor::Error) -> Self {
        Failure::Arbor(e)
    }
}

/// The body of [`say!`].
pub fn say_line(args: std::fmt::Arguments) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(args).and_then(|_| out.write_all(b"\n")) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
    }
}

/// The scene argument as a display name.
pub fn shown(path: &Option<PathBuf>) -> String {
    path.as_ref().map_or_else(|| "(built-in example)".to_string(), |p| p.display().to_string())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // Checked before any work: the kernel reads it at the first query and would take a typo as no cap.
    if let Err(msg) = arbor::accel::bvh::Isa::cap_from_env() {
        return report(Failure::Usage(msg));
    }
    let stopped = match cli.command {
        Command::Render(_) => signals::RENDER_STOPPED,
        Command::Merge(_) => signals::MERGE_STOPPED,
        Command::Info(_) | Command::Bench(_) | Command::Diff(_) | Command::View(_) => signals::STOPPED,
    };
    let signals = match signals::Signals::install(stopped) {
        Ok(s) => s,
        Err(f) => return report(f),
    };
    let result = match cli.command {
        Command::Render(args) => render::run(args, &signals),
        Command::Info(args) => info::run(args),
        Command::Bench(args) => bench::run(args),
        Command::Diff(args) => diff::run(args),
        Command::Merge(args) => merge::run(args, &signals),
        Command::View(args) => view::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // Through the watcher's lock, so that the watcher cannot report the same signal a second time.
        Err(Failure::Interrupted(code)) => signals.exit(code),
        Err(f) => report(f),
    }
}

/// Prints a failure and gives its exit code.
fn report(failure: Failure) -> ExitCode {
    match failure {
        Failure::TooDifferent => ExitCode::from(1),
        Failure::Usage(msg) => {
            eprintln!("error: {msg}");
            ExitCode::from(2)
        }
        Failure::Interrupted(code) => {
            eprintln!("{}", signals::STOPPED);
            ExitCode::from(code)
        }
        Failure::OutOfMemory(msg) => {
            eprintln!("error: {msg}");
            ExitCode::from(4)
        }
        Failure::Arbor(e) => {
            eprintln!("error: {e}");
            ExitCode::from(if e.is_io() { 4 } else { 3 })
        }
        Failure::At(at, e) => {
            eprintln!("error: {at}: {e}");
            ExitCode::from(if e.is_io() { 4 } else { 3 })
        }
    }
}
