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
//!   `|h_k''|` ([`crate::SwitchingStructure::switching_curvature_bound`]), a step on the positive
//!   side of every surface whose chord between its end values stays above the height even when bent
//!   by `M dt^2 / 8` is sampled at its ends only, and reports no extrema; an exact-flow step is
//!   stretched (beyond `exact_step_limit`) as far as `h_k(t0) + h_k'(t0) s - M s^2 / 2` stays above
//!   the height. In a step that is sampled, a sample interval whose chord bent by `M spacing^2 / 8`
//!   stays above the height is not searched for an extremum (free flight between contacts, whose
//!   gap minima clear the sample). At any height, a step whose end rates have one sign and `|r0| +
//!   |r1| > M dt` is monotone (the rate cannot reach zero in between) and is sampled at its ends
//!   only. None of these can hide a crossing: the bound is rigorous.
//! * Steps settled on their interpolant. Where every `h_k` is affine in the state and time
//!   ([`crate::SwitchingStructure::switching_is_affine`]), its interpolant over a Runge-Kutta step
//!   is a polynomial of degree 7 in the step's clock (20 over a Taylor step: the series itself),
//!   and the Bernstein coefficients of it and of its derivative bound them on the whole step
//!   (`crate::bernstein`). A step on which every `h_k` is proven strictly monotone (both end rates
//!   of that sign too), or above the surface and the extremum height, is sampled at its ends only:
//!   it holds no extremum the samples could find, and at most one crossing per surface, which the
//!   signs at its ends show and which is located on the interpolant as usual. Inside a Hertz
//!   contact every step but the one holding the deepest indentation is monotone. The bound is
//!   rigorous for the interpolant, which is what sampling inspects too. Where an `h_k` is affine
//!   in the state only, with a time part whose series the system gives
//!   ([`crate::SwitchingStructure::switching_is_affine_in_state`], a gap with a base motion in
//!   it), the same holds over Taylor steps (the state's series weighted by the gradient plus the
//!   time part's series) but not over Runge-Kutta steps, which are then sampled. Where an `h_k`
//!   is not affine in the state but the system gives its series along a Taylor step's
//!   ([`crate::SwitchingStructure::switching_series`], a standard linear solid's `d +
//!   rho^{2/3}`), that series is its polynomial over the step, which is kept within the reach
//!   at which the series' last two terms stay below the state's tolerance; a step from where the
//!   system gives none is a Runge-Kutta step.
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
//! [`crate::SwitchingStructure::half_power_surface`]), the solution next to a transversal crossing
//! `t_c` behaves like `|t - t_c|^{7/2}`: a step in time that starts or ends there has an error of
//! order 3.5 in its length, whatever the method's order, so onset and release would cost a
//! geometric sequence of short steps each, and the variational equations (whose Jacobian goes like
//! `|h|^{1/2}`) would carry errors the state-only controller does not see. In `sigma = sign(t -
//! t_c) sqrt|t - t_c|` the same solution is smooth, so such steps run on a square-root clock
//! (`crate::clock`):
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
//! * where the field has a `|h_k|^{1/2}` term, so that its Jacobian grows as `|h_k|^{-1/2}`
//!   ([`crate::SwitchingStructure::jacobian_diverges_at_crossing`]: JKR's force at pull-off, a
//!   viscous contact at release), the clock centred `ROOT_OVERSHOOT` past the predicted crossing
//!   leaves `(dt/dsigma) J` a branch point inside the landing step, and the tangents an error of
//!   about `sqrt(ROOT_OVERSHOOT)` of the step's share that no tolerance removes. The
//!   Runge-Kutta step in which such a crossing fires is therefore redone from its start on the
//!   clock centred on the crossing located in it, ending there (`Solver::redo_onto_crossing`;
//!   one more attempt of 12 stages and the dense output per crossing; the event then fires at
//!   the redone step's end, and the redone step is the one observers see). A system that
//!   declares the divergence gives no Taylor series on a square-root clock centred ahead
//!   (afm's JKR series run on the time clock only), whose tangents would be summed at the
//!   branch point. In such a mode Runge-Kutta steps make the whole approach: after the last
//!   series step, a step in time at most `SERIES_HANDOVER_FRACTION` of the way to the crossing
//!   its series predicted; then steps on the square-root clock, each located by continuing the
//!   last one up to its reference (past it, the continuation in `sigma` retraces the approach);
//!   and the step that reaches the crossing so located probes rather than lands (that location,
//!   extrapolated far in `sigma`, may fall short of the crossing, leaving the branch point at
//!   the landing's end).
//!
//! # Taylor-series steps
//!
//! Where the system gives the Taylor series of the mode's solution
//! ([`crate::TaylorExpansion::taylor_series`]; the AFM model in Hertz contact), a step is one
//! series of order 20 in the step's clock offset (`crate::taylor`), as long as its last two terms
//! stay below the tolerance (Jorba and Zou 2005); the tangents come from the system's tangent
//! series along it ([`crate::TaylorExpansion::taylor_tangents`]). The clock is the one in which the
//! solution is analytic up to its nearest non-smooth point: the square-root clock from the crossing
//! that entered the mode, until the crossing out of it that the last series predicts (its first
//! zero of the half-power surface within two reaches) is nearer (the series of a step is re-centred
//! on a crossing inside its own reach on that condition too, so that no series is expanded next to
//! the entering crossing's half power: a grazing contact, shorter than that reach, is one step on
//! the clock of its onset); then the square-root clock centred `ROOT_OVERSHOOT` past that predicted
//! crossing, re-centred on the zero of its own series when they differ, so that the step landing on
//! its reference holds the crossing, which is then located on the series like any other. A ridge of
//! that surface (approached and left without a crossing: the indentation's shallow minimum between
//! two merged contacts), seen ahead on the series or passed earlier in the mode, puts branch points
//! of `|h|^{1/2}` next to the real axis that the state's last terms do not show: the step then
//! stays within half their distance (`crate::series_step::surface_ahead`,
//! `TaylorStep::radius_reach`). The series is the step's dense output, and its polynomial in the
//! switching function carries the Bernstein tests above. A system that gives no series, a series
//! that cannot be formed (a grazing touch), a crossing predicted past the reference, or a reach
//! collapsing below `1e-3` of the last series step hands the step to DOP853. Through a Hertz
//! contact a series step replaces tens of DOP853 attempts, and on the square-root clock the
//! monodromy matrix is accurate to the state's tolerance without error control of the sensitivities
//! (`cargo run --release -p afm --example monodromy_error` compares the methods).

