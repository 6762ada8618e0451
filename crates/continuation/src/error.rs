//! The error type of the continuation crate: every way shooting, continuation or the location
//! of a special point can fail, with the parameter value and the quantity that failed.

use thiserror::Error;

/// Why a shooting, continuation or location computation failed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ContinuationError {
    /// A vector has the wrong length for the problem.
    #[error("dimension mismatch in {what}: expected {expected}, found {found}")]
    DimensionMismatch {
        /// Which vector (`"initial state"`, `"image"`, ...).
        what: &'static str,
        /// Length the problem requires ([`crate::PeriodicProblem::dim`], or `dim + 1`).
        expected: usize,
        /// Length supplied.
        found: usize,
    },
    /// The period map (or a quantity derived from it) is NaN or infinite.
    #[error("non-finite {what} at parameter p = {parameter:e}")]
    NonFinite {
        /// Which quantity (`"image"`, `"monodromy"`, `"state"`, ...).
        what: &'static str,
        /// The parameter value at which it happened.
        parameter: f64,
    },
    /// A Newton matrix (`M - I`, or the bordered pseudo-arclength matrix) is singular.
    #[error("singular {what} at parameter p = {parameter:e}")]
    SingularMatrix {
        /// Which matrix (`"shooting Jacobian M - I"`, `"bordered Jacobian"`).
        what: &'static str,
        /// The parameter value at which it happened.
        parameter: f64,
    },
    /// The problem could not evaluate its period map (for a hybrid problem, the integration
    /// failed); `message` carries the underlying error.
    #[error("period map failed at parameter p = {parameter:e}: {message}")]
    PeriodMapFailed {
        /// The parameter value of the evaluation.
        parameter: f64,
        /// The underlying error, as text.
        message: String,
    },
    /// The hybrid solver failed to integrate the period map.
    #[error(
        "hybrid integration of the period map failed at parameter p = {parameter:e}: {source}"
    )]
    Hybrid {
        /// The parameter value of the evaluation.
        parameter: f64,
        /// The solver's error.
        source: hybrid::HybridError,
    },
    /// Newton's method at the start of a branch did not reach the tolerance.
    #[error(
        "starting orbit not converged at p = {parameter:e}: residual {residual:e} after {iterations} Newton iterations"
    )]
    StartNotConverged {
        /// The parameter value of the start.
        parameter: f64,
        /// Newton iterations made.
        iterations: usize,
        /// Final residual `|P(x; p) - x|` (state units).
        residual: f64,
    },
    /// The continuation step was cut below the minimum step without a converged corrector.
    #[error(
        "continuation step {step:e} below the minimum at p = {parameter:e}: the corrector failed (last residual {residual:e})"
    )]
    StepTooSmall {
        /// Parameter value of the last accepted branch point.
        parameter: f64,
        /// The step (arclength) that was attempted.
        step: f64,
        /// The last corrector residual (state units; infinite if the period map failed).
        residual: f64,
    },
    /// The system refused a value of its second parameter (see
    /// [`crate::TwoParametrised::set_second_parameter`]).
    #[error("second parameter q = {value:e} not allowed: {message}")]
    SecondParameter {
        /// The refused value.
        value: f64,
        /// The system's reason.
        message: String,
    },
    /// A settings field is outside its allowed range.
    #[error("invalid setting `{field}` = {value:e}: allowed {allowed}")]
    InvalidSettings {
        /// Name of the offending field.
        field: &'static str,
        /// Its value (converted to `f64` for integer fields).
        value: f64,
        /// The allowed range, in words.
        allowed: &'static str,
    },
}
