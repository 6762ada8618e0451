//! The error type of the beam crate: every way a modal analysis can be refused or fail, with
//! the field, the offending value and the allowed range.

use thiserror::Error;

/// Why a cantilever modal analysis was refused or failed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum BeamError {
    /// The tip mass ratio `m_tip / m_c` is not finite or lies outside `[0, max]`.
    #[error(
        "invalid `tip_mass_ratio` = {value}: must be finite and in [0, {max}] \
         (point tip mass over the cantilever's own mass, dimensionless)"
    )]
    TipMassRatioOutOfRange {
        /// The value given.
        value: f64,
        /// The largest accepted value, [`crate::MAX_TIP_MASS_RATIO`].
        max: f64,
    },
    /// The number of modes (or a mode index, counted from 1) lies outside `1..=max`.
    #[error("invalid `{field}` = {value}: must be in 1..={max}")]
    ModeOutOfRange {
        /// Which argument: `"modes"` (a count) or `"index"` (a 1-based mode number).
        field: &'static str,
        /// The value given.
        value: usize,
        /// The largest accepted value, [`crate::MAX_MODES`].
        max: usize,
    },
    /// The root finder did not return a root of the characteristic equation inside the
    /// bracket `[(n-1) pi, n pi]` that provably holds the `n`-th root.
    #[error(
        "eigenvalue b_{index} (tip_mass_ratio = {tip_mass_ratio}) not found in \
         [{lower}, {upper}]: {reason}"
    )]
    EigenvalueNotFound {
        /// The 1-based mode number.
        index: usize,
        /// The tip mass ratio `m_tip / m_c`.
        tip_mass_ratio: f64,
        /// Lower end of the bracket (dimensionless eigenvalue `b`).
        lower: f64,
        /// Upper end of the bracket (dimensionless eigenvalue `b`).
        upper: f64,
        /// What went wrong (the root finder's report, or the residual that was too large).
        reason: String,
    },
    /// A Gauss-Legendre rule or a composite quadrature was asked for with an unusable size.
    #[error("invalid quadrature `{field}` = {value}: must be in {min}..={max}")]
    QuadratureOutOfRange {
        /// `"order"` (points per panel) or `"panels"`.
        field: &'static str,
        /// The value given.
        value: usize,
        /// The smallest accepted value.
        min: usize,
        /// The largest accepted value.
        max: usize,
    },
    /// A number of a geometry or fluid lies outside its accepted range (or is not finite).
    #[error("invalid `{field}` = {value}: must be finite and in [{min}, {max}]")]
    FieldOutOfRange {
        /// The field's name, with its unit (e.g. `length_um`).
        field: &'static str,
        /// The value given.
        value: f64,
        /// The smallest accepted value.
        min: f64,
        /// The largest accepted value.
        max: f64,
    },
    /// Two numbers of a geometry contradict the slender-beam theory's assumptions.
    #[error("invalid geometry: {reason}")]
    Geometry {
        /// What is wrong, with the numbers.
        reason: String,
    },
    /// A mode's Reynolds number lies outside the range of Sader's fit of the rectangular beam's
    /// hydrodynamic function.
    #[error(
        "mode {mode}: Reynolds number Re = rho w b^2 / (4 eta) = {value:.3e} is outside \
         [{min:e}, {max:e}], the range of Sader's (1998) fit of the rectangular beam's \
         hydrodynamic function: change the width, the mode count or the fluid"
    )]
    ReynoldsOutOfRange {
        /// The 1-based mode number.
        mode: usize,
        /// The Reynolds number.
        value: f64,
        /// The smallest value of the fit.
        min: f64,
        /// The largest value of the fit.
        max: f64,
    },
    /// The fixed point `w_n = b_n(mu_eff(w_n))^2 sqrt(EI / (m_eff(w_n) L^4))` was not reached.
    #[error("mode {mode}: the frequency in the fluid did not converge: {reason}")]
    FluidFrequencyNotConverged {
        /// The 1-based mode number.
        mode: usize,
        /// The last iterates.
        reason: String,
    },
}