mod crossing_search;
mod dense_output;
mod events;
mod exact_step;
mod predictors;
mod runge_kutta;
mod step_proofs;
mod stepping;
mod taylor_step;
mod tuning;

use nalgebra::DMatrix;

use crate::accelerations::Accelerations;
use crate::clock::Clock;
use crate::error::HybridError;
use crate::event::{Event, Extremum};
use crate::sensitivity::Sensitivity;
use crate::series_step::Ridge;
use crate::settings::Settings;
use crate::system::{HybridSystem, Mode, MAX_SURFACES};
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
    /// Runge-Kutta steps redone onto a crossing of a half-power surface at which the mode's
    /// Jacobian diverges, ending exactly on it (not counted in `steps`; see the module docs,
    /// "Half-power surfaces").
    pub redone_steps: usize,
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
    /// The system's optional accelerations ([`HybridSystem::accelerations`]).
    accelerations: Accelerations<'a>,
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
    /// The curvature bounds of every surface over the span [`Solver::clear_exact_span`]
    /// considered from the last step's start, where `span_bounded`: a bound over that span
    /// bounds the step taken inside it, so the step's search reuses them.
    span_bounds: [f64; MAX_SURFACES],
    span_bounded: bool,
    /// `(surface, t)` of the state in `x_far`: the earliest point on the far side of that
    /// surface the crossing search of the last step evaluated, `None` if none.
    far_evaluated: Option<(usize, f64)>,
    /// Whether every switching function is affine (gradients and drifts in the buffers), so
    /// that a Runge-Kutta step may be proven settled on its interpolant.
    affine_switching: bool,
    /// Whether every switching function is affine in the state (gradients in the buffers;
    /// affine in time too, or with the time part's series from the system,
    /// [`crate::SwitchingStructure::switching_time_series`]), so that its polynomial along a
    /// Taylor step's series is known.
    series_switching: bool,
    /// The surfaces (bit `k`) that are not affine in the state but whose series along a
    /// Taylor step the system gives ([`crate::SwitchingStructure::switching_series`]).
    given_series: u32,
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
        let accelerations = system.accelerations();
        let affine_switching = (0..surfaces).all(|k| accelerations.switching_is_affine(k));
        let series_switching = affine_switching
            || (0..surfaces).all(|k| {
                accelerations.switching_is_affine(k)
                    || accelerations.switching_is_affine_in_state(k)
                    || accelerations.switching_has_series(k)
            });
        // The surfaces whose series along a Taylor step the system gives (bit `k`).
        let given_series = (0..surfaces)
            .filter(|&k| {
                !affine_switching
                    && !accelerations.switching_is_affine(k)
                    && !accelerations.switching_is_affine_in_state(k)
                    && accelerations.switching_has_series(k)
            })
            .fold(0_u32, |bits, k| bits | 1 << k);
        if series_switching {
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
            accelerations,
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
            span_bounds: [0.0; MAX_SURFACES],
            span_bounded: false,
            far_evaluated: None,
            affine_switching,
            series_switching,
            given_series,
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

    /// Continue in `mode` instead of the mode [`HybridSystem::mode_of`] gave at the start: for
    /// a flow that continues another one's end (a period map split at a grazing), where the
    /// state alone does not tell a hysteretic system's mode (the attached bit of a contact
    /// that forms at one surface and breaks at another; [`HybridSystem::mode_after_crossing`]).
    /// Call it before the first step.
    pub fn set_mode(&mut self, mode: Mode) {
        self.mode = mode;
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
