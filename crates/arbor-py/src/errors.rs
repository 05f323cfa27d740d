//! Arbor's errors as Python exceptions: a file that cannot be read is `OSError`, bad content or a bad
//! request `ValueError`, a buffer that cannot be allocated `MemoryError`; the message is the CLI's.

use pyo3::exceptions::{PyMemoryError, PyOSError, PyValueError};
use pyo3::PyErr;

/// `e` as the Python exception of its kind, with its message.
pub fn to_py(e: arbor::Error) -> PyErr {
    let msg = e.to_string();
    match e {
        arbor::Error::Io { .. } => PyOSError::new_err(msg),
        arbor::Error::OutOfMemory(_) => PyMemoryError::new_err(msg),
        _ => PyValueError::new_err(msg),
    }
}
