//! The DOP853 step with its error control, crossing landings and square-root clocks (module
//! docs of [`crate::solver`], "Step-size control" and "Half-power surfaces").

use crate::clock::Clock;
use crate::dop853::Dop853;
use crate::error::HybridError;
use crate::system::{HybridSystem, Mode};

use super::crossing_search::crossing_fraction;
use super::predictors::{predict_crossing, resolvable};
use super::tuning::{
    APPROACH_FRACTION, FAILED_LANDING_ORDER, LANDING_OVERSHOOT, LANDING_REACH, MAX_RETARGETS,
    MIN_STEP_EPSILONS, NON_FINITE_RETRY, ORDER_ESTIMATE_RANGE, PREDICTED_OVERSHOOT,
    PROBE_OVERSHOOT, REJECTION_TARGET_ERROR, RETARGET_MOVE, ROOT_APPROACH, ROOT_CLOCK_SPAN,
    ROOT_OVERSHOOT, SERIES_HANDOVER_FRACTION, STEP_RATIO_AFTER_REJECTION,
};
use super::{Solver, StepKind};
use crate::variational_field::clocked_field;
use crate::workspace::Buffers;

/// The attempts at one Runge-Kutta step: the clock and step they run on and the crossing they
/// aim at, as the rejections adjust them.
struct Attempts {
    /// The clock of the next attempt.
    clock: Clock,
    /// Its reading at the step start.
    sigma0: f64,
    /// The rate `dt/dsigma` stage 0 holds its derivative with (`None`: not usable).
    stage0: Option<f64>,
    /// The next attempt's length in time units.
    h: f64,
    /// The step the controller proposed, before any aim at a crossing.
    h_proposed: f64,
    /// The predicted distance to the crossing a landing (or a probe) aims just past.
    landing: Option<f64>,
    /// The reference of the square-root clock the attempt ends exactly on (its crossing).
    crossing_target: Option<f64>,
    /// Whether a landing past a crossing was tried already in this step.
    landing_tried: bool,
    /// Re-centred square-root landings so far.
    retargets: usize,
    /// The clock step and error of the previous rejected attempt, for the order estimate.
    previous: Option<(f64, f64)>,
    /// Whether an attempt was rejected.
    rejected: bool,
    /// Whether the last attempt gave a non-finite error.
    non_finite: bool,
}

/// One attempt: its clock step, end time, whether it ends at `t_end`, and its error (accepted
/// when finite and at most 1).
#[derive(Clone, Copy)]
struct Trial {
    dsigma: f64,
    t1: f64,
    lands: bool,
    error: f64,
}

impl<'a, S: HybridSystem + ?Sized> Solver<'a, S> {
    /// One accepted DOP853 step (with as many rejected attempts as needed); returns the end
    /// time. Writes `z_new`, stage 12 and the state's dense output.
    ///
    /// The step runs on the time clock, or on a square-root clock (see [`Clock`]) in a mode
    /// whose field has a half-power surface: from the event that entered the mode through it,
    /// and towards a predicted crossing of it when the step lands on that crossing.
    pub(super) fn runge_kutta_step(&mut self, t_end: f64) -> Result<f64, HybridError> {
        let mode = self.mode;
        let t0 = self.t;
        let half_power = self.accelerations.half_power_surface(mode);
        let (rate, h) = self.start_runge_kutta_step();
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
        let mut attempts = Attempts {
            clock: base_clock,
            sigma0: t0,
            stage0: Some(rate),
            h,
            h_proposed: h,
            landing: None,
            crossing_target: None,
            landing_tried: false,
            retargets: 0,
            previous: None,
            rejected: false,
            non_finite: false,
        };
        self.aim_at_crossing(t_end, half_power, &mut attempts);
        attempts.sigma0 = attempts.clock.sigma(t0);
        attempts.stage0 =
            self.prepare_first_stage(mode, attempts.clock, attempts.sigma0, attempts.stage0);
        attempts.landing_tried = attempts.landing.is_some();
        let trial = loop {
            self.check_attempt(&attempts)?;
            let trial = self.attempt(t_end, &attempts);
            if trial.error.is_finite() && trial.error <= 1.0 {
                break trial;
            }
            self.statistics.rejected_steps += 1;
            attempts.rejected = true;
            self.after_rejection(half_power, &mut attempts, trial);
        };
        self.propose_after(&attempts, trial);
        self.finish_runge_kutta_step(attempts.clock, attempts.sigma0, trial)
    }

