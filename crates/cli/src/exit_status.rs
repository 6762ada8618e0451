//! The exit statuses of `drumroll` (documented in the README and in `drumroll --help`):
//!
//! - 0: success;
//! - 1: an error (bad input, a failed computation): nothing, or only complete files, written;
//! - 2: the command line does not parse (clap's usage error);
//! - 3: the run stopped before its requested end (a point cap, a failed corrector, a sweep
//!   that failed midway): what was computed is written, and stderr and the JSON's `stop` and
//!   `completed` say why.

use std::fmt;

/// Exit status of a run that stopped before its requested end.
pub const INCOMPLETE: u8 = 3;

/// The error a command returns after writing its output when the run did not reach its
/// requested end; `main` prints it and exits with [`INCOMPLETE`].
#[derive(Debug)]
pub struct Incomplete(pub String);

impl fmt::Display for Incomplete {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "the run stopped before its requested end: {}", self.0)
    }
}

impl std::error::Error for Incomplete {}
