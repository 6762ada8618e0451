//! The predictions of the paper's approximate theory: the tip-sample impulse of Eq. 3 and the
//! impulse response of the second eigenmode of Eq. 4, from the cantilever's first two modes,
//! the free amplitude `a_0` of `q_1` and the phase `phi` of `q_1` on the orbit.

use std::f64::consts::PI;

use serde::Serialize;

use crate::error::AfmError;
use crate::model::TappingModel;
use crate::theory::impact_numbers::MultipleImpactNumbers;

/// Relative difference between the drive frequency and `f_1` below which the drive counts as
/// "at `w_1`" (the paper's assumption `w = w_1`, under which Eq. 3 is derived).
const FUNDAMENTAL_TOLERANCE: f64 = 1e-9;

/// The constants of the paper's approximate theory for one model (Eqs. 3 and 4, MODEL.md
/// section 7). Angular frequencies in rad/us, times in us, stiffness in N/m (= nN/nm).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ImpactTheory {
    /// `lambda_1 = w_2^2 k_1 / (w_1 w_2d k_2 Q_1)` (initial amplitude of the momentary
    /// excitation of mode 2 per unit `pi a_0 cos(phi)`).
    pub lambda_1: f64,
    /// `lambda_2 = w_2d / w_1` (ringing periods of `q_2` per drive period).
    pub lambda_2: f64,
    /// `lambda_3 = Q_2 w_1 / w_2` (decay of the ringing over a period).
    pub lambda_3: f64,
    /// `k_1`, N/m.
    pub stiffness_1_n_per_m: f64,
    /// `Q_1`.
    pub quality_factor_1: f64,
    /// `w_1`, rad/us.
    pub angular_frequency_1: f64,
    /// `k_2`, N/m.
    pub stiffness_2_n_per_m: f64,
    /// `Q_2`.
    pub quality_factor_2: f64,
    /// `w_2`, rad/us.
    pub angular_frequency_2: f64,
    /// `w_2d = w_2 sqrt(1 - 1/(4 Q_2^2))`, rad/us.
    pub damped_angular_frequency_2: f64,
    /// The drive's angular frequency `w`, rad/us.
    pub drive_angular_frequency: f64,
    /// The drive period `T = 2 pi / w`, us.
    pub period_us: f64,
    /// `a_0`: the free (`F_ts = 0`) first-harmonic amplitude of `q_1` at the drive frequency,
    /// nm (not of `u`: MODEL.md section 3 sets `A0` on `u`). At `w = w_1`, `F_1 = k_1 a_0 / Q_1`.
    pub free_q1_amplitude_nm: f64,
    /// The drive force amplitude `F_1`, nN.
    pub drive_force_nn: f64,
    /// Whether the drive is at `w_1` (relative difference below 1e-9): the assumption under
    /// which Eq. 3 is derived. When false, the predictions are still computed from the
    /// paper's formulas with `a_0` at the actual drive frequency, and are not to be trusted.
    pub drive_at_fundamental: bool,
    /// `tau = 2 Q_2 / w_2`, us: the decay time of the ringing of `q_2` (Eq. 4).
    pub q2_decay_time_us: f64,
    /// `exp(-T / tau)`: the factor by which the ringing's amplitude decays over one drive
    /// period (Eq. 4; equal to `exp(-pi / lambda_3)` at `w = w_1`).
    pub q2_decay_over_period: f64,
    /// The paper's criterion `Q_2 <= w_2 / w_1` (`lambda_3 <= 1`): the ringing decays by more
    /// than 95% (`exp(-pi) = 0.043`) before the next impact.
    pub ring_down_criterion_holds: bool,
    /// `w_2^2 / (k_2 w_2d)`, nm per nN us: the initial amplitude of `q_2`'s ringing per unit
    /// impulse (the impulse response of Eq. 1, `i = 2`, behind Eq. 4).
    pub q2_amplitude_per_impulse: f64,
}

/// The predictions of Eqs. 3 and 4 for one phase `phi` of `q_1`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ImpactPrediction {
    /// The phase `phi` of `q_1 = a cos(w t - phi)` used, degrees (a lag, like MODEL.md's `Phi`).
    pub q1_phase_deg: f64,
    /// Eq. 3: the tip-sample impulse per period `pi k_1 a_0 cos(phi) / (Q_1 w_1)`, nN us.
    pub impulse_nn_us: f64,
    /// Eq. 4: the initial amplitude of the ringing of `q_2`,
    /// `a_0 pi w_2^2 k_1 cos(phi) / (Q_1 w_1 w_2d k_2) = pi a_0 lambda_1 cos(phi)`, nm.
    pub q2_initial_amplitude_nm: f64,
    /// Eq. 4: `tau = 2 Q_2 / w_2`, us.
    pub q2_decay_time_us: f64,
    /// Eq. 4: `exp(-T / tau)`, the ringing's decay over one period.
    pub q2_decay_over_period: f64,
    /// The moment of impact the theory assumes, `theta = w t - phi = pi` (the lowest point of
    /// `q_1`), in drive periods in `[0, 1)` from `t = 0` (`cos(w t) = 1`).
    pub impact_time_periods: f64,
}

