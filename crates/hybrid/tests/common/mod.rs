//! Reference systems with known answers, shared by the integration tests.
#![allow(clippy::needless_range_loop)]
#![allow(dead_code)]

use hybrid::{
    Accelerations, Direction, ExactFlow, HybridSystem, Mode, SwitchingPartials, SwitchingStructure,
};
use nalgebra::DMatrix;

/// Forced damped linear oscillator `x'' + 2 zeta omega x' + omega^2 x = A cos(w t)`, state
/// `(x, v)`, parameter `p = A`. One switching function `h = x - level` that the tests place
/// out of reach (or not). Its exact solution is [`ForcedOscillator::exact`]; with
/// `exact_flow_limit = Some(l)` every mode uses that closed form with steps `<= l`.
#[derive(Clone, Copy, Debug)]
pub struct ForcedOscillator {
    pub omega: f64,
    pub zeta: f64,
    pub amplitude: f64,
    pub drive: f64,
    pub level: f64,
    pub exact_flow_limit: Option<f64>,
}

impl ForcedOscillator {
    pub fn reference() -> Self {
        Self {
            omega: 1.3,
            zeta: 0.05,
            amplitude: 0.7,
            drive: 1.1,
            level: 100.0,
            exact_flow_limit: None,
        }
    }

    fn particular(&self, t: f64) -> (f64, f64) {
        let (w0, w) = (self.omega, self.drive);
        let det = (w0 * w0 - w * w).powi(2) + (2.0 * self.zeta * w0 * w).powi(2);
        let a = self.amplitude * (w0 * w0 - w * w) / det;
        let b = self.amplitude * 2.0 * self.zeta * w0 * w / det;
        (
            a * (w * t).cos() + b * (w * t).sin(),
            -a * w * (w * t).sin() + b * w * (w * t).cos(),
        )
    }

    /// Homogeneous flow over `tau` of `(x0, v0)`.
    fn homogeneous(&self, tau: f64, x0: f64, v0: f64) -> (f64, f64) {
        let a = self.zeta * self.omega;
        let wd = self.omega * (1.0 - self.zeta * self.zeta).sqrt();
        let c1 = x0;
        let c2 = (v0 + a * c1) / wd;
        let e = (-a * tau).exp();
        let (s, c) = (wd * tau).sin_cos();
        (
            e * (c1 * c + c2 * s),
            e * ((-a * c1 + wd * c2) * c + (-a * c2 - wd * c1) * s),
        )
    }

    /// Exact state at `t0 + tau` from `(x0, v0)` at `t0`, its transition matrix and `dx/dA`.
    pub fn exact(&self, t0: f64, x0: [f64; 2], tau: f64) -> ([f64; 2], [[f64; 2]; 2], [f64; 2]) {
        let (xp0, vp0) = self.particular(t0);
        let (xp1, vp1) = self.particular(t0 + tau);
        let (hx, hv) = self.homogeneous(tau, x0[0] - xp0, x0[1] - vp0);
        let col0 = self.homogeneous(tau, 1.0, 0.0);
        let col1 = self.homogeneous(tau, 0.0, 1.0);
        let phi = [[col0.0, col1.0], [col0.1, col1.1]];
        // The particular solution is linear in A; dx/dA = x_p/A - Phi x_p(t0)/A.
        let (sx, sv) = self.homogeneous(tau, xp0, vp0);
        let dxda = [(xp1 - sx) / self.amplitude, (vp1 - sv) / self.amplitude];
        ([xp1 + hx, vp1 + hv], phi, dxda)
    }
}

