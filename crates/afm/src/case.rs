//! A simulation case: a cantilever, a sample, the free amplitude and the drive frequency.

use serde::{Deserialize, Serialize};

use crate::eigenmode::{MAX_FREQUENCY, MIN_FREQUENCY};
use crate::validation::{check, check_name, Interval};
use crate::{AfmError, Cantilever, Sample};

/// Largest accepted free amplitude, nm.
const MAX_FREE_AMPLITUDE_NM: f64 = 1e5;

/// A case file as written on disk (`fixtures/cases/*.json`): the cantilever and the sample are
/// referenced by name (a built-in fixture) or by a path ending in `.json` (relative to the case
/// file's directory).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseFile {
    /// Short name (the fixture's file stem, e.g. `biolever-mica`); non-empty.
    pub name: String,
    /// Free-text description; may be empty.
    #[serde(default)]
    pub description: String,
    /// A built-in cantilever name (e.g. `biolever`) or a path to a cantilever JSON file.
    pub cantilever: String,
    /// A built-in sample name (e.g. `mica`) or a path to a sample JSON file.
    pub sample: String,
    /// The free amplitude `A0`: first-harmonic amplitude of `u` with `F_ts = 0`, nm;
    /// range (0, 1e5] (MODEL.md section 3).
    pub free_amplitude_nm: f64,
    /// The drive frequency `f = w / 2 pi`, kHz; range [1e-2, 1e6] (as a natural frequency's);
    /// absent: `f_1` (the paper's `w = w_1`, MODEL.md section 3).
    #[serde(default)]
    pub drive_frequency_khz: Option<f64>,
}

impl CaseFile {
    /// Check every field's range (errors name `file`, the field and the allowed range).
    pub fn validate(&self, file: &str) -> Result<(), AfmError> {
        check_name(file, "name", &self.name)?;
        check_name(file, "cantilever", &self.cantilever)?;
        check_name(file, "sample", &self.sample)?;
        check_case_numbers(file, self.free_amplitude_nm, self.drive_frequency_khz)
    }
}

pub(crate) fn check_case_numbers(
    file: &str,
    free_amplitude_nm: f64,
    drive_frequency_khz: Option<f64>,
) -> Result<(), AfmError> {
    check(
        file,
        "free_amplitude_nm",
        free_amplitude_nm,
        Interval::positive(MAX_FREE_AMPLITUDE_NM, "nm"),
    )?;
    if let Some(frequency) = drive_frequency_khz {
        check(
            file,
            "drive_frequency_khz",
            frequency,
            Interval::closed(MIN_FREQUENCY, MAX_FREQUENCY, "kHz"),
        )?;
    }
    Ok(())
}

/// A resolved case: everything [`crate::TappingModel::from_case`] needs.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    /// Short name, e.g. `biolever-mica`.
    pub name: String,
    /// Free-text description.
    pub description: String,
    /// The cantilever.
    pub cantilever: Cantilever,
    /// The sample.
    pub sample: Sample,
    /// The free amplitude `A0` of `u`, nm (MODEL.md section 3).
    pub free_amplitude_nm: f64,
    /// The drive frequency, kHz; `None` means the fundamental `f_1`.
    pub drive_frequency_khz: Option<f64>,
}

impl Case {
    /// The drive frequency actually used, kHz: the case's value, or `f_1` when absent.
    pub fn drive_frequency_or_fundamental_khz(&self) -> f64 {
        self.drive_frequency_khz
            .unwrap_or_else(|| self.cantilever.fundamental_frequency_khz())
    }

    /// Check every field (the cantilever's and the sample's included); `file` names the source
    /// in errors.
    pub fn validate(&self, file: &str) -> Result<(), AfmError> {
        check_name(file, "name", &self.name)?;
        self.cantilever.validate(file)?;
        self.sample.validate(file)?;
        check_case_numbers(file, self.free_amplitude_nm, self.drive_frequency_khz)
    }
}
