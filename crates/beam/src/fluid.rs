//! The fluid a cantilever vibrates in: its density and dynamic viscosity, the two numbers
//! Sader's hydrodynamic function needs ([`crate::hydrodynamic`]).

use serde::{Deserialize, Serialize};

use crate::error::BeamError;

/// The accepted fluid densities, kg/m^3: from a rarefied gas (0.01, a hundredth of air at sea
/// level) to the densest liquids (mercury, 13 534).
pub const FLUID_DENSITY_RANGE_KG_M3: (f64, f64) = (0.01, 20_000.0);
/// The accepted dynamic viscosities, Pa s: from hydrogen (8.9e-6) with margin to glycerol
/// (1.4) with margin.
pub const FLUID_VISCOSITY_RANGE_PA_S: (f64, f64) = (1e-6, 10.0);

/// A Newtonian, incompressible fluid (Sader 1998's assumptions).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fluid {
    /// Short name (e.g. `water`).
    pub name: String,
    /// Density `rho`, kg/m^3, in [`FLUID_DENSITY_RANGE_KG_M3`].
    pub density_kg_m3: f64,
    /// Dynamic viscosity `eta`, Pa s, in [`FLUID_VISCOSITY_RANGE_PA_S`].
    pub viscosity_pa_s: f64,
}

impl Fluid {
    /// Water at 20 C: `rho = 998.2 kg/m^3`, `eta = 1.002e-3 Pa s` (CRC Handbook of Chemistry and
    /// Physics, "Properties of water in the range 0-100 C").
    #[must_use]
    pub fn water() -> Self {
        Self {
            name: String::from("water"),
            density_kg_m3: 998.2,
            viscosity_pa_s: 1.002e-3,
        }
    }

    /// Air at about 20 C and sea level: `rho = 1.18 kg/m^3`, `eta = 1.86e-5 Pa s`, the values of
    /// Sader, Chon & Mulvaney, Rev. Sci. Instrum. 70, 3967 (1999).
    #[must_use]
    pub fn air() -> Self {
        Self {
            name: String::from("air"),
            density_kg_m3: 1.18,
            viscosity_pa_s: 1.86e-5,
        }
    }

    /// The built-in fluid called `name` (`water`, `air`), or `None`.
    #[must_use]
    pub fn builtin(name: &str) -> Option<Self> {
        match name {
            "water" => Some(Self::water()),
            "air" => Some(Self::air()),
            _ => None,
        }
    }

    /// Check both numbers against their ranges.
    ///
    /// # Errors
    /// [`BeamError::FieldOutOfRange`] naming the field, its value and the range.
    pub fn validate(&self) -> Result<(), BeamError> {
        check_range(
            "density_kg_m3",
            self.density_kg_m3,
            FLUID_DENSITY_RANGE_KG_M3,
        )?;
        check_range(
            "viscosity_pa_s",
            self.viscosity_pa_s,
            FLUID_VISCOSITY_RANGE_PA_S,
        )
    }
}

/// `Ok` when `value` is finite and in `[range.0, range.1]`, else
/// [`BeamError::FieldOutOfRange`] naming `field`.
pub(crate) fn check_range(
    field: &'static str,
    value: f64,
    range: (f64, f64),
) -> Result<(), BeamError> {
    if value.is_finite() && (range.0..=range.1).contains(&value) {
        Ok(())
    } else {
        Err(BeamError::FieldOutOfRange {
            field,
            value,
            min: range.0,
            max: range.1,
        })
    }
}
