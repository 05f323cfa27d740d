//! The one error type of the library: every failure of user input names the file, where in it (line and
//! column for text, byte offset for binary data) and what is wrong.

use std::fmt;
use std::path::{Path, PathBuf};

/// Where in an input file something was found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    /// The file, as the user named it (or as resolved relative to the scene file).
    pub file: PathBuf,
    /// 1-based line, when the file is text.
    pub line: Option<u32>,
    /// 1-based column, when known.
    pub col: Option<u32>,
    /// Byte offset, for binary data.
    pub byte: Option<u64>,
}

impl Location {
    /// The whole file, no position inside it.
    pub fn file(file: impl AsRef<Path>) -> Self {
        Location { file: file.as_ref().to_path_buf(), line: None, col: None, byte: None }
    }
    /// A line (and column, when non-zero) in a text file.
    pub fn at(file: impl AsRef<Path>, line: u32, col: u32) -> Self {
        Location { file: file.as_ref().to_path_buf(), line: Some(line), col: (col > 0).then_some(col), byte: None }
    }
    /// A byte offset in a binary file.
    pub fn byte(file: impl AsRef<Path>, offset: u64) -> Self {
        Location { file: file.as_ref().to_path_buf(), line: None, col: None, byte: Some(offset) }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
            if let Some(col) = self.col {
                write!(f, ":{col}")?;
            }
        }
        if let Some(byte) = self.byte {
            write!(f, ": byte {byte}")?;
        }
        Ok(())
    }
}

/// Everything that can go wrong in the library.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// What the operating system said.
        source: std::io::Error,
    },
    /// The content of an input file is wrong (syntax or meaning).
    #[error("{loc}: {msg}")]
    Input {
        /// Where.
        loc: Location,
        /// What is wrong, in words a user understands.
        msg: String,
    },
    /// A request that makes no sense independently of any file (bad option value, empty scene...).
    #[error("{0}")]
    Invalid(String),
    /// A buffer the work needs could not be allocated (the message says which and how large).
    #[error("{0}")]
    OutOfMemory(String),
}

impl Error {
    /// An input error at `loc`.
    pub fn input(loc: Location, msg: impl Into<String>) -> Self {
        Error::Input { loc, msg: msg.into() }
    }
    /// An I/O error on `path`.
    pub fn io(path: impl AsRef<Path>, source: std::io::Error) -> Self {
        Error::Io { path: path.as_ref().to_path_buf(), source }
    }
    /// True when the failure is the machine's (file system, memory) rather than the input's (CLI exit code 4
    /// vs 3).
    pub fn is_io(&self) -> bool {
        matches!(self, Error::Io { .. } | Error::OutOfMemory(_))
    }
}

/// How a user lifts the resource limits (scenes, images): the end of every message that refuses
/// something for exceeding one.
pub const LIFT_LIMITS: &str = "--no-limits lifts the limits";

/// The library's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;
