//! A uniform rectangular cantilever from its geometry and material, and its flexural modes in a
//! viscous fluid from Sader's hydrodynamic function (J. E. Sader, J. Appl. Phys. 84, 64 (1998)).
//!
//! # Model
//!
//! The beam (length `L`, width `b`, thickness `h`, Young's modulus `E`, density `rho_c`;
//! `I = b h^3 / 12`, `m_c = rho_c b h L`) carries a point tip mass `m_tip = mu m_c`. In a fluid
//! of density `rho` and viscosity `eta`, a mode vibrating at `w` feels per unit length the
//! added mass `(pi/4) rho b^2 Gamma_r(w)` and the damping coefficient
//! `c = (pi/4) rho b^2 w Gamma_i(w)` (Sader 1998 Eq. 8, [`crate::hydrodynamic`]). Mode by mode,
//! with `T = pi rho b / (4 rho_c h)` and the Reynolds number `Re_n` of the mode's own frequency
//! (Sader 1998 Eq. 4):
//!
//! ```text
//! m_eff  = rho_c b h (1 + T Gamma_r(w_n))            beam and entrained fluid, per length
//! mu_eff = mu / (1 + T Gamma_r(w_n))                 the tip mass over the loaded beam's mass
//! w_n    = b_n(mu_eff)^2 sqrt(E I / (m_eff L^4))     (b_n: crate::characteristic)
//! Q_n    = (1 + T Gamma_r) (int phi_n^2 + mu_eff) / (T Gamma_i int phi_n^2)
//! k_n    = (E I / L^3) b_n^4 (int phi_n^2 + mu_eff)  (ModeShape::stiffness; elastic, so the
//!                                                     fluid changes it only through the shape)
//! ```
//!
//! `w_n` is a fixed point (`Gamma` depends on `w_n`), found by iteration (a contraction: the
//! added mass varies slowly with `w`). With `mu = 0` these are Sader 1998's Eqs. 22 and 23 for
//! `Q >> 1`: `w_R / w_vac = (1 + T Gamma_r(w_R))^{-1/2}`, `Q = (1/T + Gamma_r(w_R)) / Gamma_i(w_R)`.
//! The damping matrix `c int phi_m phi_n` is not diagonal with a tip mass (the tip carries no
//! fluid load); its off-diagonal terms are dropped, as the modal Eq. 1 requires. The frequency
//! reported is the natural frequency `w_n` of Eq. 1's mode (the peak of the response of a mode
//! with `Q_n` near 1 lies below it, at `w_n sqrt(1 - 1/(2 Q_n^2))`). Sader's theory assumes
//! `L >> b >> h`, small amplitudes, an incompressible fluid and no nearby wall; drumroll refuses
//! `L < 2 b` and `h > b` and reports the aspect ratio.

use serde::Serialize;

use crate::cantilever::{check_mode, Beam};
use crate::error::BeamError;
use crate::fluid::{check_range, Fluid};
use crate::hydrodynamic::{
    rectangular_hydrodynamic_function, reynolds_number, MAX_REYNOLDS, MIN_REYNOLDS,
};
use crate::mode_shape::ModeShape;

/// Accepted lengths, um.
pub const LENGTH_RANGE_UM: (f64, f64) = (1.0, 10_000.0);
/// Accepted widths, um.
pub const WIDTH_RANGE_UM: (f64, f64) = (0.1, 1_000.0);
/// Accepted thicknesses, um.
pub const THICKNESS_RANGE_UM: (f64, f64) = (0.01, 100.0);
/// Accepted Young's moduli, GPa (from polymers, 0.1, to diamond, 1 200).
pub const YOUNGS_MODULUS_RANGE_GPA: (f64, f64) = (0.1, 1_500.0);
/// Accepted densities of the cantilever's material, kg/m^3 (from polymers to platinum).
pub const DENSITY_RANGE_KG_M3: (f64, f64) = (500.0, 25_000.0);
/// The smallest accepted aspect ratio `L / b` (Sader's theory is for `L >> b`; his 1998
/// paper shows it within a few percent of experiment from `L / b ~ 3`).
pub const MIN_ASPECT_RATIO: f64 = 2.0;

