//! Optional accelerations of a hybrid system: what a model may add to the core
//! ([`crate::HybridSystem`]) to be integrated faster, never to be integrated correctly.
//!
//! Every event guarantee of the solver (each crossing found and fired once, extrema of every
//! switching function reported, exact grazing, the transition matrix carried through events)
//! holds for a system that offers none of them. Each is a small trait; a system lists the
//! ones it implements in [`crate::HybridSystem::accelerations`]:
//!
//! * [`ExactFlow`]: a closed-form flow in some modes (free flight of a linear oscillator), so
//!   the solver steps it exactly, with its transition matrix, instead of integrating.
//! * [`TaylorExpansion`]: the Taylor series of the solution of a mode, so a step is one series
//!   of high order ([`crate::taylor`]).
//! * [`SwitchingStructure`]: what is known of the switching functions: affine in the state
//!   (their interpolant is a polynomial the solver bounds), a bound on their curvature (steps
//!   proven clear of every surface are not sampled inside), a surface entering a field through
//!   half-integer powers (the solver then steps next to its crossings in the square root of
//!   the time).

use nalgebra::DMatrix;

use crate::mode::Mode;
use crate::taylor::{ClockPolynomial, TaylorSeries};

/// The optional accelerations a system offers, each `None` when it offers none of that kind
/// ([`Accelerations::NONE`], the default of [`crate::HybridSystem::accelerations`]). A system
/// implementing the traits returns itself for each, e.g.
/// `Accelerations { exact_flow: Some(self), ..Accelerations::NONE }`.
#[derive(Clone, Copy)]
pub struct Accelerations<'a> {
    /// The closed-form flows of some modes.
    pub exact_flow: Option<&'a dyn ExactFlow>,
    /// The Taylor series of the solution of some modes.
    pub taylor: Option<&'a dyn TaylorExpansion>,
    /// What is known of the switching functions' shape.
    pub switching: Option<&'a dyn SwitchingStructure>,
}

impl<'a> Accelerations<'a> {
    /// No acceleration: every mode integrated by DOP853, every step sampled inside.
    pub const NONE: Self = Self {
        exact_flow: None,
        taylor: None,
        switching: None,
    };

    /// Whether mode `mode` has a closed-form flow ([`ExactFlow::has_exact_flow`]; `false`
    /// without one).
    #[inline]
    pub fn has_exact_flow(&self, mode: Mode) -> bool {
        self.exact_flow
            .is_some_and(|flow| flow.has_exact_flow(mode))
    }

    /// [`TaylorExpansion::taylor_order_limit`] of mode `mode`; 0 without series.
    pub fn taylor_order_limit(&self, mode: Mode) -> usize {
        self.taylor
            .map_or(0, |taylor| taylor.taylor_order_limit(mode))
    }

    /// [`SwitchingStructure::switching_is_affine`] for surface `k`; `false` when unknown.
    pub fn switching_is_affine(&self, k: usize) -> bool {
        self.switching
            .is_some_and(|switching| switching.switching_is_affine(k))
    }

    /// [`SwitchingStructure::switching_is_affine_in_state`] for surface `k`; `false` when
    /// unknown.
    pub fn switching_is_affine_in_state(&self, k: usize) -> bool {
        self.switching
            .is_some_and(|switching| switching.switching_is_affine_in_state(k))
    }

    /// [`SwitchingStructure::switching_time_series`] for surface `k` into `coefficients[1..]`
    /// (zeros without a switching structure).
    pub fn switching_time_series(
        &self,
        k: usize,
        clock: &ClockPolynomial,
        coefficients: &mut [f64],
    ) {
        match self.switching {
            Some(switching) => switching.switching_time_series(k, clock, coefficients),
            None => coefficients.iter_mut().skip(1).for_each(|c| *c = 0.0),
        }
    }

    /// [`SwitchingStructure::switching_has_series`] for surface `k`; `false` when unknown.
    pub fn switching_has_series(&self, k: usize) -> bool {
        self.switching
            .is_some_and(|switching| switching.switching_has_series(k))
    }

