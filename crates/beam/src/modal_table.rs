//! The ratios Eq. 1 of the paper needs, mode by mode, relative to the first mode.

use serde::Serialize;

use crate::cantilever::Beam;
use crate::error::BeamError;

/// Modal properties of mode `index` relative to mode 1, for modes normalised to unit tip
/// deflection (MODEL.md section 1: `q_i'' / w_i^2 + q_i' / (w_i Q_i) + q_i = (F_i / k_i) cos(w t)
/// + F_ts / k_i`, `u = sum chi_i q_i`). All ratios are dimensionless and equal 1 for mode 1.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ModalProperties {
    /// 1-based mode number `n`.
    pub index: usize,
    /// Eigenvalue `b_n`, root of `1 + cos b cosh b + mu b (cos b sinh b - sin b cosh b) = 0`.
    pub eigenvalue: f64,
    /// `w_n / w_1 = (b_n / b_1)^2`, natural frequencies in vacuum.
    pub frequency_ratio: f64,
    /// `k_n / k_1`, with `k_n = w_n^2 M_n` and `M_n` the modal mass including the tip mass
    /// (the paper's `k_2 / k_1`: 39 at `mu = 0`, 74 at `mu = 0.1`).
    pub stiffness_ratio: f64,
    /// Optical-lever sensitivity ratio `chi_n = phi_n'(1) / phi_1'(1)`, the ratio of tip slopes
    /// (the paper's `chi`: 3.47 at `mu = 0`, 5.26 at `mu = 0.16`).
    pub chi: f64,
    /// `F_n / F_1` for a uniformly distributed drive on the beam (magnetic excitation):
    /// `int phi_n / int phi_1` (the paper's `F_2 / F_1`: -0.554 at `mu = 0`, -1.54 at 0.16).
    pub force_ratio_distributed: f64,
    /// `F_n / F_1` for a force at the tip: `phi_n(1) / phi_1(1) = 1` by the normalisation.
    pub force_ratio_tip: f64,
}

impl Beam {
    /// The first `modes` rows of [`ModalProperties`] for this beam (see [`modal_table()`]).
    ///
    /// # Errors
    /// [`BeamError::ModeOutOfRange`] unless `1 <= modes <= MAX_MODES`;
    /// [`BeamError::EigenvalueNotFound`] if root finding fails (not expected for valid input).
    pub fn modal_table(&self, modes: usize) -> Result<Vec<ModalProperties>, BeamError> {
        let shapes = self.modes(modes)?;
        let Some(first) = shapes.first() else {
            // `modes` validated >= 1 above, so this is unreachable; report it as a range error.
            return Err(BeamError::ModeOutOfRange {
                field: "modes",
                value: modes,
                max: crate::MAX_MODES,
            });
        };
        let b1 = first.eigenvalue();
        let k1 = first.stiffness();
        let slope1 = first.tip_slope();
        let distributed1 = first.distributed_force_integral();
        let tip1 = first.tip_force_integral();
        Ok(shapes
            .iter()
            .map(|mode| ModalProperties {
                index: mode.index(),
                eigenvalue: mode.eigenvalue(),
                frequency_ratio: (mode.eigenvalue() / b1).powi(2),
                stiffness_ratio: mode.stiffness() / k1,
                chi: mode.tip_slope() / slope1,
                force_ratio_distributed: mode.distributed_force_integral() / distributed1,
                force_ratio_tip: mode.tip_force_integral() / tip1,
            })
            .collect())
    }
}

/// Equivalent stiffness, frequency, optical-lever sensitivity and forcing ratios of the first
/// `modes` modes of a cantilever with point tip mass ratio `tip_mass_ratio = m_tip / m_c`,
/// relative to mode 1 (Eq. 1 of the paper; MODEL.md sections 1 and 7).
///
/// Takes microseconds: one bracketed Brent solve per mode and closed-form integrals.
///
/// # Errors
/// [`BeamError::TipMassRatioOutOfRange`] unless the ratio is finite and in
/// `[0, MAX_TIP_MASS_RATIO]`; [`BeamError::ModeOutOfRange`] unless `1 <= modes <= MAX_MODES`.
pub fn modal_table(tip_mass_ratio: f64, modes: usize) -> Result<Vec<ModalProperties>, BeamError> {
    Beam::new(tip_mass_ratio)?.modal_table(modes)
}
