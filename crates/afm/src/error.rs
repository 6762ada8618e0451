//! The error type of the `afm` crate: bad input files, bad parameters, unknown fixture names.

use thiserror::Error;

/// Everything that can go wrong when loading or building a cantilever model.
///
/// Every variant names where the problem is (`file`: a path, a built-in fixture, or a
/// description of an in-memory value) so that a user can fix it.
#[derive(Debug, Error)]
pub enum AfmError {
    /// A field of an input (file or in-memory struct) lies outside its allowed range.
    #[error("{file}: field `{field}` = {value} is invalid; allowed: {allowed}")]
    InvalidField {
        /// The file (or in-memory source) holding the field.
        file: String,
        /// The field's path, e.g. `modes[1].quality_factor`.
        field: String,
        /// The offending value as written.
        value: String,
        /// The allowed range or values, in words, with units.
        allowed: String,
    },
    /// The file is not valid JSON for its schema (syntax error, unknown or missing field,
    /// wrong type); the message names the field the error is in (empty: the top level), and
    /// `serde_json`'s the expected type or fields and the line and column.
    #[error("{file}: {}{source}", if field.is_empty() { String::new() } else { format!("field `{field}`: ") })]
    Json {
        /// The file that failed to parse.
        file: String,
        /// The path of the field the error is in, e.g. `modes[1].quality_factor`.
        field: String,
        /// The parser's error (with line and column).
        #[source]
        source: serde_json::Error,
    },
    /// The file could not be read.
    #[error("cannot read {file}: {source}")]
    Io {
        /// The path that could not be read.
        file: String,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// A name that is neither a built-in fixture nor a readable file.
    #[error("unknown {kind} `{name}`; built-in {kind}s: {known}")]
    UnknownFixture {
        /// `case`, `cantilever` or `sample`.
        kind: &'static str,
        /// The name asked for.
        name: String,
        /// The built-in names, comma separated.
        known: String,
    },
    /// The drive cannot produce the requested free amplitude: the transfer function from
    /// `F_1` to the first harmonic of `u` vanishes at the drive frequency.
    #[error(
        "the drive at {drive_frequency_khz} kHz does not move the photodiode signal u \
         (|sum_i chi_i r_i H_i(w)| = {gain:e} nm/nN): no F_1 gives A0"
    )]
    DegenerateDrive {
        /// The drive frequency in kHz.
        drive_frequency_khz: f64,
        /// The magnitude of the transfer function `sum_i chi_i r_i H_i(w)` in nm/nN.
        gain: f64,
    },
    /// The hybrid solver failed while computing an orbit or its observables.
    #[error("solver failure: {0}")]
    Solver(#[from] hybrid::HybridError),
    /// A search along a branch ended without reaching its target.
    #[error("{what} not reached: {reason}")]
    NotReached {
        /// What was searched for, e.g. `A/A0 = 0.5`.
        what: String,
        /// Why the search stopped.
        reason: String,
    },
    /// The caller asked a long computation to stop (a Ctrl-C), through the callback of
    /// [`crate::diagram::bifurcation_diagram::diagram_until`].
    #[error("the computation was interrupted")]
    Interrupted,
    /// Shooting or continuation of a periodic orbit failed.
    #[error("periodic orbit: {0}")]
    Continuation(#[from] continuation::ContinuationError),
}