impl ImpactTheory {
    /// The theory's constants for `model` (its first two eigenmodes; higher modes are ignored,
    /// as in the paper). Fails when the model has a single mode or an over-damped second mode
    /// (`Q_2 <= 0.5`: no ringing, no `w_2d`).
    pub fn new(model: &TappingModel) -> Result<Self, AfmError> {
        let cantilever = model.cantilever();
        let numbers =
            MultipleImpactNumbers::of(cantilever).ok_or_else(|| AfmError::InvalidField {
                file: format!("cantilever `{}`", cantilever.name),
                field: String::from("modes"),
                value: format!(
                    "{} mode(s), Q_2 = {}",
                    cantilever.modes.len(),
                    cantilever
                        .modes
                        .get(1)
                        .map_or(f64::NAN, |mode| mode.quality_factor)
                ),
                allowed: String::from(
                    "at least two eigenmodes with Q_2 > 0.5 (the theory of Eqs. 3-4 needs a \
                     ringing second mode)",
                ),
            })?;
        let first = &cantilever.modes[0];
        let second = &cantilever.modes[1];
        let w1 = first.angular_frequency();
        let w2 = second.angular_frequency();
        let q2 = second.quality_factor;
        let w2d = w2 * (1.0 - 1.0 / (4.0 * q2 * q2)).sqrt();
        let w = model.drive_angular_frequency();
        let period = model.period_us();
        let tau = 2.0 * q2 / w2;
        let [a, b] = model.free_response().modal_coefficients()[0];
        Ok(Self {
            lambda_1: numbers.lambda_1,
            lambda_2: numbers.lambda_2,
            lambda_3: numbers.lambda_3,
            stiffness_1_n_per_m: first.stiffness_n_per_m,
            quality_factor_1: first.quality_factor,
            angular_frequency_1: w1,
            stiffness_2_n_per_m: second.stiffness_n_per_m,
            quality_factor_2: q2,
            angular_frequency_2: w2,
            damped_angular_frequency_2: w2d,
            drive_angular_frequency: w,
            period_us: period,
            free_q1_amplitude_nm: a.hypot(b),
            drive_force_nn: model.drive_force_nn(),
            drive_at_fundamental: (w - w1).abs() <= FUNDAMENTAL_TOLERANCE * w1,
            q2_decay_time_us: tau,
            q2_decay_over_period: (-period / tau).exp(),
            ring_down_criterion_holds: q2 <= w2 / w1,
            q2_amplitude_per_impulse: w2 * w2 / (second.stiffness_n_per_m * w2d),
        })
    }

    /// Eq. 3: the tip-sample impulse per period `pi k_1 a_0 cos(phi) / (Q_1 w_1)`, nN us, for
    /// the phase `phi` of `q_1` in radians.
    pub fn impulse_nn_us(&self, q1_phase_rad: f64) -> f64 {
        PI * self.stiffness_1_n_per_m * self.free_q1_amplitude_nm * q1_phase_rad.cos()
            / (self.quality_factor_1 * self.angular_frequency_1)
    }

    /// The coefficient of Eq. 4, `a_0 pi w_2^2 k_1 cos(phi) / (Q_1 w_1 w_2d k_2)`, nm: the
    /// initial amplitude of the ringing of `q_2` (Eq. 3's impulse times
    /// [`Self::q2_amplitude_per_impulse`]); `phi` in radians.
    pub fn q2_initial_amplitude_nm(&self, q1_phase_rad: f64) -> f64 {
        self.impulse_nn_us(q1_phase_rad) * self.q2_amplitude_per_impulse
    }

    /// Eq. 4: `q_2(t_bar) = C e^{-t_bar/tau} sin(w_2d t_bar)`, nm, `t_bar` in us since the
    /// impact (`0 <= t_bar <= T`), `C` = [`Self::q2_initial_amplitude_nm`].
    pub fn q2_impulse_response_nm(&self, q1_phase_rad: f64, t_bar_us: f64) -> f64 {
        self.q2_initial_amplitude_nm(q1_phase_rad)
            * (-t_bar_us / self.q2_decay_time_us).exp()
            * (self.damped_angular_frequency_2 * t_bar_us).sin()
    }

    /// All predictions for the phase `phi` of `q_1`, degrees.
    pub fn predict(&self, q1_phase_deg: f64) -> ImpactPrediction {
        let phase = q1_phase_deg.to_radians();
        ImpactPrediction {
            q1_phase_deg,
            impulse_nn_us: self.impulse_nn_us(phase),
            q2_initial_amplitude_nm: self.q2_initial_amplitude_nm(phase),
            q2_decay_time_us: self.q2_decay_time_us,
            q2_decay_over_period: self.q2_decay_over_period,
            impact_time_periods: ((PI + phase) / (2.0 * PI)).rem_euclid(1.0),
        }
    }
}
