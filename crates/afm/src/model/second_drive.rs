//! The second drive of a bimodal excitation (MODEL.md section 14): `r_i F_1b cos(w_b t)` on
//! mode `i`, `F_1b` solved from its free amplitude `A0_b`, at a frequency commensurate with the
//! first drive (`w_b / w = p / q`), and its free flight per mode.

use crate::error::AfmError;
use crate::model::cantilever::Cantilever;
use crate::model::commensurate::Ratio;
use crate::model::drive::{photodiode_transfer_function, Drive};
use crate::model::eigenmode::angular_frequency_rad_per_us;
use crate::model::free_flight::DrivenOscillator;

/// The second drive of a bimodal excitation.
#[derive(Debug, Clone, PartialEq)]
pub struct SecondDrive {
    /// Its frequency `f_b`, kHz.
    pub frequency_khz: f64,
    /// Its angular frequency `w_b = 2 pi f_b / 1000`, rad/us.
    pub angular_frequency: f64,
    /// Its force amplitude on mode 1, `F_1b = A0_b / |G(w_b)|`, nN (MODEL.md section 3's `G`).
    pub force_nn: f64,
    /// Its free amplitude `A0_b`: the amplitude of `u` at `f_b` without the sample, nm.
    pub free_amplitude_nm: f64,
    /// `w_b / w = p / q`: the common period is `q` periods of the first drive.
    pub ratio: Ratio,
    /// `F_1b / F_1`: the second drive's factor in `cos(w t) + (F_1b / F_1) cos(w_b t)`.
    pub relative_force: f64,
    /// Each mode's steady response to the second drive (the free flight's second particular
    /// solution).
    pub(crate) oscillators: Vec<DrivenOscillator>,
}

impl SecondDrive {
    /// The second drive of `cantilever` at `frequency_khz` with free amplitude
    /// `free_amplitude_nm`, added to `first` with the ratio `ratio` (checked by the caller).
    /// Fails if the transfer function `G(w_b)` vanishes.
    pub fn new(
        cantilever: &Cantilever,
        first: &Drive,
        frequency_khz: f64,
        free_amplitude_nm: f64,
        ratio: Ratio,
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
        let oscillators = cantilever
            .modes
            .iter()
            .map(|mode| {
                DrivenOscillator::new(
                    mode.angular_frequency(),
                    mode.quality_factor,
                    mode.force_ratio * force_nn / mode.stiffness_n_per_m,
                    angular_frequency,
                )
            })
            .collect();
        Ok(Self {
            frequency_khz,
            angular_frequency,
            force_nn,
            free_amplitude_nm,
            ratio,
            relative_force: force_nn / first.force_nn,
            oscillators,
        })
    }
}
