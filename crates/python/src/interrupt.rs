//! Long computations run without the GIL, so other Python threads go on meanwhile, and look
//! for a Ctrl-C (a pending `KeyboardInterrupt`) every [`CHECK_INTERVAL`] between two steps.

use pyo3::{PyErr, Python};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, RecvTimeoutError};
use std::time::{Duration, Instant};

/// How often a long computation asks Python whether a signal (Ctrl-C) is pending: often
/// enough that an interrupt answers at once for a person, rarely enough that taking the GIL
/// back costs nothing measurable.
const CHECK_INTERVAL: Duration = Duration::from_millis(50);

/// Run `work` with the GIL released. `work` gets a callback to call between steps; it
/// answers `true` once Python has a pending exception from a signal handler (Ctrl-C), which
/// is then returned as `Err` in place of the result (the computation must stop when told).
pub fn without_gil<T: Send>(
    py: Python<'_>,
    work: impl FnOnce(&mut dyn FnMut() -> bool) -> T + Send,
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

/// Run `work` with the GIL released on a thread of its own, while the calling thread (Python's
/// main thread, the only one that sees signals) looks for a Ctrl-C every [`CHECK_INTERVAL`]:
/// `work` gets a callback, callable from any thread, that answers `true` once one is pending,
/// which is then returned as `Err` in place of the result (the computation must stop when
/// told). For work spread over rayon's threads, whose callbacks cannot ask Python for signals
/// themselves as [`without_gil`]'s do. A panic in `work` continues on the calling thread.
pub fn without_gil_on_workers<T: Send>(
    py: Python<'_>,
    work: impl FnOnce(&(dyn Fn() -> bool + Sync)) -> T + Send,
) -> Result<T, PyErr> {
    let stop = AtomicBool::new(false);
    let mut pending: Option<PyErr> = None;
    let joined = py.allow_threads(|| {
        std::thread::scope(|scope| {
            let (done, finished) = channel::<()>();
            let stop = &stop;
            let worker = scope.spawn(move || {
                let result = work(&|| stop.load(Ordering::Relaxed));
                // The receiver waits for this (or for the sender's drop, on a panic).
                let _ = done.send(());
                result
            });
            while let Err(RecvTimeoutError::Timeout) = finished.recv_timeout(CHECK_INTERVAL) {
                if pending.is_none() {
                    pending = Python::with_gil(|py| py.check_signals()).err();
                    stop.store(pending.is_some(), Ordering::Relaxed);
                }
            }
            worker.join()
        })
    });
    let result = joined.unwrap_or_else(|panic| std::panic::resume_unwind(panic));
    match pending {
        Some(error) => Err(error),
        None => Ok(result),
    }
}
