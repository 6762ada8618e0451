//! The problem statement of a piecewise-smooth (hybrid) system: what a system *is*, separate
//! from how it is integrated.
//!
//! A hybrid system here is an ODE `x' = f_m(t, x)` whose right-hand side depends on a discrete
//! *mode* `m`, together with `K` scalar *switching functions* `h_k(t, x)`. The state space is cut
//! by the surfaces `h_k = 0`; the mode records on which side of every surface the state lies
//! (bit `k` of the mode is set when `h_k < 0`). When a trajectory reaches a surface the solver
//! stops exactly there, and either
//!
//! * flips the mode bit and carries on with the same state (a *crossing*; this is how a
//!   continuous contact force such as Hertz contact is expressed), or
//! * applies the system's *reset map* `x+ = R(t, x-)` (a hard impact with restitution) and
//!   chooses the new mode from the sign of `dh/dt` after the reset: a reset that sends the
//!   state back (a bounce) is applied at the bracket end on the old side, so the mode bit is
//!   unchanged; otherwise the bit flips. Precisely, the new bit is the side of `h` at the
//!   post-reset state (on the surface: the side `dh/dt` points to); see [`crate::solver`].
//!
//! A mode may also provide an *exact flow*: when the dynamics in that region are linear with
//! harmonic forcing (the free flight of a cantilever), the solver propagates the state and its
//! state-transition matrix in closed form instead of integrating.
//!
//! Every system carries one scalar *parameter* `p` (for the AFM model, the separation `Z`); the
//! derivatives with respect to it let the solver compute `dx(t)/dp` along with the monodromy
//! matrix, as pseudo-arclength continuation needs.

use nalgebra::DMatrix;

use crate::sensitivity::{jacobian_products, LinearisationBuffers};
use crate::taylor::{ClockPolynomial, TaylorSeries};

/// Which side of every switching surface a state lies on: bit `k` is set when `h_k < 0`.
///
/// With at most 32 surfaces, a `u32` names every region of state space.
pub type Mode = u32;

/// The maximum number of switching surfaces a system may declare (the bits of a [`Mode`]).
pub const MAX_SURFACES: usize = 32;

/// `+1` if `mode` has `h_k` on its positive side, `-1` if on its negative side (bit `k` set):
/// `side_sign * h_k` is positive on the current side of surface `k`.
pub(crate) fn side_sign(mode: Mode, k: usize) -> f64 {
    if mode & (1 << k) != 0 {
        -1.0
    } else {
        1.0
    }
}

/// Direction in which a trajectory crosses a switching surface `h = 0`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Direction {
    /// From `h > 0` to `h < 0` (`dh/dt < 0`): for a gap, the onset of contact.
    Down,
    /// From `h < 0` to `h > 0` (`dh/dt > 0`): for a gap, the release of contact.
    Up,
}

/// The partial derivatives of a switching function `h_k(t, x; p)` other than the gradient
/// with respect to the state.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SwitchingPartials {
    /// `dh/dt` at fixed state (non-zero when the surface moves, e.g. a separation ramp `Z(t)`).
    pub t: f64,
    /// `dh/dp` with respect to the system's parameter.
    pub p: f64,
}

/// A piecewise-smooth dynamical system: vector fields per mode, switching surfaces, optional
/// reset maps and optional exact flows.
///
/// All vectors are slices of length [`HybridSystem::dim`]; all matrices are `dim x dim`
/// `nalgebra` matrices supplied (already sized) by the caller, so that an implementation never
/// allocates.
pub trait HybridSystem {
    /// Dimension `n` of the state vector `x`.
    fn dim(&self) -> usize;

    /// Number `K` of switching functions (at most [`MAX_SURFACES`]).
    fn surface_count(&self) -> usize;

    /// The vector field `f_m(t, x)` of mode `mode`, written into `dxdt`.
    ///
    /// The solver evaluates the field of the current mode even at states that lie a rounding
    /// error on the other side of a surface (Runge-Kutta stages, the point just past an event),
    /// so `f_m` must be defined (finite) on a neighbourhood of its region.
    fn vector_field(&self, mode: Mode, t: f64, x: &[f64], dxdt: &mut [f64]);

    /// The Jacobian `df_m/dx` at `(t, x)`, written into `jacobian` (`n x n`).
    fn jacobian(&self, mode: Mode, t: f64, x: &[f64], jacobian: &mut DMatrix<f64>);

