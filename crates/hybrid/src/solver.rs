//! The hybrid solver: one step at a time ([`Solver::step`] is the primitive), Runge-Kutta
//! (DOP853), Taylor-series or exact-flow steps, never across a switching surface.
//!
//! # Events and the rules that keep them unique
//!
//! * At the start of every step, each `h_k` is *taken* to have the sign its mode bit says
//!   (bit set: negative), whatever its computed value; a zero at the very start of a step is
//!   therefore never a new crossing, and an event never fires twice.
//! * A crossing needs `h_k` strictly on the other side at a sample point or at a located
//!   extremum. The event is located on the first monotone piece where that happens (pieces are
//!   delimited by samples and extrema), to `event_time_tolerance * max(|t|, |step|)`, or until
//!   both bracket ends have `|h| <= event_value_tolerance`.
//! * The returned state is on the side of the *new* mode (or exactly on the surface): for a
//!   crossing the bracket end past the surface; for a reset that sends the state back to the
//!   side it came from (a bounce), the bracket end before the surface.
//! * **Exact grazing.** A minimum of `h_k` that touches zero without going strictly negative
//!   fires no event: it is reported as an [`Extremum`] with value `0` (the grazing quantity
//!   continuation tracks). A minimum that dips strictly below zero, however little, fires two
//!   events (down, then up), both flagged `grazing` when `|dh/dt| < grazing_rate`; each event
//!   advances time past its bracket, so neither repeats.
//! * **Rounding at the surface.** A sample computed past surface `k` by no more than
//!   `event_value_tolerance`, where `dh_k/dt` points into the mode at it and at the previous
//!   sample point with no extremum between (so that sampling takes `h_k` to be monotone there,
//!   away from the surface), is no crossing: it is the rounding of `h_k` next to zero, as in
//!   the first nanoseconds of a contact only a rounding error deep. A crossing located in a
//!   rejected trial that started on the surface moving into the mode is searched from the
//!   maximum of the excursion (`crate::event_location::turnaround`), and a crossing nearer
//!   than `1024 eps |t|` is not landed on: the controller shortens the step, and the event is
//!   located in the step it accepts.
//! * A reset chooses its bracket end from the sign of `dh_k/dt` just after the reset
//!   (evaluated with the pre-event mode's field) at the far end: the near end if the state
//!   bounces back, the far end if it goes through. The new mode bit of surface `k` is then the
//!   side of `h_k` at the post-reset state (on the surface, the side `dh_k/dt` points to), so
//!   the mode always matches the side the state is on and no later crossing can be missed;
//!   other bits are unchanged. A Zeno accumulation (a bouncing ball coming to rest) ends in
//!   [`HybridError::TooManyEvents`].
//! * Resolution: an extremum is found when `dh/dt` changes sign between neighbouring samples
//!   (`samples_per_step` interior points per step); two extrema closer than the sample spacing
//!   (a minimum and a maximum between the same two samples) are not seen, and nor is a dip
//!   through a surface that lies between them.
//! * Steps proven clear. With a finite `Settings::extremum_height` and a system that bounds
//!   `|h_k''|` ([`HybridSystem::switching_curvature_bound`]), a step on the positive side of
//!   every surface whose chord between its end values stays above the height even when bent
//!   by `M dt^2 / 8` is sampled at its ends only, and reports no extrema; an exact-flow step is
//!   stretched (beyond `exact_step_limit`) as far as `h_k(t0) + h_k'(t0) s - M s^2 / 2` stays
//!   above the height. In a step that is sampled, a sample interval whose chord bent by
//!   `M spacing^2 / 8` stays above the height is not searched for an extremum (free flight
//!   between contacts, whose gap minima clear the sample). At any height, a step whose end
//!   rates have one sign and `|r0| + |r1| > M dt` is monotone (the rate cannot reach zero in
//!   between) and is sampled at its ends only. None of these can hide a crossing: the bound
//!   is rigorous.
//! * Steps settled on their interpolant. Where every `h_k` is affine in the state and time
//!   ([`HybridSystem::switching_is_affine`]), its interpolant over a Runge-Kutta step is a
//!   polynomial of degree 7 in the step's clock (20 over a Taylor step: the series itself), and the Bernstein coefficients of it and of
//!   its derivative bound them on the whole step (`crate::bernstein`). A step on which every
//!   `h_k` is proven strictly monotone (both end rates of that sign too), or above the surface
//!   and the extremum height, is sampled at its ends only: it holds no extremum the samples
//!   could find, and at most one crossing per surface, which the signs at its ends show and
//!   which is located on the interpolant as usual. Inside a Hertz contact every step but the
//!   one holding the deepest indentation is monotone. The bound is rigorous for the
//!   interpolant, which is what sampling inspects too.
//!
//! # Step-size control
//!
//! Hairer's DOP853 controller (`safe = 0.9`, step ratio in `[1/3, 6]`, no growth right after a
//! rejection) on the state components, and on the sensitivities if
//! `Settings::sensitivity_tolerance` is set. Two additions for non-smooth fields: a rejected
//! trial that ends across a switching surface is retried once, landing `1e-6` of a step past
//! the crossing estimated by cubic Hermite interpolation of `h` (so the kink of the field is
//! inside the step's last millionth instead of forcing a sequence of shrinking steps); and on
//! successive rejections the error's actual order in `h` is estimated from the last two
//! attempts (far below 8 next to a singularity such as a Hertz contact onset).
//!
//! Before each Runge-Kutta step the next crossing is predicted from the state (the quadratic
//! in time of `h_k`, its rate, and the rate's derivative along the field). A proposed step
//! reaching `LANDING_REACH` of the predicted distance is stretched to land `1e-3` of the
//! distance past the crossing, so one step holds it and the event is located by dense output.
//! If that landing is rejected, the distance from which a landing should pass is estimated
//! from the rejected error, and the crossing is approached in steps of at most
//! `APPROACH_FRACTION` of the remaining distance until a landing is tried from there.
//!
//! # Half-power surfaces: the square-root clock
//!
//! Where a mode's field contains `|h_k|^{3/2}` (Hertz contact;
//! [`HybridSystem::half_power_surface`]), the solution next to a transversal crossing `t_c`
//! behaves like `|t - t_c|^{7/2}`: a step in time that starts or ends there has an error of
//! order 3.5 in its length, whatever the method's order, so onset and release used to cost a
//! geometric sequence of short steps each, and the variational equations (whose Jacobian goes
//! like `|h|^{1/2}`) carried errors the state-only controller did not see. In
//! `sigma = sign(t - t_c) sqrt|t - t_c|` the same solution is smooth, so such steps run on a
//! square-root clock (`crate::clock`):
//!
//! * after entering the mode through the surface, from the event, while the time since it is
//!   below `ROOT_CLOCK_SPAN` proposed steps;
//! * towards a crossing predicted within `ROOT_APPROACH` proposed steps, centred on it as
//!   located on the last step's dense output continued (the solution is smooth up to it); the
//!   step that reaches it ends exactly there (`sigma = 0`, `ROOT_OVERSHOOT` past the located
//!   crossing). Without a last step to continue, a probe just past the predicted crossing
//!   locates it on its own dense output when the kink makes it fail. A rejected trial that
//!   passed a crossing of the surface is likewise located on its dense output and the clock
//!   re-centred there.
//!
//! # Taylor-series steps
//!
//! Where the system gives the Taylor series of the mode's solution
//! ([`HybridSystem::taylor_series`]; the AFM model in Hertz contact), a step is one series of
//! order 20 in the step's clock offset (`crate::taylor`), as long as its last two terms stay
//! below the tolerance (Jorba and Zou 2005); the tangents come from the system's tangent series
//! along it ([`HybridSystem::taylor_tangents`]). The clock is the one in which the solution is
//! analytic up to its nearest non-smooth point: the square-root clock from the crossing that
//! entered the mode, until the crossing out of it that the last series predicts (its first
//! zero of the half-power surface within two reaches) is nearer (the series of a step is
//! re-centred on a crossing inside its own reach on that condition too, so that no series is
//! expanded next to the entering crossing's half power: a grazing contact, shorter than that
//! reach, is one step on the clock of its onset); then the square-root clock
//! centred `ROOT_OVERSHOOT` past that predicted crossing, re-centred on the zero of its own
//! series when they differ, so that the step landing on its reference holds the crossing, which
//! is then located on the series like any other. A ridge of that surface (approached and left
//! without a crossing: the indentation's shallow minimum between two merged contacts), seen
//! ahead on the series or passed earlier in the mode, puts branch points of `|h|^{1/2}` next to
//! the real axis that the state's last terms do not show: the step then stays within half
//! their distance (`crate::taylor::surface_ahead`, `TaylorStep::radius_reach`). The series is
//! the step's dense output, and
//! its polynomial in the switching function carries the Bernstein tests above. A system that
//! gives no series, a series that cannot be formed (a grazing touch), a crossing predicted past
//! the reference, or a reach collapsing below `1e-3` of the last series step hands the step to
//! DOP853. Measured on one period at `A/A0 = 0.5` (Biolever on mica, three impacts, tolerance
//! 1e-12): 24 series steps and 2 DOP853 steps for the three contacts, where DOP853 alone took
//! 74 accepted and 21 rejected steps (1357 evaluations of the field).
//!
//! Measured on one period of the Biolever on mica (`cargo run --release -p afm --example
//! monodromy_error`, state-only error control): at `A/A0 = 0.95` 461 RHS evaluations instead of
//! 633 stepping in time, and the monodromy matrix within 4.2e-8 (relative) of a run with the
//! sensitivities under error control instead of 2.4e-5; at `A/A0 = 0.5` (three impacts) 1378
//! instead of 1946, and 1.1e-7 instead of 5.5e-5.

use nalgebra::{DMatrix, DMatrixView};

use crate::bernstein::{stays_above, strict_sign};
use crate::clock::Clock;
use crate::dop853::Dop853;
use crate::error::HybridError;
use crate::event::{Event, Extremum};
use crate::event_location::{
    crossing_guess, locate_sign_change, turnaround, Bracket, CubicHermite,
};
use crate::extrema::Clearance;
use crate::sensitivity::{Sensitivity, VariationalField};
use crate::settings::Settings;
use crate::system::{side_sign, Direction, HybridSystem, Mode, MAX_SURFACES};
use crate::taylor::{
    surface_ahead, tangent_control, ClockPolynomial, Ridge, SurfaceAhead, TaylorStep, TAYLOR_ORDER,
};
use crate::workspace::{Buffers, SolverWorkspace};

/// Why [`Solver::step`] returned.
#[derive(Debug, Clone, PartialEq)]
pub enum StepOutcome {
    /// An ordinary step ended before `t_end`, with no event.
    Internal,
    /// The step was truncated at an event on a switching surface (already applied: the solver
    /// is in the new mode, with the post-event state).
    Event(Event),
    /// The solver reached `t_end` exactly.
    EndTime,
}

/// Work counters of a solver.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Statistics {
    /// Accepted steps, Runge-Kutta and exact-flow.
    pub steps: usize,
    /// Rejected Runge-Kutta step attempts.
    pub rejected_steps: usize,
    /// Accepted exact-flow steps (included in `steps`).
    pub exact_steps: usize,
    /// Evaluations of `HybridSystem::vector_field` by the integrator (stages, dense output,
    /// events; each augmented evaluation counts once).
    pub rhs_evaluations: usize,
    /// Events fired.
    pub events: usize,
    /// Accepted Taylor-series steps (included in `steps`).
    pub series_steps: usize,
    /// Steps sampled inside (at `samples_per_step` interior points) for extrema and brief
    /// dips; the others were proven clear of the surfaces or settled on their interpolant and
    /// sampled at their ends only (see the module docs).
    pub sampled_steps: usize,
}

