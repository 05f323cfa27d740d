//! Input files read whole, and only when they are regular files.
//!
//! Every asset a scene names (meshes, images, environment maps, textures) and every ray file goes
//! through [`load_bytes`]. It refuses anything that is not a regular file, because a named pipe blocks
//! a reader forever and a character device such as `/dev/zero` never ends; and it reads at most the
//! length the file had when it was opened, so a file that grows meanwhile cannot exhaust memory, and
//! one that shrinks is simply shorter (the parsers report where it ends), never a crash: files are
//! read, not mapped into memory, where a truncation under the mapping kills the process with SIGBUS.
//!
//! Errors are I/O errors on the path ([`Error::Io`]), so callers that know where the scene names the
//! file locate them there, as for a missing file.

use std::fs::{File, Metadata, OpenOptions};
use std::io::{ErrorKind, Read};
use std::path::Path;

use crate::{Error, Result};

/// The bytes of the regular file at `path` (symbolic links followed), at most as many as it had when
/// opened.
pub fn load_bytes(path: &Path) -> Result<Vec<u8>> {
    let file = open_regular(path)?;
    let len = file.metadata().map_err(|e| Error::io(path, e))?.len();
    let mut bytes = Vec::new();
    let room = usize::try_from(len).ok().and_then(|n| bytes.try_reserve_exact(n).ok());
    if room.is_none() {
        let msg = format!("not enough memory to read it ({:.1} MiB)", len as f64 / (1u64 << 20) as f64);
        return Err(Error::io(path, std::io::Error::new(ErrorKind::OutOfMemory, msg)));
    }
    file.take(len).read_to_end(&mut bytes).map_err(|e| Error::io(path, e))?;
    Ok(bytes)
}

/// An empty vector with room for `n` items of what is read from `path`, or, when they cannot be
/// allocated, an out-of-memory I/O error naming the file, `what(gib)` saying what did not fit: the CLI's
/// exit 4 (a scene's asset is located at its element instead) rather than an abort.
pub(crate) fn vec_for<T>(n: u64, path: &Path, what: impl FnOnce(f64) -> String) -> Result<Vec<T>> {
    let mut v = Vec::new();
    if usize::try_from(n).ok().and_then(|n| v.try_reserve_exact(n).ok()).is_none() {
        let gib = n as f64 * std::mem::size_of::<T>() as f64 / (1u64 << 30) as f64;
        return Err(Error::io(path, std::io::Error::new(ErrorKind::OutOfMemory, what(gib))));
    }
    Ok(v)
}

/// Opens `path` for reading if it is a regular file.
pub fn open_regular(path: &Path) -> Result<File> {
    let mut options = OpenOptions::new();
    options.read(true);
    // Opening a named pipe waits for a writer; non-blocking, open returns at once and the type check
    // below refuses it. Regular files ignore the flag.
    #[cfg(target_os = "linux")]
    std::os::unix::fs::OpenOptionsExt::custom_flags(&mut options, libc::O_NONBLOCK);
    #[cfg(not(target_os = "linux"))]
    if let Ok(meta) = std::fs::metadata(path) {
        check_regular(path, &meta)?;
    }
    let file = options.open(path).map_err(|e| Error::io(path, e))?;
    check_regular(path, &file.metadata().map_err(|e| Error::io(path, e))?)?;
    Ok(file)
}

fn check_regular(path: &Path, meta: &Metadata) -> Result<()> {
    if meta.is_file() {
        return Ok(());
    }
    let msg = format!("not a regular file ({})", kind(meta));
    Err(Error::io(path, std::io::Error::new(ErrorKind::InvalidInput, msg)))
}

/// What a file that is not a regular file is, in words.
fn kind(meta: &Metadata) -> &'static str {
    if meta.is_dir() {
        return "a directory";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_fifo() {
            return "a named pipe";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    "not a plain file"
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn load_bytes_reads_regular_files_whole() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.bin");
        std::fs::write(&path, b"hello").unwrap();
        assert_eq!(load_bytes(&path).unwrap(), b"hello");
        let empty = dir.path().join("empty.bin");
        std::fs::write(&empty, b"").unwrap();
        assert_eq!(load_bytes(&empty).unwrap(), b"");
    }

    #[test]
    fn load_bytes_refuses_folders_and_devices() {
        let dir = tempfile::tempdir().unwrap();
        let e = load_bytes(dir.path()).unwrap_err();
        assert_eq!(e.to_string(), format!("{}: not a regular file (a directory)", dir.path().display()));
        assert!(e.is_io());
        #[cfg(unix)]
        {
            let link = dir.path().join("zero.ply");
            std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
            let e = load_bytes(&link).unwrap_err();
            assert_eq!(e.to_string(), format!("{}: not a regular file (a character device)", link.display()));
        }
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn load_bytes_reads_no_more_than_the_length_at_open() {
        // A procfs file is regular and says it is empty, yet reading it yields text: only its stated
        // length (none) is read, as for a file that grows while it is read.
        let status = Path::new("/proc/self/status");
        assert!(!std::fs::read(status).unwrap().is_empty());
        assert_eq!(load_bytes(status).unwrap(), b"");
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn load_bytes_refuses_a_named_pipe_without_blocking() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe.ply");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        // SAFETY: `c` is a valid NUL-terminated path for the duration of the call.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let e = load_bytes(&fifo).unwrap_err();
        assert_eq!(e.to_string(), format!("{}: not a regular file (a named pipe)", fifo.display()));
    }
}
