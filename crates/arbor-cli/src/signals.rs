//! SIGINT and SIGTERM: every command stops within a second, exits 130 or 143 and leaves no partial
//! output.
//!
//! A watcher thread receives the signals (signal-hook's self-pipe: nothing runs in the handler itself)
//! and acts on the stage the command is in:
//! - [`Stage::Prepare`] (reading the scene, loading meshes, building structures: nothing is written
//!   yet): exit at once.
//! - [`Stage::Render`]: set the cancel flag, which the renderer checks before every tile; the command
//!   then returns [`Failure::Interrupted`] without writing. Should it not have ended after [`GRACE`]
//!   (a slow tile), or on a second signal, exit at once: still nothing written.
//! - [`Stage::Write`] (an atomic image write in progress): let it finish, so that no temporary file is
//!   left behind; the command reports the signal right after ([`Signals::check`]).
//!
//! The stage lives behind a mutex that the watcher holds while it exits, so the command cannot start a
//! write in the middle of an exit.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::time::Duration;

use signal_hook::consts::{SIGINT, SIGTERM};

use crate::Failure;

/// How long a render may take to notice the cancel flag before the process exits anyway.
const GRACE: Duration = Duration::from_millis(500);

/// The line printed when a signal stops `render`.
pub const RENDER_STOPPED: &str = "interrupted: an image whose render was stopped is not written";
/// The line printed when a signal stops `merge`, whose one write is atomic whenever the signal comes.
pub const MERGE_STOPPED: &str = "interrupted: the merged image is written whole or not at all";
/// The line printed when a signal stops a command that writes no file (`info`, `bench`, `diff`).
pub const STOPPED: &str = "interrupted";

/// What the command is doing, which decides what a signal does.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Stage {
    /// Nothing is being written: a signal exits at once.
    Prepare,
    /// Rendering: a signal cancels the render (exiting after [`GRACE`] or on a second signal).
    Render,
    /// Writing a file: a signal waits for the write to finish.
    Write,
}

struct State {
    stage: Stage,
    /// The exit code of the first signal received (130 or 143).
    code: Option<u8>,
    /// The line printed on the way out: what the signal did to the command's output.
    message: &'static str,
}

/// The command's side of the signal handling.
pub struct Signals {
    cancel: Arc<AtomicBool>,
    state: Arc<Mutex<State>>,
}

impl Signals {
    /// Starts the watcher, which prints `message` when a signal stops the command ([`RENDER_STOPPED`],
    /// [`MERGE_STOPPED`] or [`STOPPED`]); the command starts in [`Stage::Prepare`].
    pub fn install(message: &'static str) -> Result<Signals, Failure> {
        let mut incoming = signal_hook::iterator::Signals::new([SIGINT, SIGTERM])
            .map_err(|e| arbor::Error::Invalid(format!("cannot install a signal handler: {e}")))?;
        let s = Signals {
            cancel: Arc::default(),
            state: Arc::new(Mutex::new(State { stage: Stage::Prepare, code: None, message })),
        };
        let (cancel, state) = (Arc::clone(&s.cancel), Arc::clone(&s.state));
        std::thread::Builder::new()
            .name("signals".into())
            .spawn(move || {
                for sig in incoming.forever() {
                    received(if sig == SIGINT { 130 } else { 143 }, &cancel, &state);
                }
            })
            .map_err(|e| arbor::Error::Invalid(format!("cannot start the signal watcher: {e}")))?;
        Ok(s)
    }

    /// The flag the renderer checks before every tile.
    pub fn cancel_flag(&self) -> Arc<AtomicBool> {
        Arc::clone(&self.cancel)
    }

    /// Moves to `stage`.
    pub fn enter(&self, stage: Stage) {
        lock(&self.state).stage = stage;
    }

    /// Runs `write` in [`Stage::Write`], then returns to [`Stage::Render`].
    pub fn writing<T>(&self, write: impl FnOnce() -> T) -> T {
        self.enter(Stage::Write);
        let out = write();
        self.enter(Stage::Render);
        out
    }

    /// Ends the process for the signal `code` stands for, unless the watcher is already doing so.
    pub fn exit(&self, code: u8) -> ! {
        let held = lock(&self.state);
        exit_now(code, held.message)
    }

    /// `Err(Interrupted)` once a signal came.
    pub fn check(&self) -> Result<(), Failure> {
        match lock(&self.state).code {
            Some(code) => Err(Failure::Interrupted(code)),
            None if self.cancel.load(Ordering::SeqCst) => Err(Failure::Interrupted(130)),
            None => Ok(()),
        }
    }
}

fn lock(state: &Mutex<State>) -> MutexGuard<'_, State> {
    // The state is two plain values, consistent after any panic.
    state.lock().unwrap_or_else(PoisonError::into_inner)
}

/// What the watcher does with one signal.
fn received(code: u8, cancel: &Arc<AtomicBool>, state: &Arc<Mutex<State>>) {
    cancel.store(true, Ordering::SeqCst);
    let mut s = lock(state);
    let first = s.code.is_none();
    let code = *s.code.get_or_insert(code);
    match s.stage {
        Stage::Prepare => exit_now(code, s.message),
        Stage::Render if !first => exit_now(code, s.message),
        Stage::Render => {
            drop(s);
            let state = Arc::clone(state);
            std::thread::spawn(move || {
                std::thread::sleep(GRACE);
                let s = lock(&state);
                if s.stage != Stage::Write {
                    exit_now(code, s.message);
                }
            });
        }
        Stage::Write => {}
    }
}

/// Ends the process with `code`, saying `message`. Called with the stage locked, so no write can begin
/// meanwhile.
fn exit_now(code: u8, message: &str) -> ! {
    eprintln!("{message}");
    std::process::exit(i32::from(code))
}
