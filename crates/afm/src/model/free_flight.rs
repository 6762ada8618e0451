//! The exact flow of one damped, harmonically driven oscillator: eigenmode `i` of Eq. 1 with
//! `F_ts = 0` (free flight),
//!
//! ```text
//! q'' + (w_i / Q_i) q' + w_i^2 q = w_i^2 (F_i / k_i) cos(w t),
//! ```
//!
//! valid for every `Q_i > 0` (under-, critically and over-damped).

use nalgebra::Complex;

use crate::model::phase;

/// The dimensionless frequency response `1 / (1 - r^2 + i r / Q)`, `r = w / w_i`, of a mode of
/// Eq. 1: the steady response to `(F_i/k_i) e^{i w t}` is `(F_i/k_i)` times this.
pub fn dimensionless_response(
    natural_angular_frequency: f64,
    quality_factor: f64,
    drive_angular_frequency: f64,
) -> Complex<f64> {
    let ratio = drive_angular_frequency / natural_angular_frequency;
    Complex::new(1.0 - ratio * ratio, ratio / quality_factor).inv()
}

/// A damped oscillator `q'' + (w_n/Q) q' + w_n^2 q = w_n^2 s cos(w t)` (one mode of Eq. 1 in
/// free flight, with `s = F_i / k_i` in nm), and its exact flow.
///
/// Time in us, angular frequencies in rad/us, `q` in nm, `q'` in nm/us.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrivenOscillator {
    /// Natural angular frequency `w_n`, rad/us.
    natural_angular_frequency: f64,
    /// Drive angular frequency `w`, rad/us.
    drive_angular_frequency: f64,
    /// `mu = -w_n / (2 Q)`: the real part shared by both characteristic roots, 1/us.
    mu: f64,
    /// `delta^2 = mu^2 - w_n^2`: > 0 over-damped, < 0 under-damped, 1/us^2.
    delta_squared: f64,
    /// Steady (particular) solution `q_p = a cos(w t) + b sin(w t)`: `[a, b]` in nm.
    steady: [f64; 2],
}

/// Number of terms of the power series used for `|delta^2 t^2| < SERIES_RADIUS`.
const SERIES_TERMS: usize = 12;
/// Below this `|delta^2 t^2|` the near-critical series is used (its 12th term is < 1e-40).
const SERIES_RADIUS: f64 = 1e-2;

impl DrivenOscillator {
    /// The oscillator with natural angular frequency `w_n` (rad/us), quality factor `Q > 0`,
    /// static deflection `s = F_i / k_i` (nm) and drive angular frequency `w` (rad/us).
    pub fn new(
        natural_angular_frequency: f64,
        quality_factor: f64,
        static_deflection_nm: f64,
        drive_angular_frequency: f64,
    ) -> Self {
        let w = natural_angular_frequency;
        let q = quality_factor;
        // mu^2 - w^2 = w^2 (1 - 2Q)(1 + 2Q) / (4 Q^2): exact sign and small relative error
        // near critical damping.
        let delta_squared = w * w * (1.0 - 2.0 * q) * (1.0 + 2.0 * q) / (4.0 * q * q);
        let response = dimensionless_response(w, q, drive_angular_frequency);
        // Re[s H e^{iwt}] = s Re H cos(wt) - s Im H sin(wt).
        let steady = [
            static_deflection_nm * response.re,
            -static_deflection_nm * response.im,
        ];
        Self {
            natural_angular_frequency: w,
            drive_angular_frequency,
            mu: -w / (2.0 * q),
            delta_squared,
            steady,
        }
    }

    /// The steady solution's coefficients `[a, b]` (nm): `q_p(t) = a cos(w t) + b sin(w t)`.
    pub fn steady_coefficients(&self) -> [f64; 2] {
        self.steady
    }

    /// The steady (periodic, particular) solution `[q_p(t), q_p'(t)]` (nm, nm/us).
    #[inline]
    pub fn steady_state(&self, t: f64) -> [f64; 2] {
        let (sin, cos) = phase::sin_cos(self.drive_angular_frequency * t);
        self.steady_state_at_phase(sin, cos)
    }

    /// The steady solution `[q_p, q_p']` at a time whose drive phase has sine `sin` and cosine
    /// `cos` (`sin(w t)`, `cos(w t)`: shared between modes driven at the same frequency).
    #[inline]
    pub fn steady_state_at_phase(&self, sin: f64, cos: f64) -> [f64; 2] {
        let [a, b] = self.steady;
        [
            a * cos + b * sin,
            self.drive_angular_frequency * (b * cos - a * sin),
        ]
    }

