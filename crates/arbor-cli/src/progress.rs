//! Render progress on standard error: an indicatif bar on a terminal; plain lines every 10% (with the
//! elapsed time) when standard error is a file or pipe, as in a Slurm or Kubernetes job log, where a
//! redrawn bar would be one endless line of control characters.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};

/// Progress of one image.
pub enum Progress {
    /// Nothing shown (`--quiet`).
    Hidden,
    /// A bar redrawn in place.
    Bar(ProgressBar),
    /// One line per tenth done.
    Lines {
        /// The image's name.
        name: String,
        /// When the render started.
        start: Instant,
        /// The last tenth printed.
        tenth: AtomicU64,
    },
}

impl Progress {
    /// The kind of progress that suits standard error for an image of `len` pixels.
    pub fn new(quiet: bool, len: u64, name: &str) -> Progress {
        if quiet {
            return Progress::Hidden;
        }
        if !std::io::stderr().is_terminal() {
            return Progress::Lines { name: name.to_string(), start: Instant::now(), tenth: AtomicU64::new(0) };
        }
        let bar = ProgressBar::new(len);
        bar.set_style(
            ProgressStyle::with_template("{msg} [{bar:40}] {percent:>3}% {elapsed_precise} (eta {eta})")
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        bar.set_message(name.to_string());
        Progress::Bar(bar)
    }

    /// `done` of `total` pixels are finished (called from worker threads).
    pub fn set(&self, done: u64, total: u64) {
        match self {
            Progress::Hidden => {}
            Progress::Bar(bar) => bar.set_position(done),
            Progress::Lines { name, start, tenth } => {
                let now = done * 10 / total.max(1);
                // Only the thread that moves the counter prints, so each tenth appears once.
                if tenth.fetch_max(now, Ordering::Relaxed) < now {
                    let secs = start.elapsed().as_secs_f64();
                    eprintln!("{name}: {}% ({done}/{total} pixels, {secs:.1} s)", now * 10);
                }
            }
        }
    }

    /// Removes the bar, if any.
    pub fn finish(&self) {
        if let Progress::Bar(bar) = self {
            bar.finish_and_clear();
        }
    }
}
