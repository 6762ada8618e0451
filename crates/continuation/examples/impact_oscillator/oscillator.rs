//! The hard impact oscillator `x'' + c x' + k x = A cos(w t)` with a rigid stop at `x = d`
//! (switching function `h = d - x`) and Newton's restitution law `v+ = -e v-`, as a
//! [`Parametrised`] hybrid system with parameter `p = A` and second parameter `q = w`; shared by the example and its test.

use continuation::{
    Branch, Continuation, ContinuationError, ContinuationSettings, HybridPeriodicProblem,
    Parametrised, SpecialPointKind, TwoParametrised,
};
use hybrid::{Direction, HybridSystem, Mode, Settings, SwitchingPartials};
use nalgebra::DMatrix;

/// Stiffness, damping, drive frequency, stop position, restitution and drive amplitude (all
/// dimensionless; time in units of the equation's time).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImpactOscillator {
    /// Stiffness `k`.
    pub k: f64,
    /// Damping `c`.
    pub c: f64,
    /// Drive frequency `w`.
    pub w: f64,
    /// Position of the stop `d` (> 0).
    pub d: f64,
    /// Coefficient of restitution `e` in `[0, 1]`.
    pub e: f64,
    /// Drive amplitude `A`, the continuation parameter.
    pub amplitude: f64,
}

impl ImpactOscillator {
    /// The closed-form grazing amplitude: the free steady state `x = A |G| cos(w t - phi)`,
    /// `G = 1 / (k - w^2 + i c w)`, reaches `x = d` when `A = d sqrt((k - w^2)^2 + (c w)^2)`.
    pub fn grazing_amplitude_closed_form(&self) -> f64 {
        self.d * ((self.k - self.w * self.w).powi(2) + (self.c * self.w).powi(2)).sqrt()
    }

    /// The non-impacting steady state at `t = 0` in closed form, `(Re X, -w Im X)` with
    /// `X = A G`.
    pub fn free_steady_state(&self) -> [f64; 2] {
        let re = self.k - self.w * self.w;
        let im = self.c * self.w;
        let den = re * re + im * im;
        let (x_re, x_im) = (self.amplitude * re / den, -self.amplitude * im / den);
        [x_re, -self.w * x_im]
    }
}

impl HybridSystem for ImpactOscillator {
    fn dim(&self) -> usize {
        2
    }

    fn surface_count(&self) -> usize {
        1
    }

    fn vector_field(&self, _mode: Mode, t: f64, x: &[f64], dxdt: &mut [f64]) {
        dxdt[0] = x[1];
        dxdt[1] = self.amplitude * (self.w * t).cos() - self.c * x[1] - self.k * x[0];
    }

    fn jacobian(&self, _mode: Mode, _t: f64, _x: &[f64], jacobian: &mut DMatrix<f64>) {
        jacobian[(0, 0)] = 0.0;
        jacobian[(0, 1)] = 1.0;
        jacobian[(1, 0)] = -self.k;
        jacobian[(1, 1)] = -self.c;
    }

    fn parameter_derivative(&self, _mode: Mode, t: f64, _x: &[f64], dfdp: &mut [f64]) {
        dfdp[0] = 0.0;
        dfdp[1] = (self.w * t).cos();
    }

    fn switching(&self, _k: usize, _t: f64, x: &[f64]) -> f64 {
        self.d - x[0]
    }

    fn switching_rate(&self, _k: usize, _mode: Mode, _t: f64, x: &[f64]) -> f64 {
        -x[1]
    }

    fn switching_gradient(
        &self,
        _k: usize,
        _t: f64,
        _x: &[f64],
        gradient: &mut [f64],
    ) -> SwitchingPartials {
        gradient[0] = -1.0;
        gradient[1] = 0.0;
        SwitchingPartials::default()
    }

    fn has_reset(&self, _k: usize, direction: Direction) -> bool {
        direction == Direction::Down
    }

    fn reset(
        &self,
        _k: usize,
        _direction: Direction,
        _t: f64,
        x: &mut [f64],
        jacobian: &mut DMatrix<f64>,
        dxdp: &mut [f64],
    ) {
        x[1] *= -self.e;
        jacobian.fill(0.0);
        jacobian[(0, 0)] = 1.0;
        jacobian[(1, 1)] = -self.e;
        dxdp.fill(0.0);
    }
}

impl Parametrised for ImpactOscillator {
    fn parameter(&self) -> f64 {
        self.amplitude
    }

    fn set_parameter(&mut self, p: f64) {
        self.amplitude = p;
    }

    fn period(&self) -> f64 {
        2.0 * std::f64::consts::PI / self.w
    }
}

impl TwoParametrised for ImpactOscillator {
    /// The drive frequency `w` (the period `2 pi / w` follows it).
    fn second_parameter(&self) -> f64 {
        self.w
    }

    fn set_second_parameter(&mut self, q: f64) -> Result<(), String> {
        if !(q.is_finite() && q > 0.0) {
            return Err(format!("drive frequency w = {q}: need w > 0, finite"));
        }
        self.w = q;
        Ok(())
    }
}

/// The branch of period-one orbits continued in `A` from `A0 = d c w / 2` (below the grazing
/// amplitude, which is at least `d c w`, so the start does not impact) up to `a_max`, with at
/// most `max_points` points. The start is shot from the closed-form free steady state.
///
/// # Errors
/// A failure to start the branch (a linear orbit: shooting converges in one step).
pub fn continue_in_amplitude(
    oscillator: &ImpactOscillator,
    a_max: f64,
    max_points: usize,
) -> Result<Branch, ContinuationError> {
    let mut start = *oscillator;
    start.amplitude = 0.5 * oscillator.d * oscillator.c * oscillator.w;
    let problem = HybridPeriodicProblem::new(start, 1, Settings::default())?;
    let settings = ContinuationSettings {
        initial_step: 1e-2 * oscillator.d,
        max_step: 0.1 * oscillator.d,
        min_step: 1e-9 * oscillator.d,
        parameter_min: -1.0,
        parameter_max: a_max,
        max_points,
        ..ContinuationSettings::default()
    };
    let guess = start.free_steady_state();
    let branch = Continuation::new(&problem, &guess, start.amplitude, settings)?.run();
    Ok(branch)
}

/// The amplitude of the first grazing `G1` of a branch (first contact), if it was located.
pub fn first_grazing(branch: &Branch) -> Option<f64> {
    branch
        .special_points
        .iter()
        .find(|s| s.kind == SpecialPointKind::Grazing && s.impacts_after == 1)
        .map(|s| s.parameter)
}
