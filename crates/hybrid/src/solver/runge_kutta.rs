//! The DOP853 step with its error control, crossing landings and square-root clocks (module
//! docs of [`crate::solver`], "Step-size control" and "Half-power surfaces").

use crate::clock::Clock;
use crate::dop853::Dop853;
use crate::error::HybridError;
use crate::system::{HybridSystem, Mode};

use super::crossing_search::crossing_fraction;
use super::predictors::{predict_crossing, resolvable};
use super::tuning::{
    APPROACH_FRACTION, LANDING_OVERSHOOT, LANDING_REACH, MAX_RETARGETS, PREDICTED_OVERSHOOT,
    PROBE_OVERSHOOT, ROOT_APPROACH, ROOT_CLOCK_SPAN, ROOT_OVERSHOOT,
};
use super::{clocked_field, Solver, StepKind};

impl<'a, S: HybridSystem + ?Sized> Solver<'a, S> {
    /// One accepted DOP853 step (with as many rejected attempts as needed); returns the end
    /// time. Writes `z_new`, stage 12 and the state's dense output.
    ///
    /// The step runs on the time clock, or on a square-root clock (see [`Clock`]) in a mode
    /// whose field has a half-power surface: from the event that entered the mode through it,
    /// and towards a predicted crossing of it when the step lands on that crossing.
    pub(super) fn runge_kutta_step(&mut self, t_end: f64) -> Result<f64, HybridError> {
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
}
