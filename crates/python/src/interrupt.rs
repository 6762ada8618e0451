//! Long computations run without the GIL, so other Python threads go on meanwhile, and look
//! for a Ctrl-C (a pending `KeyboardInterrupt`) every [`CHECK_INTERVAL`] between two steps.

use pyo3::{PyErr, Python};
use std::time::{Duration, Instant};

/// How often a long computation asks Python whether a signal (Ctrl-C) is pending: often
/// enough that an interrupt answers at once for a person, rarely enough that taking the GIL
/// back costs nothing measurable.
const CHECK_INTERVAL: Duration = Duration::from_millis(50);

/// Run `work` with the GIL released. `work` gets a callback to call between steps; it
/// answers `true` once Python has a pending exception from a signal handler (Ctrl-C), which
/// is then returned as `Err` in place of the result (the computation must stop when told).
/// The callback may be moved to another thread (behind a lock, for work on several).
pub fn without_gil<T: Send>(
    py: Python<'_>,
    work: impl FnOnce(&mut (dyn FnMut() -> bool + Send)) -> T + Send,
) -> Result<T, PyErr> {
    let mut pending: Option<PyErr> = None;
    let result = py.allow_threads(|| {
        let mut last_check = Instant::now();
        let mut interrupted = || {
            if pending.is_some() {
                return true;
            }
            if last_check.elapsed() < CHECK_INTERVAL {
                return false;
            }
            last_check = Instant::now();
            pending = Python::with_gil(|py| py.check_signals()).err();
            pending.is_some()
        };
        work(&mut interrupted)
    });
    match pending {
        Some(error) => Err(error),
        None => Ok(result),
    }
}
