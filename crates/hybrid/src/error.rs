//! The error type of the hybrid solver: every way an integration can fail, with the time and
//! the quantity that failed.

use thiserror::Error;

/// Why a hybrid integration (or its set-up) failed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum HybridError {
    /// The step-size controller asked for a step too small to advance time in floating point
    /// (below `8 eps |t|`): the problem is too stiff for an explicit method, or singular.
    #[error("step size underflow at t = {t:e}: proposed step {step:e} cannot advance time")]
    StepSizeUnderflow {
        /// Time at which the step failed (system time units).
        t: f64,
        /// The step the controller proposed (system time units).
        step: f64,
    },
    /// More step attempts (accepted and rejected) than `Settings::max_steps`.
    #[error("too many steps: {steps} step attempts reached the limit at t = {t:e}")]
    TooManySteps {
        /// Time reached when the limit was hit.
        t: f64,
        /// Number of step attempts made.
        steps: usize,
    },
    /// More events than `Settings::max_events` (for instance a Zeno accumulation of impacts).
    #[error(
        "too many events: {events} events reached the limit at t = {t:e} (Zeno accumulation?)"
    )]
    TooManyEvents {
        /// Time of the event that exceeded the limit.
        t: f64,
        /// Number of events fired before the limit was hit.
        events: usize,
    },
    /// The state (initial, or produced by the integration or a reset map) is NaN or infinite.
    #[error("non-finite state at t = {t:e}")]
    NonFiniteState {
        /// Time at which the non-finite value appeared.
        t: f64,
    },
    /// A switching function returned NaN or infinity inside a step.
    #[error("switching function {surface} is not finite at t = {t:e}")]
    NonFiniteSwitching {
        /// Time of the evaluation.
        t: f64,
        /// Index of the switching function.
        surface: usize,
    },
    /// A settings field is outside its allowed range.
    #[error("invalid setting `{field}` = {value:e}: allowed {allowed}")]
    InvalidSettings {
        /// Name of the offending field of [`crate::Settings`].
        field: &'static str,
        /// Its value (converted to `f64` for integer fields).
        value: f64,
        /// The allowed range, in words.
        allowed: &'static str,
    },
    /// A vector has the wrong length for the system.
    #[error("dimension mismatch: expected {expected}, found {found}")]
    DimensionMismatch {
        /// Length the system requires ([`crate::HybridSystem::dim`]).
        expected: usize,
        /// Length supplied.
        found: usize,
    },
    /// The system declares more switching surfaces than a [`crate::Mode`] can hold.
    #[error("too many switching surfaces: {surfaces} (at most {max})")]
    TooManySurfaces {
        /// Number declared by the system.
        surfaces: usize,
        /// The maximum, [`crate::MAX_SURFACES`].
        max: usize,
    },
    /// An end time (or duration) that is not finite or lies before the current time.
    #[error("invalid end time {t_end:e} at t = {t:e}: must be finite and not before t")]
    InvalidEndTime {
        /// Current time of the solver.
        t: f64,
        /// The requested end time.
        t_end: f64,
    },
    /// An event with `dh/dt = 0` exactly where the vector field jumps: the saltation matrix
    /// `(f+ - R_x f-) h_x^T / hdot` is infinite, so the sensitivities do not exist.
    #[error(
        "singular saltation at t = {t:e} on surface {surface}: dh/dt = 0 where the field jumps"
    )]
    SingularSaltation {
        /// Time of the event.
        t: f64,
        /// Index of the switching surface.
        surface: usize,
    },
}