impl HybridSystem for ForcedOscillator {
    fn dim(&self) -> usize {
        2
    }
    fn surface_count(&self) -> usize {
        1
    }
    fn vector_field(&self, _mode: Mode, t: f64, x: &[f64], dxdt: &mut [f64]) {
        dxdt[0] = x[1];
        dxdt[1] = -2.0 * self.zeta * self.omega * x[1] - self.omega * self.omega * x[0]
            + self.amplitude * (self.drive * t).cos();
    }
    fn jacobian(&self, _mode: Mode, _t: f64, _x: &[f64], jacobian: &mut DMatrix<f64>) {
        jacobian[(0, 0)] = 0.0;
        jacobian[(0, 1)] = 1.0;
        jacobian[(1, 0)] = -self.omega * self.omega;
        jacobian[(1, 1)] = -2.0 * self.zeta * self.omega;
    }
    fn parameter_derivative(&self, _mode: Mode, t: f64, _x: &[f64], dfdp: &mut [f64]) {
        dfdp[0] = 0.0;
        dfdp[1] = (self.drive * t).cos();
    }
    fn switching(&self, _k: usize, _t: f64, x: &[f64]) -> f64 {
        x[0] - self.level
    }
    fn switching_rate(&self, _k: usize, _mode: Mode, _t: f64, x: &[f64]) -> f64 {
        x[1]
    }
    fn switching_gradient(
        &self,
        _k: usize,
        _t: f64,
        _x: &[f64],
        g: &mut [f64],
    ) -> SwitchingPartials {
        g[0] = 1.0;
        g[1] = 0.0;
        SwitchingPartials::default()
    }
    fn accelerations(&self) -> Accelerations<'_> {
        Accelerations {
            exact_flow: Some(self),
            ..Accelerations::NONE
        }
    }
}

impl ExactFlow for ForcedOscillator {
    fn has_exact_flow(&self, _mode: Mode) -> bool {
        self.exact_flow_limit.is_some()
    }
    fn exact_step_limit(&self, _mode: Mode) -> f64 {
        self.exact_flow_limit.unwrap_or(f64::INFINITY)
    }
    fn exact_flow(
        &self,
        _mode: Mode,
        t0: f64,
        x0: &[f64],
        dt: f64,
        x: &mut [f64],
        transition: Option<&mut DMatrix<f64>>,
        dxdp: Option<&mut [f64]>,
    ) {
        let (state, phi, dxda) = self.exact(t0, [x0[0], x0[1]], dt);
        x.copy_from_slice(&state);
        if let Some(m) = transition {
            for i in 0..2 {
                for j in 0..2 {
                    m[(i, j)] = phi[i][j];
                }
            }
        }
        if let Some(s) = dxdp {
            s.copy_from_slice(&dxda);
        }
    }
}

/// Harmonic rotation `u' = v, v' = -u` from `(cos(-t_c), sin(t_c))`, so `u = cos(t - t_c)`;
/// switching function `h = c - u` (a surface crossed twice per period when `|c| < 1`, a dip of
/// depth `1 - c` around `t_c + 2 pi k` when `c` is just below 1). The field is the same in both
/// modes. With `exact_flow_limit = Some(l)` the rotation is used as an exact flow. With
/// `curvature_bound`, the system bounds `|h''| = |u| <= sqrt(u^2 + v^2)` (the radius, constant
/// along the flow), so that steps clear of the surface may go unsampled.
#[derive(Clone, Copy, Debug)]
pub struct Rotation {
    pub c: f64,
    pub t_c: f64,
    pub exact_flow_limit: Option<f64>,
    pub curvature_bound: bool,
    /// Whether `h = c - x_0` is declared affine (the solver may then skip sampling steps on
    /// which its interpolant is proven monotone).
    pub affine: bool,
}

impl Rotation {
    pub fn initial_state(&self) -> [f64; 2] {
        [(-self.t_c).cos(), self.t_c.sin()]
    }
}

impl HybridSystem for Rotation {
    fn dim(&self) -> usize {
        2
    }
    fn surface_count(&self) -> usize {
        1
    }
    fn vector_field(&self, _mode: Mode, _t: f64, x: &[f64], dxdt: &mut [f64]) {
        dxdt[0] = x[1];
        dxdt[1] = -x[0];
    }
    fn jacobian(&self, _mode: Mode, _t: f64, _x: &[f64], j: &mut DMatrix<f64>) {
        j[(0, 0)] = 0.0;
        j[(0, 1)] = 1.0;
        j[(1, 0)] = -1.0;
        j[(1, 1)] = 0.0;
    }
    fn switching(&self, _k: usize, _t: f64, x: &[f64]) -> f64 {
        self.c - x[0]
    }
    fn switching_rate(&self, _k: usize, _mode: Mode, _t: f64, x: &[f64]) -> f64 {
        -x[1]
    }
    fn switching_gradient(
        &self,
        _k: usize,
        _t: f64,
        _x: &[f64],
        g: &mut [f64],
    ) -> SwitchingPartials {
        g[0] = -1.0;
        g[1] = 0.0;
        SwitchingPartials::default()
    }
    fn accelerations(&self) -> Accelerations<'_> {
        Accelerations {
            exact_flow: Some(self),
            switching: Some(self),
            ..Accelerations::NONE
        }
    }
}

