//! Errors crossing into Python: the CLI's messages (the error and its causes, joined by `: `)
//! raised as the built-in exception a Python user expects.

use afm::AfmError;
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::PyErr;

/// The Python exception for a failed drumroll call: `ValueError` for bad input (an option out
/// of range, an unknown name, a malformed file or dict: every message names the option or
/// field and its allowed range), `OSError` for a file that cannot be read, `RuntimeError` for
/// a computation that failed on valid input (no steady orbit, a continuation error).
pub fn to_py_err(error: anyhow::Error) -> PyErr {
    let message = format!("{error:#}");
    let afm_error = error
        .chain()
        .find_map(|cause| cause.downcast_ref::<AfmError>());
    match afm_error {
        Some(AfmError::Io { .. }) => PyOSError::new_err(message),
        Some(
            AfmError::Solver(_)
            | AfmError::NotReached { .. }
            | AfmError::Continuation(_)
            | AfmError::Interrupted,
        ) => PyRuntimeError::new_err(message),
        _ => PyValueError::new_err(message),
    }
}

/// [`to_py_err`] for a library error without context.
pub fn afm_to_py_err(error: AfmError) -> PyErr {
    to_py_err(anyhow::Error::new(error))
}