    /// [`SwitchingStructure::switching_series`] of surface `k` along `state`; `false` without a
    /// switching structure.
    pub fn switching_series(
        &self,
        k: usize,
        mode: Mode,
        clock: &ClockPolynomial,
        state: &TaylorSeries,
        coefficients: &mut [f64],
    ) -> bool {
        self.switching.is_some_and(|switching| {
            switching.switching_series(k, mode, clock, state, coefficients)
        })
    }

    /// [`SwitchingStructure::half_power_surface`] of mode `mode`; `None` when unknown.
    pub fn half_power_surface(&self, mode: Mode) -> Option<usize> {
        self.switching
            .and_then(|switching| switching.half_power_surface(mode))
    }

    /// [`SwitchingStructure::jacobian_diverges_at_crossing`] of mode `mode`; `false` when
    /// unknown.
    pub fn jacobian_diverges_at_crossing(&self, mode: Mode) -> bool {
        self.switching
            .is_some_and(|switching| switching.jacobian_diverges_at_crossing(mode))
    }

    /// [`SwitchingStructure::switching_curvature_bound`]; `None` when unknown.
    pub fn switching_curvature_bound(
        &self,
        k: usize,
        mode: Mode,
        t0: f64,
        x0: &[f64],
        dt: f64,
    ) -> Option<f64> {
        self.switching
            .and_then(|switching| switching.switching_curvature_bound(k, mode, t0, x0, dt))
    }
}

impl Default for Accelerations<'_> {
    fn default() -> Self {
        Self::NONE
    }
}

/// Closed-form flows: where the dynamics of a mode are linear with harmonic forcing (the free
/// flight of a cantilever), the solver propagates the state and its state-transition matrix
/// in closed form instead of integrating.
pub trait ExactFlow {
    /// Whether mode `mode` has a closed-form flow ([`ExactFlow::exact_flow`]).
    fn has_exact_flow(&self, mode: Mode) -> bool;

    /// The longest time the solver may advance an exact flow in one step of mode `mode`.
    ///
    /// The flow has no truncation error; the bound exists so that the extrema of every
    /// switching function can be found by sampling inside each step. It should be a fraction
    /// (at most a quarter) of the shortest oscillation period present in that mode. Where the
    /// solver may skip extrema (finite [`crate::Settings::extremum_height`]) and the system
    /// bounds the switching functions' curvature
    /// ([`SwitchingStructure::switching_curvature_bound`]), steps proven clear of every surface
    /// are stretched beyond it. The default is `f64::INFINITY` (no limit).
    fn exact_step_limit(&self, mode: Mode) -> f64 {
        let _ = mode;
        f64::INFINITY
    }

    /// The exact flow of mode `mode` from `(t0, x0)` over a time `dt` (which may be negative
    /// or zero): the state `x(t0 + dt)` into `x`, and optionally the state-transition matrix
    /// `dx(t0 + dt)/dx0` into `transition` and the parameter sensitivity `dx(t0 + dt)/dp`
    /// (for fixed `x0`) into `dxdp`.
    ///
    /// Called only where [`ExactFlow::has_exact_flow`] is `true`.
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
    );

    /// The exact flow of mode `mode` from `(t0, x0)` at the equally spaced times
    /// `t0 + j dt / count`, `j = 1..count` (`count >= 1`): state `j` into
    /// `states[(j - 1) n .. j n]` (`states.len() >= count n`). The solver samples the
    /// switching functions inside exact steps with it. The default calls
    /// [`ExactFlow::exact_flow`] per point; override it when the flow over one spacing can
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
}

/// Taylor series of the solution of a mode (by the recurrences of automatic differentiation;
/// see [`crate::taylor`]), which the solver sums as one step of high order.
pub trait TaylorExpansion {
    /// The highest order to which [`TaylorExpansion::taylor_series`] expands the solution of
    /// mode `mode`; 0 where it gives no Taylor series (see [`crate::taylor`] for their use).
    fn taylor_order_limit(&self, mode: Mode) -> usize;

