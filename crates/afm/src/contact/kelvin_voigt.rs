//! The Kelvin-Voigt viscoelastic law (MODEL.md section 9): Hertz with a viscous term in the
//! rate of the indentation's 3/2 power.

use super::ForceSlopes;

/// One Pa s in nN us / nm^2 (1 Pa = 1e-9 nN/nm^2, 1 s = 1e6 us).
pub const PASCAL_SECOND_IN_NN_US_PER_NM2: f64 = 1e-3;

/// Kelvin-Voigt contact of a sphere: with `s = -d` and `c = (4/3) E* sqrt(R)`,
/// `F = (4/3) sqrt(R) [E* s^{3/2} + eta* d(s^{3/2})/dt] = c s^{1/2} (s + tau s')`,
/// `tau = 1.5 eta* / E*`, `eta* = eta / (1 - nu_s^2)`. Clipped (the default), the force is
/// zero where this is negative: the surface `h_1 = s + tau s' = -d - tau d' = 0` inside
/// contact is then a switching surface. Unclipped, the law pulls the tip when the sample
/// recedes faster than `s / tau` (a tensile artefact: a purely viscoelastic sample does not
/// stick).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KelvinVoigtContact {
    /// The reduced modulus `E*`, GPa.
    pub effective_modulus_gpa: f64,
    /// The tip radius `R`, nm.
    pub tip_radius_nm: f64,
    /// The reduced viscosity `eta* = eta / (1 - nu_s^2)`, Pa s.
    pub effective_viscosity_pa_s: f64,
    /// Whether the force is clipped at zero.
    pub clip: bool,
}

impl KelvinVoigtContact {
    /// `tau = 1.5 eta* / E*`, us (`eta*` converted to nN us/nm^2, `E*` in nN/nm^2).
    pub fn release_time_us(&self) -> f64 {
        1.5 * self.effective_viscosity_pa_s * PASCAL_SECOND_IN_NN_US_PER_NM2
            / self.effective_modulus_gpa
    }

    /// The unclipped force `F = c s^{1/2} (s + tau s')` (nN) at gap `d` (nm) and rate `d'`
    /// (nm/us), `s = max(-d, 0)`, with `dF/dd = -c s^{-1/2} (1.5 s + 0.5 tau s')` and
    /// `dF/dd' = -c tau s^{1/2}`. At `s = 0` the slope in `d` is infinite for `s' != 0`
    /// (the force grows as `s^{1/2}`); it is returned as 0 there, where the solver's
    /// square-root clock multiplies it by a vanishing rate.
    pub fn force_slopes(&self, gap_nm: f64, gap_rate: f64) -> ForceSlopes {
        let c = 4.0 / 3.0 * self.effective_modulus_gpa * self.tip_radius_nm.sqrt();
        let tau = self.release_time_us();
        let s = (-gap_nm).max(0.0);
        let root = s.sqrt();
        let s_rate = -gap_rate;
        let gap_slope = if root > 0.0 {
            -c * (1.5 * s + 0.5 * tau * s_rate) / root
        } else {
            0.0
        };
        ForceSlopes {
            force: c * root * (s + tau * s_rate),
            gap_slope,
            rate_slope: -c * tau * root,
        }
    }
}
