//! The capillary meniscus in air (MODEL.md section 9 "Capillary meniscus"): a water bridge
//! that condenses when the tip touches the sample and ruptures at a larger gap, pulling with
//! the Laplace force of a sphere on a flat (Israelachvili, *Intermolecular and Surface Forces*,
//! 3rd ed., Academic Press 2011, sec. 17.7, Eqs. 17.19 and 17.21), on top of Hertz contact.

use std::f64::consts::PI;

use super::{ForceSlopes, HertzShape};

/// The gas constant, J/(mol K).
pub const GAS_CONSTANT_J_PER_MOL_K: f64 = 8.314_462_618;

/// Hertz contact of a sphere plus a meniscus force: while the meniscus exists (from contact,
/// `d = 0` on approach, to its rupture at `d = d_r` on retract) the force is
/// `F = F_Hertz(d) - F_m` with `F_m = 4 pi R gamma cos(theta)` (nN; `R` nm, `gamma` nN/nm);
/// without it, zero. The rupture gap is the height of a Kelvin meniscus between the tip and
/// the sample, `d_r = 2 r_K cos(theta)`, with the Kelvin radius
/// `r_K = gamma V_m / (R_g T ln(1/RH))` (nm): capillary condensation fills gaps below `d_r`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CapillaryContact {
    /// The Hertz sphere inside contact.
    pub hertz: HertzShape,
    /// The meniscus force `F_m = 4 pi R gamma cos(theta)`, nN (attractive).
    pub meniscus_force_nn: f64,
    /// The rupture gap `d_r = 2 r_K cos(theta)`, nm.
    pub rupture_gap_nm: f64,
}

impl CapillaryContact {
    /// The law for tip radius `R` (nm), relative humidity `RH` (0 to 1, exclusive), surface
    /// tension `gamma` (mN/m = 1e-3 nN/nm), contact angle `theta` (deg, the same on tip and
    /// sample), temperature `T` (K) and the liquid's molar volume `V_m` (m^3/mol).
    pub fn new(
        hertz: HertzShape,
        tip_radius_nm: f64,
        relative_humidity: f64,
        surface_tension_mn_per_m: f64,
        contact_angle_deg: f64,
        temperature_k: f64,
        molar_volume_m3_per_mol: f64,
    ) -> Self {
        let gamma = surface_tension_mn_per_m * 1e-3;
        let cos = contact_angle_deg.to_radians().cos();
        Self {
            hertz,
            meniscus_force_nn: 4.0 * PI * tip_radius_nm * gamma * cos,
            rupture_gap_nm: 2.0
                * kelvin_radius_nm(
                    relative_humidity,
                    surface_tension_mn_per_m,
                    temperature_k,
                    molar_volume_m3_per_mol,
                )
                * cos,
        }
    }

    /// The energy the meniscus takes from the cantilever per formation, `E_m = F_m d_r` (nN nm):
    /// the area of its force loop, `-F_m` from `d = 0` to `d_r` on the way out only (MODEL.md
    /// section 9, "Capillary meniscus").
    pub fn loop_area_nn_nm(&self) -> f64 {
        self.meniscus_force_nn * self.rupture_gap_nm
    }

    /// The force and slope while the meniscus exists: Hertz inside contact (`inside`, `d < 0`)
    /// minus `F_m`; outside contact `-F_m` with zero slope.
    pub fn attached(&self, inside: bool, gap_nm: f64) -> ForceSlopes {
        let mut total = if inside {
            self.hertz.force_slopes(gap_nm)
        } else {
            ForceSlopes::ZERO
        };
        total.force -= self.meniscus_force_nn;
        total
    }
}

/// The Kelvin radius `r_K = gamma V_m / (R_g T ln(1/RH))`, nm, for surface tension `gamma`
/// (mN/m), temperature `T` (K), molar volume `V_m` (m^3/mol) and relative humidity `RH`
/// (Israelachvili 2011, Eq. 17.19; 0.54 nm / ln(1/RH) for water at 20 C).
pub fn kelvin_radius_nm(
    relative_humidity: f64,
    surface_tension_mn_per_m: f64,
    temperature_k: f64,
    molar_volume_m3_per_mol: f64,
) -> f64 {
    let gamma = surface_tension_mn_per_m * 1e-3; // N/m
    let metres = gamma * molar_volume_m3_per_mol
        / (GAS_CONSTANT_J_PER_MOL_K * temperature_k * (1.0 / relative_humidity).ln());
    metres * 1e9
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::HertzTip;

    /// Israelachvili 2011 (sec. 17.7): for water at 20 C, `gamma V_m / (R_g T) = 0.54 nm`
    /// (72.8 mN/m, 18.0e-6 m^3/mol, 293.15 K: 0.5376 nm), so at RH = 1/e the Kelvin radius is
    /// that length; to 0.005 nm, the book's rounding.
    #[test]
    fn kelvin_radius_of_water_matches_the_book() {
        let r = kelvin_radius_nm((-1.0f64).exp(), 72.8, 293.15, 18.0e-6);
        assert!((r - 0.54).abs() < 0.005, "{r}");
    }

    /// The meniscus force of a 10 nm tip in water (72 mN/m, theta = 0) is
    /// `4 pi R gamma = 9.048 nN` (to 1e-3 nN), and it adds to Hertz inside contact.
    #[test]
    fn meniscus_force_adds_to_hertz() {
        let hertz = HertzShape {
            effective_modulus_gpa: 2.0,
            tip: HertzTip::Sphere { radius_nm: 10.0 },
        };
        let law = CapillaryContact::new(hertz, 10.0, 0.5, 72.0, 0.0, 293.15, 18.0e-6);
        assert!((law.meniscus_force_nn - 9.048).abs() < 1e-3);
        let inside = law.attached(true, -1.0).force;
        let expected = 4.0 / 3.0 * 2.0 * 10f64.sqrt() - law.meniscus_force_nn;
        assert!((inside - expected).abs() < 1e-12);
        assert_eq!(law.attached(false, 0.3).force, -law.meniscus_force_nn);
    }
}