    /// The Taylor coefficients, to `series.order()`, of the solution of `dx/ds = (dt/ds)
    /// f_mode(t(s), x)` through `x(0)` = the constant terms of `series` (set by the caller), in
    /// the clock offset `s` with `t(s)` = `clock`: every coefficient of `series` written.
    /// `false` if the series cannot be formed there.
    ///
    /// To be called only for modes with a positive [`TaylorExpansion::taylor_order_limit`] and
    /// orders up to it. A clock with `rate == 0` starts at the reference of a square-root clock,
    /// which a step starts from only at the crossing of the mode's
    /// [`SwitchingStructure::half_power_surface`] that entered the mode: the state is on that
    /// surface.
    ///
    /// `shared` is space the implementation may resize and keep intermediate series in (its
    /// own layout) for [`TaylorExpansion::taylor_tangents`] along the same series: the solver
    /// passes the same vector to both, the tangents' call (if any) right after this one. Its
    /// capacity is [`crate::SHARED_SERIES_CAPACITY`] values, so that an implementation needing
    /// no more allocates nothing in a step.
    fn taylor_series(
        &self,
        mode: Mode,
        clock: &ClockPolynomial,
        series: &mut TaylorSeries,
        shared: &mut Vec<f64>,
    ) -> bool;

    /// The Taylor coefficients, to `tangents.order()` (at most `state.order()`; the solver asks for
    /// fewer under [`crate::SensitivityMethod::Decoupled`]), of a tangent matrix `V` (`n` rows,
    /// `tangents.dim() / n` columns) along the solution whose series is `state` (from
    /// [`TaylorExpansion::taylor_series`] with the same `mode` and `clock`): `dV/ds = (dt/ds)
    /// J(t(s), x(s)) V`, plus `(dt/ds) df/dp` on the last column when `parameter_column`. Each
    /// coefficient of `tangents` is a row-major matrix (component `row * columns + column`: the
    /// recurrences then run along rows of contiguous columns); the constant terms hold `V` at `s =
    /// 0`, and every other coefficient is written. `scratch` is free space the implementation may
    /// resize; the solver's has capacity for `(tangents.order() + 2) * columns` values, so that an
    /// implementation needing no more allocates nothing in a step. `shared` is what
    /// [`TaylorExpansion::taylor_series`] left there when it computed `state` (the
    /// implementation may read and extend it).
    ///
    /// To be called only where [`TaylorExpansion::taylor_series`] returned `true` for `state`,
    /// with the `shared` it was given and nothing computed in between.
    #[allow(clippy::too_many_arguments)]
    fn taylor_tangents(
        &self,
        mode: Mode,
        clock: &ClockPolynomial,
        state: &TaylorSeries,
        shared: &mut Vec<f64>,
        tangents: &mut TaylorSeries,
        parameter_column: bool,
        scratch: &mut Vec<f64>,
    );
}

/// What is known of the shape of the switching functions, which lets the solver prove steps
/// free of crossings and extrema (and so skip sampling them inside) and choose the clock of a
/// step next to a surface that enters a field through half-integer powers. Every method's
/// default is "unknown".
pub trait SwitchingStructure {
    /// Whether `h_k` is affine in the state and in time, `h_k(t, x) = g . x + b t + c` with `g` and
    /// `b` constant (as [`crate::HybridSystem::switching_gradient`] gives them, read once per
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

    /// Whether `h_k` is affine in the state but not in time, `h_k(t, x) = g . x + b_k(t)` with
    /// `g` constant (as [`crate::HybridSystem::switching_gradient`] gives it, read once per
    /// solver) and a time part whose Taylor series [`SwitchingStructure::switching_time_series`]
    /// gives (a gap with a base motion `Y cos(w t)` in it). The default is `false`.
    ///
    /// Along a Taylor step's series such an `h_k` is still a polynomial in the step's clock
    /// offset, so the solver takes Taylor steps next to it as a half-power surface (its zeros
    /// ahead found on that polynomial) and may prove a Taylor step settled on it, as for an
    /// affine one; a Runge-Kutta step's interpolant of it is no polynomial and is sampled.
    fn switching_is_affine_in_state(&self, k: usize) -> bool {
        let _ = k;
        false
    }

    /// For an `h_k` affine in the state ([`SwitchingStructure::switching_is_affine_in_state`]),
    /// the Taylor coefficients `1..coefficients.len()` of its time part `b_k(t(s))` in the clock
    /// offset `s` of `clock` (`t(s) = start + rate s + curvature s^2`), written into
    /// `coefficients[1..]` (`coefficients[0]` is the caller's). Called only where
    /// `switching_is_affine_in_state(k)`; the default writes zeros (a constant time part).
    fn switching_time_series(&self, k: usize, clock: &ClockPolynomial, coefficients: &mut [f64]) {
        let _ = (k, clock);
        for c in coefficients.iter_mut().skip(1) {
            *c = 0.0;
        }
    }