/// What produced the last step, for interpolation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum StepKind {
    /// No step taken yet.
    None,
    /// A DOP853 step with dense output.
    RungeKutta,
    /// An exact-flow step.
    Exact,
    /// A Taylor-series step (the series is its dense output).
    Taylor,
}

/// A stepper for a [`HybridSystem`]: integrates mode by mode, stops at every event, and carries
/// the state-transition matrix and parameter sensitivity through events (saltation).
pub struct Solver<'a, S: HybridSystem + ?Sized> {
    system: &'a S,
    settings: Settings,
    sensitivity: Sensitivity,
    n: usize,
    surfaces: usize,
    dim: usize,
    t: f64,
    mode: Mode,
    /// Every heap buffer (the state and its sensitivities, the stepper's workspace, samples,
    /// scratch vectors and matrices): handed from one solver to the next by
    /// [`Solver::into_workspace`] and [`Solver::with_workspace`].
    buffers: Buffers,
    proposed_step: Option<f64>,
    landing_limit: Option<f64>,
    steps_in_mode: usize,
    first_same_as_last: bool,
    /// `dt/dsigma` with which stage 0 holds the derivative when `first_same_as_last`.
    stage0_rate: f64,
    /// The surface and time of the event that entered the current mode, if one did.
    entered: Option<(usize, f64)>,
    /// The clock of the last Runge-Kutta step and its reading at the step start.
    clock: Clock,
    sigma_start: f64,
    kind: StepKind,
    step_mode: Mode,
    step_start: f64,
    step_end: f64,
    full_dense: bool,
    /// Whether the last step was proven clear of every surface before it was taken (an exact
    /// step inside the span of [`Solver::clear_exact_span`], stretched or not).
    proven_clear: bool,
    /// Whether every switching function is affine (gradients and drifts in the buffers), so
    /// that a Runge-Kutta step may be proven settled on its interpolant.
    affine_switching: bool,
    /// The crossing of the mode's half-power surface that the last Taylor step's series
    /// predicts (its first zero up to [`RELEASE_LOOKAHEAD`] reaches past the step).
    predicted_crossing: Option<f64>,
    /// The last ridge of the mode's half-power surface a Taylor step's series showed (time and
    /// half width in time units), which bounds the radius of every later series in the mode,
    /// after it as before it.
    ridge: Option<Ridge>,
    /// The time length of the last Taylor step.
    last_series_step: f64,
    statistics: Statistics,
}

impl<'a, S: HybridSystem + ?Sized> Solver<'a, S> {
    /// A solver at `(t0, x0)`, in the mode [`HybridSystem::mode_of`] gives, with the
    /// transition matrix the identity and the parameter sensitivity zero. Allocates every
    /// buffer the steps use.
    ///
    /// # Errors
    /// [`HybridError::InvalidSettings`], [`HybridError::DimensionMismatch`] (`x0` length),
    /// [`HybridError::TooManySurfaces`], [`HybridError::NonFiniteState`] (`t0` or `x0`).
    pub fn new(
        system: &'a S,
        t0: f64,
        x0: &[f64],
        sensitivity: Sensitivity,
        settings: Settings,
    ) -> Result<Self, HybridError> {
        Self::with_workspace(
            system,
            t0,
            x0,
            sensitivity,
            settings,
            SolverWorkspace::default(),
        )
    }

    /// A solver like [`Solver::new`] that takes its buffers from `workspace` (released by
    /// [`Solver::into_workspace`] of an earlier solver) instead of allocating them, if they fit
    /// (the same state dimension, surface count, sensitivity, samples per step and sensitivity
    /// tolerance; otherwise it allocates). The run is identical to one from a new solver.
    ///
    /// # Errors
    /// As [`Solver::new`].
    pub fn with_workspace(
        system: &'a S,
        t0: f64,
        x0: &[f64],
        sensitivity: Sensitivity,
        settings: Settings,
        workspace: SolverWorkspace,
    ) -> Result<Self, HybridError> {
        settings.validate()?;
        let n = system.dim();
        check_start(n, t0, x0)?;
        let surfaces = system.surface_count();
        if surfaces > MAX_SURFACES {
            return Err(HybridError::TooManySurfaces {
                surfaces,
                max: MAX_SURFACES,
            });
        }
        let mut buffers = match workspace.buffers {
            Some(buffers) if buffers.fits(n, surfaces, sensitivity, &settings) => buffers,
            _ => Buffers::allocate(n, surfaces, sensitivity, &settings),
        };
        // What a system's reset map or exact flow may only partly overwrite starts as it does
        // in fresh buffers.
        buffers.reset_jacobian.fill_with_identity();
        buffers.flow_transition.fill_with_identity();
        buffers.reset_dxdp.fill(0.0);
        buffers.flow_dxdp.fill(0.0);
        let affine_switching = (0..surfaces).all(|k| system.switching_is_affine(k));
        if affine_switching {
            for k in 0..surfaces {
                let partials = system.switching_gradient(
                    k,
                    t0,
                    x0,
                    &mut buffers.affine_gradients[k * n..(k + 1) * n],
                );
                buffers.affine_drifts[k] = partials.t;
            }
        }
        let mut solver = Self {
            system,
            sensitivity,
            n,
            surfaces,
            dim: sensitivity.augmented_dim(n),
            t: t0,
            mode: 0,
            buffers,
            proposed_step: settings.initial_step,
            landing_limit: None,
            steps_in_mode: 0,
            first_same_as_last: false,
            stage0_rate: 1.0,
            entered: None,
            clock: Clock::Time,
            sigma_start: t0,
            kind: StepKind::None,
            step_mode: 0,
            step_start: t0,
            step_end: t0,
            full_dense: false,
            proven_clear: false,
            affine_switching,
            predicted_crossing: None,
            ridge: None,
            last_series_step: 0.0,
            statistics: Statistics::default(),
            settings,
        };
        solver.restart(t0, x0)?;
        Ok(solver)
    }

    /// Release the solver's buffers for [`Solver::with_workspace`] (the next run of the same
    /// shape then allocates nothing).
    pub fn into_workspace(self) -> SolverWorkspace {
        SolverWorkspace {
            buffers: Some(self.buffers),
        }
    }

    /// Restart from `(t0, x0)` reusing every buffer (no allocation): the mode from
    /// [`HybridSystem::mode_of`], identity transition, zero parameter sensitivity, zeroed
    /// statistics and the configured initial step, so the run is identical to one from a new
    /// solver. Useful for repeated flow maps (Newton iterations on a periodic orbit).
    ///
    /// # Errors
    /// [`HybridError::DimensionMismatch`], [`HybridError::NonFiniteState`].
    pub fn restart(&mut self, t0: f64, x0: &[f64]) -> Result<(), HybridError> {
        let n = self.n;
        check_start(n, t0, x0)?;
        self.buffers.z.fill(0.0);
        self.buffers.z[..n].copy_from_slice(x0);
        if self.sensitivity.transition() {
            for i in 0..n {
                self.buffers.z[n + i * n + i] = 1.0;
            }
        }
        self.buffers.z_start.copy_from_slice(&self.buffers.z);
        self.buffers.z_new.copy_from_slice(&self.buffers.z);
        self.t = t0;
        self.mode = self.system.mode_of(t0, x0);
        self.buffers.transition.fill_with_identity();
        self.proposed_step = self.settings.initial_step;
        self.landing_limit = None;
        self.steps_in_mode = 0;
        self.first_same_as_last = false;
        self.entered = None;
        self.predicted_crossing = None;
        self.ridge = None;
        self.last_series_step = 0.0;
        self.clock = Clock::Time;
        self.kind = StepKind::None;
        self.step_start = t0;
        self.step_end = t0;
        self.full_dense = false;
        self.buffers.samples.start_valid = false;
        self.buffers.extrema.clear();
        self.buffers.field.evaluations = 0;
        self.statistics = Statistics::default();
        Ok(())
    }

    /// Current time (system time units).
    pub fn t(&self) -> f64 {
        self.t
    }

    /// Current state `x(t)`.
    pub fn state(&self) -> &[f64] {
        &self.buffers.z[..self.n]
    }

    /// Current mode (bit `k` set when the state is on the negative side of surface `k`).
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// The state-transition matrix `dx(t)/dx(t0)` through all events so far (saltation
    /// included); the identity if the transition is not tracked.
    pub fn transition(&self) -> &DMatrix<f64> {
        &self.buffers.transition
    }

    /// The parameter sensitivity `dx(t)/dp` (for fixed `x(t0)`); zeros if not tracked.
    pub fn parameter_sensitivity(&self) -> &[f64] {
        if self.sensitivity.parameter() {
            let offset = self.n + self.n * self.n;
            &self.buffers.z[offset..offset + self.n]
        } else {
            &self.buffers.zero_parameter
        }
    }

    /// `[t_start, t_end]` of the last step (truncated at the event if there was one).
    pub fn last_step(&self) -> (f64, f64) {
        (self.step_start, self.step_end)
    }

    /// The independent variable of the last step: its states are a polynomial (the dense
    /// output or the Taylor series) in this clock's reading, not necessarily in time, so a
    /// quadrature over the step is accurate in the clock (nodes in `sigma`, weights times
    /// [`Clock::rate`]). Exact-flow steps report [`Clock::Time`].
    pub fn last_step_clock(&self) -> Clock {
        match self.kind {
            StepKind::RungeKutta | StepKind::Taylor => self.clock,
            StepKind::Exact | StepKind::None => Clock::Time,
        }
    }

    /// The states at the interior sample times ([`Samples::time`]) of the Taylor step `[t0,
    /// t1]` just taken, into `grid` (`n` per point): by [`Solver::interpolate_clock`], each the
    /// value `state_in_step` gives (the end's state where a sample time rounds onto an end).
    fn series_grid(&self, t0: f64, t1: f64, grid: &mut [f64]) {
        const BLOCK: usize = 8;
        let n = self.n;
        let samples = &self.buffers.samples;
        let last = samples.points() - 1;
        for (first, states) in (1..last).step_by(BLOCK).zip(grid.chunks_mut(BLOCK * n)) {
            let points = first..(first + BLOCK).min(last);
            let mut readings = [0.0; BLOCK];
            for (reading, i) in readings.iter_mut().zip(points.clone()) {
                *reading = self.clock.sigma(samples.time(t0, t1, i));
            }
            let states = &mut states[..points.len() * n];
            self.interpolate_clock(&readings[..points.len()], states);
            for (i, state) in points.zip(states.chunks_exact_mut(n)) {
                let t = samples.time(t0, t1, i);
                if t == t1 {
                    state.copy_from_slice(&self.buffers.z_new[..n]);
                } else if t == t0 {
                    state.copy_from_slice(&self.buffers.z_start[..n]);
                }
            }
        }
    }

    /// The states at the readings `sigma` of the last step's clock ([`Solver::last_step_clock`],
    /// inside the step), into `states` (`n` per reading, in order): what
    /// [`Solver::interpolate`] gives at the times `clock.time(sigma)`, without the round trip
    /// through time, and on a Taylor-series step evaluated together
    /// ([`crate::TaylorSeries::evaluate_many`]): the nodes of a quadrature in the clock.
    pub fn interpolate_clock(&self, sigma: &[f64], states: &mut [f64]) {
        let n = self.n;
        match self.kind {
            StepKind::Taylor => {
                self.buffers
                    .taylor
                    .state
                    .evaluate_many(self.sigma_start, sigma, states);
            }
            StepKind::RungeKutta => {
                for (reading, x) in sigma.iter().zip(states.chunks_exact_mut(n)) {
                    let theta = (reading - self.sigma_start) / self.buffers.rk.h;
                    self.buffers.rk.interpolate(&self.buffers.z_start, theta, x);
                }
            }
            StepKind::Exact | StepKind::None => {
                for (&reading, x) in sigma.iter().zip(states.chunks_exact_mut(n)) {
                    self.interpolate(reading, x);
                }
            }
        }
    }