impl ExactFlow for Rotation {
    fn has_exact_flow(&self, _mode: Mode) -> bool {
        self.exact_flow_limit.is_some()
    }
    fn exact_step_limit(&self, _mode: Mode) -> f64 {
        self.exact_flow_limit.unwrap_or(f64::INFINITY)
    }
    fn exact_flow(
        &self,
        _mode: Mode,
        _t0: f64,
        x0: &[f64],
        dt: f64,
        x: &mut [f64],
        transition: Option<&mut DMatrix<f64>>,
        dxdp: Option<&mut [f64]>,
    ) {
        let (s, c) = dt.sin_cos();
        x[0] = c * x0[0] + s * x0[1];
        x[1] = -s * x0[0] + c * x0[1];
        if let Some(m) = transition {
            m[(0, 0)] = c;
            m[(0, 1)] = s;
            m[(1, 0)] = -s;
            m[(1, 1)] = c;
        }
        if let Some(p) = dxdp {
            p.fill(0.0);
        }
    }
}

impl SwitchingStructure for Rotation {
    fn switching_is_affine(&self, _k: usize) -> bool {
        self.affine
    }
    fn switching_curvature_bound(
        &self,
        _k: usize,
        _mode: Mode,
        _t0: f64,
        x0: &[f64],
        _dt: f64,
    ) -> Option<f64> {
        self.curvature_bound.then(|| x0[0].hypot(x0[1]))
    }
}

/// Bouncing ball `x' = v, v' = -g`, surface `h = x`, reset `v+ = -e v-` on the way down.
#[derive(Clone, Copy, Debug)]
pub struct BouncingBall {
    pub gravity: f64,
    pub restitution: f64,
}

impl BouncingBall {
    /// Impact times of a ball dropped from rest at height `x0` at `t = 0`:
    /// `t_1 = sqrt(2 x0 / g)`, `t_n = t_1 + 2 t_1 (e + ... + e^(n-1))`.
    pub fn impact_times(&self, x0: f64, count: usize) -> Vec<f64> {
        let t1 = (2.0 * x0 / self.gravity).sqrt();
        let e = self.restitution;
        (0..count)
            .map(|n| t1 + 2.0 * t1 * e * (1.0 - e.powi(n as i32)) / (1.0 - e))
            .collect()
    }

    /// The Zeno time `t_1 (1 + 2 e / (1 - e))` at which the impacts accumulate.
    pub fn zeno_time(&self, x0: f64) -> f64 {
        let t1 = (2.0 * x0 / self.gravity).sqrt();
        t1 * (1.0 + 2.0 * self.restitution / (1.0 - self.restitution))
    }
}

impl HybridSystem for BouncingBall {
    fn dim(&self) -> usize {
        2
    }
    fn surface_count(&self) -> usize {
        1
    }
    fn vector_field(&self, _mode: Mode, _t: f64, x: &[f64], dxdt: &mut [f64]) {
        dxdt[0] = x[1];
        dxdt[1] = -self.gravity;
    }
    fn jacobian(&self, _mode: Mode, _t: f64, _x: &[f64], j: &mut DMatrix<f64>) {
        j.fill(0.0);
        j[(0, 1)] = 1.0;
    }
    fn switching(&self, _k: usize, _t: f64, x: &[f64]) -> f64 {
        x[0]
    }
    fn switching_rate(&self, _k: usize, _mode: Mode, _t: f64, x: &[f64]) -> f64 {
        x[1]
    }
    fn switching_gradient(
        &self,
        _k: usize,
        _t: f64,
        _x: &[f64],
        g: &mut [f64],
    ) -> SwitchingPartials {
        g[0] = 1.0;
        g[1] = 0.0;
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
        restitution_reset(self.restitution, x, jacobian, dxdp);
    }
}