/// Iterations allowed for the fluid frequency's fixed point (it contracts by a factor of at
/// most about 1/2 per step, so 200 is far more than the ~50 needed from the vacuum value).
const MAX_ITERATIONS: usize = 200;
/// Relative change of `w_n` at which the fixed point is taken as reached.
const FREQUENCY_TOLERANCE: f64 = 1e-14;

/// A uniform rectangular cantilever with a point tip mass, from its geometry and material.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RectangularCantilever {
    /// Length `L`, um.
    pub length_um: f64,
    /// Width `b`, um.
    pub width_um: f64,
    /// Thickness `h`, um.
    pub thickness_um: f64,
    /// Young's modulus `E`, GPa.
    pub youngs_modulus_gpa: f64,
    /// Density of the material `rho_c`, kg/m^3.
    pub density_kg_m3: f64,
    /// Tip mass over the cantilever's own mass `m_tip / m_c` (dimensionless).
    pub tip_mass_ratio: f64,
}

/// One flexural mode of a rectangular cantilever in a fluid (module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FluidMode {
    /// 1-based mode number `n`.
    pub index: usize,
    /// Natural frequency in vacuum `f_vac = w_vac / 2 pi`, kHz.
    pub vacuum_frequency_khz: f64,
    /// Natural frequency in the fluid `f_n = w_n / 2 pi`, kHz.
    pub frequency_khz: f64,
    /// Quality factor in the fluid `Q_n` (dimensionless).
    pub quality_factor: f64,
    /// Modal stiffness `k_n` at the tip (mode normalised to unit tip deflection), N/m.
    pub stiffness_n_per_m: f64,
    /// Reynolds number `Re_n = rho w_n b^2 / (4 eta)` (dimensionless).
    pub reynolds_number: f64,
    /// Real part of the rectangular hydrodynamic function `Gamma_r(w_n)` (added mass).
    pub hydrodynamic_real: f64,
    /// Imaginary part `Gamma_i(w_n)` (viscous damping).
    pub hydrodynamic_imaginary: f64,
    /// The tip mass over the fluid-loaded beam's mass, `mu_eff = mu / (1 + T Gamma_r)`.
    pub effective_tip_mass_ratio: f64,
    /// Optical-lever sensitivity `chi_n = phi_n'(1) / phi_1'(1)` (dimensionless, 1 for mode 1).
    pub optical_sensitivity: f64,
    /// `F_n / F_1` of a load uniformly distributed on the beam (magnetic drive):
    /// `int phi_n / int phi_1`.
    pub force_ratio_distributed: f64,
    /// Participation factor of base motion `gamma_n = (int phi_n + mu_eff) / (int phi_n^2 +
    /// mu_eff)`: base acceleration `y''` loads mode `n` with `-gamma_n M_n y''`
    /// (1.566 for mode 1 without tip mass).
    pub base_participation: f64,
}

impl RectangularCantilever {
    /// Check every field against its range and the slender-beam assumptions.
    ///
    /// # Errors
    /// [`BeamError::FieldOutOfRange`] naming the field; [`BeamError::Geometry`] when `L < 2 b`
    /// or `h > b`; [`BeamError::TipMassRatioOutOfRange`].
    pub fn validate(&self) -> Result<(), BeamError> {
        check_range("length_um", self.length_um, LENGTH_RANGE_UM)?;
        check_range("width_um", self.width_um, WIDTH_RANGE_UM)?;
        check_range("thickness_um", self.thickness_um, THICKNESS_RANGE_UM)?;
        check_range(
            "youngs_modulus_gpa",
            self.youngs_modulus_gpa,
            YOUNGS_MODULUS_RANGE_GPA,
        )?;
        check_range("density_kg_m3", self.density_kg_m3, DENSITY_RANGE_KG_M3)?;
        Beam::new(self.tip_mass_ratio)?;
        if self.length_um < MIN_ASPECT_RATIO * self.width_um {
            return Err(BeamError::Geometry {
                reason: format!(
                    "length {} um over width {} um is {:.3}, below {MIN_ASPECT_RATIO}: Sader's \
                     hydrodynamic function is for slender beams (L >> b)",
                    self.length_um,
                    self.width_um,
                    self.length_um / self.width_um
                ),
            });
        }
        if self.thickness_um > self.width_um {
            return Err(BeamError::Geometry {
                reason: format!(
                    "thickness {} um exceeds width {} um: the theory is for a thin blade (h << b)",
                    self.thickness_um, self.width_um
                ),
            });
        }
        Ok(())
    }

