//! One flexural eigenmode of the cantilever: the constants of one line of Eq. 1.

use serde::{Deserialize, Serialize};

use crate::validation::{check, invalid, Interval};
use crate::AfmError;

/// Smallest accepted modal stiffness, N/m: a thousandth of the softest cantilevers made
/// (the Biolever's 0.036 N/m is among them). Far below it the contact is so stiff against the
/// lever that steps underflow (measured on the Biolever on mica: `k_1` = 1e-12 N/m still
/// converges, 1e-20 N/m does not).
pub(crate) const MIN_STIFFNESS: f64 = 1e-6;
/// Largest accepted modal stiffness, N/m.
pub(crate) const MAX_STIFFNESS: f64 = 1e6;
/// Smallest accepted natural frequency, kHz (10 Hz, far below any cantilever's: the paper's are
/// 3.5 to 72 kHz). A drive period of a slower one takes millions of steps at the contact's time
/// scale (measured: `f_1` = 1 Hz converges in 0.8 s, 0.1 Hz exhausts the step limit).
pub(crate) const MIN_FREQUENCY: f64 = 1e-2;
/// Largest accepted natural frequency, kHz (1 GHz).
pub(crate) const MAX_FREQUENCY: f64 = 1e6;
/// Smallest accepted quality factor: a mode damped a thousand times past critical (measured:
/// `Q_2` = 1e-6 still converges, in 2 s; 1e-9 exhausts the step limit).
pub(crate) const MIN_QUALITY: f64 = 1e-3;
/// Largest accepted quality factor.
pub(crate) const MAX_QUALITY: f64 = 1e6;
/// Largest accepted magnitude of an optical sensitivity or forcing ratio.
const MAX_RATIO: f64 = 1e3;

/// Convert a frequency in kHz to an angular frequency in rad/us: `w = 2 pi f / 1000`.
pub fn angular_frequency_rad_per_us(frequency_khz: f64) -> f64 {
    2.0 * std::f64::consts::PI * frequency_khz / 1000.0
}

/// The constants of eigenmode `i` in Eq. 1 (MODEL.md section 1):
/// `q_i'' / w_i^2 + q_i' / (w_i Q_i) + q_i = (F_i / k_i) cos(w t) + F_ts(d) / k_i`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Eigenmode {
    /// Equivalent modal stiffness `k_i` at the tip, N/m (= nN/nm); range [1e-6, 1e6].
    pub stiffness_n_per_m: f64,
    /// Natural frequency `f_i = w_i / 2 pi` (in liquid), kHz; range [1e-2, 1e6].
    pub frequency_khz: f64,
    /// Quality factor `Q_i`; any value in [1e-3, 1e6] (over-damped `Q_i <= 0.5` included).
    pub quality_factor: f64,
    /// Optical-lever sensitivity `chi_i` of the mode in the photodiode signal
    /// `u = sum_i chi_i q_i`; exactly 1 for mode 1, [-1000, 1000] otherwise.
    pub optical_sensitivity: f64,
    /// Forcing ratio `r_i = F_i / F_1` of the drive; exactly 1 for mode 1,
    /// [-1000, 1000] otherwise.
    pub force_ratio: f64,
}

impl Eigenmode {
    /// Natural angular frequency `w_i`, rad/us.
    pub fn angular_frequency(&self) -> f64 {
        angular_frequency_rad_per_us(self.frequency_khz)
    }

    /// Check every field's range; `index` is the 0-based position in `modes` (mode `index + 1`),
    /// used in the field path of the error (`modes[index].field`).
    pub fn validate(&self, file: &str, index: usize) -> Result<(), AfmError> {
        let field = |name: &str| format!("modes[{index}].{name}");
        check(
            file,
            &field("stiffness_n_per_m"),
            self.stiffness_n_per_m,
            Interval::closed(MIN_STIFFNESS, MAX_STIFFNESS, "N/m"),
        )?;
        check(
            file,
            &field("frequency_khz"),
            self.frequency_khz,
            Interval::closed(MIN_FREQUENCY, MAX_FREQUENCY, "kHz"),
        )?;
        check(
            file,
            &field("quality_factor"),
            self.quality_factor,
            Interval::closed(MIN_QUALITY, MAX_QUALITY, ""),
        )?;
        if index == 0 {
            for (name, value, meaning) in [
                (
                    "optical_sensitivity",
                    self.optical_sensitivity,
                    "chi_1 = 1 defines the units of u",
                ),
                ("force_ratio", self.force_ratio, "F_1 / F_1 = 1"),
            ] {
                if value != 1.0 {
                    return Err(invalid(
                        file,
                        &field(name),
                        value,
                        format!("exactly 1 for the first mode ({meaning})"),
                    ));
                }
            }
        } else {
            check(
                file,
                &field("optical_sensitivity"),
                self.optical_sensitivity,
                Interval::closed(-MAX_RATIO, MAX_RATIO, ""),
            )?;
            check(
                file,
                &field("force_ratio"),
                self.force_ratio,
                Interval::closed(-MAX_RATIO, MAX_RATIO, ""),
            )?;
        }
        Ok(())
    }
}
