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

/// Issue `message` as a Python `UserWarning` (what the CLI prints on stderr as `warning: ...`,
/// e.g. a film law used beyond its range), so that notebooks show it and `warnings` filters
/// it.
pub fn warn(py: pyo3::Python<'_>, message: &str) -> pyo3::PyResult<()> {
    let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
    let text = std::ffi::CString::new(message.replace('\0', " "))?;
    PyErr::warn(py, &category, &text, 1)
}