    /// Bending stiffness over the cube of the length, `E I / L^3` with `I = b h^3 / 12`, N/m.
    #[must_use]
    pub fn bending_stiffness_n_per_m(&self) -> f64 {
        let (length, width, thickness) = self.dimensions_m();
        self.youngs_modulus_gpa * 1e9 * width * thickness.powi(3) / 12.0 / length.powi(3)
    }

    /// The static stiffness at the tip `3 E I / L^3`, N/m (the massless-spring limit; mode 1's
    /// `k_1` is 1.03 times it without tip mass).
    #[must_use]
    pub fn static_stiffness_n_per_m(&self) -> f64 {
        3.0 * self.bending_stiffness_n_per_m()
    }

    /// `(L, b, h)` in metres.
    fn dimensions_m(&self) -> (f64, f64, f64) {
        (
            self.length_um * 1e-6,
            self.width_um * 1e-6,
            self.thickness_um * 1e-6,
        )
    }

    /// `sqrt(E I / (rho_c b h L^4))`, rad/s: `w_vac = b_n^2` times this.
    fn vacuum_frequency_scale(&self) -> f64 {
        let (length, width, thickness) = self.dimensions_m();
        let linear_density = self.density_kg_m3 * width * thickness;
        (self.bending_stiffness_n_per_m() * length.powi(3) / (linear_density * length.powi(4)))
            .sqrt()
    }

    /// `T = pi rho b / (4 rho_c h)`: the fluid's added mass per unit `Gamma_r` over the beam's
    /// mass (dimensionless).
    fn mass_loading(&self, fluid: &Fluid) -> f64 {
        std::f64::consts::PI * fluid.density_kg_m3 * self.width_um
            / (4.0 * self.density_kg_m3 * self.thickness_um)
    }

    /// The first `count` modes in `fluid` (module documentation).
    ///
    /// # Errors
    /// As [`Self::validate`] and [`Fluid::validate`]; [`BeamError::ModeOutOfRange`] unless
    /// `1 <= count <= MAX_MODES`; [`BeamError::ReynoldsOutOfRange`] when a mode's Reynolds number
    /// leaves Sader's fit; [`BeamError::FluidFrequencyNotConverged`] if the fixed point fails
    /// (not expected for valid input).
    pub fn modes_in_fluid(&self, fluid: &Fluid, count: usize) -> Result<Vec<FluidMode>, BeamError> {
        self.validate()?;
        fluid.validate()?;
        check_mode("modes", count)?;
        let solved: Vec<(FluidState, ModeShape)> = (1..=count)
            .map(|index| self.solve_mode(fluid, index))
            .collect::<Result<_, _>>()?;
        let Some((_, first)) = solved.first() else {
            return Err(BeamError::ModeOutOfRange {
                field: "modes",
                value: count,
                max: crate::MAX_MODES,
            });
        };
        let slope1 = first.tip_slope();
        let distributed1 = first.distributed_force_integral();
        let scale = self.vacuum_frequency_scale();
        let vacuum = Beam::new(self.tip_mass_ratio)?;
        let loading = self.mass_loading(fluid);
        solved
            .iter()
            .map(|(state, shape)| {
                let index = shape.index();
                let mu = state.effective_tip_mass_ratio;
                let beam_integral = shape.beam_mass_integral();
                let b_vacuum = vacuum.eigenvalue(index)?;
                Ok(FluidMode {
                    index,
                    vacuum_frequency_khz: b_vacuum * b_vacuum * scale
                        / (2.0e3 * std::f64::consts::PI),
                    frequency_khz: state.angular_frequency / (2.0e3 * std::f64::consts::PI),
                    quality_factor: (1.0 + loading * state.gamma_real) * (beam_integral + mu)
                        / (loading * state.gamma_imaginary * beam_integral),
                    stiffness_n_per_m: self.bending_stiffness_n_per_m() * shape.stiffness(),
                    reynolds_number: state.reynolds,
                    hydrodynamic_real: state.gamma_real,
                    hydrodynamic_imaginary: state.gamma_imaginary,
                    effective_tip_mass_ratio: mu,
                    optical_sensitivity: shape.tip_slope() / slope1,
                    force_ratio_distributed: shape.distributed_force_integral() / distributed1,
                    base_participation: (shape.distributed_force_integral() + mu)
                        / (beam_integral + mu),
                })
            })
            .collect()
    }

