//! The electrostatic double-layer force between a charged sphere and a charged flat in an
//! electrolyte (MODEL.md section 9), added to any contact law.

use super::ForceSlopes;

/// The vacuum permittivity `eps_0`, F/m (CODATA 2018).
pub const VACUUM_PERMITTIVITY_F_PER_M: f64 = 8.854_187_812_8e-12;

/// The double layer `F = (4 pi R sigma_t sigma_s lambda_D / (eps_r eps_0)) exp(-d/lambda_D)`:
/// with `R`, `lambda_D` in nm and the charges in C/m^2 the prefactor is
/// `4 pi R sigma_t sigma_s lambda_D 1e-9 / (eps_r eps_0)` nN. Inside contact the model holds it
/// at its value on the contact surface ([`super::TipSampleForce`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DoubleLayer {
    /// The prefactor `F_dl(0)`, nN (positive: repulsive, like charges).
    pub amplitude_nn: f64,
    /// The Debye length `lambda_D`, nm.
    pub debye_length_nm: f64,
}

impl DoubleLayer {
    /// The double layer of a tip of radius `R` (nm) with surface charges `sigma_t`, `sigma_s`
    /// (C/m^2) in a medium of relative permittivity `eps_r` with Debye length `lambda_D` (nm).
    pub fn new(
        tip_radius_nm: f64,
        tip_charge_c_per_m2: f64,
        sample_charge_c_per_m2: f64,
        relative_permittivity: f64,
        debye_length_nm: f64,
    ) -> Self {
        let amplitude_nn = 4.0
            * std::f64::consts::PI
            * tip_radius_nm
            * tip_charge_c_per_m2
            * sample_charge_c_per_m2
            * debye_length_nm
            * 1e-9
            / (relative_permittivity * VACUUM_PERMITTIVITY_F_PER_M);
        Self {
            amplitude_nn,
            debye_length_nm,
        }
    }

    /// `F_dl(d)`, nN.
    pub fn force(&self, gap_nm: f64) -> f64 {
        self.amplitude_nn * (-gap_nm / self.debye_length_nm).exp()
    }

    /// `F_dl(d)` and `dF_dl/dd = -F_dl / lambda_D`.
    pub fn force_slopes(&self, gap_nm: f64) -> ForceSlopes {
        let force = self.force(gap_nm);
        ForceSlopes {
            force,
            gap_slope: -force / self.debye_length_nm,
            rate_slope: 0.0,
        }
    }

    /// The energy `U_dl(d) = int_d^inf F_dl dd' = lambda_D F_dl(d)`, nN nm (MODEL.md
    /// section 10).
    pub fn potential_nn_nm(&self, gap_nm: f64) -> f64 {
        self.debye_length_nm * self.force(gap_nm)
    }
}