    /// The derivative `df_m/dp` of the vector field with respect to the system's parameter,
    /// written into `dfdp`. The default is zero (the parameter does not enter the field).
    fn parameter_derivative(&self, mode: Mode, t: f64, x: &[f64], dfdp: &mut [f64]) {
        let _ = (mode, t, x);
        dfdp.fill(0.0);
    }

    /// The field, its Jacobian and (if `dfdp` is `Some`) its parameter derivative at one point,
    /// from which the default [`HybridSystem::variational_field`] forms the variational
    /// equations' right-hand side. The default calls
    /// [`HybridSystem::vector_field`], [`HybridSystem::jacobian`] and
    /// [`HybridSystem::parameter_derivative`]; override it (with the same results) when the
    /// three share expensive work, such as a contact force and its slope.
    fn linearisation(
        &self,
        mode: Mode,
        t: f64,
        x: &[f64],
        dxdt: &mut [f64],
        jacobian: &mut DMatrix<f64>,
        dfdp: Option<&mut [f64]>,
    ) {
        self.vector_field(mode, t, x, dxdt);
        self.jacobian(mode, t, x, jacobian);
        if let Some(dfdp) = dfdp {
            self.parameter_derivative(mode, t, x, dfdp);
        }
    }

    /// The right-hand side of the variational equations at one point: the field `f_m(t, x)`
    /// into `dxdt`, and `J v` (`J = df_m/dx`) for every column `v` of `tangents` into the same
    /// column of `tangent_rates` (both column-major with `n` rows, as many columns as
    /// `tangents.len() / n`), plus `df_m/dp` on the last column when `parameter_column` is
    /// true: `Phi' = J Phi` for the transition matrix and `s' = J s + df/dp` for the parameter
    /// sensitivity (Hairer, Norsett, Wanner I, Sec. I.14).
    ///
    /// The default forms `J` and `df/dp` with [`HybridSystem::linearisation`] in `buffers` and
    /// multiplies (`n^2` multiply-adds per column). Override it, with the same results up to
    /// rounding, when `J` has a structure that makes the products cheaper (a mechanical system's
    /// `[[0, I], [-K, -C]]` blocks with a low-rank contact coupling); `buffers` is then free
    /// scratch space.
    #[allow(clippy::too_many_arguments)]
    fn variational_field(
        &self,
        mode: Mode,
        t: f64,
        x: &[f64],
        dxdt: &mut [f64],
        tangents: &[f64],
        tangent_rates: &mut [f64],
        parameter_column: bool,
        buffers: &mut LinearisationBuffers,
    ) {
        let LinearisationBuffers { jacobian, dfdp } = buffers;
        self.linearisation(
            mode,
            t,
            x,
            dxdt,
            jacobian,
            parameter_column.then_some(&mut dfdp[..]),
        );
        jacobian_products(
            jacobian,
            tangents,
            tangent_rates,
            parameter_column.then_some(&dfdp[..]),
        );
    }

    /// The switching function `h_k(t, x)`; the surface is `h_k = 0`.
    fn switching(&self, k: usize, t: f64, x: &[f64]) -> f64;

    /// The time derivative of `h_k` along the flow of mode `mode`:
    /// `dh_k/dt = dh_k/dt|_x + (grad_x h_k) . f_m(t, x)`.
    ///
    /// Local minima of `h_k` (grazing and near-grazing) are the zeros of this function.
    fn switching_rate(&self, k: usize, mode: Mode, t: f64, x: &[f64]) -> f64;

    /// The gradient `grad_x h_k` written into `gradient`, and the partials with respect to time
    /// and to the parameter. Used for saltation matrices and event-time sensitivities.
    fn switching_gradient(
        &self,
        k: usize,
        t: f64,
        x: &[f64],
        gradient: &mut [f64],
    ) -> SwitchingPartials;

    /// Whether `h_k` is affine in the state and in time, `h_k(t, x) = g . x + b t + c` with
    /// `g` and `b` constant (as [`HybridSystem::switching_gradient`] gives them, read once per
    /// solver). The default is `false`.
    ///
    /// Over a Runge-Kutta or Taylor step the interpolant of such an `h_k` is a polynomial in
    /// the step's clock, and the solver bounds it through its Bernstein coefficients: a step on
    /// which every surface's `h_k` is proven strictly monotone (no extremum; a crossing shows in
    /// the signs at the ends) or farther than [`crate::Settings::extremum_height`] from its
    /// surface is not sampled inside. A gap `Z(t) + sum_i q_i` with a constant or linear
    /// `Z(t)` is affine.
    fn switching_is_affine(&self, k: usize) -> bool {
        let _ = k;
        false
    }

