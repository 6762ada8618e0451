//! The case file's `drive` object (MODEL.md sections 3 and 14): which excitation drives the
//! cantilever. `direct` (the default: a force on the beam, magnetic or photothermal),
//! `acoustic` (the base moves, `y_base = Y cos(w t)`), or `bimodal` (a direct drive at a second,
//! commensurate frequency added to the first).

use serde::{Deserialize, Serialize};

use crate::error::AfmError;
use crate::model::cantilever::Cantilever;
use crate::model::commensurate::{commensurate_ratio, nearest_ratios, Ratio, MAX_DENOMINATOR};
use crate::validation::{check, invalid, ranges, Interval};

/// The allowed second free amplitude `A0_b` of a bimodal drive, nm (0 switches it off).
pub const SECOND_FREE_AMPLITUDE_NM: Interval = Interval::closed(0.0, 1e5, "nm");

/// The excitation of a case (`"drive": {"kind": ...}` in a case file; absent: `direct`).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum DriveSpec {
    /// A force `F_i cos(w t)` on each mode, `F_i = r_i F_1` with the cantilever's forcing ratios
    /// (magnetic or photothermal excitation; MODEL.md section 3).
    #[default]
    Direct,
    /// The base moves as `y_base(t) = Y cos(w t)` (nm), loading mode `i` with the inertial force
    /// `k_i gamma_i (w / w_i)^2 Y cos(w t)` and shifting the gap by `y_base` (MODEL.md
    /// section 14). `Y` is solved from `A0`.
    Acoustic {
        /// The participation factors `gamma_i` of base motion, one per mode (MODEL.md section
        /// 14), each in [-1000, 1000], `gamma_1 != 0`; absent: the Euler-Bernoulli beam's
        /// `(int phi_i + mu) / (int phi_i^2 + mu)` at the cantilever's `tip_mass_ratio` `mu`
        /// (1.566 and -0.868 for the first two modes at `mu = 0`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        base_participation: Option<Vec<f64>>,
    },
    /// A second direct drive `r_i F_1b cos(w_b t)` added to the first, at a frequency whose ratio
    /// to the first is a fraction `p / q` with `q <= 16` (MODEL.md section 14).
    Bimodal {
        /// The second drive's frequency `f_b`, kHz; in the cantilever's drive range, with
        /// `f_b / f = p / q` (lowest terms, `q <= 16`) to a relative 1e-9.
        second_frequency_khz: f64,
        /// The second drive's free amplitude `A0_b`: the amplitude of `u` at `f_b` without the
        /// sample, nm; range [0, 1e5] (0: the single drive).
        second_free_amplitude_nm: f64,
    },
}

impl DriveSpec {
    /// The drive's name in outputs: `direct`, `acoustic` or `bimodal`.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::Direct => "direct",
            Self::Acoustic { .. } => "acoustic",
            Self::Bimodal { .. } => "bimodal",
        }
    }

    /// Check the drive against `cantilever` and the first drive frequency
    /// `drive_frequency_khz` (errors name `file`, the field `drive.…` and the allowed range;
    /// an incommensurate bimodal ratio names the nearest commensurate frequencies).
    pub fn validate(
        &self,
        file: &str,
        cantilever: &Cantilever,
        drive_frequency_khz: f64,
    ) -> Result<(), AfmError> {
        match self {
            Self::Direct => Ok(()),
            Self::Acoustic { base_participation } => {
                if let Some(factors) = base_participation {
                    check_participation(file, cantilever, factors)?;
                }
                Ok(())
            }
            Self::Bimodal {
                second_frequency_khz,
                second_free_amplitude_nm,
            } => {
                check(
                    file,
                    "drive.second_free_amplitude_nm",
                    *second_free_amplitude_nm,
                    SECOND_FREE_AMPLITUDE_NM,
                )?;
                check(
                    file,
                    "drive.second_frequency_khz",
                    *second_frequency_khz,
                    ranges::FREQUENCY_KHZ,
                )?;
                let (lowest, highest) = cantilever.drive_frequency_range_khz();
                if !(lowest..=highest).contains(second_frequency_khz) {
                    return Err(invalid(
                        file,
                        "drive.second_frequency_khz",
                        *second_frequency_khz,
                        format!(
                            "[{lowest:.6}, {highest:.6}] kHz for this cantilever (from f_1/100 \
                             to 100 times its highest modal frequency)"
                        ),
                    ));
                }
                bimodal_ratio(file, drive_frequency_khz, *second_frequency_khz).map(|_| ())
            }
        }
    }
}

/// The ratio `f_b / f = p / q` of a bimodal drive, or the error naming `file`, the field
/// `drive.second_frequency_khz` and the nearest commensurate frequencies. The ratio 1/1 is
/// refused too: a second drive at the first's frequency is one drive of another amplitude, and
/// neither `A0` nor `A0_b` would be the free amplitude at its frequency (MODEL.md section 14).
pub fn bimodal_ratio(
    file: &str,
    drive_frequency_khz: f64,
    second_frequency_khz: f64,
) -> Result<Ratio, AfmError> {
    let ratio = second_frequency_khz / drive_frequency_khz;
    if let Some(Ratio {
        numerator: 1,
        denominator: 1,
    }) = commensurate_ratio(ratio)
    {
        return Err(invalid(
            file,
            "drive.second_frequency_khz",
            second_frequency_khz,
            format!(
                "a frequency other than the drive's {} kHz (the same frequency is one drive: \
                 set free_amplitude_nm to the sum instead)",
                crate::validation::format_number(drive_frequency_khz)
            ),
        ));
    }
    commensurate_ratio(ratio).ok_or_else(|| {
        let choices: Vec<String> = nearest_ratios(ratio, 3)
            .iter()
            .map(|r| {
                format!(
                    "{} kHz (ratio {}/{})",
                    crate::validation::format_number(drive_frequency_khz * r.value()),
                    r.numerator,
                    r.denominator
                )
            })
            .collect();
        invalid(
            file,
            "drive.second_frequency_khz",
            second_frequency_khz,
            format!(
                "a frequency commensurate with the drive's {} kHz (ratio p/q with q <= \
                 {MAX_DENOMINATOR}, to 1e-9); the nearest: {}",
                crate::validation::format_number(drive_frequency_khz),
                choices.join(", ")
            ),
        )
    })
}

/// Check an acoustic drive's participation factors: one per mode, each in [-1000, 1000], the
/// first nonzero.
fn check_participation(
    file: &str,
    cantilever: &Cantilever,
    factors: &[f64],
) -> Result<(), AfmError> {
    if factors.len() != cantilever.mode_count() {
        return Err(AfmError::InvalidField {
            file: file.to_string(),
            field: "drive.base_participation".to_string(),
            value: format!("{} values", factors.len()),
            allowed: format!(
                "one factor per mode of the cantilever ({} modes)",
                cantilever.mode_count()
            ),
        });
    }
    for (index, &factor) in factors.iter().enumerate() {
        check(
            file,
            &format!("drive.base_participation[{index}]"),
            factor,
            ranges::MODE_RATIO,
        )?;
    }
    if factors[0] == 0.0 {
        return Err(invalid(
            file,
            "drive.base_participation[0]",
            0.0,
            "a nonzero gamma_1 in [-1000, 1000] (with gamma_1 = 0 the base does not drive mode 1)"
                .to_string(),
        ));
    }
    Ok(())
}