    /// The fixed point of mode `index`'s frequency in `fluid`, and its mode shape there. The
    /// iteration starts at the vacuum frequency, whose Reynolds number exceeds the fluid's
    /// `Re_n` by `sqrt(1 + T Gamma_r)`; so an iterate evaluates `Gamma` at its `Re` clamped into
    /// Sader's fit, and only the converged `Re_n` must lie in the fit's range (MODEL.md
    /// section 11).
    fn solve_mode(
        &self,
        fluid: &Fluid,
        index: usize,
    ) -> Result<(FluidState, ModeShape), BeamError> {
        let (_, width, _) = self.dimensions_m();
        let scale = self.vacuum_frequency_scale();
        let loading = self.mass_loading(fluid);
        let vacuum = Beam::new(self.tip_mass_ratio)?.eigenvalue(index)?;
        let mut angular_frequency = vacuum * vacuum * scale;
        let mut history = Vec::new();
        for _ in 0..MAX_ITERATIONS {
            let reynolds = reynolds_number(
                fluid.density_kg_m3,
                fluid.viscosity_pa_s,
                angular_frequency,
                width,
            );
            let gamma = rectangular_hydrodynamic_function(
                reynolds.clamp(MIN_REYNOLDS, MAX_REYNOLDS),
                index,
            )?;
            let added = 1.0 + loading * gamma.re;
            let effective_tip_mass_ratio = self.tip_mass_ratio / added;
            let b = Beam::new(effective_tip_mass_ratio)?.eigenvalue(index)?;
            let next = b * b * scale / added.sqrt();
            let change = (next - angular_frequency).abs();
            history.push(next);
            let converged = change <= FREQUENCY_TOLERANCE * next;
            angular_frequency = next;
            if converged {
                // Gamma at the converged frequency (the last evaluation was at the previous
                // iterate, which differs by less than the tolerance; evaluate once more so that
                // Q and the reported Re belong to w_n exactly).
                let reynolds = reynolds_number(
                    fluid.density_kg_m3,
                    fluid.viscosity_pa_s,
                    angular_frequency,
                    width,
                );
                let gamma = rectangular_hydrodynamic_function(reynolds, index)?;
                let effective_tip_mass_ratio = self.tip_mass_ratio / (1.0 + loading * gamma.re);
                let shape = Beam::new(effective_tip_mass_ratio)?.mode(index)?;
                return Ok((
                    FluidState {
                        angular_frequency,
                        reynolds,
                        gamma_real: gamma.re,
                        gamma_imaginary: gamma.im,
                        effective_tip_mass_ratio,
                    },
                    shape,
                ));
            }
        }
        let tail: Vec<String> = history
            .iter()
            .rev()
            .take(3)
            .map(|w| format!("{w:.12e} rad/s"))
            .collect();
        Err(BeamError::FluidFrequencyNotConverged {
            mode: index,
            reason: format!(
                "{MAX_ITERATIONS} iterations, last iterates {}",
                tail.join(", ")
            ),
        })
    }
}

/// A mode's converged frequency and hydrodynamic load.
#[derive(Debug, Clone, Copy)]
struct FluidState {
    /// `w_n`, rad/s.
    angular_frequency: f64,
    /// `Re_n`.
    reynolds: f64,
    /// `Gamma_r(w_n)`.
    gamma_real: f64,
    /// `Gamma_i(w_n)`.
    gamma_imaginary: f64,
    /// `mu / (1 + T Gamma_r(w_n))`.
    effective_tip_mass_ratio: f64,
}
