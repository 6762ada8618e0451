//! The Taylor-series step (module docs of [`crate::solver`], "Taylor-series steps").

use crate::accelerations::Accelerations;
use crate::clock::Clock;
use crate::error::HybridError;
use crate::mode::Mode;
use crate::series_step::{
    surface_ahead, tangent_control, Ridge, SurfaceAhead, TaylorStep, TAYLOR_ORDER,
};
use crate::system::{side_sign, HybridSystem};
use crate::taylor::ClockPolynomial;

use super::tuning::{
    MAX_RETARGETS, MIN_SERIES_FRACTION, RELEASE_LOOKAHEAD, RETARGET_MOVE, ROOT_OVERSHOOT,
};
use super::{Solver, StepKind};

impl<'a, S: HybridSystem + ?Sized> Solver<'a, S> {
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
    pub(super) fn taylor_step(&mut self, t_end: f64) -> Result<Option<f64>, HybridError> {
        let mode = self.mode;
        let accelerations = self.accelerations;
        if !self.settings.taylor_series || accelerations.taylor_order_limit(mode) < TAYLOR_ORDER {
            return Ok(None);
        }
        let half_power = accelerations.half_power_surface(mode);
        if half_power.is_some() && !self.series_switching {
            return Ok(None);
        }
        self.check_attempts()?;
        let t0 = self.t;
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
            let polynomial = clock_polynomial(clock, t0, sigma0);
            let Some(mut reach) = self.expand_series(polynomial) else {
                return Ok(None);
            };
            // On a square-root clock centred ahead, the step ends at its reference at the
            // latest. (On the time clock `sigma0 = t0` may be negative: it is never ahead.)
            let ahead = matches!(clock, Clock::SquareRoot { .. }) && sigma0 < 0.0;
            let mut landing = ahead && reach >= -sigma0;
            if ahead {
                reach = reach.min(-sigma0);
            }
            // The half-power surface's first zero along the series: within the step, the
            // crossing the step must hold; beyond it, the prediction for the next step.
            let crossing = match half_power {
                Some(k) => {
                    let upto = if ahead {
                        -sigma0
                    } else {
                        RELEASE_LOOKAHEAD * reach
                    };
                    let (zero, radius_reach) = self.half_power_zero(k, polynomial, upto);
                    if let Some(radius_reach) = radius_reach {
                        reach = reach.min(radius_reach);
                        landing = landing && reach >= -sigma0;
                    }
                    zero
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
                    landing
                        && reference - t_cross > RETARGET_MOVE * ROOT_OVERSHOOT * (reference - t0)
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
            break self.series_step_length(clock, sigma0, reach, t_end);
        };
        // A series whose reach collapses (a start next to a non-smooth point it is not centred
        // on) would crawl: the Runge-Kutta step's landings handle that.
        if t1 < t_end && t1 - t0 < MIN_SERIES_FRACTION * self.last_series_step {
            return Ok(None);
        }
        self.finish_taylor_step(clock, sigma0, length, t1).map(Some)
    }

    /// Expand the series of the state (and, with sensitivities, of the tangents) from the
    /// current state on the clock `polynomial`; the reach of the step it allows (in the clock
    /// offset), or `None` where the system cannot form the series.
    fn expand_series(&mut self, polynomial: ClockPolynomial) -> Option<f64> {
        let (mode, n) = (self.mode, self.n);
        let expansion = self.accelerations.taylor?;
        let taylor = &mut self.buffers.taylor;
        if !taylor.expand(expansion, mode, polynomial, &self.buffers.z[..n]) {
            return None;
        }
        let mut reach = TaylorStep::reach(
            &taylor.state,
            self.settings.relative_tolerance,
            self.settings.absolute_tolerance,
        );
        // A surface whose series the system gives is summed within the same tolerance, so
        // that its polynomial is as accurate as the state's over the step.
        let mut given = self.given_series;
        while given != 0 {
            let k = given.trailing_zeros() as usize;
            given &= given - 1;
            let order = taylor.state.order().min(TAYLOR_ORDER);
            let mut power = [0.0; TAYLOR_ORDER + 1];
            if !accelerations_series(self.accelerations, k, mode, taylor, &mut power[..=order]) {
                return None;
            }
            reach = reach.min(TaylorStep::polynomial_reach(
                &power[..=order],
                self.settings.relative_tolerance,
                self.settings.absolute_tolerance,
            ));
            // Kept for the surface's zeros ahead and the step's proofs.
            taylor.surface = Some((k, power));
        }
        if self.sensitivity.transition() {
            // The tangents' order was fixed with the workspace (it fits these settings).
            let (_, tolerance) = tangent_control(&self.settings);
            taylor.expand_tangents(
                expansion,
                mode,
                &self.buffers.z[n..],
                self.sensitivity.parameter(),
            );
            if let Some(tolerance) = tolerance {
                reach = reach.min(TaylorStep::reach(&taylor.tangents, tolerance, tolerance));
            }
        }
        Some(reach)
    }

    /// The first zero in `(0, upto]` of the half-power surface `k` along the series just
    /// expanded on `polynomial`, as a time, and the reach (in the clock offset) to which a
    /// ridge of the surface limits the series, if one was seen: a ridge (the surface approached
    /// and left without a crossing) bounds the series' radius, which the step keeps well
    /// inside. The ridge is kept, in time units, for the later steps in the mode.
    fn half_power_zero(
        &mut self,
        k: usize,
        polynomial: ClockPolynomial,
        upto: f64,
    ) -> (Option<f64>, Option<f64>) {
        let t0 = self.t;
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
        let radius_reach = radius
            .filter(|r| r.is_finite())
            .map(TaylorStep::radius_reach);
        (surface.zero.map(|s| polynomial.time(s)), radius_reach)
    }

    /// The step the series allows from reading `sigma0` of `clock`: `(sigma0, length in the
    /// clock, end time)`, its `reach` cut at `t_end` and at `max_step`.
    fn series_step_length(
        &self,
        clock: Clock,
        sigma0: f64,
        reach: f64,
        t_end: f64,
    ) -> (f64, f64, f64) {
        let t0 = self.t;
        let t_reach = clock.time(sigma0 + reach);
        let max_step = self.settings.max_step;
        if t_reach >= t_end {
            (sigma0, clock.sigma(t_end) - sigma0, t_end)
        } else if t_reach - t0 > max_step {
            let length = clock.clock_step(t0, max_step);
            (sigma0, length, clock.time(sigma0 + length))
        } else {
            (sigma0, reach, t_reach)
        }
    }

    /// Take the series step of `length` (in the clock offset) on `clock` from reading
    /// `sigma0`, ending at `t1`: `z_new` from the series, the counters; returns `t1`.
    fn finish_taylor_step(
        &mut self,
        clock: Clock,
        sigma0: f64,
        length: f64,
        t1: f64,
    ) -> Result<f64, HybridError> {
        let (t0, n) = (self.t, self.n);
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
        Ok(t1)
    }

    /// The first zero in `(0, upto]` of surface `k` (affine) along the last Taylor series, in
    /// its clock offset, and the radius a ridge of it limits the series to
    /// ([`surface_ahead`]). The surface's polynomial is kept with the series
    /// ([`TaylorStep::surface`]) for the step's Bernstein tests.
    pub(super) fn surface_ahead(&mut self, k: usize, upto: f64) -> SurfaceAhead {
        let start = self.buffers.taylor.clock.start;
        let start_value = self.system.switching(k, start, &self.buffers.z[..self.n]);
        let Some(power) = self.series_surface_polynomial(k, start_value) else {
            return SurfaceAhead {
                zero: None,
                ridge: None,
            };
        };
        self.buffers.taylor.surface = Some((k, power));
        surface_ahead(&power, upto, side_sign(self.mode, k))
    }

    /// The polynomial in the clock offset `s` of the surface `k`, affine in the state, along
    /// the last Taylor series: `h_k(t0) + g . (x(s) - x(0)) + b (t(s) - t0)` for an affine
    /// one, with `h_k(t0) = start_value`; for a time part `b_k(t)` that is not affine, its
    /// series from the system ([`crate::SwitchingStructure::switching_time_series`]) in place of
    /// `b (t(s) - t0)`; for a surface not affine in the state, the system's series of it
    /// ([`crate::SwitchingStructure::switching_series`]; `None` where it gives none).
    pub(super) fn series_surface_polynomial(
        &self,
        k: usize,
        start_value: f64,
    ) -> Option<[f64; TAYLOR_ORDER + 1]> {
        let n = self.n;
        let taylor = &self.buffers.taylor;
        let mut power = [0.0; TAYLOR_ORDER + 1];
        if self.given_series & (1 << k) != 0 {
            if let Some((kept, mut power)) = taylor.surface {
                if kept == k {
                    power[0] = start_value;
                    return Some(power);
                }
            }
            let order = taylor.state.order().min(TAYLOR_ORDER);
            if !accelerations_series(
                self.accelerations,
                k,
                self.mode,
                taylor,
                &mut power[..=order],
            ) {
                return None;
            }
            power[0] = start_value;
            return Some(power);
        }
        taylor.state.weighted_sum(
            &self.buffers.affine_gradients[k * n..(k + 1) * n],
            &mut power,
        );
        if self.affine_switching {
            let drift = self.buffers.affine_drifts[k];
            power[1] += drift * taylor.clock.rate;
            power[2] += drift * taylor.clock.curvature;
        } else {
            let order = taylor.state.order().min(TAYLOR_ORDER);
            let mut time_part = [0.0; TAYLOR_ORDER + 1];
            self.accelerations
                .switching_time_series(k, &taylor.clock, &mut time_part[..=order]);
            for (p, b) in power.iter_mut().zip(&time_part).skip(1) {
                *p += b;
            }
        }
        power[0] = start_value;
        Some(power)
    }
}

/// The system's series of surface `k` along the step's state series `taylor` in mode `mode`
/// ([`crate::SwitchingStructure::switching_series`]) into `power`.
fn accelerations_series(
    accelerations: Accelerations<'_>,
    k: usize,
    mode: Mode,
    taylor: &TaylorStep,
    power: &mut [f64],
) -> bool {
    accelerations.switching_series(k, mode, &taylor.clock, &taylor.state, power)
}

/// The time along a step on `clock` from `t0` (reading `sigma0`) as a polynomial in the
/// clock offset ([`ClockPolynomial`]): `t0 + s` on the time clock, `t0 + 2 |sigma0| s +
/// sign(sigma0) s^2` on a square-root clock.
fn clock_polynomial(clock: Clock, t0: f64, sigma0: f64) -> ClockPolynomial {
    match clock {
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
    }
}
