//! The hydration (solvation) force of ordered water layers between the tip sphere and the
//! sample (MODEL.md section 9, "Hydration force"), added to any contact law.

use std::f64::consts::PI;

use super::ForceSlopes;

/// One MPa in nN/nm^2 (1 Pa = 1e-9 nN/nm^2).
pub const MEGAPASCAL_IN_NN_PER_NM2: f64 = 1e-3;

/// The oscillatory solvation pressure between flat surfaces at distance `D`,
/// `P(D) = P_0 cos(2 pi D / sigma) exp(-D / lambda)` (Israelachvili, *Intermolecular and
/// Surface Forces*, 3rd ed., section 15.2, with a decay length `lambda` of its own), on the tip
/// sphere by the Derjaguin approximation `F = 2 pi R W(d)`, `W(d) = int_d^inf P dD`:
///
/// `F_h(d) = 2 pi R P_0 lambda exp(-d/lambda) [cos(k d) - k lambda sin(k d)] / (1 + (k lambda)^2)`,
/// `k = 2 pi / sigma` (nN for `R`, `d`, `sigma`, `lambda` in nm and `P_0` in nN/nm^2).
/// Inside contact the model holds it at its value on the contact surface, as the double layer
/// ([`super::TipSampleForce`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HydrationForce {
    /// `2 pi R P_0 lambda / (1 + (k lambda)^2)`, nN.
    pub amplitude_nn: f64,
    /// The layer spacing `sigma`, nm.
    pub layer_spacing_nm: f64,
    /// The decay length `lambda`, nm.
    pub decay_length_nm: f64,
}

impl HydrationForce {
    /// The force on a tip of radius `R` (nm) of the pressure amplitude `P_0` (MPa, positive:
    /// repulsive at contact), layer spacing `sigma` (nm) and decay length `lambda` (nm).
    pub fn new(
        tip_radius_nm: f64,
        pressure_mpa: f64,
        layer_spacing_nm: f64,
        decay_length_nm: f64,
    ) -> Self {
        let k_lambda = 2.0 * PI / layer_spacing_nm * decay_length_nm;
        Self {
            amplitude_nn: 2.0
                * PI
                * tip_radius_nm
                * pressure_mpa
                * MEGAPASCAL_IN_NN_PER_NM2
                * decay_length_nm
                / (1.0 + k_lambda * k_lambda),
            layer_spacing_nm,
            decay_length_nm,
        }
    }

    /// `F_h(d)`, nN.
    pub fn force(&self, gap_nm: f64) -> f64 {
        self.force_slopes(gap_nm).force
    }

    /// `F_h(d)` and `dF_h/dd = -2 pi R P(d) = -A (1/lambda + k^2 lambda) exp(-d/lambda)
    /// cos(k d)` (`A` = [`HydrationForce::amplitude_nn`]).
    pub fn force_slopes(&self, gap_nm: f64) -> ForceSlopes {
        let k = 2.0 * PI / self.layer_spacing_nm;
        let lambda = self.decay_length_nm;
        let decay = self.amplitude_nn * (-gap_nm / lambda).exp();
        let (sin, cos) = (k * gap_nm).sin_cos();
        ForceSlopes {
            force: decay * (cos - k * lambda * sin),
            gap_slope: -decay * (1.0 / lambda + k * k * lambda) * cos,
            rate_slope: 0.0,
        }
    }

    /// The energy `U_h(d) = int_d^inf F_h dd'`, nN nm (MODEL.md section 10):
    /// `A exp(-d/lambda) [(1/lambda - k^2 lambda) cos(k d) - 2 k sin(k d)] / (1/lambda^2 + k^2)`.
    pub fn potential_nn_nm(&self, gap_nm: f64) -> f64 {
        let k = 2.0 * PI / self.layer_spacing_nm;
        let lambda = self.decay_length_nm;
        let decay = self.amplitude_nn * (-gap_nm / lambda).exp();
        let (sin, cos) = (k * gap_nm).sin_cos();
        decay * ((1.0 / lambda - k * k * lambda) * cos - 2.0 * k * sin)
            / (1.0 / (lambda * lambda) + k * k)
    }
}