/// Oscillator `x'' + c x' + k x = A cos(w t) + F`, with a Hertz-like contact force
/// `F = -stiffness (x - d)^{3/2}` when the gap `h = d - x` is negative (continuous at `h = 0`).
/// Parameter `p = d` (the obstacle position, like the AFM separation).
#[derive(Clone, Copy, Debug)]
pub struct HertzOscillator {
    pub damping: f64,
    pub stiffness_linear: f64,
    pub amplitude: f64,
    pub drive: f64,
    pub obstacle: f64,
    pub contact_stiffness: f64,
    /// Whether the contact mode declares the gap its half-power surface (the solver then
    /// steps next to contact onset and release on a square-root clock).
    pub half_power: bool,
    /// Whether `h = obstacle - x_0` is declared affine.
    pub affine: bool,
}

impl HertzOscillator {
    pub fn reference() -> Self {
        Self {
            damping: 0.1,
            stiffness_linear: 1.0,
            amplitude: 1.0,
            drive: 1.2,
            obstacle: 0.8,
            contact_stiffness: 20.0,
            half_power: true,
            affine: false,
        }
    }
}

impl HybridSystem for HertzOscillator {
    fn dim(&self) -> usize {
        2
    }
    fn surface_count(&self) -> usize {
        1
    }
    fn vector_field(&self, mode: Mode, t: f64, x: &[f64], dxdt: &mut [f64]) {
        let contact = if mode & 1 != 0 {
            -self.contact_stiffness * (x[0] - self.obstacle).max(0.0).powf(1.5)
        } else {
            0.0
        };
        dxdt[0] = x[1];
        dxdt[1] = -self.damping * x[1] - self.stiffness_linear * x[0]
            + self.amplitude * (self.drive * t).cos()
            + contact;
    }
    fn jacobian(&self, mode: Mode, _t: f64, x: &[f64], j: &mut DMatrix<f64>) {
        let dcontact = if mode & 1 != 0 {
            -1.5 * self.contact_stiffness * (x[0] - self.obstacle).max(0.0).sqrt()
        } else {
            0.0
        };
        j[(0, 0)] = 0.0;
        j[(0, 1)] = 1.0;
        j[(1, 0)] = -self.stiffness_linear + dcontact;
        j[(1, 1)] = -self.damping;
    }
    fn parameter_derivative(&self, mode: Mode, _t: f64, x: &[f64], dfdp: &mut [f64]) {
        dfdp[0] = 0.0;
        dfdp[1] = if mode & 1 != 0 {
            1.5 * self.contact_stiffness * (x[0] - self.obstacle).max(0.0).sqrt()
        } else {
            0.0
        };
    }
    fn switching(&self, _k: usize, _t: f64, x: &[f64]) -> f64 {
        self.obstacle - x[0]
    }
    fn switching_rate(&self, _k: usize, _mode: Mode, _t: f64, x: &[f64]) -> f64 {
        -x[1]
    }
    fn switching_gradient(
        &self,
        _k: usize,
        _t: f64,
        _x: &[f64],
        g: &mut [f64],
    ) -> SwitchingPartials {
        g[0] = -1.0;
        g[1] = 0.0;
        SwitchingPartials { t: 0.0, p: 1.0 }
    }
    fn accelerations(&self) -> Accelerations<'_> {
        Accelerations {
            switching: Some(self),
            ..Accelerations::NONE
        }
    }
}

impl SwitchingStructure for HertzOscillator {
    fn half_power_surface(&self, mode: Mode) -> Option<usize> {
        (self.half_power && mode & 1 != 0).then_some(0)
    }
    fn switching_is_affine(&self, _k: usize) -> bool {
        self.affine
    }
}

/// Impact oscillator `x'' + c x' + k x = A cos(w t)` with a rigid obstacle at `x = d`
/// (`h = d - x`) and restitution `e` (`v+ = -e v-`). Parameter `p = A`.
#[derive(Clone, Copy, Debug)]
pub struct ImpactOscillator {
    pub damping: f64,
    pub stiffness: f64,
    pub amplitude: f64,
    pub drive: f64,
    pub obstacle: f64,
    pub restitution: f64,
}