    /// The state at time `t` inside the last step, written into `x` (length `n`; a shorter
    /// slice receives the leading components): the 7th-order DOP853 dense output, or the exact
    /// flow from the step start. Before the first step, the current state.
    pub fn interpolate(&self, t: f64, x: &mut [f64]) {
        let m = x.len().min(self.n);
        let x = &mut x[..m];
        match self.kind {
            StepKind::None => x.copy_from_slice(&self.buffers.z[..m]),
            StepKind::RungeKutta => {
                let theta = (self.clock.sigma(t) - self.sigma_start) / self.buffers.rk.h;
                self.buffers.rk.interpolate(&self.buffers.z_start, theta, x);
            }
            StepKind::Taylor => {
                let s = self.clock.sigma(t) - self.sigma_start;
                self.buffers.taylor.state.evaluate(s, x);
            }
            StepKind::Exact => {
                if m == self.n {
                    self.system.exact_flow(
                        self.step_mode,
                        self.step_start,
                        &self.buffers.z_start[..self.n],
                        t - self.step_start,
                        x,
                        None,
                        None,
                    );
                } else {
                    let mut full = vec![0.0; self.n];
                    self.system.exact_flow(
                        self.step_mode,
                        self.step_start,
                        &self.buffers.z_start[..self.n],
                        t - self.step_start,
                        &mut full,
                        None,
                        None,
                    );
                    x.copy_from_slice(&full[..m]);
                }
            }
        }
    }

    /// Extrema of the switching functions found in the last step (up to its end or its event),
    /// sorted by time.
    pub fn step_extrema(&self) -> &[Extremum] {
        &self.buffers.extrema
    }

    /// Work counters since [`Solver::new`].
    pub fn statistics(&self) -> &Statistics {
        &self.statistics
    }

    /// The settings in use.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// The sensitivities tracked.
    pub fn sensitivity(&self) -> Sensitivity {
        self.sensitivity
    }