    /// Whether reaching surface `k` in `direction` applies a reset map (a hard impact) rather
    /// than a plain crossing. The default is `false` for every surface.
    fn has_reset(&self, k: usize, direction: Direction) -> bool {
        let _ = (k, direction);
        false
    }

    /// Apply the reset map `x+ = R(t, x-)` at surface `k` in place, and write its Jacobian
    /// `dR/dx` into `jacobian` and its parameter derivative `dR/dp` into `dxdp`.
    ///
    /// Called only where [`HybridSystem::has_reset`] is `true`; the default is the identity.
    fn reset(
        &self,
        k: usize,
        direction: Direction,
        t: f64,
        x: &mut [f64],
        jacobian: &mut DMatrix<f64>,
        dxdp: &mut [f64],
    ) {
        let _ = (k, direction, t, x);
        jacobian.fill_with_identity();
        dxdp.fill(0.0);
    }

    /// The surface `k`, if any, whose switching function enters the field of mode `mode`
    /// through half-integer powers of `|h_k|` (Hertz contact: `F = c (-h)^{3/2}`), so that the
    /// solution is smooth in `sqrt|t - t_c|` but not in `t` next to a transversal crossing
    /// `t_c` of that surface. The solver then integrates the steps right after entering the
    /// mode through `k` and those approaching a crossing of `k` in the square root of the time
    /// from the crossing, keeping the method's order there (see [`crate::solver`]). The
    /// default is `None` (every field smooth up to its surfaces).
    fn half_power_surface(&self, mode: Mode) -> Option<usize> {
        let _ = mode;
        None
    }

    /// The highest order to which [`HybridSystem::taylor_series`] expands the solution of mode
    /// `mode`; 0 (the default) where the system gives no Taylor series (see [`crate::taylor`]
    /// for their use).
    fn taylor_order_limit(&self, mode: Mode) -> usize {
        let _ = mode;
        0
    }

    /// The Taylor coefficients, to `series.order()`, of the solution of `dx/ds = (dt/ds)
    /// f_mode(t(s), x)` through `x(0)` = the constant terms of `series` (set by the caller), in
    /// the clock offset `s` with `t(s)` = `clock`: every coefficient of `series` written.
    /// `false` if the series cannot be formed there.
    ///
    /// To be called only for modes with a positive [`HybridSystem::taylor_order_limit`] and
    /// orders up to it. A clock with `rate == 0` starts at the reference of a square-root clock,
    /// which a step starts from only at the crossing of the mode's
    /// [`HybridSystem::half_power_surface`] that entered the mode: the state is on that surface.
    fn taylor_series(
        &self,
        mode: Mode,
        clock: &ClockPolynomial,
        series: &mut TaylorSeries,
    ) -> bool {
        let _ = (mode, clock, series);
        false
    }

    /// The Taylor coefficients, to `tangents.order()` (at most `state.order()`; the solver asks for
    /// fewer under [`crate::SensitivityMethod::Decoupled`]), of a tangent matrix `V` (`n` rows,
    /// `tangents.dim() / n` columns) along the solution whose series is `state` (from
    /// [`HybridSystem::taylor_series`] with the same `mode` and `clock`): `dV/ds = (dt/ds) J(t(s),
    /// x(s)) V`, plus `(dt/ds) df/dp` on the last column when `parameter_column`. Each coefficient
    /// of `tangents` is a row-major matrix (component `row * columns + column`: the recurrences
    /// then run along rows of contiguous columns); the constant terms hold `V` at `s = 0`, and
    /// every other coefficient is written. `scratch` is free space the implementation may
    /// resize; the solver's has capacity for `(tangents.order() + 2) * columns` values, so
    /// that an implementation needing no more allocates nothing in a step.
    ///
    /// To be called only where [`HybridSystem::taylor_series`] returned `true` for `state`.
    fn taylor_tangents(
        &self,
        mode: Mode,
        clock: &ClockPolynomial,
        state: &TaylorSeries,
        tangents: &mut TaylorSeries,
        parameter_column: bool,
        scratch: &mut Vec<f64>,
    ) {
        let _ = (mode, clock, state, tangents, parameter_column, scratch);
    }