    /// The transition matrix `exp(A dt)` of the homogeneous oscillator
    /// `A = [[0, 1], [-w_n^2, -w_n/Q]]`, for any `dt` (also negative):
    /// `exp(A t) = e^{mu t} [C(t) I + S(t) (A - mu I)]` with `C = cos(delta t)`,
    /// `S = sin(delta t)/delta` (under-damped), `C = cosh`, `S = sinh/delta` (over-damped, in
    /// exponential form that cannot overflow), and their power series in `delta^2 t^2` near
    /// critical damping.
    #[inline]
    pub fn homogeneous_transition(&self, dt: f64) -> [[f64; 2]; 2] {
        let mu = self.mu;
        let z = self.delta_squared * dt * dt;
        let (c, s) = if z.abs() < SERIES_RADIUS {
            // C = sum z^k/(2k)!, S = t sum z^k/(2k+1)!.
            let mut c_term = 1.0;
            let mut s_term = 1.0;
            let mut c_sum = 1.0;
            let mut s_sum = 1.0;
            for k in 1..SERIES_TERMS {
                let k = k as f64;
                c_term *= z / ((2.0 * k - 1.0) * (2.0 * k));
                s_term *= z / ((2.0 * k) * (2.0 * k + 1.0));
                c_sum += c_term;
                s_sum += s_term;
            }
            let decay = (mu * dt).exp();
            (decay * c_sum, decay * dt * s_sum)
        } else if self.delta_squared < 0.0 {
            let delta = (-self.delta_squared).sqrt();
            let decay = (mu * dt).exp();
            let (sin, cos) = phase::sin_cos(delta * dt);
            (decay * cos, decay * sin / delta)
        } else {
            let delta = self.delta_squared.sqrt();
            let fast = mu - delta;
            // (mu + delta)(mu - delta) = w_n^2: the slow root without cancellation.
            let slow = self.natural_angular_frequency * self.natural_angular_frequency / fast;
            let (slow_exp, fast_exp) = ((slow * dt).exp(), (fast * dt).exp());
            // S = (e^{slow t} - e^{fast t}) / (2 delta), factored on the exponential that
            // dominates in the direction of time (slow - fast = 2 delta), so that the other
            // factor is an expm1 in (-1, 0]: forward, e^{slow t} (1 - e^{-2 delta t}) (the
            // factor e^{fast t} e^{2 delta t} overflowed to 0 inf once 2 delta t > 709, as for
            // Q = 0.01 at 72 kHz over 40 us).
            let difference = if dt >= 0.0 {
                -slow_exp * (-2.0 * delta * dt).exp_m1()
            } else {
                fast_exp * (2.0 * delta * dt).exp_m1()
            };
            (0.5 * (slow_exp + fast_exp), difference / (2.0 * delta))
        };
        let w2 = self.natural_angular_frequency * self.natural_angular_frequency;
        [[c - mu * s, s], [-w2 * s, c + mu * s]]
    }

    /// The exact flow from `[q, q']` at `t0` over `dt`: returns the state at `t0 + dt` and the
    /// transition matrix `d x(t0 + dt) / d x(t0)`.
    #[inline]
    pub fn flow(&self, t0: f64, x0: [f64; 2], dt: f64) -> ([f64; 2], [[f64; 2]; 2]) {
        let start = phase::sin_cos(self.drive_angular_frequency * t0);
        let end = phase::sin_cos(self.drive_angular_frequency * (t0 + dt));
        self.flow_between_phases(start, end, x0, dt)
    }

    /// As [`DrivenOscillator::flow`], with the drive phases `(sin, cos)` of `w t0` and
    /// `w (t0 + dt)` supplied by the caller (computed once for all modes).
    #[inline]
    pub fn flow_between_phases(
        &self,
        start_phase: (f64, f64),
        end_phase: (f64, f64),
        x0: [f64; 2],
        dt: f64,
    ) -> ([f64; 2], [[f64; 2]; 2]) {
        let phi = self.homogeneous_transition(dt);
        (
            self.flow_with_transition(start_phase, end_phase, x0, &phi),
            phi,
        )
    }

    /// As [`DrivenOscillator::flow_between_phases`], with the homogeneous transition `phi`
    /// over the step supplied by the caller (kept for a step length used again and again):
    /// returns the state at the step's end.
    #[inline]
    pub fn flow_with_transition(
        &self,
        start_phase: (f64, f64),
        end_phase: (f64, f64),
        x0: [f64; 2],
        phi: &[[f64; 2]; 2],
    ) -> [f64; 2] {
        let start = self.steady_state_at_phase(start_phase.0, start_phase.1);
        let end = self.steady_state_at_phase(end_phase.0, end_phase.1);
        let y = [x0[0] - start[0], x0[1] - start[1]];
        [
            end[0] + phi[0][0] * y[0] + phi[0][1] * y[1],
            end[1] + phi[1][0] * y[0] + phi[1][1] * y[1],
        ]
    }
}