    /// The system integrated.
    pub fn system(&self) -> &'a S {
        self.system
    }

    fn check_attempts(&self) -> Result<(), HybridError> {
        let attempts = self.statistics.steps + self.statistics.rejected_steps;
        if attempts >= self.settings.max_steps {
            return Err(HybridError::TooManySteps {
                t: self.t,
                steps: attempts,
            });
        }
        Ok(())
    }

    /// Advance by one step: a DOP853 step with error control or an exact-flow step, never past
    /// `t_end` and never across a switching surface (the step is truncated at the earliest
    /// event, which is then applied). Allocates nothing (except `Event::state`).
    ///
    /// # Errors
    /// [`HybridError::InvalidEndTime`] if `t_end` is not finite or before `t`; step-size
    /// underflow, too many steps or events, non-finite states or switching values, singular
    /// saltation.
    pub fn step(&mut self, t_end: f64) -> Result<StepOutcome, HybridError> {
        if !t_end.is_finite() || t_end < self.t {
            return Err(HybridError::InvalidEndTime { t: self.t, t_end });
        }
        self.buffers.extrema.clear();
        if t_end == self.t {
            return Ok(StepOutcome::EndTime);
        }
        let t0 = self.t;
        let mode = self.mode;
        self.buffers.z_start.copy_from_slice(&self.buffers.z);
        self.proven_clear = false;
        let t1 = if self.system.has_exact_flow(mode) {
            self.exact_step(t_end)?
        } else if let Some(t1) = self.taylor_step(t_end)? {
            t1
        } else {
            self.runge_kutta_step(t_end)?
        };
        self.step_mode = mode;
        self.step_start = t0;
        self.step_end = t1;
        self.full_dense = false;

        // Sample h and dh/dt, locate extrema, then the earliest crossing.
        let time_tolerance =
            self.settings.event_time_tolerance * t0.abs().max(t1.abs()).max(t1 - t0);
        // The curvature bounds of the step (if the system gives them): a step they prove
        // monotone holds no extremum; with a finite extremum height, a step, or a sample
        // interval of it, that they prove farther than the height from every surface is not
        // searched for extrema.
        let mut bounds = [0.0; MAX_SURFACES];
        let bounded = !self.proven_clear && self.curvature_bounds(mode, t0, t1, &mut bounds);
        let clearance = (bounded && self.settings.extremum_height.is_finite()).then(|| Clearance {
            height: self.settings.extremum_height,
            bounds: &bounds[..self.surfaces],
        });
        // A Runge-Kutta step with affine switching functions may be proven settled on its
        // interpolant, whatever the height.
        let polynomial =
            self.affine_switching && matches!(self.kind, StepKind::RungeKutta | StepKind::Taylor);
        let clear = (self.settings.extremum_height.is_finite() || polynomial || bounded) && {
            self.buffers.samples.sample_ends(
                self.system,
                mode,
                t0,
                t1,
                &self.buffers.z_start[..self.n],
                &self.buffers.z_new[..self.n],
            )?;
            self.proven_clear
                || clearance
                    .as_ref()
                    .is_some_and(|clearance| self.clear_of_surfaces(mode, t0, t1, clearance))
                || (polynomial && self.interpolant_settled(mode))
                || (bounded && self.monotone_by_curvature(t1 - t0, &bounds))
        };
        if !clear {
            self.statistics.sampled_steps += 1;
            let system = self.system;
            let n = self.n;
            let kind = self.kind;
            let dense = (&self.buffers.rk, &self.buffers.taylor);
            let z_start = &self.buffers.z_start;
            let z_new = &self.buffers.z_new;
            let clock = (self.clock, self.sigma_start);
            let mut state_at = |t: f64, out: &mut [f64]| {
                state_in_step(
                    system, kind, mode, dense, clock, z_start, z_new, t0, t1, n, t, out,
                );
            };
            // Exact steps: every interior state from one call (a linear flow reuses its
            // transition over one spacing). Taylor steps: from one pass over the series, at
            // the sample times `Samples::sample` takes (each the value `state_in_step` gives).
            let grid = match kind {
                StepKind::Exact => {
                    let count = self.buffers.samples.points() - 1;
                    system.exact_flow_grid(
                        mode,
                        t0,
                        &z_start[..n],
                        t1 - t0,
                        count,
                        &mut self.buffers.grid,
                    );
                    Some(&self.buffers.grid[..])
                }
                StepKind::Taylor => {
                    let mut grid = std::mem::take(&mut self.buffers.grid);
                    self.series_grid(t0, t1, &mut grid);
                    self.buffers.grid = grid;
                    Some(&self.buffers.grid[..])
                }
                _ => None,
            };
            self.buffers.samples.sample(
                system,
                mode,
                t0,
                t1,
                &mut state_at,
                grid,
                &mut self.buffers.x,
            )?;
            self.buffers.samples.locate_extrema(
                system,
                mode,
                &mut state_at,
                &mut self.buffers.x,
                time_tolerance,
                clearance,
                &mut self.buffers.extrema,
            );
        }
        let crossing = self.earliest_crossing(mode, t0, t1, time_tolerance);
        match crossing {
            None => {
                self.buffers.z.copy_from_slice(&self.buffers.z_new);
                self.t = t1;
                self.sync_transition();
                self.buffers.samples.carry_over();
                if self.kind == StepKind::RungeKutta {
                    self.buffers.rk.reuse_last_derivative();
                    self.first_same_as_last = true;
                }
                self.buffers
                    .extrema
                    .sort_unstable_by(|a, b| a.t.total_cmp(&b.t).then(a.surface.cmp(&b.surface)));
                Ok(if t1 == t_end {
                    StepOutcome::EndTime
                } else {
                    StepOutcome::Internal
                })
            }
            Some((k, bracket)) => {
                let event = self.fire(k, bracket, time_tolerance)?;
                self.buffers.extrema.retain(|e| e.t <= event.t);
                self.buffers
                    .extrema
                    .sort_unstable_by(|a, b| a.t.total_cmp(&b.t).then(a.surface.cmp(&b.surface)));
                Ok(StepOutcome::Event(event))
            }
        }
    }

    /// The longest span from `t0` (at most `longest`) over which the exact flow of `mode` is
    /// proven farther than `extremum_height` from every surface before it is taken: with the
    /// start samples `g0 = side h_k(t0)`, `g0' = side dh_k/dt(t0)` and the system's curvature
    /// bound `M` over `[t0, t0 + longest]`, `g(t0 + s) >= g0 + g0' s - M s^2 / 2`, which stays
    /// above the height up to the positive root of that parabola. `None` if the start samples
    /// are not at hand (first step after an event), the height is infinite, the system gives
    /// no bound, or a surface is already within the height.
    fn clear_exact_span(&self, mode: Mode, t0: f64, longest: f64) -> Option<f64> {
        let height = self.settings.extremum_height;
        if !height.is_finite() || !self.buffers.samples.start_valid {
            return None;
        }
        let p = self.buffers.samples.points();
        let mut span = longest;
        for k in 0..self.surfaces {
            let side = side_sign(mode, k);
            let margin = side * self.buffers.samples.values[k * p] - height;
            let rate = side * self.buffers.samples.rates[k * p];
            let bound = self.system.switching_curvature_bound(
                k,
                mode,
                t0,
                &self.buffers.z_start[..self.n],
                longest,
            )?;
            if !(side > 0.0
                && margin > 0.0
                && bound >= 0.0
                && bound.is_finite()
                && rate.is_finite())
            {
                return None;
            }
            // The positive root of margin + rate s - bound s^2 / 2, in the form without
            // cancellation for either sign of the rate.
            let root = (rate * rate + 2.0 * bound * margin).sqrt();
            let clear = if rate < 0.0 {
                2.0 * margin / (root - rate)
            } else if bound > 0.0 {
                (rate + root) / bound
            } else {
                f64::INFINITY
            };
            // A margin for the rounding of the root.
            span = span.min(clear * (1.0 - 1e-9));
        }
        Some(span)
    }

    /// Whether the step of length `dt` just sampled at its ends ([`Samples::sample_ends`])
    /// has every `h_k` strictly monotone, by the curvature bounds `M_k` on `|h_k''|`: with end
    /// rates `r0`, `r1` of one sign, `|dh_k/dt| >= (|r0| + |r1| - M_k dt) / 2` throughout (the
    /// rate moves at most `M_k` per time unit from either end), so a positive right side
    /// leaves no extremum, and a crossing shows in the signs at the ends.
    fn monotone_by_curvature(&self, dt: f64, bounds: &[f64]) -> bool {
        let p = self.buffers.samples.points();
        let rates = &self.buffers.samples.rates;
        (0..self.surfaces).all(|k| {
            let (r0, r1) = (rates[k * p], rates[k * p + p - 1]);
            // A margin for the rounding of the bound's product.
            r0 * r1 > 0.0 && r0.abs() + r1.abs() > bounds[k] * dt * (1.0 + 1e-9)
        })
    }

    /// Whether the Runge-Kutta or Taylor step just taken (sampled at its ends,
    /// [`Samples::sample_ends`]) is proven, on its interpolant, to hold nothing that interior
    /// samples would find: for every surface either `side h_k` stays above the extremum height
    /// (and zero) on the whole step, or `h_k` is strictly monotone with both end rates of that
    /// sign (no extremum; a crossing shows in the signs at the ends). The interpolant of an
    /// affine `h_k` is `h_k(t0) + g . (x(theta) - x0) + b (t(theta) - t0)`, a polynomial in the
    /// clock fraction `theta` of degree 7 (DOP853's dense output) or 20 (the series), as
    /// `t(theta)` is linear on the time clock and quadratic on a square-root clock, whose
    /// `sigma` keeps one sign over a step; its range and that of its derivative are bounded by
    /// their Bernstein coefficients.
    fn interpolant_settled(&self, mode: Mode) -> bool {
        let n = self.n;
        let p = self.buffers.samples.points();
        (0..self.surfaces).all(|k| {
            let samples = &self.buffers.samples;
            let (start_value, start_rate, end_rate) = (
                samples.values[k * p],
                samples.rates[k * p],
                samples.rates[k * p + p - 1],
            );
            let rates = (start_rate, end_rate);
            if self.kind == StepKind::Taylor {
                // The series' polynomial in the clock offset, in the fraction of the step.
                let length = self.buffers.taylor.length;
                let mut power = match self.buffers.taylor.surface {
                    Some((kept, mut power)) if kept == k => {
                        power[0] = start_value;
                        power
                    }
                    _ => self.series_surface_polynomial(k, start_value),
                };
                let mut scale = 1.0;
                for c in power.iter_mut() {
                    *c *= scale;
                    scale *= length;
                }
                self.polynomial_settled::<{ TAYLOR_ORDER + 1 }, TAYLOR_ORDER>(mode, k, power, rates)
            } else {
                // t(theta) - t0 = linear theta + quadratic theta^2.
                let rk = &self.buffers.rk;
                let (linear, quadratic) = match self.clock {
                    Clock::Time => (rk.h, 0.0),
                    Clock::SquareRoot { .. } => {
                        let (sigma0, dsigma) = (self.sigma_start, rk.h);
                        let sign = (sigma0 + 0.5 * dsigma).signum();
                        (sign * 2.0 * sigma0 * dsigma, sign * dsigma * dsigma)
                    }
                };
                let drift = self.buffers.affine_drifts[k];
                let mut power =
                    rk.dense_polynomial(&self.buffers.affine_gradients[k * n..(k + 1) * n]);
                power[0] = start_value;
                power[1] += drift * linear;
                power[2] += drift * quadratic;
                self.polynomial_settled::<8, 7>(mode, k, power, rates)
            }
        })
    }

    /// [`Solver::interpolant_settled`] for surface `k` whose interpolant over the step has the
    /// power-basis coefficients `power` in the clock fraction (degree `D - 1`; `E = D - 1`
    /// coefficients for its derivative), and the rates `(start, end)` at the step's ends.
    fn polynomial_settled<const D: usize, const E: usize>(
        &self,
        mode: Mode,
        k: usize,
        power: [f64; D],
        (start_rate, end_rate): (f64, f64),
    ) -> bool {
        let height = self.settings.extremum_height;
        // Above the surface (positive side) and the height throughout: nothing wanted.
        if side_sign(mode, k) > 0.0 && height.is_finite() && stays_above(&power, height.max(0.0)) {
            return true;
        }
        let mut derivative = [0.0; E];
        for (j, d) in derivative.iter_mut().enumerate() {
            *d = (j + 1) as f64 * power[j + 1];
        }
        strict_sign(&derivative)
            .is_some_and(|sign| sign * start_rate > 0.0 && sign * end_rate > 0.0)
    }

    /// The system's bound `M_k` on `|h_k''|` over the step `[t0, t1]` for every surface
    /// ([`HybridSystem::switching_curvature_bound`]), written into `bounds`; `false` (and
    /// nothing usable written) when the system gives none, or a bound is NaN or negative.
    fn curvature_bounds(&self, mode: Mode, t0: f64, t1: f64, bounds: &mut [f64]) -> bool {
        (0..self.surfaces).all(|k| {
            match self.system.switching_curvature_bound(
                k,
                mode,
                t0,
                &self.buffers.z_start[..self.n],
                t1 - t0,
            ) {
                Some(bound) if bound >= 0.0 => {
                    bounds[k] = bound;
                    true
                }
                _ => false,
            }
        })
    }

    /// Whether the step `[t0, t1]` just sampled at its ends ([`Samples::sample_ends`]) stays
    /// farther than the extremum height from every surface throughout: the chord between its
    /// end values, bent by the curvature bound over the whole step, as
    /// [`Clearance::proves`] tests a sample interval.
    fn clear_of_surfaces(&self, mode: Mode, t0: f64, t1: f64, clearance: &Clearance) -> bool {
        let p = self.buffers.samples.points();
        let values = &self.buffers.samples.values;
        (0..self.surfaces).all(|k| {
            clearance.proves(
                k,
                side_sign(mode, k),
                values[k * p],
                values[k * p + p - 1],
                t1 - t0,
            )
        })
    }

    /// An exact-flow step of length `min(exact_step_limit, max_step, t_end - t)`; returns the
    /// end time. Writes `z_new`.
    fn exact_step(&mut self, t_end: f64) -> Result<f64, HybridError> {
        self.check_attempts()?;
        let mode = self.mode;
        let limit = self
            .system
            .exact_step_limit(mode)
            .min(self.settings.max_step);
        if limit.is_nan() || limit <= 0.0 {
            return Err(HybridError::InvalidSettings {
                field: "exact_step_limit",
                value: limit,
                allowed: "> 0 (a property of the system's mode)",
            });
        }
        let t0 = self.t;
        let remaining = t_end - t0;
        let longest = remaining.min(self.settings.max_step);
        let span = self.clear_exact_span(mode, t0, longest);
        let step = span.filter(|&span| span > limit).unwrap_or(limit);
        let (dt, t1) = if step >= remaining {
            (remaining, t_end)
        } else {
            (step, t0 + step)
        };
        // A step inside the span is clear before it is taken: no second look at its ends.
        self.proven_clear = span.is_some_and(|span| span >= dt);
        self.exact_advance(mode, t0, dt);
        if self.buffers.z_new.iter().any(|v| !v.is_finite()) {
            return Err(HybridError::NonFiniteState { t: t1 });
        }
        self.kind = StepKind::Exact;
        self.first_same_as_last = false;
        self.statistics.steps += 1;
        self.statistics.exact_steps += 1;
        Ok(t1)
    }

    /// `z_new` = exact flow of the augmented state from `z_start` over `dt`:
    /// `x = phi(dt, x0)`, `Phi_new = Phi_step Phi_old`, `s_new = Phi_step s_old + dxdp_step`.
    fn exact_advance(&mut self, mode: Mode, t0: f64, dt: f64) {
        let n = self.n;
        let (x_start, _) = self.buffers.z_start.split_at(n);
        let (x_new, rest) = self.buffers.z_new.split_at_mut(n);
        match self.sensitivity {
            Sensitivity::None => {
                self.system
                    .exact_flow(mode, t0, x_start, dt, x_new, None, None);
            }
            Sensitivity::Transition => {
                self.system.exact_flow(
                    mode,
                    t0,
                    x_start,
                    dt,
                    x_new,
                    Some(&mut self.buffers.flow_transition),
                    None,
                );
            }
            Sensitivity::TransitionAndParameter => {
                self.system.exact_flow(
                    mode,
                    t0,
                    x_start,
                    dt,
                    x_new,
                    Some(&mut self.buffers.flow_transition),
                    Some(&mut self.buffers.flow_dxdp),
                );
            }
        }
        if self.sensitivity.transition() {
            let nn = n * n;
            {
                let phi_old = DMatrixView::from_slice(&self.buffers.z_start[n..n + nn], n, n);
                self.buffers
                    .product
                    .gemm(1.0, &self.buffers.flow_transition, &phi_old, 0.0);
            }
            rest[..nn].copy_from_slice(self.buffers.product.as_slice());
            if self.sensitivity.parameter() {
                let s_old = &self.buffers.z_start[n + nn..n + nn + n];
                let s_new = &mut rest[nn..nn + n];
                for (i, out) in s_new.iter_mut().enumerate() {
                    let mut v = self.buffers.flow_dxdp[i];
                    for (j, &sj) in s_old.iter().enumerate() {
                        v += self.buffers.flow_transition[(i, j)] * sj;
                    }
                    *out = v;
                }
            }
        }
    }

    /// A Taylor-series step ([`crate::taylor`]) where the system gives series of the mode's
    /// solution to [`TAYLOR_ORDER`]; `None` (nothing done: the caller takes a Runge-Kutta step)
    /// where it gives none or cannot form one here. Writes `z_new`.
    ///
    /// The step is as long as the series' last two terms stay below the tolerance
    /// ([`TaylorStep::reach`]), on the clock in which the solution is analytic up to its
    /// nearest non-smooth point: the square root of the time since the crossing of the mode's
    /// half-power surface that entered it, the square root of the time to the crossing the last
    /// series predicts (its first zero within [`RELEASE_LOOKAHEAD`] reaches) when that is the
    /// nearer, else time. A step on the latter lands on its reference, just past the crossing
    /// (re-centred on the zero of its own series when that lies farther than the overshoot), so
    /// the step holds the crossing, which the event location then finds on the series. With
    /// sensitivities, the tangents' series come along, to the order and (where set) under the
    /// tolerance of [`tangent_control`], which then also limits the step.
    fn taylor_step(&mut self, t_end: f64) -> Result<Option<f64>, HybridError> {
        let system = self.system;
        let mode = self.mode;
        if !self.settings.taylor_series || system.taylor_order_limit(mode) < TAYLOR_ORDER {
            return Ok(None);
        }
        let half_power = system.half_power_surface(mode);
        if half_power.is_some() && !self.affine_switching {
            return Ok(None);
        }
        self.check_attempts()?;
        let (t0, n) = (self.t, self.n);
        let (rtol, atol) = (
            self.settings.relative_tolerance,
            self.settings.absolute_tolerance,
        );
        let onset = match (half_power, self.entered) {
            (Some(k), Some((entered, t_event))) if k == entered => Some(t_event),
            _ => None,
        };
        // A clock centred on a crossing ahead serves only while that crossing is nearer than the
        // onset that entered the mode: a series expanded nearer the onset would start next to
        // its half power, outside the series' own radius.
        let nearer_than_onset =
            |t_cross: f64| onset.is_none_or(|t_event| t_cross - t0 <= t0 - t_event);
        let ahead = self.predicted_crossing.filter(|&t_cross| {
            t_cross > t0 && self.steps_in_mode > 0 && nearer_than_onset(t_cross)
        });
        let mut clock = match (ahead, onset) {
            (Some(t_cross), _) => Clock::SquareRoot { reference: t_cross },
            (None, Some(t_event)) => Clock::SquareRoot { reference: t_event },
            (None, None) => Clock::Time,
        };
        let mut recentred = 0;
        let (sigma0, length, t1) = loop {
            let sigma0 = clock.sigma(t0);
            let polynomial = match clock {
                Clock::Time => ClockPolynomial {
                    start: t0,
                    rate: 1.0,
                    curvature: 0.0,
                },
                Clock::SquareRoot { .. } => ClockPolynomial {
                    start: t0,
                    rate: 2.0 * sigma0.abs(),
                    curvature: if sigma0 < 0.0 { -1.0 } else { 1.0 },
                },
            };
            let taylor = &mut self.buffers.taylor;
            if !taylor.expand(system, mode, polynomial, &self.buffers.z[..n]) {
                return Ok(None);
            }
            let mut reach = TaylorStep::reach(&taylor.state, rtol, atol);
            if self.sensitivity.transition() {
                // The tangents' order was fixed with the workspace (it fits these settings).
                let (_, tolerance) = tangent_control(&self.settings);
                taylor.expand_tangents(
                    system,
                    mode,
                    &self.buffers.z[n..],
                    self.sensitivity.parameter(),
                );
                if let Some(tolerance) = tolerance {
                    reach = reach.min(TaylorStep::reach(&taylor.tangents, tolerance, tolerance));
                }
            }
            // On a square-root clock centred ahead, the step ends at its reference at the
            // latest. (On the time clock `sigma0 = t0` may be negative: it is never ahead.)
            let ahead = matches!(clock, Clock::SquareRoot { .. }) && sigma0 < 0.0;
            let mut landing = ahead && reach >= -sigma0;
            if ahead {
                reach = reach.min(-sigma0);
            }
            // The half-power surface's first zero along the series: within the step, the
            // crossing the step must hold; beyond it, the prediction for the next step. A ridge
            // before it (the surface approached and left without a crossing) bounds the
            // series' radius, which the step keeps well inside.
            let crossing = match half_power {
                Some(k) => {
                    let upto = if ahead {
                        -sigma0
                    } else {
                        RELEASE_LOOKAHEAD * reach
                    };
                    let surface = self.surface_ahead(k, upto);
                    if let Some(ridge) = surface.ridge {
                        // Kept in time units for the steps after it.
                        self.ridge = Some(Ridge {
                            at: polynomial.time(ridge.at),
                            half_width: ridge.half_width * polynomial.time_rate(ridge.at),
                        });
                    }
                    // The ridge's distance in this series' clock offset, at its rate here.
                    let radius = self.ridge.map(|ridge| {
                        let rate = polynomial.time_rate(0.0);
                        Ridge {
                            at: (ridge.at - t0) / rate,
                            half_width: ridge.half_width / rate,
                        }
                        .radius_from(0.0)
                    });
                    if let Some(radius) = radius.filter(|r| r.is_finite()) {
                        reach = reach.min(TaylorStep::radius_reach(radius));
                        landing = landing && reach >= -sigma0;
                    }
                    surface.zero.map(|s| polynomial.time(s))
                }
                None => None,
            };
            // Centre a clock on the crossing (ROOT_OVERSHOOT past it) when it lies inside the
            // reach of a series not centred ahead, or when a landing series finds it well short
            // of its reference. Not while the onset is nearer (`nearer_than_onset`; on the first
            // step of a grazing contact the series would be expanded at the onset itself): the
            // step then stays on the onset's clock, which its reach keeps short of the crossing,
            // and the next step chooses again.
            let retarget = crossing.filter(|&t_cross| match clock {
                Clock::SquareRoot { reference } if ahead => {
                    landing && reference - t_cross > 10.0 * ROOT_OVERSHOOT * (reference - t0)
                }
                _ => t_cross <= clock.time(sigma0 + reach) && nearer_than_onset(t_cross),
            });
            if let Some(t_cross) = retarget.filter(|_| recentred < MAX_RETARGETS) {
                recentred += 1;
                clock = Clock::SquareRoot {
                    reference: t0 + (t_cross - t0) * (1.0 + ROOT_OVERSHOOT),
                };
                continue;
            }
            if landing && crossing.is_none() {
                // The crossing was predicted but lies past the reference: leave the approach
                // to the Runge-Kutta step's own landing.
                return Ok(None);
            }
            self.predicted_crossing = crossing;
            let t_reach = clock.time(sigma0 + reach);
            let max_step = self.settings.max_step;
            break if t_reach >= t_end {
                (sigma0, clock.sigma(t_end) - sigma0, t_end)
            } else if t_reach - t0 > max_step {
                let length = clock.clock_step(t0, max_step);
                (sigma0, length, clock.time(sigma0 + length))
            } else {
                (sigma0, reach, t_reach)
            };
        };
        // A series whose reach collapses (a start next to a non-smooth point it is not centred
        // on) would crawl: the Runge-Kutta step's landings handle that.
        if t1 < t_end && t1 - t0 < MIN_SERIES_FRACTION * self.last_series_step {
            return Ok(None);
        }
        let taylor = &mut self.buffers.taylor;
        taylor.length = length;
        let (x1, tangents) = self.buffers.z_new.split_at_mut(n);
        taylor.state.evaluate(length, x1);
        if !tangents.is_empty() {
            taylor.tangents_at(length, tangents);
        }
        if self.buffers.z_new.iter().any(|v| !v.is_finite()) {
            return Err(HybridError::NonFiniteState { t: t1 });
        }
        self.clock = clock;
        self.sigma_start = sigma0;
        self.kind = StepKind::Taylor;
        self.first_same_as_last = false;
        self.proposed_step = Some(t1 - t0);
        self.last_series_step = t1 - t0;
        self.steps_in_mode += 1;
        self.statistics.steps += 1;
        self.statistics.series_steps += 1;
        Ok(Some(t1))
    }

    /// The first zero in `(0, upto]` of surface `k` (affine) along the last Taylor series, in
    /// its clock offset, and the radius a ridge of it limits the series to
    /// ([`surface_ahead`]). The surface's polynomial is kept with the series
    /// ([`TaylorStep::surface`]) for the step's Bernstein tests.
    fn surface_ahead(&mut self, k: usize, upto: f64) -> SurfaceAhead {
        let start = self.buffers.taylor.clock.start;
        let start_value = self.system.switching(k, start, &self.buffers.z[..self.n]);
        let power = self.series_surface_polynomial(k, start_value);
        self.buffers.taylor.surface = Some((k, power));
        surface_ahead(&power, upto, side_sign(self.mode, k))
    }

    /// The polynomial in the clock offset `s` of the affine surface `k` along the last Taylor
    /// series: `h_k(t0) + g . (x(s) - x(0)) + b (t(s) - t0)`, with `h_k(t0) = start_value`.
    fn series_surface_polynomial(&self, k: usize, start_value: f64) -> [f64; TAYLOR_ORDER + 1] {
        let n = self.n;
        let taylor = &self.buffers.taylor;
        let mut power = [0.0; TAYLOR_ORDER + 1];
        taylor.state.weighted_sum(
            &self.buffers.affine_gradients[k * n..(k + 1) * n],
            &mut power,
        );
        let drift = self.buffers.affine_drifts[k];
        power[0] = start_value;
        power[1] += drift * taylor.clock.rate;
        power[2] += drift * taylor.clock.curvature;
        power
    }

    /// One accepted DOP853 step (with as many rejected attempts as needed); returns the end
    /// time. Writes `z_new`, stage 12 and the state's dense output.
    ///
    /// The step runs on the time clock, or on a square-root clock (see [`Clock`]) in a mode
    /// whose field has a half-power surface: from the event that entered the mode through it,
    /// and towards a predicted crossing of it when the step lands on that crossing.
    fn runge_kutta_step(&mut self, t_end: f64) -> Result<f64, HybridError> {
        let system = self.system;
        let mode = self.mode;
        let t0 = self.t;
        let n = self.n;
        let rtol = self.settings.relative_tolerance;
        let atol = self.settings.absolute_tolerance;
        let max_step = self.settings.max_step;
        let half_power = system.half_power_surface(mode);
        // Stage 0: the derivative at the step start times the rate `dt/dsigma` it was
        // computed with (reused from the last step's end), or evaluated afresh in time units
        // if it holds nothing usable; f(t0, x) from it for the prediction.
        let rate = match self.first_same_as_last.then_some(self.stage0_rate) {
            Some(rate) if rate != 0.0 => rate,
            _ => {
                let mut rhs =
                    clocked_field(&mut self.buffers.field, system, mode, Clock::Time, true);
                self.buffers
                    .rk
                    .evaluate_first_stage(&mut rhs, t0, &self.buffers.z);
                1.0
            }
        };
        let mut stage0 = Some(rate);
        self.buffers.rk.first_stage(&mut self.buffers.velocity);
        for v in &mut self.buffers.velocity {
            *v /= rate;
        }
        // Without a proposed step (the first step of a solver, whose stage 0 was just
        // evaluated in time units), Hairer's starting step.
        let mut h = match self.proposed_step {
            Some(h) => h,
            None => {
                let mut rhs =
                    clocked_field(&mut self.buffers.field, system, mode, Clock::Time, true);
                self.buffers
                    .rk
                    .initial_step(&mut rhs, t0, &self.buffers.z, rtol, atol, max_step)
            }
        }
        .min(max_step);
        // The square root of the time since the event that entered the mode through its
        // half-power surface while that is within a few steps, else time.
        let base_clock = match (half_power, self.entered) {
            (Some(k), Some((entered, t_event)))
                if k == entered && t0 - t_event < ROOT_CLOCK_SPAN * h =>
            {
                Clock::SquareRoot { reference: t_event }
            }
            _ => Clock::Time,
        };
        // Aim at the predicted crossing (see the module docs): land just past it when the
        // proposed step reaches it (on a square-root clock centred there if it is a crossing
        // of the half-power surface), or approach it in steps of a fixed fraction of the
        // distance once a landing from too far has failed.
        let mut clock = base_clock;
        let mut landing: Option<f64> = None;
        let mut crossing_target: Option<f64> = None;
        let h_proposed = h;
        let predicted = predict_crossing(
            system,
            &self.buffers.velocity,
            &mut self.buffers.x_ahead,
            &self.buffers.z[..n],
            mode,
            self.surfaces,
            t0,
            h,
        );
        // In the first step after an event, a crossing closer than the proposed step (a brief
        // dip through the surface near grazing) is left to that step and the event location.
        let first = self.steps_in_mode == 0;
        if let Some((s, k)) = predicted.filter(|&(s, _)| !first || s >= h) {
            // Too close to resolve in time (a Zeno accumulation): leave the step to the
            // controller and the event location.
            if resolvable(s, t0) && s < t_end - t0 {
                if half_power == Some(k) && h >= s / ROOT_APPROACH {
                    // Within a few steps of a crossing of the half-power surface: steps on a
                    // square-root clock centred on it, located on the last step's dense output
                    // continued (the solution is smooth up to the crossing); the step that
                    // reaches it lands on it. Without that location, a probe: a step just
                    // past the predicted crossing, whose dense output locates it if the kink
                    // makes it fail.
                    let located = if self.first_same_as_last && self.kind == StepKind::RungeKutta {
                        self.continue_last_step(k, s * (1.0 + PROBE_OVERSHOOT))
                    } else {
                        None
                    };
                    match located {
                        Some(t_cross)
                            if resolvable(t_cross - t0, t0) && t_cross - t0 <= max_step =>
                        {
                            let target = (t_cross - t0) * (1.0 + ROOT_OVERSHOOT);
                            let reference = t0 + target;
                            clock = Clock::SquareRoot { reference };
                            if h >= target {
                                crossing_target = Some(reference);
                                h = target;
                            }
                        }
                        _ if h >= s => {
                            h = (s * (1.0 + PROBE_OVERSHOOT)).min(max_step);
                            landing = Some(s);
                        }
                        _ => {}
                    }
                } else {
                    let limit_ok = self.landing_limit.is_none_or(|limit| s <= limit);
                    if limit_ok && h >= LANDING_REACH * s {
                        h = (s * (1.0 + PREDICTED_OVERSHOOT)).min(max_step);
                        landing = Some(s);
                    } else if !limit_ok {
                        h = h.min(APPROACH_FRACTION * s);
                    }
                }
            }
        }
        let mut sigma0 = clock.sigma(t0);
        stage0 = self.prepare_first_stage(mode, clock, sigma0, stage0);
        let mut rejected = false;
        let mut non_finite = false;
        let mut landing_tried = landing.is_some();
        let mut retargets = 0;
        let mut previous: Option<(f64, f64)> = None;
        let (dsigma, t1, lands, error) = loop {
            let attempts = self.statistics.steps + self.statistics.rejected_steps;
            if attempts >= self.settings.max_steps {
                return Err(HybridError::TooManySteps {
                    t: t0,
                    steps: attempts,
                });
            }
            if h.is_nan() || h <= 8.0 * f64::EPSILON * t0.abs() || !h.is_finite() {
                return Err(if non_finite {
                    HybridError::NonFiniteState { t: t0 }
                } else {
                    HybridError::StepSizeUnderflow { t: t0, step: h }
                });
            }
            let remaining = t_end - t0;
            let (dsigma, t1, lands) = match crossing_target {
                // Exactly onto the reference, where the clock's variable is zero.
                Some(reference) => (-sigma0, reference, false),
                None if h >= remaining => (clock.sigma(t_end) - sigma0, t_end, true),
                None => {
                    let dsigma = clock.clock_step(t0, h);
                    (dsigma, clock.time(sigma0 + dsigma), false)
                }
            };
            let error = {
                let mut rhs = clocked_field(&mut self.buffers.field, system, mode, clock, true);
                self.buffers.rk.attempt(
                    &mut rhs,
                    sigma0,
                    &self.buffers.z,
                    dsigma,
                    &mut self.buffers.z_new,
                    rtol,
                    atol,
                )
            };
            if error.is_finite() && error <= 1.0 {
                break (dsigma, t1, lands, error);
            }
            self.statistics.rejected_steps += 1;
            rejected = true;
            if !error.is_finite() {
                non_finite = true;
                h = 0.1 * (t1 - t0);
                crossing_target = None;
                previous = None;
                continue;
            }
            non_finite = false;
            // Where the trial crossed a surface before its end (cubic Hermite estimate).
            let crossed = crossing_fraction(
                system,
                mode,
                self.surfaces,
                n,
                clock,
                (t0, sigma0, &self.buffers.z),
                (t1, dsigma, &self.buffers.z_new),
            );
            // A trial that passed a crossing of the half-power surface: locate the crossing
            // on the trial's dense output and land on it on a square-root clock centred there
            // (repeated with the landing's own dense output if that fails too).
            if let Some((_, k)) = crossed.filter(|&(_, k)| half_power == Some(k)) {
                if retargets < MAX_RETARGETS {
                    if let Some(t_cross) =
                        self.locate_in_trial(mode, clock, (t0, sigma0), (t1, dsigma), k)
                    {
                        let target = (t_cross - t0) * (1.0 + ROOT_OVERSHOOT);
                        // Re-centring helps only if the crossing is not where the clock
                        // already is.
                        let moved = crossing_target.is_none_or(|reference| {
                            (t0 + target - reference).abs() > 10.0 * ROOT_OVERSHOOT * target
                        });
                        if moved && resolvable(target, t0) && target <= max_step {
                            retargets += 1;
                            let reference = t0 + target;
                            clock = Clock::SquareRoot { reference };
                            sigma0 = clock.sigma(t0);
                            stage0 = self.prepare_first_stage(mode, clock, sigma0, stage0);
                            crossing_target = Some(reference);
                            landing = None;
                            landing_tried = true;
                            h = target;
                            previous = None;
                            continue;
                        }
                    }
                }
            }
            // A square-root landing that failed without passing the crossing (it ends just
            // before it and the step is too long for the field's own variation): shorter
            // steps on the same clock, towards it.
            if crossing_target.take().is_some() {
                h = clock.time_step(t0, Dop853::next_step(dsigma, error, false));
                previous = Some((dsigma, error));
                continue;
            }
            // A probe that failed without passing the crossing: the controller's step.
            if half_power.is_some() && landing.take().is_some() {
                h = h_proposed.min(clock.time_step(t0, Dop853::next_step(dsigma, error, false)));
                previous = Some((dsigma, error));
                continue;
            }
            // A predicted landing that failed: the step ending at a non-smooth crossing is too
            // long. Its error grows like a power of its length (s^3.5 next to a Hertz
            // contact's kink, larger for smoother kinks, so the estimate is conservative):
            // remember the distance from which a landing should succeed and approach it.
            if let Some(s) = landing.take() {
                let limit = s * (0.5 / error).powf(1.0 / 3.5).clamp(0.01, 0.9);
                self.landing_limit = Some(self.landing_limit.map_or(limit, |l| l.min(limit)));
                h = APPROACH_FRACTION * s;
                previous = None;
                continue;
            }
            // A trial that ends across a switching surface was probably rejected for the kink
            // of the field there: retry once landing just past the estimated crossing, so the
            // step holds the crossing with a negligible non-smooth part (instead of a geometric
            // sequence of steps shrinking towards the surface): on a square-root clock centred
            // on it for the half-power surface.
            if !landing_tried {
                if let Some((theta, _)) = crossed {
                    landing_tried = true;
                    let fraction = (theta + LANDING_OVERSHOOT).min(1.0);
                    // (On a square-root clock a crossing next to its start lands a step of the
                    // fraction squared: one too short to advance time is left to the
                    // controller.)
                    let landing_step = clock.time_step(t0, fraction * dsigma);
                    if fraction < 1.0 && resolvable(landing_step, t0) {
                        h = landing_step;
                        previous = None;
                        continue;
                    }
                }
            }
            // Successive rejections: estimate the error's actual order in the step from the
            // last two attempts (near a singularity of the field it is far below 8) and aim
            // for an error of 0.5 with it.
            let next = match previous {
                Some((previous_step, previous_error))
                    if previous_step > dsigma && previous_error > error =>
                {
                    let order = (previous_error / error).ln() / (previous_step / dsigma).ln();
                    if (0.5..=9.0).contains(&order) {
                        dsigma * (0.5 / error).powf(1.0 / order).clamp(0.01, 0.9)
                    } else {
                        Dop853::next_step(dsigma, error, false)
                    }
                }
                _ => Dop853::next_step(dsigma, error, false),
            };
            h = clock.time_step(t0, next);
            previous = Some((dsigma, error));
        };
        let sigma1 = sigma0 + dsigma;
        let next_dsigma = Dop853::next_step(dsigma, error, rejected);
        // The proposal in time units: on a square-root clock the step's time resolution at
        // its end (`dt/dsigma` there), which keeps the next step's error near the target as
        // the clock speeds up; after a landing on a crossing, the step proposed before it.
        let mut next = match clock {
            Clock::Time => next_dsigma,
            Clock::SquareRoot { .. } if sigma1 > 0.0 => next_dsigma * clock.rate(sigma1),
            Clock::SquareRoot { .. } if sigma1 < 0.0 && sigma1 + next_dsigma < 0.0 => {
                clock.time(sigma1 + next_dsigma) - clock.time(sigma1)
            }
            Clock::SquareRoot { .. } => h_proposed,
        }
        .min(max_step);
        if lands && !rejected {
            next = next.max(h);
        }
        self.proposed_step = Some(next);
        {
            let mut rhs = clocked_field(&mut self.buffers.field, system, mode, clock, true);
            self.buffers
                .rk
                .derivative_at_end(&mut rhs, sigma0, &self.buffers.z_new);
        }
        {
            let mut rhs = clocked_field(&mut self.buffers.field, system, mode, clock, false);
            self.buffers.rk.dense_coefficients(
                &mut rhs,
                sigma0,
                &self.buffers.z,
                &self.buffers.z_new,
                n,
            );
        }
        let buffers = &mut self.buffers;
        if let Some(tangents) = buffers.tangents.as_mut() {
            let (x1, end) = buffers.z_new.split_at_mut(n);
            let (rk, z0) = (&buffers.rk, &buffers.z);
            let mut state_at = |fraction: f64, x: &mut [f64]| match fraction {
                0.0 => x.copy_from_slice(&z0[..n]),
                1.0 => x.copy_from_slice(x1),
                _ => rk.interpolate(z0, fraction, x),
            };
            buffers.field.evaluations += tangents.advance(
                system,
                mode,
                clock,
                (sigma0, dsigma),
                &mut state_at,
                &z0[n..],
                end,
            );
        }
        self.statistics.rhs_evaluations = self.buffers.field.evaluations;
        if self.buffers.z_new.iter().any(|v| !v.is_finite()) {
            return Err(HybridError::NonFiniteState { t: t1 });
        }
        self.clock = clock;
        self.sigma_start = sigma0;
        self.stage0_rate = clock.rate(sigma1);
        self.kind = StepKind::RungeKutta;
        self.first_same_as_last = false;
        self.steps_in_mode += 1;
        self.statistics.steps += 1;
        Ok(t1)
    }

    /// The time at which surface `k` is crossed within `reach` of the current time, located on
    /// the last accepted step's dense output continued past its end (which ended here, with
    /// no event since), if it is crossed there.
    fn continue_last_step(&mut self, k: usize, reach: f64) -> Option<f64> {
        let n = self.n;
        let system = self.system;
        let mode = self.mode;
        let (clock, sigma0, dsigma) = (self.clock, self.sigma_start, self.buffers.rk.h);
        let t0 = self.t;
        let t1 = t0 + reach;
        let side = side_sign(mode, k);
        let rk = &self.buffers.rk;
        let z_end = &self.buffers.z;
        let x = &mut self.buffers.x;
        let mut g = |t: f64| {
            rk.extrapolate_from_end(z_end, (clock.sigma(t) - sigma0) / dsigma, x);
            side * system.switching(k, t, x)
        };
        let g0 = (side * system.switching(k, t0, &self.buffers.z[..n])).abs();
        let g1 = g(t1);
        if g1.is_nan() || g1 >= 0.0 {
            return None;
        }
        let tolerance = self.settings.event_time_tolerance * t0.abs().max(t1.abs());
        Some(locate_sign_change(t0, g0, t1, g1, &mut g, tolerance, 0.0, None).far)
    }

    /// The time at which surface `k` is crossed inside the rejected trial on `clock` from
    /// `(t0, sigma0)` over `dsigma` to `t1` (its end across the surface), located on the
    /// trial's dense output (state part; stage 12 is overwritten, as it is when a step is
    /// accepted).
    fn locate_in_trial(
        &mut self,
        mode: Mode,
        clock: Clock,
        (t0, sigma0): (f64, f64),
        (t1, dsigma): (f64, f64),
        k: usize,
    ) -> Option<f64> {
        let n = self.n;
        {
            let mut rhs = clocked_field(&mut self.buffers.field, self.system, mode, clock, false);
            self.buffers
                .rk
                .derivative_at_end(&mut rhs, sigma0, &self.buffers.z_new);
            self.buffers.rk.dense_coefficients(
                &mut rhs,
                sigma0,
                &self.buffers.z,
                &self.buffers.z_new,
                n,
            );
        }
        let system = self.system;
        let side = side_sign(mode, k);
        let g1 = side * system.switching(k, t1, &self.buffers.z_new[..n]);
        if g1.is_nan() || g1 >= 0.0 {
            return None;
        }
        let rk = &self.buffers.rk;
        let z0 = &self.buffers.z;
        let x = &mut self.buffers.x;
        let mut g = |t: f64| {
            rk.interpolate(z0, (clock.sigma(t) - sigma0) / dsigma, x);
            side * system.switching(k, t, x)
        };
        // The first sample past the surface and the one before it bracket the crossing (a
        // start on the surface, right after the event that entered the mode, is no crossing).
        let mut before = (
            t0,
            (side * system.switching(k, t0, &self.buffers.z[..n])).abs(),
        );
        let mut after = (t1, g1);
        for j in 1..TRIAL_SAMPLES {
            let t = clock.time(sigma0 + dsigma * j as f64 / TRIAL_SAMPLES as f64);
            let value = g(t);
            if value < 0.0 {
                after = (t, value);
                break;
            }
            before = (t, value);
        }
        let tolerance = self.settings.event_time_tolerance * t0.abs().max(t1.abs());
        let mut point = |t: f64| {
            rk.interpolate(z0, (clock.sigma(t) - sigma0) / dsigma, x);
            (
                side * system.switching(k, t, x),
                side * system.switching_rate(k, mode, t, x),
            )
        };
        let before = turnaround(before, after.0, &mut point, tolerance)?;
        let mut g = |t: f64| point(t).0;
        let bracket = locate_sign_change(
            before.0, before.1, after.0, after.1, &mut g, tolerance, 0.0, None,
        );
        Some(bracket.far)
    }

    /// Make stage 0 hold the augmented derivative at the step start on `clock` (reading
    /// `sigma0`): rescale the one it holds (`stage0`, the rate it was computed with) or
    /// evaluate it. Returns the rate stage 0 now holds.
    fn prepare_first_stage(
        &mut self,
        mode: Mode,
        clock: Clock,
        sigma0: f64,
        stage0: Option<f64>,
    ) -> Option<f64> {
        let rate = clock.rate(sigma0);
        match stage0 {
            Some(held) if held == rate => {}
            Some(held) if held != 0.0 => self.buffers.rk.scale_first_stage(rate / held),
            _ => {
                let mut rhs =
                    clocked_field(&mut self.buffers.field, self.system, mode, clock, true);
                self.buffers
                    .rk
                    .evaluate_first_stage(&mut rhs, sigma0, &self.buffers.z);
            }
        }
        Some(rate)
    }

    /// Scan every surface for its first strict crossing in the step (through samples and
    /// located extrema, so a brief dip is found through its negative minimum), locate each,
    /// and return the earliest.
    fn earliest_crossing(
        &mut self,
        mode: Mode,
        t0: f64,
        t1: f64,
        time_tolerance: f64,
    ) -> Option<(usize, Bracket)> {
        let p = self.buffers.samples.points();
        // A step sampled at its ends only is one interval, from the first point to the last,
        // with no extremum.
        let ends_only = self.buffers.samples.ends_only;
        let intervals = if ends_only { 1 } else { p - 1 };
        let mut best: Option<(usize, Bracket)> = None;
        let value_tolerance = self.settings.event_value_tolerance;
        for k in 0..self.surfaces {
            let side = side_sign(mode, k);
            // At the step start the side is the mode's, whatever the computed value.
            // Each point: time, g = side h_k, and h_k and its rate (for the first guess).
            let h0 = self.buffers.samples.values[k * p];
            let mut prev = (t0, (side * h0).abs(), h0, self.buffers.samples.rates[k * p]);
            let mut candidate = None;
            for i in 0..intervals {
                let te = if ends_only {
                    f64::NAN
                } else {
                    self.buffers.samples.extremum_time[k * (p - 1) + i]
                };
                if !te.is_nan() && te > prev.0 {
                    let he = self.buffers.samples.extremum_value[k * (p - 1) + i];
                    let point = (te, side * he, he, 0.0);
                    if point.1 < 0.0 {
                        candidate = Some((prev, point));
                        break;
                    }
                    prev = point;
                }
                let j = if ends_only { p - 1 } else { i + 1 };
                let hb = self.buffers.samples.values[k * p + j];
                let rb = self.buffers.samples.rates[k * p + j];
                let mut point = (self.buffers.samples.times[j], side * hb, hb, rb);
                if point.1 < 0.0 {
                    if !is_rounding(side, prev.3, point.1, rb, value_tolerance) {
                        candidate = Some((prev, point));
                        break;
                    }
                    point.1 = 0.0;
                }
                if point.0 > prev.0 {
                    prev = point;
                }
            }
            let Some(((a, ga, ha, ra), (b, gb, hb, rb))) = candidate else {
                continue;
            };
            let guess = crossing_guess((a, ha, ra), (b, hb, rb), side);
            if let Some((_, found)) = &best {
                if a >= found.far {
                    continue;
                }
            }
            let system = self.system;
            let n = self.n;
            let kind = self.kind;
            let dense = (&self.buffers.rk, &self.buffers.taylor);
            let z_start = &self.buffers.z_start;
            let z_new = &self.buffers.z_new;
            let clock = (self.clock, self.sigma_start);
            let x = &mut self.buffers.x;
            let mut g = |t: f64| {
                state_in_step(
                    system, kind, mode, dense, clock, z_start, z_new, t0, t1, n, t, x,
                );
                side * system.switching(k, t, x)
            };
            let bracket = locate_sign_change(
                a,
                ga,
                b,
                gb,
                &mut g,
                time_tolerance,
                self.settings.event_value_tolerance,
                guess,
            );
            let better = match &best {
                None => true,
                Some((_, found)) => bracket.far < found.far,
            };
            if better {
                best = Some((k, bracket));
            }
        }
        best
    }

    /// The augmented state (state, transition, parameter sensitivity) at time `t` of the
    /// current step, into `z`.
    fn augmented_at(&mut self, t: f64) {
        let (t0, t1, mode) = (self.step_start, self.step_end, self.step_mode);
        if t == t1 {
            self.buffers.z.copy_from_slice(&self.buffers.z_new);
            return;
        }
        match self.kind {
            StepKind::RungeKutta if self.buffers.tangents.is_some() => {
                // The state from the dense output, the sensitivities carried to `t` from the
                // step start as over a whole step.
                let n = self.n;
                let (clock, sigma0) = (self.clock, self.sigma_start);
                let theta = (clock.sigma(t) - sigma0) / self.buffers.rk.h;
                let buffers = &mut self.buffers;
                let (x, tangents_at) = buffers.z.split_at_mut(n);
                buffers.rk.interpolate(&buffers.z_start, theta, x);
                let (rk, z_start) = (&buffers.rk, &buffers.z_start);
                let mut state_at = |fraction: f64, x: &mut [f64]| {
                    rk.interpolate(z_start, fraction * theta, x);
                };
                if let Some(tangents) = buffers.tangents.as_mut() {
                    buffers.field.evaluations += tangents.advance(
                        self.system,
                        mode,
                        clock,
                        (sigma0, theta * rk.h),
                        &mut state_at,
                        &z_start[n..],
                        tangents_at,
                    );
                }
                self.statistics.rhs_evaluations = buffers.field.evaluations;
            }
            StepKind::RungeKutta => {
                let (clock, sigma0) = (self.clock, self.sigma_start);
                if !self.full_dense && self.dim > self.n {
                    {
                        let mut rhs =
                            clocked_field(&mut self.buffers.field, self.system, mode, clock, true);
                        self.buffers.rk.dense_coefficients(
                            &mut rhs,
                            sigma0,
                            &self.buffers.z_start,
                            &self.buffers.z_new,
                            self.dim,
                        );
                    }
                    self.statistics.rhs_evaluations = self.buffers.field.evaluations;
                    self.full_dense = true;
                }
                let theta = (clock.sigma(t) - sigma0) / self.buffers.rk.h;
                self.buffers
                    .rk
                    .interpolate(&self.buffers.z_start, theta, &mut self.buffers.z);
            }
            StepKind::Taylor => {
                let n = self.n;
                let s = self.clock.sigma(t) - self.sigma_start;
                let (x, tangents) = self.buffers.z.split_at_mut(n);
                self.buffers.taylor.state.evaluate(s, x);
                if !tangents.is_empty() {
                    self.buffers.taylor.tangents_at(s, tangents);
                }
            }
            StepKind::Exact => {
                // Reuse z_new as scratch: the step is being truncated.
                self.exact_advance(mode, t0, t - t0);
                self.buffers.z.copy_from_slice(&self.buffers.z_new);
            }
            StepKind::None => {}
        }
    }

    /// Apply the event on surface `k` located in `bracket`: choose the side, reset or flip the
    /// mode, apply saltation, and truncate the step there.
    fn fire(
        &mut self,
        k: usize,
        bracket: Bracket,
        time_tolerance: f64,
    ) -> Result<Event, HybridError> {
        let system = self.system;
        let n = self.n;
        let mode = self.step_mode;
        let was_negative = mode & (1 << k) != 0;
        let direction = if was_negative {
            Direction::Up
        } else {
            Direction::Down
        };
        if self.statistics.events >= self.settings.max_events {
            return Err(HybridError::TooManyEvents {
                t: bracket.far,
                events: self.statistics.events,
            });
        }
        let reset = system.has_reset(k, direction);
        let mut t_event = bracket.far;
        self.augmented_at(t_event);
        if reset {
            // Does the reset send the state back to the side it came from (a bounce)? Then
            // return the bracket end on that side.
            self.buffers.x_after.copy_from_slice(&self.buffers.z[..n]);
            system.reset(
                k,
                direction,
                t_event,
                &mut self.buffers.x_after,
                &mut self.buffers.reset_jacobian,
                &mut self.buffers.reset_dxdp,
            );
            let negative_after =
                system.switching_rate(k, mode, t_event, &self.buffers.x_after) < 0.0;
            let near_usable = bracket.far - bracket.near <= time_tolerance
                || bracket.near_value <= self.settings.event_value_tolerance;
            if negative_after == was_negative && near_usable && bracket.near != t_event {
                t_event = bracket.near;
                self.augmented_at(t_event);
            }
        }
        self.buffers.x.copy_from_slice(&self.buffers.z[..n]);
        let rate = system.switching_rate(k, mode, t_event, &self.buffers.x);
        if self.sensitivity.transition() {
            system.vector_field(mode, t_event, &self.buffers.x, &mut self.buffers.f_minus);
            self.buffers.field.evaluations += 1;
        }
        let negative_after = if reset {
            system.reset(
                k,
                direction,
                t_event,
                &mut self.buffers.z[..n],
                &mut self.buffers.reset_jacobian,
                &mut self.buffers.reset_dxdp,
            );
            // The side of the post-reset state; on the surface, the side it moves to.
            let h = system.switching(k, t_event, &self.buffers.z[..n]);
            h < 0.0
                || (h == 0.0 && system.switching_rate(k, mode, t_event, &self.buffers.z[..n]) < 0.0)
        } else {
            !was_negative
        };
        if self.buffers.z[..n].iter().any(|v| !v.is_finite()) {
            return Err(HybridError::NonFiniteState { t: t_event });
        }
        let new_mode = if negative_after {
            mode | (1 << k)
        } else {
            mode & !(1 << k)
        };
        if self.sensitivity.transition() {
            system.vector_field(
                new_mode,
                t_event,
                &self.buffers.z[..n],
                &mut self.buffers.f_plus,
            );
            self.buffers.field.evaluations += 1;
            let partials =
                system.switching_gradient(k, t_event, &self.buffers.x, &mut self.buffers.gradient);
            let hdot = partials.t
                + self
                    .buffers
                    .gradient
                    .iter()
                    .zip(&self.buffers.f_minus)
                    .map(|(a, b)| a * b)
                    .sum::<f64>();
            let reset_jacobian = if reset {
                &self.buffers.reset_jacobian
            } else {
                &self.buffers.identity
            };
            if !reset {
                self.buffers.reset_dxdp.fill(0.0);
            }
            let nn = n * n;
            let (_, rest) = self.buffers.z.split_at_mut(n);
            let (phi, s) = rest.split_at_mut(nn);
            let parameter = if self.sensitivity.parameter() {
                Some((&mut s[..n], &self.buffers.reset_dxdp[..], partials.p))
            } else {
                None
            };
            self.buffers.saltation.apply(
                reset_jacobian,
                &self.buffers.f_minus,
                &self.buffers.f_plus,
                &self.buffers.gradient,
                hdot,
                phi,
                parameter,
                t_event,
                k,
            )?;
        }
        self.statistics.rhs_evaluations = self.buffers.field.evaluations;
        self.statistics.events += 1;
        self.t = t_event;
        self.mode = new_mode;
        self.step_end = t_event;
        self.first_same_as_last = false;
        self.buffers.samples.start_valid = false;
        self.landing_limit = None;
        self.steps_in_mode = 0;
        self.ridge = None;
        self.entered = Some((k, t_event));
        self.sync_transition();
        Ok(Event {
            t: t_event,
            surface: k,
            direction,
            rate,
            grazing: rate.abs() < self.settings.grazing_rate,
            reset,
            state: self.buffers.z[..n].to_vec(),
        })
    }

    fn sync_transition(&mut self) {
        if self.sensitivity.transition() {
            let n = self.n;
            self.buffers
                .transition
                .as_mut_slice()
                .copy_from_slice(&self.buffers.z[n..n + n * n]);
        }
    }
}

