//! The drive: its frequency and the force amplitude `F_1` that gives the requested free
//! amplitude `A0` (MODEL.md section 3), solved exactly from the linear steady state.

use nalgebra::Complex;

use crate::error::AfmError;
use crate::model::cantilever::Cantilever;
use crate::model::eigenmode::angular_frequency_rad_per_us;
use crate::model::eigenmode::Eigenmode;
use crate::model::free_flight::dimensionless_response;

/// The transfer function `H_i(w) = (1/k_i) / (1 - (w/w_i)^2 + i (w/w_i)/Q_i)` of eigenmode `i`
/// of Eq. 1, nm/nN: the steady response of `q_i` to a force `F e^{i w t}` is `F H_i(w) e^{i w t}`.
/// `w` in rad/us.
pub fn transfer_function(mode: &Eigenmode, drive_angular_frequency: f64) -> Complex<f64> {
    dimensionless_response(
        mode.angular_frequency(),
        mode.quality_factor,
        drive_angular_frequency,
    ) / mode.stiffness_n_per_m
}

/// The transfer function from `F_1` to the photodiode signal `u`:
/// `G(w) = sum_i chi_i r_i H_i(w)`, nm/nN (MODEL.md sections 1 and 3).
pub fn photodiode_transfer_function(
    cantilever: &Cantilever,
    drive_angular_frequency: f64,
) -> Complex<f64> {
    cantilever
        .modes
        .iter()
        .map(|mode| {
            transfer_function(mode, drive_angular_frequency)
                * (mode.optical_sensitivity * mode.force_ratio)
        })
        .sum()
}

/// The harmonic drive `F_i cos(w t)`, `F_i = r_i F_1`, of Eq. 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drive {
    /// Drive frequency `f`, kHz.
    pub frequency_khz: f64,
    /// Drive angular frequency `w = 2 pi f / 1000`, rad/us.
    pub angular_frequency: f64,
    /// Force amplitude `F_1` of the first mode, nN.
    pub force_nn: f64,
}

impl Drive {
    /// The drive at `frequency_khz` whose free (`F_ts = 0`) steady response has a first
    /// harmonic of `u` of amplitude `free_amplitude_nm`: `F_1 = A0 / |G(w)|` with
    /// `G = sum_i chi_i r_i H_i(w)` (MODEL.md section 3). Fails if `G` vanishes.
    pub fn for_free_amplitude(
        cantilever: &Cantilever,
        free_amplitude_nm: f64,
        frequency_khz: f64,
    ) -> Result<Self, AfmError> {
        let angular_frequency = angular_frequency_rad_per_us(frequency_khz);
        let gain = photodiode_transfer_function(cantilever, angular_frequency).norm();
        let force_nn = free_amplitude_nm / gain;
        if !(gain > 0.0 && force_nn.is_finite()) {
            return Err(AfmError::DegenerateDrive {
                drive_frequency_khz: frequency_khz,
                gain,
            });
        }
        Ok(Self {
            frequency_khz,
            angular_frequency,
            force_nn,
        })
    }

    /// The drive period `T = 2 pi / w`, us.
    pub fn period_us(&self) -> f64 {
        2.0 * std::f64::consts::PI / self.angular_frequency
    }
}