impl ImpactOscillator {
    pub fn reference() -> Self {
        Self {
            damping: 0.1,
            stiffness: 1.0,
            amplitude: 1.0,
            drive: 1.2,
            obstacle: 0.5,
            restitution: 0.8,
        }
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
        dxdt[1] =
            -self.damping * x[1] - self.stiffness * x[0] + self.amplitude * (self.drive * t).cos();
    }
    fn jacobian(&self, _mode: Mode, _t: f64, _x: &[f64], j: &mut DMatrix<f64>) {
        j[(0, 0)] = 0.0;
        j[(0, 1)] = 1.0;
        j[(1, 0)] = -self.stiffness;
        j[(1, 1)] = -self.damping;
    }
    fn parameter_derivative(&self, _mode: Mode, t: f64, _x: &[f64], dfdp: &mut [f64]) {
        dfdp[0] = 0.0;
        dfdp[1] = (self.drive * t).cos();
    }
    fn switching(&self, _k: usize, _t: f64, x: &[f64]) -> f64 {
        self.obstacle - x[0]
    }
    fn switching_rate(&self, _k: usize, _mode: Mode, _t: f64, x: &[f64]) -> f64 {
        -x[1]
    }
    fn switching_gradient(
        &self,
        _k: usize,
        _t: f64,
        _x: &[f64],
        g: &mut [f64],
    ) -> SwitchingPartials {
        g[0] = -1.0;
        g[1] = 0.0;
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
        restitution_reset(self.restitution, x, jacobian, dxdp);
    }
}

/// Rotation `u = cos t, v = -sin t` with three switching functions:
/// `h0 = 0.5 - u`, `h1 = v - 0.2`, `h2 = u - 0.5` (`h2 = -h0`: both cross at the same instants,
/// in opposite directions). The field is the same in every mode.
#[derive(Clone, Copy, Debug)]
pub struct ThreeSurfaces;

impl HybridSystem for ThreeSurfaces {
    fn dim(&self) -> usize {
        2
    }
    fn surface_count(&self) -> usize {
        3
    }
    fn vector_field(&self, _mode: Mode, _t: f64, x: &[f64], dxdt: &mut [f64]) {
        dxdt[0] = x[1];
        dxdt[1] = -x[0];
    }
    fn jacobian(&self, _mode: Mode, _t: f64, _x: &[f64], j: &mut DMatrix<f64>) {
        j[(0, 0)] = 0.0;
        j[(0, 1)] = 1.0;
        j[(1, 0)] = -1.0;
        j[(1, 1)] = 0.0;
    }
    fn switching(&self, k: usize, _t: f64, x: &[f64]) -> f64 {
        match k {
            0 => 0.5 - x[0],
            1 => x[1] - 0.2,
            _ => x[0] - 0.5,
        }
    }
    fn switching_rate(&self, k: usize, _mode: Mode, _t: f64, x: &[f64]) -> f64 {
        match k {
            0 => -x[1],
            1 => -x[0],
            _ => x[1],
        }
    }
    fn switching_gradient(
        &self,
        k: usize,
        _t: f64,
        _x: &[f64],
        g: &mut [f64],
    ) -> SwitchingPartials {
        match k {
            0 => g.copy_from_slice(&[-1.0, 0.0]),
            1 => g.copy_from_slice(&[0.0, 1.0]),
            _ => g.copy_from_slice(&[1.0, 0.0]),
        }
        SwitchingPartials::default()
    }
}

/// The impact law `v+ = -e v-` on the velocity `x[1]` of a state `(x, v)`, with its Jacobian
/// `diag(1, -e)` and no parameter dependence (the reset of the bouncing ball and of the impact
/// oscillator).
fn restitution_reset(
    restitution: f64,
    x: &mut [f64],
    jacobian: &mut DMatrix<f64>,
    dxdp: &mut [f64],
) {
    x[1] *= -restitution;
    jacobian.fill_with_identity();
    jacobian[(1, 1)] = -restitution;
    dxdp.fill(0.0);
}