    /// Whether mode `mode` has a closed-form flow ([`HybridSystem::exact_flow`]).
    /// The default is `false`: every mode is integrated numerically.
    fn has_exact_flow(&self, mode: Mode) -> bool {
        let _ = mode;
        false
    }

    /// The longest time the solver may advance an exact flow in one step of mode `mode`.
    ///
    /// The flow has no truncation error; the bound exists so that the extrema of every
    /// switching function can be found by sampling inside each step. It should be a fraction
    /// (at most a quarter) of the shortest oscillation period present in that mode. Where the
    /// solver may skip extrema (finite [`crate::Settings::extremum_height`]) and the system
    /// bounds the switching functions' curvature
    /// ([`HybridSystem::switching_curvature_bound`]), steps proven clear of every surface
    /// are stretched beyond it.
    fn exact_step_limit(&self, mode: Mode) -> f64 {
        let _ = mode;
        f64::INFINITY
    }

    /// A rigorous upper bound of `|d^2 h_k / dt^2|` along the flow of mode `mode` from
    /// `(t0, x0)` over `[t0, t0 + dt]`, in switching-function units per time unit squared, or
    /// `None` if the system cannot bound it (the default).
    ///
    /// With the bound `M`, `h_k` stays within `M dt^2 / 8` of the chord between its values at
    /// the step's ends, so a step whose ends both lie farther than that from surface `k` cannot
    /// cross it; and `dh_k/dt` moves at most `M` per time unit, so end rates `r0`, `r1` of one
    /// sign with `|r0| + |r1| > M dt` leave no extremum inside. The solver uses this to skip
    /// the interior sampling of steps proven clear of every surface by more than
    /// [`crate::Settings::extremum_height`] (their extrema are then not reported) and of steps
    /// proven monotone. A bound that is too small makes the solver miss contacts: it must hold
    /// for every time in the interval, not only at `t0`.
    fn switching_curvature_bound(
        &self,
        k: usize,
        mode: Mode,
        t0: f64,
        x0: &[f64],
        dt: f64,
    ) -> Option<f64> {
        let _ = (k, mode, t0, x0, dt);
        None
    }

    /// The exact flow of mode `mode` from `(t0, x0)` at the equally spaced times
    /// `t0 + j dt / count`, `j = 1..count` (`count >= 1`): state `j` into
    /// `states[(j - 1) n .. j n]` (`states.len() >= count n`). The solver samples the
    /// switching functions inside exact steps with it. The default calls
    /// [`HybridSystem::exact_flow`] per point; override it when the flow over one spacing can
    /// be reused (a linear flow: one transition matrix and phase rotation for all points), with
    /// the same states up to rounding.
    fn exact_flow_grid(
        &self,
        mode: Mode,
        t0: f64,
        x0: &[f64],
        dt: f64,
        count: usize,
        states: &mut [f64],
    ) {
        let n = x0.len();
        for j in 1..=count {
            let fraction = j as f64 / count as f64;
            self.exact_flow(
                mode,
                t0,
                x0,
                dt * fraction,
                &mut states[(j - 1) * n..j * n],
                None,
                None,
            );
        }
    }

    /// The exact flow of mode `mode` from `(t0, x0)` over a time `dt` (which may be negative
    /// or zero): the state `x(t0 + dt)` into `x`, and optionally the state-transition matrix
    /// `dx(t0 + dt)/dx0` into `transition` and the parameter sensitivity `dx(t0 + dt)/dp`
    /// (for fixed `x0`) into `dxdp`.
    ///
    /// Called only where [`HybridSystem::has_exact_flow`] is `true`. The default leaves its
    /// outputs untouched, so a system that claims an exact flow must implement it.
    #[allow(clippy::too_many_arguments)]
    fn exact_flow(
        &self,
        mode: Mode,
        t0: f64,
        x0: &[f64],
        dt: f64,
        x: &mut [f64],
        transition: Option<&mut DMatrix<f64>>,
        dxdp: Option<&mut [f64]>,
    ) {
        let _ = (mode, t0, x0, dt, x, transition, dxdp);
    }

    /// The mode of state `x` at time `t`, from the signs of the switching functions
    /// (bit `k` set when `h_k(t, x) < 0`). Used to start an integration.
    fn mode_of(&self, t: f64, x: &[f64]) -> Mode {
        (0..self.surface_count()).fold(0, |mode, k| {
            if self.switching(k, t, x) < 0.0 {
                mode | (1 << k)
            } else {
                mode
            }
        })
    }
}
