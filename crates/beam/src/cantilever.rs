//! The validated description of a cantilever for modal analysis: its tip mass ratio.

use serde::Serialize;

use crate::characteristic::{characteristic_function, eigenvalue};
use crate::error::BeamError;
use crate::mode_shape::ModeShape;

/// Largest accepted tip mass ratio `m_tip / m_c`.
///
/// AFM cantilevers have ratios of order 0.1 (the paper: 0 to 0.2); colloidal probes reach a few.
/// At 1000 the first mode is already the massless-spring-plus-mass oscillator
/// (`b_1^4 = 3 / mu` to 2e-4), so larger values describe no cantilever one would model with beam
/// modes. The bound also keeps the small-`b` cancellation in the first mode shape and in the
/// characteristic function (relative error `~ eps / b_1^2`, `b_1 ~ (3 / mu)^{1/4}`) below `1e-14`.
pub const MAX_TIP_MASS_RATIO: f64 = 1000.0;

/// Largest accepted number of modes (and mode index).
///
/// The overflow-free mode shape ([`crate::mode_shape`]) is accurate at any `b`, so the bound is
/// not numerical: by mode 50 (`b ~ 156`) the wavelength `2 pi L / b ~ L / 25` is comparable with
/// the thickness of a stubby cantilever, where Euler-Bernoulli theory and the neglect of the tip's
/// rotary inertia break down. (The textbook form `cosh - cos - sigma (sinh - sin)` would already
/// lose all digits near mode 12, where `eps e^{b} ~ 1`.) The one numerical effect that grows
/// with the mode number is the unit-tip normalisation's amplification of the rounding of `b`,
/// a relative error `~ eps (b + mu b^2)`: at most `~1e-9` here (mode 50, `mu = 1000`).
/// Beyond mode 50 the root brackets, shapes and closed forms would still work.
pub const MAX_MODES: usize = 50;

/// A uniform rectangular Euler-Bernoulli cantilever, clamped at the base, carrying a point mass
/// (no rotary inertia) at its free end. Only the ratio `mu = m_tip / m_c` matters for the
/// dimensionless modal quantities this crate computes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Beam {
    /// Tip mass over cantilever mass, `m_tip / m_c` (dimensionless), in
    /// `[0, MAX_TIP_MASS_RATIO]`. The paper: 0 for the Biolever, 0.16 for the MAClever.
    tip_mass_ratio: f64,
}

impl Beam {
    /// A cantilever with tip mass ratio `m_tip / m_c`.
    ///
    /// # Errors
    /// [`BeamError::TipMassRatioOutOfRange`] unless the ratio is finite and in
    /// `[0, MAX_TIP_MASS_RATIO]`.
    pub fn new(tip_mass_ratio: f64) -> Result<Self, BeamError> {
        if !(tip_mass_ratio.is_finite() && (0.0..=MAX_TIP_MASS_RATIO).contains(&tip_mass_ratio)) {
            return Err(BeamError::TipMassRatioOutOfRange {
                value: tip_mass_ratio,
                max: MAX_TIP_MASS_RATIO,
            });
        }
        Ok(Self { tip_mass_ratio })
    }

    /// Tip mass over cantilever mass, `m_tip / m_c` (dimensionless).
    #[must_use]
    pub fn tip_mass_ratio(&self) -> f64 {
        self.tip_mass_ratio
    }

    /// The scaled characteristic function `g(b) = f(b) / cosh b` of this beam
    /// ([`characteristic_function`]), whose roots are the eigenvalues `b_n`.
    #[must_use]
    pub fn characteristic(&self, b: f64) -> f64 {
        characteristic_function(b, self.tip_mass_ratio)
    }

    /// The `index`-th eigenvalue `b_n` (1-based, dimensionless; `w_n = b_n^2 sqrt(EI/(rho A L^4))`).
    ///
    /// # Errors
    /// [`BeamError::ModeOutOfRange`] unless `1 <= index <= MAX_MODES`;
    /// [`BeamError::EigenvalueNotFound`] if root finding fails (not expected for valid input).
    pub fn eigenvalue(&self, index: usize) -> Result<f64, BeamError> {
        check_mode("index", index)?;
        eigenvalue(index, self.tip_mass_ratio)
    }

    /// The `index`-th mode shape (1-based), normalised to unit tip deflection.
    ///
    /// # Errors
    /// As [`Self::eigenvalue`].
    pub fn mode(&self, index: usize) -> Result<ModeShape, BeamError> {
        let b = self.eigenvalue(index)?;
        Ok(ModeShape::new(index, b, self.tip_mass_ratio))
    }

    /// The first `count` mode shapes, in order of increasing frequency.
    ///
    /// # Errors
    /// [`BeamError::ModeOutOfRange`] unless `1 <= count <= MAX_MODES`; otherwise as
    /// [`Self::eigenvalue`].
    pub fn modes(&self, count: usize) -> Result<Vec<ModeShape>, BeamError> {
        check_mode("modes", count)?;
        (1..=count).map(|index| self.mode(index)).collect()
    }
}

/// Checks a mode count or 1-based mode index against `1..=MAX_MODES`.
pub(crate) fn check_mode(field: &'static str, value: usize) -> Result<(), BeamError> {
    if (1..=MAX_MODES).contains(&value) {
        Ok(())
    } else {
        Err(BeamError::ModeOutOfRange {
            field,
            value,
            max: MAX_MODES,
        })
    }
}
