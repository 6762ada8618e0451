//! The standard linear solid (Zener) sample with a Hertz sphere (MODEL.md section 9, "Standard
//! linear solid"): a contact law with an internal state, the sample's unrecovered
//! deformation, that the model integrates with the cantilever in contact and while the free
//! surface recovers between impacts.

use super::ForceSlopes;

/// A Hertz sphere on a standard linear solid: a spring `E_inf` in parallel with a Maxwell arm
/// (spring `E_0 - E_inf`, dashpot of relaxation time `tau`), in the Lee-Radok form of the
/// Hertz indentation `p = s^{3/2}` (`s = -d`, nm). The state `rho` (nm^{3/2}) is the sample's
/// unrecovered `p`: its surface under the tip lies `sigma = rho^{2/3}` nm below the rest
/// position. With `c_0 = (4/3) E_0* sqrt(R)` and `beta = 1 - E_inf*/E_0*`:
///
/// - contact is `s > sigma` (the tip below the unrecovered surface), where
///   `F = c_0 (s^{3/2} - rho)` and `rho' = (beta s^{3/2} - rho) / tau`;
/// - out of contact `F = 0` and `rho' = -(1 - beta) rho / tau` (the surface recovers at zero
///   load with the retardation time `tau E_0*/E_inf*`).
///
/// `E_0 = E_inf` (`beta = 0`) keeps `rho = 0`: Hertz with `E_0*` exactly.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StandardLinearSolid {
    /// The instantaneous reduced modulus `E_0*`, GPa (= nN/nm^2).
    pub instant_modulus_gpa: f64,
    /// The relaxed reduced modulus `E_inf*`, GPa, at most `E_0*`.
    pub relaxed_modulus_gpa: f64,
    /// The relaxation time `tau` of the Maxwell arm at fixed indentation, us.
    pub relaxation_time_us: f64,
    /// The tip radius `R`, nm.
    pub tip_radius_nm: f64,
}

impl StandardLinearSolid {
    /// `c_0 = (4/3) E_0* sqrt(R)`, nN/nm^{3/2}.
    pub fn coefficient(&self) -> f64 {
        4.0 / 3.0 * self.instant_modulus_gpa * self.tip_radius_nm.sqrt()
    }

    /// `beta = 1 - E_inf*/E_0*`, in [0, 1).
    pub fn relaxing_fraction(&self) -> f64 {
        1.0 - self.relaxed_modulus_gpa / self.instant_modulus_gpa
    }

    /// The free surface's recovery rate `(1 - beta) / tau = E_inf* / (E_0* tau)`, 1/us.
    pub fn recovery_rate_per_us(&self) -> f64 {
        (1.0 - self.relaxing_fraction()) / self.relaxation_time_us
    }

    /// The unrecovered depth `sigma = rho^{2/3}` of the surface, nm (0 for `rho <= 0`).
    pub fn unrecovered_depth_nm(state: f64) -> f64 {
        if state > 0.0 {
            let root = state.cbrt();
            root * root
        } else {
            0.0
        }
    }

    /// `d sigma / d rho = (2/3) rho^{-1/3}`, 1/nm^{1/2}; 0 at `rho <= 0` (where `beta = 0`
    /// keeps `rho` and its perturbations zero).
    pub fn depth_slope(state: f64) -> f64 {
        if state > 0.0 {
            2.0 / 3.0 / state.cbrt()
        } else {
            0.0
        }
    }

    /// In contact: `F = c_0 (s^{3/2} - rho)` (nN) with `dF/dd = -1.5 c_0 s^{1/2}`; the slope
    /// `dF/drho = -c_0` is [`StandardLinearSolid::state_force_slope`].
    pub fn force_slopes(&self, gap_nm: f64, state: f64) -> ForceSlopes {
        let c = self.coefficient();
        let s = (-gap_nm).max(0.0);
        let root = s.sqrt();
        ForceSlopes {
            force: c * (s * root - state),
            gap_slope: -1.5 * c * root,
            rate_slope: 0.0,
        }
    }

    /// `dF/drho = -c_0` in contact, 0 outside, nN/nm^{3/2}.
    pub fn state_force_slope(&self, inside: bool) -> f64 {
        if inside {
            -self.coefficient()
        } else {
            0.0
        }
    }

    /// `rho'` (nm^{3/2}/us) with its slopes `d rho'/dd` and `d rho'/d rho`: in contact
    /// `(beta s^{3/2} - rho) / tau`, outside `-(1 - beta) rho / tau`.
    pub fn state_rate(&self, inside: bool, gap_nm: f64, state: f64) -> (f64, f64, f64) {
        let tau = self.relaxation_time_us;
        if inside {
            let beta = self.relaxing_fraction();
            let s = (-gap_nm).max(0.0);
            let root = s.sqrt();
            (
                (beta * s * root - state) / tau,
                -1.5 * beta * root / tau,
                -1.0 / tau,
            )
        } else {
            let rate = self.recovery_rate_per_us();
            (-rate * state, 0.0, -rate)
        }
    }

    /// The indentation seen by the sample, `max(s, sigma)`, nm: the tip's where it touches,
    /// the free surface's where it does not.
    fn sample_indentation(gap_nm: f64, state: f64) -> f64 {
        (-gap_nm).max(Self::unrecovered_depth_nm(state))
    }

    /// The energy stored in the sample, nN nm:
    /// `U = c_0 [(2/5) S^{5/2} - rho S + (3/5) beta^{-2/3} rho^{5/3}]` with `S = max(s, sigma)`
    /// (0 for an unloaded, recovered sample; `dU/ds = F` in contact).
    pub fn stored_energy(&self, gap_nm: f64, state: f64) -> f64 {
        let c = self.coefficient();
        let s = Self::sample_indentation(gap_nm, state);
        let elastic = 0.4 * s * s * s.sqrt();
        let beta = self.relaxing_fraction();
        if beta > 0.0 && state > 0.0 {
            let sigma_arm = Self::unrecovered_depth_nm(state) / beta.cbrt().powi(2);
            c * (elastic - state * s + 0.6 * state * sigma_arm)
        } else {
            c * elastic
        }
    }

    /// The dashpot's dissipation rate `D = -dU/dt + F s'`, nN nm/us:
    /// `D = c_0 (S - (rho/beta)^{2/3}) (beta S^{3/2} - rho) / tau >= 0` (`S` as in
    /// [`StandardLinearSolid::stored_energy`]; 0 for `beta = 0`).
    pub fn dissipation_rate(&self, gap_nm: f64, state: f64) -> f64 {
        let beta = self.relaxing_fraction();
        if beta <= 0.0 {
            return 0.0;
        }
        let s = Self::sample_indentation(gap_nm, state);
        let arm = Self::unrecovered_depth_nm(state / beta);
        self.coefficient() * (s - arm) * (beta * s * s.sqrt() - state) / self.relaxation_time_us
    }
}