    /// Whether the system gives the Taylor series of `h_k` along a step's state series
    /// ([`SwitchingStructure::switching_series`]) for an `h_k` that is not affine in the state
    /// (a standard linear solid's contact surface `d + rho^{2/3}`). The default is `false`.
    ///
    /// Along a Taylor step such an `h_k` is then a polynomial in the step's clock offset, used
    /// as an affine one's is (its zeros ahead for a half-power surface, the proof that a step
    /// is settled), and the step is kept within the reach at which that polynomial's last two
    /// terms stay below the state's tolerance; where the system cannot give it, the step is a
    /// Runge-Kutta step.
    fn switching_has_series(&self, k: usize) -> bool {
        let _ = k;
        false
    }

    /// For an `h_k` with [`SwitchingStructure::switching_has_series`], the Taylor coefficients
    /// `0..coefficients.len()` of `h_k(t(s), x(s))` in the clock offset `s` of `clock`, along
    /// the state's series `state` of mode `mode` (its order at least `coefficients.len() - 1`);
    /// `false` where the series does not exist there (`h_k` not analytic at the step's start).
    /// The default returns `false`.
    fn switching_series(
        &self,
        k: usize,
        mode: Mode,
        clock: &ClockPolynomial,
        state: &TaylorSeries,
        coefficients: &mut [f64],
    ) -> bool {
        let _ = (k, mode, clock, state, coefficients);
        false
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

    /// Whether the Jacobian of mode `mode`'s field grows without bound at its
    /// [`SwitchingStructure::half_power_surface`] (as `|h|^{-1/2}`: a field with a `|h|^{1/2}`
    /// term, for which [`SwitchingStructure::crossing_tangent_limit`] gives the limit at the
    /// crossing). The variational equations on a square-root clock are then smooth only on the
    /// clock centred exactly on the crossing: on one centred `eps` past it, `(dt/dsigma) J`
    /// has a branch point `sqrt(eps)` from the step's end, which a Runge-Kutta step integrates
    /// with a relative error of about `sqrt(eps / step)` that no control of the state's error
    /// sees. The solver therefore redoes a Runge-Kutta step in which a crossing of this mode's
    /// half-power surface fires on the square-root clock centred on the located crossing,
    /// ending there (see [`crate::solver`], "Half-power surfaces"); a Taylor step landing on
    /// the crossing is not redone, so a system declaring the divergence gives no series on a
    /// square-root clock centred ahead of a crossing in that mode
    /// ([`TaylorExpansion::taylor_series`] returns `false` there). The default is `false` (a
    /// Jacobian bounded next to the surface, as Hertz's `~ |h|^{1/2}`).
    fn jacobian_diverges_at_crossing(&self, mode: Mode) -> bool {
        let _ = mode;
        false
    }

    /// For a field that grows as `|h|^{1/2}` from its half-power surface (a viscous contact
    /// force `~ |h|^{1/2} dh/dt`), whose Jacobian therefore grows as `|h|^{-1/2}`: the limit at
    /// the crossing (`sigma = 0` of the square-root clock centred on it, where
    /// `dt/dsigma = 2 |sigma| = 0`) of `(dt/dsigma) J v` for every column `v` of `tangents`
    /// (column-major, `n` rows), plus `(dt/dsigma) df/dp` on the last column when
    /// `parameter_column`, written into `tangent_rates`; returns `true` when written. The
    /// default returns `false`: the limit is zero, as for any Jacobian bounded next to the
    /// surface (Hertz: `J ~ |h|^{1/2}`). Without it a step starting or ending on the crossing
    /// would take its stage there as zero and carry an error of the order of its length into
    /// the transition matrix.
    #[allow(clippy::too_many_arguments)]
    fn crossing_tangent_limit(
        &self,
        mode: Mode,
        t: f64,
        x: &[f64],
        tangents: &[f64],
        tangent_rates: &mut [f64],
        parameter_column: bool,
    ) -> bool {
        let _ = (mode, t, x, tangents, tangent_rates, parameter_column);
        false
    }
}
