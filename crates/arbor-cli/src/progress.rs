//! Render progress on standard error: an indicatif bar on a terminal; when standard error is a file or
//! pipe (a Slurm or Kubernetes job log, where a redrawn bar would be one endless line of control
//! characters), a plain line at most every [`EVERY`], none before the render has run that long, so a
//! short render leaves nothing in the log.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

/// The shortest time between two plain progress lines, and before the first.
pub const EVERY: Duration = Duration::from_secs(5);

/// Progress of one image.
pub enum Progress {
    /// Nothing shown (`--quiet`).
    Hidden,
    /// A bar redrawn in place.
    Bar(ProgressBar),
    /// A line now and then.
    Lines(Lines),
}

/// The state of plain progress lines.
pub struct Lines {
    name: String,
    start: Instant,
    /// Milliseconds after `start` of the last line printed (0: none yet).
    last_ms: AtomicU64,
    every: Duration,
}

impl Lines {
    /// Lines for the image `name`, at most one per `every`.
    pub fn new(name: &str, every: Duration) -> Lines {
        Lines { name: name.to_string(), start: Instant::now(), last_ms: AtomicU64::new(0), every }
    }

    /// The line to print for `done` of `total` pixels at `elapsed` since the start, if one is due; only
    /// one caller gets a given line, so concurrent workers never print it twice.
    fn due(&self, done: u64, total: u64, elapsed: Duration) -> Option<String> {
        let now = elapsed.as_millis() as u64;
        let every = self.every.as_millis() as u64;
        let last = self.last_ms.load(Ordering::Relaxed);
        if now < last + every || self.last_ms.compare_exchange(last, now, Ordering::Relaxed, Ordering::Relaxed).is_err()
        {
            return None;
        }
        let percent = done * 100 / total.max(1);
        Some(format!("{}: {percent}% ({done}/{total} pixels, {:.1} s)", self.name, elapsed.as_secs_f64()))
    }
}

impl Progress {
    /// The kind of progress that suits standard error for an image of `len` pixels.
    pub fn new(quiet: bool, len: u64, name: &str) -> Progress {
        if quiet {
            return Progress::Hidden;
        }
        if !std::io::stderr().is_terminal() {
            return Progress::Lines(Lines::new(name, EVERY));
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
            Progress::Lines(lines) => {
                if let Some(line) = lines.due(done, total, lines.start.elapsed()) {
                    eprintln!("{line}");
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn progress_lines_wait_and_then_space_out() {
        let lines = Lines::new("a.png", Duration::from_secs(5));
        let at = |s: f64| Duration::from_secs_f64(s);
        assert_eq!(lines.due(50, 100, at(0.1)), None, "nothing for a short render");
        assert_eq!(lines.due(60, 100, at(4.9)), None);
        assert_eq!(lines.due(70, 100, at(5.0)).as_deref(), Some("a.png: 70% (70/100 pixels, 5.0 s)"));
        assert_eq!(lines.due(71, 100, at(5.0)), None, "one line per moment");
        assert_eq!(lines.due(80, 100, at(9.9)), None);
        assert_eq!(lines.due(90, 100, at(10.0)).as_deref(), Some("a.png: 90% (90/100 pixels, 10.0 s)"));
    }
}
