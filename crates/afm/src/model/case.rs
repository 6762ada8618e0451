//! A simulation case: a cantilever, a sample, the free amplitude and the drive frequency.

use serde::{Deserialize, Serialize};

use crate::error::AfmError;
use crate::model::cantilever::Cantilever;
use crate::model::drive_spec::DriveSpec;
use crate::model::sample::Sample;
use crate::validation::{check_all, check_name, ranges, warnings_of, FieldPath, NumericField};

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
    /// range [1e-3, 1e5], typical 0.1 to 1000 (MODEL.md section 3).
    pub free_amplitude_nm: f64,
    /// The drive frequency `f = w / 2 pi`, kHz; range [1e-2, 1e6] (as a natural frequency's,
    /// and within the cantilever's [`Cantilever::drive_frequency_range_khz`]);
    /// absent: `f_1` (the paper's `w = w_1`, MODEL.md section 3).
    #[serde(default)]
    pub drive_frequency_khz: Option<f64>,
    /// The excitation (`{"kind": "direct" | "acoustic" | "bimodal", ...}`, MODEL.md section
    /// 14); absent: `direct`.
    #[serde(default, skip_serializing_if = "is_direct")]
    pub drive: DriveSpec,
}

/// Whether `drive` is the default direct drive (left out of a written case file).
fn is_direct(drive: &DriveSpec) -> bool {
    *drive == DriveSpec::Direct
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

/// The numeric fields of a case with their ranges.
fn case_fields(free_amplitude_nm: f64, drive_frequency_khz: Option<f64>) -> Vec<NumericField> {
    let mut fields = vec![(
        FieldPath::top("free_amplitude_nm"),
        free_amplitude_nm,
        ranges::FREE_AMPLITUDE_NM,
    )];
    if let Some(frequency) = drive_frequency_khz {
        fields.push((
            FieldPath::top("drive_frequency_khz"),
            frequency,
            ranges::FREQUENCY_KHZ,
        ));
    }
    fields
}

/// Check the free amplitude and the drive frequency of a case (errors name `file`).
pub(crate) fn check_case_numbers(
    file: &str,
    free_amplitude_nm: f64,
    drive_frequency_khz: Option<f64>,
) -> Result<(), AfmError> {
    check_all(file, &case_fields(free_amplitude_nm, drive_frequency_khz))
}

/// A resolved case: everything [`crate::model::TappingModel::from_case`] needs.
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
    /// The excitation: direct (default), acoustic or bimodal (MODEL.md section 14).
    pub drive: DriveSpec,
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
        check_case_numbers(file, self.free_amplitude_nm, self.drive_frequency_khz)?;
        if let Some(frequency) = self.drive_frequency_khz {
            let (lowest, highest) = self.cantilever.drive_frequency_range_khz();
            if !(lowest..=highest).contains(&frequency) {
                return Err(crate::validation::invalid(
                    file,
                    "drive_frequency_khz",
                    frequency,
                    format!(
                        "[{lowest:.6}, {highest:.6}] kHz for this cantilever (from f_1/100 to \
                         100 times its highest modal frequency)"
                    ),
                ));
            }
        }
        self.drive.validate(
            file,
            &self.cantilever,
            self.drive_frequency_or_fundamental_khz(),
        )
    }

    /// The plausibility warnings of every field (the cantilever's and the sample's included):
    /// valid values outside the range typical of AFM, with the likely unit mistake, and a
    /// drive more than ten times away from every natural frequency.
    pub fn warnings(&self, file: &str) -> Vec<String> {
        let mut warnings = self.cantilever.warnings(file);
        warnings.extend(self.sample.warnings(file));
        warnings.extend(warnings_of(
            file,
            &case_fields(self.free_amplitude_nm, self.drive_frequency_khz),
        ));
        if let Some(warning) = self.drive_warning() {
            warnings.push(format!("{file}: field `drive_frequency_khz`: {warning}"));
        }
        warnings
    }

    /// The warning for a drive frequency more than ten times away from every natural
    /// frequency of the cantilever (allowed, but not tapping-mode AFM), with the likely unit
    /// mistake when Hz or MHz would put it within a factor 2 of `f_1`; `None` for a drive near
    /// a mode or at `f_1` by default.
    pub fn drive_warning(&self) -> Option<String> {
        let frequency = self.drive_frequency_khz?;
        let nearest = self
            .cantilever
            .modes
            .iter()
            .map(|mode| (frequency / mode.frequency_khz).ln().abs())
            .fold(f64::INFINITY, f64::min);
        if nearest <= 10f64.ln() {
            return None;
        }
        let f1 = self.cantilever.fundamental_frequency_khz();
        let hint = [(1e-3, "Hz"), (1e3, "MHz")]
            .iter()
            .find(|(factor, _)| {
                let scaled = frequency * factor;
                scaled >= 0.5 * f1 && scaled <= 2.0 * f1
            })
            .map_or_else(String::new, |(factor, unit)| {
                let typed = crate::validation::format_number(frequency);
                format!(
                    "; {typed} looks like a value in {unit}: {typed} {unit} = {} kHz",
                    crate::validation::format_number(frequency * factor)
                )
            });
        Some(format!(
            "{frequency} kHz is more than ten times away from every natural frequency of the \
             cantilever (f_1 = {f1} kHz){hint}"
        ))
    }
}
