//! One flexural eigenmode of the cantilever: the constants of one line of Eq. 1.

use serde::{Deserialize, Serialize};

use crate::error::AfmError;
use crate::validation::{check_all, invalid, ranges, warnings_of, FieldPath, NumericField};

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

    /// The numeric fields with their ranges ([`crate::validation::ranges`]), as paths
    /// `modes[index].field` (`index` 0-based: mode `index + 1`). Mode 1's ratios are fixed to 1
    /// and checked apart.
    pub(crate) fn numeric_fields(&self, index: usize) -> Vec<NumericField> {
        let field = |name| FieldPath::entry("modes", index, name);
        let mut fields = vec![
            (
                field("stiffness_n_per_m"),
                self.stiffness_n_per_m,
                ranges::STIFFNESS_N_PER_M,
            ),
            (
                field("frequency_khz"),
                self.frequency_khz,
                ranges::FREQUENCY_KHZ,
            ),
            (
                field("quality_factor"),
                self.quality_factor,
                ranges::QUALITY_FACTOR,
            ),
        ];
        if index > 0 {
            fields.push((
                field("optical_sensitivity"),
                self.optical_sensitivity,
                ranges::MODE_RATIO,
            ));
            fields.push((field("force_ratio"), self.force_ratio, ranges::MODE_RATIO));
        }
        fields
    }

    /// The plausibility warnings of the mode's fields (see [`Self::numeric_fields`]).
    pub fn warnings(&self, file: &str, index: usize) -> Vec<String> {
        warnings_of(file, &self.numeric_fields(index))
    }

    /// Check every field's range; `index` is the 0-based position in `modes` (mode `index + 1`),
    /// used in the field path of the error (`modes[index].field`).
    pub fn validate(&self, file: &str, index: usize) -> Result<(), AfmError> {
        let field = |name: &str| format!("modes[{index}].{name}");
        check_all(file, &self.numeric_fields(index))?;
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
        }
        Ok(())
    }
}
