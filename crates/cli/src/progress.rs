//! Progress bars for long runs: a bar on standard error appears once a run has taken
//! [`SHOW_AFTER`] and only when standard error is a terminal; piped, redirected or with
//! `--quiet`, nothing is drawn (and `--quiet` also silences the notes naming written files).

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// A run shorter than this shows no bar.
pub const SHOW_AFTER: Duration = Duration::from_secs(2);

static QUIET: AtomicBool = AtomicBool::new(false);

/// Set by `--quiet`: no progress bars and no notes on standard error.
pub fn set_quiet(quiet: bool) {
    QUIET.store(quiet, Ordering::Relaxed);
}

/// Whether `--quiet` was given.
pub fn quiet() -> bool {
    QUIET.load(Ordering::Relaxed)
}

/// Print a note (a file written, ...) on standard error unless `--quiet`.
pub fn note(text: &str) {
    if !quiet() {
        crate::output::print_stderr(text);
    }
}

/// Whether bars may be drawn: standard error is a terminal and `--quiet` was not given.
fn drawable() -> bool {
    !quiet() && std::io::stderr().is_terminal()
}

/// A progress bar that stays hidden for the first [`SHOW_AFTER`] of the run.
#[derive(Debug)]
pub struct Progress {
    bar: ProgressBar,
    started: Instant,
    visible: bool,
}

impl Progress {
    /// A bar counting to `total` with an indicatif `template` (`{msg}` is the message given to
    /// [`Progress::update`]).
    pub fn new(total: u64, template: &str) -> Self {
        let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::hidden());
        if let Ok(style) = ProgressStyle::with_template(template) {
            bar.set_style(style);
        }
        Self {
            bar,
            started: Instant::now(),
            visible: false,
        }
    }

    /// Move the bar to `position`; `message` is computed only while the bar is visible.
    pub fn update(&mut self, position: u64, message: impl FnOnce() -> String) {
        if !self.visible && self.started.elapsed() >= SHOW_AFTER && drawable() {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
            self.visible = true;
        }
        self.bar.set_position(position);
        if self.visible {
            self.bar.set_message(message());
        }
    }

    /// Remove the bar (the run finished).
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }

    /// Leave the bar as it is (the run failed; the error follows).
    pub fn abandon(&self) {
        self.bar.abandon();
    }
}