/// Fraction of a step past the estimated crossing at which a retried step lands.
const LANDING_OVERSHOOT: f64 = 1e-6;

/// Fraction of the predicted distance past the predicted crossing at which a step aimed at it
/// ends (covers the prediction's error, so the crossing lies inside the step).
const PREDICTED_OVERSHOOT: f64 = 1e-3;

/// A proposed step reaching this fraction of the predicted distance to a crossing is stretched
/// to land just past it.
const LANDING_REACH: f64 = 0.6;

/// Once a landing has failed, steps towards the crossing are at most this fraction of the
/// predicted distance (a graded approach to the non-smooth point, the mirror image of the
/// step growth after a contact onset).
const APPROACH_FRACTION: f64 = 0.5;

/// Fraction of the predicted distance past a predicted crossing of a half-power surface at
/// which a square-root-clock landing is centred (the crossing's non-smooth remainder inside
/// the step is then of relative size ~`ROOT_OVERSHOOT^2.5`, far below the tolerance).
const ROOT_OVERSHOOT: f64 = 1e-6;

/// Steps run on a square-root clock centred on a crossing of a half-power surface once it is
/// predicted within this many proposed steps.
const ROOT_APPROACH: f64 = 3.0;

/// Fraction of the predicted distance past the predicted crossing of a half-power surface at
/// which a probe ends (covers the quadratic prediction's error of a few per cent).
const PROBE_OVERSHOOT: f64 = 0.05;

