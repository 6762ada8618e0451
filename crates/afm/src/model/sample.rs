//! A sample: an elastic half-space for Hertz contact (MODEL.md section 1).

use serde::{Deserialize, Serialize};

use crate::contact::{ContactSpec, ElectrostaticSpec, HydrationSpec};
use crate::error::AfmError;
use crate::model::cantilever::DEFAULT_POISSON_RATIO;
use crate::validation::{check_all, check_name, ranges, warnings_of, FieldPath, NumericField};

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
    /// Young's modulus `E_s`, GPa; range [1e-7, 1e4], typical 1e-6 to 1500.
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
    /// A hydration (solvation) force added to the contact law (MODEL.md section 9); absent:
    /// none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hydration: Option<HydrationSpec>,
}

impl Sample {
    fn numeric_fields(&self) -> Vec<NumericField> {
        vec![
            (
                FieldPath::top("youngs_modulus_gpa"),
                self.youngs_modulus_gpa,
                ranges::YOUNGS_MODULUS_GPA,
            ),
            (
                FieldPath::top("poisson_ratio"),
                self.poisson_ratio,
                ranges::POISSON_RATIO,
            ),
        ]
    }

    /// The plausibility warnings of every field, naming `file` and the field.
    pub fn warnings(&self, file: &str) -> Vec<String> {
        warnings_of(file, &self.numeric_fields())
    }

    /// Check every field's range (errors name `file`, the field and the allowed range).
    pub fn validate(&self, file: &str) -> Result<(), AfmError> {
        check_name(file, "name", &self.name)?;
        check_all(file, &self.numeric_fields())?;
        if let Some(contact) = &self.contact {
            contact.validate(file)?;
        }
        if let Some(electrostatic) = &self.electrostatic {
            electrostatic.validate(file)?;
        }
        if let Some(hydration) = &self.hydration {
            hydration.validate(file)?;
        }
        Ok(())
    }
}
