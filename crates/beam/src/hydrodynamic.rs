//! Sader's hydrodynamic function of a thin rectangular beam oscillating in a viscous fluid
//! (J. E. Sader, J. Appl. Phys. 84, 64 (1998), "Sader 1998").
//!
//! A beam of width `b` vibrating at angular frequency `w` in a fluid of density `rho` and
//! viscosity `eta` feels, per unit length, the hydrodynamic load
//! `F(w) = (pi/4) rho w^2 b^2 Gamma(w) W(w)` (Sader 1998 Eq. 8), `W` its deflection. The real
//! part of `Gamma` is an added mass, the imaginary part a viscous damping. Both depend only on
//! the Reynolds number
//!
//! ```text
//! Re = rho w b^2 / (4 eta)                                  (Sader 1998 Eq. 4)
//! ```
//!
//! For a circular cylinder of diameter `b` the two-dimensional Stokes flow gives (Sader 1998
//! Eq. 18, after Rosenhead 1963)
//!
//! ```text
//! Gamma_circ(w) = 1 + 4 i K_1(-i sqrt(i Re)) / (sqrt(i Re) K_0(-i sqrt(i Re)))
//! ```
//!
//! and for a blade of width `b` and zero thickness Sader fitted the ratio
//! `Omega = Gamma_rect / Gamma_circ` to his boundary-integral solution, accurate to 0.1% for
//! `Re` in `[1e-6, 1e4]` (Sader 1998 Eq. 21, `tau = log10 Re`):
//!
//! ```text
//! Omega_r = (0.91324 - 0.48274 tau + 0.46842 tau^2 - 0.12886 tau^3 + 0.044055 tau^4
//!            - 0.0035117 tau^5 + 0.00069085 tau^6)
//!         / (1 - 0.56964 tau + 0.48690 tau^2 - 0.13444 tau^3 + 0.045155 tau^4
//!            - 0.0035862 tau^5 + 0.00069085 tau^6)
//! Omega_i = (-0.024134 - 0.029256 tau + 0.016294 tau^2 - 0.00010961 tau^3
//!            + 0.000064577 tau^4 - 0.000044510 tau^5)
//!         / (1 - 0.59702 tau + 0.55182 tau^2 - 0.18357 tau^3 + 0.079156 tau^4
//!            - 0.014369 tau^5 + 0.0028361 tau^6)
//! Gamma_rect(w) = Omega(w) Gamma_circ(w)                    (Sader 1998 Eq. 20)
//! ```

use num_complex::Complex64;

use crate::bessel::bessel_k0_k1;
use crate::error::BeamError;

/// The smallest Reynolds number of the fit `Omega` (Sader 1998 Eq. 21).
pub const MIN_REYNOLDS: f64 = 1e-6;
/// The largest Reynolds number of the fit `Omega` (Sader 1998 Eq. 21).
pub const MAX_REYNOLDS: f64 = 1e4;

/// The Reynolds number `Re = rho w b^2 / (4 eta)` of Sader 1998 Eq. 4 (dimensionless), from the
/// fluid's density `rho` (kg/m^3) and viscosity `eta` (Pa s), the angular frequency `w` (rad/s)
/// and the beam's width `b` (m).
#[must_use]
pub fn reynolds_number(
    density_kg_m3: f64,
    viscosity_pa_s: f64,
    angular_frequency_rad_s: f64,
    width_m: f64,
) -> f64 {
    density_kg_m3 * angular_frequency_rad_s * width_m * width_m / (4.0 * viscosity_pa_s)
}

/// The hydrodynamic function of a circular cylinder `Gamma_circ(Re)` (Sader 1998 Eq. 18;
/// dimensionless), for any `Re > 0` with `|sqrt(i Re)|` in the Bessel functions' range
/// ([`crate::bessel`]).
#[must_use]
pub fn circular_hydrodynamic_function(reynolds: f64) -> Complex64 {
    let root = (Complex64::i() * reynolds).sqrt();
    let argument = -Complex64::i() * root;
    let [k0, k1] = bessel_k0_k1(argument);
    Complex64::new(1.0, 0.0) + 4.0 * Complex64::i() * k1 / (root * k0)
}

/// Sader's correction `Omega(Re) = Gamma_rect / Gamma_circ` for a thin rectangular beam
/// (Sader 1998 Eq. 21, module documentation; dimensionless). Valid for `Re` in
/// `[MIN_REYNOLDS, MAX_REYNOLDS]`; the caller checks the range.
#[must_use]
pub fn rectangular_correction(reynolds: f64) -> Complex64 {
    let tau = reynolds.log10();
    let polynomial = |coefficients: &[f64]| {
        coefficients
            .iter()
            .rev()
            .fold(0.0, |sum, coefficient| sum * tau + coefficient)
    };
    let real = polynomial(&[
        0.91324, -0.48274, 0.46842, -0.12886, 0.044055, -0.0035117, 0.00069085,
    ]) / polynomial(&[
        1.0, -0.56964, 0.48690, -0.13444, 0.045155, -0.0035862, 0.00069085,
    ]);
    let imaginary = polynomial(&[
        -0.024134,
        -0.029256,
        0.016294,
        -0.00010961,
        0.000064577,
        -0.000044510,
    ]) / polynomial(&[
        1.0, -0.59702, 0.55182, -0.18357, 0.079156, -0.014369, 0.0028361,
    ]);
    Complex64::new(real, imaginary)
}

/// The hydrodynamic function of a thin rectangular beam
/// `Gamma_rect(Re) = Omega(Re) Gamma_circ(Re)` (Sader 1998 Eq. 20; dimensionless).
///
/// # Errors
/// [`BeamError::ReynoldsOutOfRange`] unless `Re` is in `[MIN_REYNOLDS, MAX_REYNOLDS]`, the range
/// of Sader's fit; `mode` (1-based) names the mode in the message.
pub fn rectangular_hydrodynamic_function(
    reynolds: f64,
    mode: usize,
) -> Result<Complex64, BeamError> {
    if !(MIN_REYNOLDS..=MAX_REYNOLDS).contains(&reynolds) {
        return Err(BeamError::ReynoldsOutOfRange {
            mode,
            value: reynolds,
            min: MIN_REYNOLDS,
            max: MAX_REYNOLDS,
        });
    }
    Ok(rectangular_correction(reynolds) * circular_hydrodynamic_function(reynolds))
}
