//! A cantilever: tip geometry and material, and its eigenmodes (the constants of Eq. 1).

use serde::{Deserialize, Serialize};

use crate::validation::{check, check_name, invalid, Interval};
use crate::{AfmError, Eigenmode};

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

/// A cantilever with a spherical tip and N eigenmodes (MODEL.md sections 1 and 6).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Cantilever {
    /// Short name (the fixture's file stem, e.g. `biolever`); non-empty.
    pub name: String,
    /// Free-text description (maker, medium, source of the values); may be empty.
    #[serde(default)]
    pub description: String,
    /// Tip radius `R`, nm; range (0, 1e5].
    pub tip_radius_nm: f64,
    /// Tip mass over cantilever mass `m_tip / m_c` (informational: the modal constants already
    /// account for it); range [0, 100].
    pub tip_mass_ratio: f64,
    /// Tip Young's modulus `E_t`, GPa; range (0, 1e4]; default 130 (the paper's note 15).
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
        check(
            file,
            "tip_radius_nm",
            self.tip_radius_nm,
            Interval::positive(1e5, "nm"),
        )?;
        check(
            file,
            "tip_mass_ratio",
            self.tip_mass_ratio,
            Interval::closed(0.0, 100.0, ""),
        )?;
        check(
            file,
            "tip_youngs_modulus_gpa",
            self.tip_youngs_modulus_gpa,
            Interval::positive(1e4, "GPa"),
        )?;
        check(
            file,
            "tip_poisson_ratio",
            self.tip_poisson_ratio,
            Interval::left_open(-1.0, 0.5, ""),
        )?;
        if self.modes.is_empty() {
            return Err(AfmError::InvalidField {
                file: file.to_string(),
                field: "modes".to_string(),
                value: "[]".to_string(),
                allowed: "at least one eigenmode".to_string(),
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