/// After entering a mode through its half-power surface, steps run on the square-root clock
/// from the event while the time since it is below this many proposed steps. Far from its
/// reference the clock is the worse one (the solution oscillates ever faster in `sigma`), and
/// a step that grows there is rejected: with 4 instead of 1 the approach benchmark's sweep
/// took 13% more instructions (callgrind: 54.0e9 against 47.7e9) and the Fig. 1 period maps
/// 4-8% more evaluations, for a monodromy 2-20 times more accurate (2.0e-9 and 5.1e-8
/// relative at A/A0 = 0.95 and 0.5, against 4.2e-8 and 1.1e-7 now; both far below the
/// 1e-6 that Newton and the Floquet multipliers are granted).
const ROOT_CLOCK_SPAN: f64 = 1.0;

/// How many of its own reaches from a Taylor step's start its series is searched for the next
/// crossing of the half-power surface: this step and about the next one's length (the series
/// converges out to about four reaches; searching three cost 3% more per period map at A/A0 =
/// 0.5 for no fewer steps).
const RELEASE_LOOKAHEAD: f64 = 2.0;

/// A Taylor step shorter than this fraction of the previous one gives way to Runge-Kutta.
const MIN_SERIES_FRACTION: f64 = 1e-3;

/// Points at which a rejected trial's dense output is sampled to bracket the crossing it
/// passed.
const TRIAL_SAMPLES: usize = 16;

