//! A sample: an elastic half-space for Hertz contact (MODEL.md section 1).

use serde::{Deserialize, Serialize};

use crate::cantilever::DEFAULT_POISSON_RATIO;
use crate::contact::{ContactSpec, ElectrostaticSpec};
use crate::validation::{check, check_name, Interval};
use crate::AfmError;

fn default_poisson_ratio() -> f64 {
    DEFAULT_POISSON_RATIO
}

/// An elastic sample (MODEL.md sections 1 and 6).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sample {
    /// Short name (the fixture's file stem, e.g. `mica`); non-empty.
    pub name: String,
    /// Free-text description; may be empty.
    #[serde(default)]
    pub description: String,
    /// Young's modulus `E_s`, GPa; range (0, 1e4].
    pub youngs_modulus_gpa: f64,
    /// Poisson ratio `nu_s`; range (-1, 0.5]; default 0.3 (the paper's note 15).
    #[serde(default = "default_poisson_ratio")]
    pub poisson_ratio: f64,
    /// The contact law (MODEL.md section 9); absent: Hertz with a spherical tip.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact: Option<ContactSpec>,
    /// An electrostatic double layer added to the contact law (MODEL.md section 9); absent:
    /// none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub electrostatic: Option<ElectrostaticSpec>,
}

impl Sample {
    /// Check every field's range (errors name `file`, the field and the allowed range).
    pub fn validate(&self, file: &str) -> Result<(), AfmError> {
        check_name(file, "name", &self.name)?;
        check(
            file,
            "youngs_modulus_gpa",
            self.youngs_modulus_gpa,
            Interval::positive(1e4, "GPa"),
        )?;
        check(
            file,
            "poisson_ratio",
            self.poisson_ratio,
            Interval::left_open(-1.0, 0.5, ""),
        )?;
        if let Some(contact) = &self.contact {
            contact.validate(file)?;
        }
        if let Some(electrostatic) = &self.electrostatic {
            electrostatic.validate(file)?;
        }
        Ok(())
    }
}