    /// Stage 0 at the step start (the derivative times the rate `dt/dsigma` it was computed
    /// with, reused from the last step's end, or evaluated afresh in time units if it holds
    /// nothing usable), `f(t0, x)` from it into the velocity buffer for the prediction, and the
    /// proposed step (Hairer's starting step for a solver's first step, whose stage 0 was just
    /// evaluated in time units), at most `max_step`. Returns the rate and the step.
    fn start_runge_kutta_step(&mut self) -> (f64, f64) {
        let (system, mode, t0) = (self.system, self.mode, self.t);
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
        self.buffers.rk.first_stage(&mut self.buffers.velocity);
        for v in &mut self.buffers.velocity {
            *v /= rate;
        }
        let max_step = self.settings.max_step;
        let h = match self.proposed_step {
            Some(h) => h,
            None => {
                let mut rhs =
                    clocked_field(&mut self.buffers.field, system, mode, Clock::Time, true);
                self.buffers.rk.initial_step(
                    &mut rhs,
                    t0,
                    &self.buffers.z,
                    self.settings.relative_tolerance,
                    self.settings.absolute_tolerance,
                    max_step,
                )
            }
        }
        .min(max_step);
        (rate, h)
    }

    /// Aim at the predicted crossing (see the module docs): land just past it when the
    /// proposed step reaches it (on a square-root clock centred there if it is a crossing of
    /// the half-power surface), or approach it in steps of a fixed fraction of the distance
    /// once a landing from too far has failed.
    fn aim_at_crossing(&mut self, t_end: f64, half_power: Option<usize>, attempts: &mut Attempts) {
        let (mode, t0, n) = (self.mode, self.t, self.n);
        let max_step = self.settings.max_step;
        let h = attempts.h;
        let predicted = predict_crossing(
            self.system,
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
        let Some((s, k)) = predicted.filter(|&(s, _)| !first || s >= h) else {
            return;
        };
        // Too close to resolve in time (a Zeno accumulation): leave the step to the
        // controller and the event location.
        if !(resolvable(s, t0) && s < t_end - t0) {
            return;
        }
        if half_power == Some(k) && h >= s / ROOT_APPROACH {
            // Within a few steps of a crossing of the half-power surface: steps on a
            // square-root clock centred on it, located on the last step's dense output
            // continued (the solution is smooth up to the crossing); the step that reaches it
            // lands on it. Without that location, a probe: a step just past the predicted
            // crossing, whose dense output locates it if the kink makes it fail.
            let divergent = self.accelerations.jacobian_diverges_at_crossing(mode);
            // After a Taylor step in a mode whose Jacobian diverges at the crossing (its series
            // take no square-root clock centred ahead, so Runge-Kutta steps make the approach):
            // the crossing that step's series predicted.
            let after_series = divergent && self.kind == StepKind::Taylor && self.steps_in_mode > 0;
            let located = if self.first_same_as_last && self.kind == StepKind::RungeKutta {
                self.continue_last_step(k, s * (1.0 + PROBE_OVERSHOOT))
            } else if after_series {
                self.predicted_crossing.filter(|&t_cross| t_cross > t0)
            } else {
                None
            };
            // Located by continuing a square-root step centred ahead (`continue_last_step`), or
            // by a series expanded before it: too coarse to land on (a landing that ends short
            // of the crossing leaves the tangents' branch point at its end). After a series, a
            // step in time at most `SERIES_HANDOVER_FRACTION` of the way (not a probe from afar,
            // which the crossing's square root rejects, nor a square-root clock centred on the
            // series' estimate: tried, it left the adhesive retract's period doublings 7e-9 nm
            // off); after a continued square-root step, the step that reaches it probes.
            let continued_root_clock = divergent
                && matches!(self.clock, Clock::SquareRoot { reference } if reference > t0);
            match located {
                Some(t_cross)
                    if after_series && resolvable(t_cross - t0, t0) && t_cross - t0 <= max_step =>
                {
                    attempts.h = h.min(SERIES_HANDOVER_FRACTION * (t_cross - t0));
                }
                Some(t_cross)
                    if continued_root_clock
                        && resolvable(t_cross - t0, t0)
                        && h >= t_cross - t0
                        && t_cross - t0 <= max_step =>
                {
                    attempts.h = ((t_cross - t0) * (1.0 + PROBE_OVERSHOOT)).min(max_step);
                    attempts.landing = Some(t_cross - t0);
                }
                Some(t_cross) if resolvable(t_cross - t0, t0) && t_cross - t0 <= max_step => {
                    let target = (t_cross - t0) * (1.0 + ROOT_OVERSHOOT);
                    let reference = t0 + target;
                    attempts.clock = Clock::SquareRoot { reference };
                    if h >= target {
                        attempts.crossing_target = Some(reference);
                        attempts.h = target;
                    }
                }
                _ if h >= s => {
                    attempts.h = (s * (1.0 + PROBE_OVERSHOOT)).min(max_step);
                    attempts.landing = Some(s);
                }
                _ => {}
            }
        } else {
            let limit_ok = self.landing_limit.is_none_or(|limit| s <= limit);
            if limit_ok && h >= LANDING_REACH * s {
                attempts.h = (s * (1.0 + PREDICTED_OVERSHOOT)).min(max_step);
                attempts.landing = Some(s);
            } else if !limit_ok {
                attempts.h = h.min(APPROACH_FRACTION * s);
            }
        }
    }

    /// Refuse a further attempt: too many steps, or a step too short to advance time (after a
    /// non-finite error: the state blew up).
    fn check_attempt(&self, attempts: &Attempts) -> Result<(), HybridError> {
        let t0 = self.t;
        let count = self.statistics.steps + self.statistics.rejected_steps;
        if count >= self.settings.max_steps {
            return Err(HybridError::TooManySteps {
                t: t0,
                steps: count,
            });
        }
        let h = attempts.h;
        if h.is_nan() || h <= MIN_STEP_EPSILONS * f64::EPSILON * t0.abs() || !h.is_finite() {
            return Err(if attempts.non_finite {
                HybridError::NonFiniteState { t: t0 }
            } else {
                HybridError::StepSizeUnderflow { t: t0, step: h }
            });
        }
        Ok(())
    }

    /// One DOP853 attempt from the step start: exactly onto the crossing target, or to `t_end`
    /// when the step reaches it, else of length `h` on the attempts' clock. Writes `z_new`.
    fn attempt(&mut self, t_end: f64, attempts: &Attempts) -> Trial {
        let (clock, sigma0, t0) = (attempts.clock, attempts.sigma0, self.t);
        let (dsigma, t1, lands) = match attempts.crossing_target {
            // Exactly onto the reference, where the clock's variable is zero.
            Some(reference) => (-sigma0, reference, false),
            None if attempts.h >= t_end - t0 => (clock.sigma(t_end) - sigma0, t_end, true),
            None => {
                let dsigma = clock.clock_step(t0, attempts.h);
                (dsigma, clock.time(sigma0 + dsigma), false)
            }
        };
        let mut rhs = clocked_field(&mut self.buffers.field, self.system, self.mode, clock, true);
        let error = self.buffers.rk.attempt(
            &mut rhs,
            sigma0,
            &self.buffers.z,
            dsigma,
            &mut self.buffers.z_new,
            self.settings.relative_tolerance,
            self.settings.absolute_tolerance,
        );
        Trial {
            dsigma,
            t1,
            lands,
            error,
        }
    }

    /// The next attempt after the rejected `trial`: a shorter step after a non-finite error; a
    /// landing re-centred on a crossing of the half-power surface the trial passed; the
    /// approach after a failed landing or probe; a landing just past a crossing the trial
    /// ended across (once); else the controller's step, with the error's order estimated from
    /// the last two attempts.
    fn after_rejection(
        &mut self,
        half_power: Option<usize>,
        attempts: &mut Attempts,
        trial: Trial,
    ) {
        let (t0, n) = (self.t, self.n);
        let Trial {
            dsigma, t1, error, ..
        } = trial;
        let clock = attempts.clock;
        if !error.is_finite() {
            attempts.non_finite = true;
            attempts.h = NON_FINITE_RETRY * (t1 - t0);
            attempts.crossing_target = None;
            attempts.previous = None;
            return;
        }
        attempts.non_finite = false;
        // Where the trial crossed a surface before its end (cubic Hermite estimate).
        let crossed = crossing_fraction(
            self.system,
            self.mode,
            self.surfaces,
            n,
            clock,
            (t0, attempts.sigma0, &self.buffers.z),
            (t1, dsigma, &self.buffers.z_new),
        );
        // A trial that passed a crossing of the half-power surface: locate the crossing on the
        // trial's dense output and land on it on a square-root clock centred there (repeated
        // with the landing's own dense output if that fails too).
        if let Some((_, k)) = crossed.filter(|&(_, k)| half_power == Some(k)) {
            if attempts.retargets < MAX_RETARGETS && self.retarget(k, attempts, trial) {
                return;
            }
        }
        let controller = |error: f64| clock.time_step(t0, Dop853::next_step(dsigma, error, false));
        // A square-root landing that failed without passing the crossing (it ends just before
        // it and the step is too long for the field's own variation): shorter steps on the
        // same clock, towards it.
        if attempts.crossing_target.take().is_some() {
            attempts.h = controller(error);
            attempts.previous = Some((dsigma, error));
            return;
        }
        // A probe that failed without passing the crossing: the controller's step.
        if half_power.is_some() && attempts.landing.take().is_some() {
            attempts.h = attempts.h_proposed.min(controller(error));
            attempts.previous = Some((dsigma, error));
            return;
        }
        // A predicted landing that failed: the step ending at a non-smooth crossing is too
        // long. Its error grows like a power of its length (s^3.5 next to a Hertz contact's
        // kink, larger for smoother kinks, so the estimate is conservative): remember the
        // distance from which a landing should succeed and approach it.
        if let Some(s) = attempts.landing.take() {
            let (low, high) = STEP_RATIO_AFTER_REJECTION;
            let limit = s
                * (REJECTION_TARGET_ERROR / error)
                    .powf(1.0 / FAILED_LANDING_ORDER)
                    .clamp(low, high);
            self.landing_limit = Some(self.landing_limit.map_or(limit, |l| l.min(limit)));
            attempts.h = APPROACH_FRACTION * s;
            attempts.previous = None;
            return;
        }
        // A trial that ends across a switching surface was probably rejected for the kink of
        // the field there: retry once landing just past the estimated crossing, so the step
        // holds the crossing with a negligible non-smooth part (instead of a geometric
        // sequence of steps shrinking towards the surface): on a square-root clock centred on
        // it for the half-power surface.
        if !attempts.landing_tried {
            if let Some((theta, _)) = crossed {
                attempts.landing_tried = true;
                let fraction = (theta + LANDING_OVERSHOOT).min(1.0);
                // (On a square-root clock a crossing next to its start lands a step of the
                // fraction squared: one too short to advance time is left to the controller.)
                let landing_step = clock.time_step(t0, fraction * dsigma);
                if fraction < 1.0 && resolvable(landing_step, t0) {
                    attempts.h = landing_step;
                    attempts.previous = None;
                    return;
                }
            }
        }
        attempts.h = clock.time_step(t0, next_after_rejections(attempts.previous, dsigma, error));
        attempts.previous = Some((dsigma, error));
    }

    /// Re-centre the attempts on the crossing of the half-power surface `k` that the rejected
    /// `trial` passed, located on its dense output: a square-root clock with its reference just
    /// past the crossing, the next attempt landing exactly there. `false` (nothing changed) if
    /// the crossing is not located, is where the clock already is, or cannot be landed on.
    fn retarget(&mut self, k: usize, attempts: &mut Attempts, trial: Trial) -> bool {
        let (mode, t0) = (self.mode, self.t);
        let Some(t_cross) = self.locate_in_trial(
            mode,
            attempts.clock,
            (t0, attempts.sigma0),
            (trial.t1, trial.dsigma),
            k,
        ) else {
            return false;
        };
        let target = (t_cross - t0) * (1.0 + ROOT_OVERSHOOT);
        // Re-centring helps only if the crossing is not where the clock already is.
        let moved = attempts.crossing_target.is_none_or(|reference| {
            (t0 + target - reference).abs() > RETARGET_MOVE * ROOT_OVERSHOOT * target
        });
        if !(moved && resolvable(target, t0) && target <= self.settings.max_step) {
            return false;
        }
        attempts.retargets += 1;
        let reference = t0 + target;
        attempts.clock = Clock::SquareRoot { reference };
        attempts.sigma0 = attempts.clock.sigma(t0);
        attempts.stage0 =
            self.prepare_first_stage(mode, attempts.clock, attempts.sigma0, attempts.stage0);
        attempts.crossing_target = Some(reference);
        attempts.landing = None;
        attempts.landing_tried = true;
        attempts.h = target;
        attempts.previous = None;
        true
    }

    /// The step proposed after the accepted `trial`, in time units: on a square-root clock the
    /// step's time resolution at its end (`dt/dsigma` there), which keeps the next step's error
    /// near the target as the clock speeds up; after a landing on a crossing, the step
    /// proposed before it; never shorter than a trial that reached `t_end` at once.
    fn propose_after(&mut self, attempts: &Attempts, trial: Trial) {
        let clock = attempts.clock;
        let sigma1 = attempts.sigma0 + trial.dsigma;
        let next_dsigma = Dop853::next_step(trial.dsigma, trial.error, attempts.rejected);
        let mut next = match clock {
            Clock::Time => next_dsigma,
            Clock::SquareRoot { .. } if sigma1 > 0.0 => next_dsigma * clock.rate(sigma1),
            Clock::SquareRoot { .. } if sigma1 < 0.0 && sigma1 + next_dsigma < 0.0 => {
                clock.time(sigma1 + next_dsigma) - clock.time(sigma1)
            }
            Clock::SquareRoot { .. } => attempts.h_proposed,
        }
        .min(self.settings.max_step);
        if trial.lands && !attempts.rejected {
            next = next.max(attempts.h);
        }
        self.proposed_step = Some(next);
    }

    /// Complete the accepted `trial` on `clock` from reading `sigma0`: stage 12 and the
    /// state's dense output, the tangents carried apart from the state's stages under
    /// [`crate::SensitivityMethod::Decoupled`], the counters; returns the end time.
    fn finish_runge_kutta_step(
        &mut self,
        clock: Clock,
        sigma0: f64,
        trial: Trial,
    ) -> Result<f64, HybridError> {
        let Trial { dsigma, t1, .. } = trial;
        complete_stages(
            &mut self.buffers,
            self.system,
            self.mode,
            clock,
            (sigma0, dsigma),
            StepStart::Step,
        );
        self.statistics.rhs_evaluations = self.buffers.field.evaluations;
        if self.buffers.z_new.iter().any(|v| !v.is_finite()) {
            return Err(HybridError::NonFiniteState { t: t1 });
        }
        self.clock = clock;
        self.sigma_start = sigma0;
        self.stage0_rate = clock.rate(sigma0 + dsigma);
        self.kind = StepKind::RungeKutta;
        self.first_same_as_last = false;
        self.steps_in_mode += 1;
        self.statistics.steps += 1;
        Ok(t1)
    }

    /// Complete the attempt of [`Solver::redo_onto_crossing`] in `mode` on `clock` from reading
    /// `sigma0` over `dsigma`, from `z_start` to `z_new`: [`complete_stages`].
    fn complete_redone_step(&mut self, mode: Mode, clock: Clock, sigma0: f64, dsigma: f64) {
        complete_stages(
            &mut self.buffers,
            self.system,
            mode,
            clock,
            (sigma0, dsigma),
            StepStart::Attempt,
        );
        self.statistics.rhs_evaluations = self.buffers.field.evaluations;
    }

    /// Redo the Runge-Kutta step just taken (in `self.step_mode`, from `z_start`) so that it
    /// ends exactly on the crossing of its mode's half-power surface `k` located at `t_event`,
    /// on the square-root clock centred there, where the system declares the mode's Jacobian
    /// divergent at that surface ([`crate::SwitchingStructure::jacobian_diverges_at_crossing`]):
    /// the step that located the crossing ran on a clock centred [`ROOT_OVERSHOOT`] past the
    /// predicted crossing (or on time), on which `(dt/dsigma) J` has a branch point inside the
    /// step, so its transition matrix carries an error of about `sqrt(ROOT_OVERSHOOT)` of the
    /// step's share, whatever the tolerance; on the clock centred on the crossing the field and
    /// its Jacobian are smooth up to the step's end, where the system's
    /// [`crate::SwitchingStructure::crossing_tangent_limit`] gives stage 12's tangents. The
    /// redone step is the step from then on (`z_new`, dense output, clock), and the event fires
    /// at its end. Its error estimate is not tested: it covers less than the accepted step it
    /// replaces, on a clock on which the solution is smoother. Returns whether it redid the
    /// step.
    pub(super) fn redo_onto_crossing(
        &mut self,
        k: usize,
        t_event: f64,
    ) -> Result<bool, HybridError> {
        let (mode, t0) = (self.step_mode, self.step_start);
        if self.kind != StepKind::RungeKutta
            || self.accelerations.half_power_surface(mode) != Some(k)
            || !self.accelerations.jacobian_diverges_at_crossing(mode)
            || !(t_event > t0 && t_event < self.step_end)
        {
            return Ok(false);
        }
        let held = self.clock.rate(self.sigma_start);
        let clock = Clock::SquareRoot { reference: t_event };
        let sigma0 = clock.sigma(t0);
        if sigma0 >= 0.0 {
            return Ok(false);
        }
        self.prepare_first_stage(mode, clock, sigma0, Some(held));
        let dsigma = -sigma0;
        {
            let buffers = &mut self.buffers;
            let mut rhs = clocked_field(&mut buffers.field, self.system, mode, clock, true);
            buffers.rk.attempt(
                &mut rhs,
                sigma0,
                &buffers.z_start,
                dsigma,
                &mut buffers.z_new,
                self.settings.relative_tolerance,
                self.settings.absolute_tolerance,
            );
        }
        self.complete_redone_step(mode, clock, sigma0, dsigma);
        if self.buffers.z_new.iter().any(|v| !v.is_finite()) {
            return Err(HybridError::NonFiniteState { t: t_event });
        }
        self.clock = clock;
        self.sigma_start = sigma0;
        self.step_end = t_event;
        self.full_dense = false;
        self.statistics.redone_steps += 1;
        Ok(true)
    }

    /// On the crossing a square-root clock is centred on, stage 0's tangent part from the
    /// system's [`crate::SwitchingStructure::crossing_tangent_limit`] (the limit of
    /// `(dt/dsigma) J v` for a Jacobian growing as `|h|^{-1/2}`), where it gives one, instead of
    /// the zero the vanishing clock rate leaves.
    fn first_stage_crossing_limit(&mut self, mode: Mode, t: f64) {
        let Some(structure) = self.accelerations.switching else {
            return;
        };
        if !self.sensitivity.transition() {
            return;
        }
        let n = self.system.dim();
        let parameter = self.sensitivity.parameter();
        let columns = if parameter { n + 1 } else { n };
        let (x, tangents) = self.buffers.z.split_at(n);
        if tangents.len() < columns * n {
            return;
        }
        self.buffers
            .rk
            .refill_first_stage(n..n + columns * n, |out| {
                structure.crossing_tangent_limit(
                    mode,
                    t,
                    x,
                    &tangents[..columns * n],
                    out,
                    parameter,
                )
            });
    }

    /// Make stage 0 hold the augmented derivative at the step start on `clock` (reading
    /// `sigma0`): rescale the one it holds (`stage0`, the rate it was computed with) or
    /// evaluate it. Returns the rate stage 0 now holds.
    pub(super) fn prepare_first_stage(
        &mut self,
        mode: Mode,
        clock: Clock,
        sigma0: f64,
        stage0: Option<f64>,
    ) -> Option<f64> {
        let rate = clock.rate(sigma0);
        match stage0 {
            Some(held) if held == rate => {}
            Some(held) if held != 0.0 => {
                self.buffers.rk.scale_first_stage(rate / held);
                if rate == 0.0 {
                    self.first_stage_crossing_limit(mode, clock.time(sigma0));
                }
            }
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
}

/// The clock step after successive rejections: with the error's actual order in the step
/// estimated from the last two attempts (near a singularity of the field it is far below 8),
/// the step aiming for an error of [`REJECTION_TARGET_ERROR`]; Hairer's controller when there
/// is no usable previous attempt or the estimate is implausible.
fn next_after_rejections(previous: Option<(f64, f64)>, dsigma: f64, error: f64) -> f64 {
    match previous {
        Some((previous_step, previous_error))
            if previous_step > dsigma && previous_error > error =>
        {
            let order = (previous_error / error).ln() / (previous_step / dsigma).ln();
            if ORDER_ESTIMATE_RANGE.contains(&order) {
                let (low, high) = STEP_RATIO_AFTER_REJECTION;
                dsigma
                    * (REJECTION_TARGET_ERROR / error)
                        .powf(1.0 / order)
                        .clamp(low, high)
            } else {
                Dop853::next_step(dsigma, error, false)
            }
        }
        _ => Dop853::next_step(dsigma, error, false),
    }
}

/// The buffer a Runge-Kutta step being completed started from.
#[derive(Clone, Copy)]
enum StepStart {
    /// `z`: a step accepted by the error control.
    Step,
    /// `z_start`: a step redone onto a crossing ([`Solver::redo_onto_crossing`]).
    Attempt,
}

/// Complete a Runge-Kutta step in `mode` on `clock` from reading `sigma0` over `dsigma`, from
/// the state named by `start` to `z_new`: stage 12 and the state's dense output, and the
/// tangents carried apart from the state's stages under
/// [`crate::SensitivityMethod::Decoupled`]. Always inlined: as a call it changed the stepping
/// loop's inlining.
#[inline(always)]
fn complete_stages<S: HybridSystem + ?Sized>(
    buffers: &mut Buffers,
    system: &S,
    mode: Mode,
    clock: Clock,
    (sigma0, dsigma): (f64, f64),
    start: StepStart,
) {
    let n = buffers.n;
    let z0 = match start {
        StepStart::Step => &buffers.z,
        StepStart::Attempt => &buffers.z_start,
    };
    {
        let mut rhs = clocked_field(&mut buffers.field, system, mode, clock, true);
        buffers
            .rk
            .derivative_at_end(&mut rhs, sigma0, &buffers.z_new);
    }
    {
        let mut rhs = clocked_field(&mut buffers.field, system, mode, clock, false);
        buffers
            .rk
            .dense_coefficients(&mut rhs, sigma0, z0, &buffers.z_new, n);
    }
    if let Some(tangents) = buffers.tangents.as_mut() {
        let (x1, end) = buffers.z_new.split_at_mut(n);
        let rk = &buffers.rk;
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
}