/// Re-centred square-root landings allowed per step after a landing passed its crossing.
const MAX_RETARGETS: usize = 3;

/// The field of `mode` on `clock`: `dz/dsigma = (dt/dsigma) f(t(sigma), z)`, augmented with
/// the variational equations when `variational` (else only the state part is written).
pub(crate) fn clocked_field<'b, S: HybridSystem + ?Sized>(
    field: &'b mut VariationalField,
    system: &'b S,
    mode: Mode,
    clock: Clock,
    variational: bool,
) -> impl FnMut(f64, &[f64], &mut [f64]) + 'b {
    move |sigma: f64, z: &[f64], dz: &mut [f64]| match clock {
        Clock::Time => field.eval(system, mode, sigma, z, dz, variational),
        Clock::SquareRoot { .. } => {
            field.eval(system, mode, clock.time(sigma), z, dz, variational);
            let rate = clock.rate(sigma);
            let written = if variational {
                dz.len()
            } else {
                field.state_dim()
            };
            for v in &mut dz[..written] {
                *v *= rate;
            }
        }
    }
}

/// Whether a crossing `distance` ahead of `t0` is far enough to land a step on:
/// `1024 eps |t0|`, a few hundred rounding steps of time. Nearer, a step cannot hold it
/// (a Zeno accumulation, or a state on the surface whose rounding puts the crossing next to
/// it): the step is left to the controller, and a crossing inside the accepted step to the
/// event location.
fn resolvable(distance: f64, t0: f64) -> bool {
    distance > 1024.0 * f64::EPSILON * t0.abs()
}

