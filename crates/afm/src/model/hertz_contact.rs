//! Hertz contact between a spherical tip and an elastic half-space (MODEL.md section 1).

use crate::model::cantilever::Cantilever;
use crate::model::sample::Sample;

/// The effective modulus `E* = [(1 - nu_s^2)/E_s + (1 - nu_t^2)/E_t]^{-1}`, GPa
/// (MODEL.md section 1; moduli in GPa).
pub fn effective_modulus_gpa(
    sample_modulus_gpa: f64,
    sample_poisson_ratio: f64,
    tip_modulus_gpa: f64,
    tip_poisson_ratio: f64,
) -> f64 {
    1.0 / ((1.0 - sample_poisson_ratio * sample_poisson_ratio) / sample_modulus_gpa
        + (1.0 - tip_poisson_ratio * tip_poisson_ratio) / tip_modulus_gpa)
}

/// The Hertz force law `F_ts(d) = c (-d)^{3/2}` for `d < 0`, 0 otherwise, with
/// `c = (4/3) E* sqrt(R)`: with `E*` in GPa (= nN/nm^2) and `R` in nm, `F_ts` is in nN for
/// `d` in nm exactly (MODEL.md sections 1 and 2). Repulsive forces are positive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HertzContact {
    /// `c = (4/3) E* sqrt(R)`, nN / nm^{3/2}.
    pub coefficient: f64,
}

impl HertzContact {
    /// The contact of a cantilever's tip with a sample: `c = (4/3) E* sqrt(R)`.
    pub fn new(cantilever: &Cantilever, sample: &Sample) -> Self {
        let modulus = effective_modulus_gpa(
            sample.youngs_modulus_gpa,
            sample.poisson_ratio,
            cantilever.tip_youngs_modulus_gpa,
            cantilever.tip_poisson_ratio,
        );
        Self::from_modulus(modulus, cantilever.tip_radius_nm)
    }

    /// `c = (4/3) E* sqrt(R)` from `E*` in GPa and `R` in nm.
    pub fn from_modulus(effective_modulus_gpa: f64, tip_radius_nm: f64) -> Self {
        Self {
            coefficient: 4.0 / 3.0 * effective_modulus_gpa * tip_radius_nm.sqrt(),
        }
    }

    /// The force `F_ts(d) = c max(-d, 0)^{3/2}`, nN, at gap `d` in nm (finite for every `d`).
    #[inline]
    pub fn force(&self, gap_nm: f64) -> f64 {
        let indentation = (-gap_nm).max(0.0);
        self.coefficient * indentation * indentation.sqrt()
    }

    /// The derivative `dF_ts/dd = -(3/2) c max(-d, 0)^{1/2}`, nN/nm (continuous, 0 at `d >= 0`).
    #[inline]
    pub fn force_derivative(&self, gap_nm: f64) -> f64 {
        -1.5 * self.coefficient * (-gap_nm).max(0.0).sqrt()
    }
}
