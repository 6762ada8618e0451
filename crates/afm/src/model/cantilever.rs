//! A cantilever: tip geometry and material, and its eigenmodes (the constants of Eq. 1).

use serde::{Deserialize, Serialize};

use crate::error::AfmError;
use crate::model::eigenmode::Eigenmode;
use crate::validation::{
    check_all, check_name, gathered_warnings, invalid, ranges, FieldPath, NumericField,
};

/// The tip's Young's modulus the paper uses, GPa (its note 15).
pub const DEFAULT_TIP_YOUNGS_MODULUS_GPA: f64 = 130.0;
/// The Poisson ratio the paper uses for tip and sample (its note 15).
pub const DEFAULT_POISSON_RATIO: f64 = 0.3;

fn default_tip_youngs_modulus() -> f64 {
    DEFAULT_TIP_YOUNGS_MODULUS_GPA
}

fn default_poisson_ratio() -> f64 {
    DEFAULT_POISSON_RATIO
}

/// The most eigenmodes a cantilever may have (MODEL.md section 6): the cost of an orbit grows
/// steeply with `N` (100 modes: about 30 s for one `simulate`; 1000: minutes and 830 MB), and
/// as many as
/// `drumroll cantilever` tabulates (`beam::MAX_MODES`).
pub const MAX_MODES: usize = 50;

/// A cantilever with a spherical tip and N eigenmodes (MODEL.md sections 1 and 6).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Cantilever {
    /// Short name (the fixture's file stem, e.g. `biolever`); non-empty.
    pub name: String,
    /// Free-text description (maker, medium, source of the values); may be empty.
    #[serde(default)]
    pub description: String,
    /// Tip radius `R`, nm; range [0.1, 1e5], typical 1 to 1e4.
    pub tip_radius_nm: f64,
    /// Tip mass over cantilever mass `m_tip / m_c` (informational: the modal constants already
    /// account for it); range [0, 100].
    pub tip_mass_ratio: f64,
    /// Tip Young's modulus `E_t`, GPa; range [1e-7, 1e4], typical 1e-6 to 1500; default 130
    /// (the paper's note 15).
    #[serde(default = "default_tip_youngs_modulus")]
    pub tip_youngs_modulus_gpa: f64,
    /// Tip Poisson ratio `nu_t`; range (-1, 0.5]; default 0.3 (the paper's note 15).
    #[serde(default = "default_poisson_ratio")]
    pub tip_poisson_ratio: f64,
    /// The eigenmodes, fundamental first, natural frequencies strictly increasing; at least one.
    pub modes: Vec<Eigenmode>,
}

impl Cantilever {
    /// Check every field's range (errors name `file`, the field and the allowed range):
    /// non-empty modes, mode 1 with `chi_1 = 1` and `F_1/F_1 = 1`, frequencies strictly
    /// increasing, every `Q_i > 0`.
    pub fn validate(&self, file: &str) -> Result<(), AfmError> {
        check_name(file, "name", &self.name)?;
        check_all(file, &self.numeric_fields())?;
        if self.modes.is_empty() {
            return Err(AfmError::InvalidField {
                file: file.to_string(),
                field: "modes".to_string(),
                value: "[]".to_string(),
                allowed: "at least one eigenmode".to_string(),
            });
        }
        if self.modes.len() > MAX_MODES {
            return Err(AfmError::InvalidField {
                file: file.to_string(),
                field: "modes".to_string(),
                value: format!("a list of {} modes", self.modes.len()),
                allowed: format!(
                    "1 to {MAX_MODES} eigenmodes (the cost of an orbit grows steeply with N: \
                     100 modes take about 30 s for one orbit, 1000 minutes and 830 MB)"
                ),
            });
        }
        for (index, mode) in self.modes.iter().enumerate() {
            mode.validate(file, index)?;
        }
        for (index, pair) in self.modes.windows(2).enumerate() {
            if pair[1].frequency_khz <= pair[0].frequency_khz {
                return Err(invalid(
                    file,
                    &format!("modes[{}].frequency_khz", index + 1),
                    pair[1].frequency_khz,
                    format!(
                        "> modes[{index}].frequency_khz = {} kHz (natural frequencies strictly \
                         increasing)",
                        pair[0].frequency_khz
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The tip's numeric fields with their ranges ([`crate::validation::ranges`]).
    fn numeric_fields(&self) -> Vec<NumericField> {
        vec![
            (
                FieldPath::top("tip_radius_nm"),
                self.tip_radius_nm,
                ranges::TIP_RADIUS_NM,
            ),
            (
                FieldPath::top("tip_mass_ratio"),
                self.tip_mass_ratio,
                ranges::TIP_MASS_RATIO,
            ),
            (
                FieldPath::top("tip_youngs_modulus_gpa"),
                self.tip_youngs_modulus_gpa,
                ranges::YOUNGS_MODULUS_GPA,
            ),
            (
                FieldPath::top("tip_poisson_ratio"),
                self.tip_poisson_ratio,
                ranges::POISSON_RATIO,
            ),
        ]
    }

    /// The plausibility warnings of every field (valid values outside the range typical of
    /// AFM, with the likely unit mistake), naming `file` and the field.
    /// Warnings of one kind (the same field of several modes) are gathered into one line with
    /// their count and range of values.
    pub fn warnings(&self, file: &str) -> Vec<String> {
        let mut fields = self.numeric_fields();
        for (index, mode) in self.modes.iter().enumerate() {
            fields.extend(mode.numeric_fields(index));
        }
        gathered_warnings(file, &fields)
    }

    /// The drive frequencies the model accepts for this cantilever, kHz: from `f_1 / 100` (far
    /// below, a drive period holds so many free-flight steps that an orbit is out of reach) to
    /// 100 times the highest modal frequency (far above, N modes no longer describe the
    /// cantilever), within [`ranges::FREQUENCY_KHZ`].
    pub fn drive_frequency_range_khz(&self) -> (f64, f64) {
        let highest = self
            .modes
            .iter()
            .map(|m| m.frequency_khz)
            .fold(0.0, f64::max);
        (
            (0.01 * self.fundamental_frequency_khz()).max(ranges::FREQUENCY_KHZ.min),
            (100.0 * highest).min(ranges::FREQUENCY_KHZ.max),
        )
    }

    /// Number of eigenmodes N.
    pub fn mode_count(&self) -> usize {
        self.modes.len()
    }

    /// The fundamental natural frequency `f_1`, kHz (the default drive frequency).
    pub fn fundamental_frequency_khz(&self) -> f64 {
        self.modes
            .first()
            .map_or(f64::NAN, |mode| mode.frequency_khz)
    }
}