/// Whether a sample that computes `g_b = side h_k < 0` (past surface `k`, by at most
/// `value_tolerance`) is rounding rather than a crossing: `dh_k/dt` points into the mode (`side
/// dh_k/dt > 0`) at the previous sample point (rate `previous_rate`) and at this one (`rate`),
/// with no extremum located between them (an extremum point carries rate 0 and so never
/// qualifies). Sampling takes `h_k` to be monotone between such points, here away from the
/// surface from a value on the mode's side, so it cannot have crossed; the computed sign is the
/// rounding of `h_k` next to zero. (At a contact onset at `1e-7` nm/us, the gap `Z + sum_i q_i`
/// with `|Z|` near 9 nm is rounded to `1.8e-15` nm steps while the true indentation stays below
/// that for `1e-8` us: without this rule, a sample there one rounding step outside fired a
/// release whose rate pointed into the contact, then a second onset.)
fn is_rounding(side: f64, previous_rate: f64, g_b: f64, rate: f64, value_tolerance: f64) -> bool {
    g_b >= -value_tolerance && side * previous_rate > 0.0 && side * rate > 0.0
}

/// If the trial step on `clock` from `(t0, sigma0, z0)` over `dsigma` to `(t1, z1)` ends
/// across a switching surface (on the other side of the one the mode says), the fraction
/// `theta` of the step (in the clock's variable) at which the cubic Hermite interpolant of
/// `h_k` (values and rates at both ends) first crosses zero, with that surface `k`.
fn crossing_fraction<S: HybridSystem + ?Sized>(
    system: &S,
    mode: Mode,
    surfaces: usize,
    n: usize,
    clock: Clock,
    (t0, sigma0, z0): (f64, f64, &[f64]),
    (t1, dsigma, z1): (f64, f64, &[f64]),
) -> Option<(f64, usize)> {
    let scale0 = clock.rate(sigma0) * dsigma;
    let scale1 = clock.rate(sigma0 + dsigma) * dsigma;
    let mut earliest: Option<(f64, usize)> = None;
    for k in 0..surfaces {
        let side = side_sign(mode, k);
        let g1 = side * system.switching(k, t1, &z1[..n]);
        if g1.is_nan() || g1 >= 0.0 {
            continue;
        }
        let g0 = (side * system.switching(k, t0, &z0[..n])).abs();
        let r0 = side * system.switching_rate(k, mode, t0, &z0[..n]) * scale0;
        let r1 = side * system.switching_rate(k, mode, t1, &z1[..n]) * scale1;
        if !(g0.is_finite() && r0.is_finite() && r1.is_finite()) {
            continue;
        }
        let cubic = CubicHermite::new((0.0, g0, r0), (1.0, g1, r1));
        let mut hermite = |s: f64| cubic.derivative(0, s);
        let bracket = locate_sign_change(0.0, g0, 1.0, g1, &mut hermite, 1e-9, 0.0, None);
        let theta = bracket.far;
        if earliest.is_none_or(|(e, _)| theta < e) {
            earliest = Some((theta, k));
        }
    }
    earliest
}

/// The predicted time from `t0` to the first crossing of any switching surface, with that
/// surface, from the quadratic `g + r s + a s^2 / 2` in the current state (`g = |h_k|`, `r`
/// its rate, `a` the rate's derivative along the field by a forward difference over
/// `1e-4 h`), if one is predicted. `velocity` is `f(t0, x)`.
#[allow(clippy::too_many_arguments)]
fn predict_crossing<S: HybridSystem + ?Sized>(
    system: &S,
    velocity: &[f64],
    x_ahead: &mut [f64],
    x: &[f64],
    mode: Mode,
    surfaces: usize,
    t0: f64,
    h: f64,
) -> Option<(f64, usize)> {
    let delta = 1e-4 * h;
    if !(delta > 0.0 && delta.is_finite()) {
        return None;
    }
    for ((ahead, &xc), &v) in x_ahead.iter_mut().zip(x).zip(velocity) {
        *ahead = xc + delta * v;
    }
    let mut earliest: Option<(f64, usize)> = None;
    for k in 0..surfaces {
        let side = side_sign(mode, k);
        let g = (side * system.switching(k, t0, x)).max(0.0);
        let r = side * system.switching_rate(k, mode, t0, x);
        let r_ahead = side * system.switching_rate(k, mode, t0 + delta, x_ahead);
        let a = (r_ahead - r) / delta;
        if let Some(s) = first_positive_root(0.5 * a, r, g) {
            if earliest.is_none_or(|(e, _)| s < e) {
                earliest = Some((s, k));
            }
        }
    }
    earliest
}

/// The smallest positive root of `a s^2 + b s + c` (`c >= 0`), if any (finite values only).
fn first_positive_root(a: f64, b: f64, c: f64) -> Option<f64> {
    if !(a.is_finite() && b.is_finite() && c.is_finite()) {
        return None;
    }
    let root = if a == 0.0 {
        if b >= 0.0 {
            return None;
        }
        -c / b
    } else {
        let discriminant = b * b - 4.0 * a * c;
        if discriminant < 0.0 {
            return None;
        }
        // Stable form: q = -(b + sign(b) sqrt(D)) / 2; roots q / a and c / q.
        let q = -0.5 * (b + b.signum() * discriminant.sqrt());
        let roots = [q / a, if q != 0.0 { c / q } else { f64::NAN }];
        roots
            .into_iter()
            .filter(|r| *r > 0.0)
            .min_by(f64::total_cmp)?
    };
    (root > 0.0 && root.is_finite()).then_some(root)
}

/// A start `(t0, x0)` for a state of dimension `n`: the right length and finite.
fn check_start(n: usize, t0: f64, x0: &[f64]) -> Result<(), HybridError> {
    if x0.len() != n {
        return Err(HybridError::DimensionMismatch {
            expected: n,
            found: x0.len(),
        });
    }
    if !t0.is_finite() || x0.iter().any(|v| !v.is_finite()) {
        return Err(HybridError::NonFiniteState { t: t0 });
    }
    Ok(())
}

/// The state at `t` in the current (not yet accepted) step: dense output or exact flow.
#[allow(clippy::too_many_arguments)]
fn state_in_step<S: HybridSystem + ?Sized>(
    system: &S,
    kind: StepKind,
    mode: Mode,
    (rk, taylor): (&Dop853, &TaylorStep),
    (clock, sigma0): (Clock, f64),
    z_start: &[f64],
    z_new: &[f64],
    t0: f64,
    t1: f64,
    n: usize,
    t: f64,
    out: &mut [f64],
) {
    if t == t1 {
        out.copy_from_slice(&z_new[..n]);
        return;
    }
    if t == t0 {
        out.copy_from_slice(&z_start[..n]);
        return;
    }
    match kind {
        StepKind::RungeKutta => rk.interpolate(z_start, (clock.sigma(t) - sigma0) / rk.h, out),
        StepKind::Taylor => taylor.state.evaluate(clock.sigma(t) - sigma0, out),
        StepKind::Exact => {
            system.exact_flow(mode, t0, &z_start[..n], t - t0, out, None, None);
        }
        StepKind::None => out.copy_from_slice(&z_start[..n]),
    }
}
