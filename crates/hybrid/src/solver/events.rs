//! Event firing: the earliest strict crossing in a step, and its application (reset or mode
//! flip, saltation of the transition matrix and parameter sensitivity, truncation of the step).

use crate::error::HybridError;
use crate::event::Event;
use crate::event_location::{crossing_guess, locate_sign_change, Bracket};
use crate::system::{side_sign, Direction, HybridSystem, Mode};

use super::dense_output::state_in_step;
use super::{Solver, StepKind};

impl<'a, S: HybridSystem + ?Sized> Solver<'a, S> {
    /// Scan every surface for its first strict crossing in the step (through samples and
    /// located extrema, so a brief dip is found through its negative minimum), locate each,
    /// and return the earliest.
    pub(super) fn earliest_crossing(
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
        self.far_evaluated = None;
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
            let exact_flow = self.accelerations.exact_flow;
            let n = self.n;
            let kind = self.kind;
            let dense = (&self.buffers.rk, &self.buffers.taylor);
            let z_start = &self.buffers.z_start;
            let z_new = &self.buffers.z_new;
            let clock = (self.clock, self.sigma_start);
            let x = &mut self.buffers.x;
            let (x_far, far_evaluated) = (&mut self.buffers.x_far, &mut self.far_evaluated);
            let mut g = |t: f64| {
                state_in_step(
                    exact_flow, kind, mode, dense, clock, z_start, z_new, t0, t1, n, t, x,
                );
                let value = side * system.switching(k, t, x);
                // The earliest far-side state is kept: the located crossing's far end is
                // usually one of them, and the event fires there.
                if value <= 0.0 && far_evaluated.is_none_or(|(surface, at)| surface != k || t < at)
                {
                    x_far.copy_from_slice(x);
                    *far_evaluated = Some((k, t));
                }
                value
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

    /// Apply the event on surface `k` located in `bracket`: choose the side, reset or flip the
    /// mode, apply saltation, and truncate the step there.
    pub(super) fn fire(
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
        let redone = !reset && self.redo_onto_crossing(k, t_event)?;
        if !redone && self.dim == n && self.far_evaluated == Some((k, t_event)) {
            // The crossing search evaluated the state there (the same call on the same step).
            self.buffers.z.copy_from_slice(&self.buffers.x_far);
            if self.kind == StepKind::Exact {
                // As `augmented_at` leaves it: the truncated exact step's end.
                self.buffers.z_new.copy_from_slice(&self.buffers.x_far);
            }
        } else {
            self.augmented_at(t_event);
        }
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
        let crossed = if negative_after {
            mode | (1 << k)
        } else {
            mode & !(1 << k)
        };
        let new_mode = system.mode_after_crossing(k, direction, mode, crossed);
        if self.sensitivity.transition() {
            self.saltation_update(k, new_mode, t_event, reset)?;
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
            mode,
        })
    }

    /// Carry the transition matrix and parameter sensitivity in `z` through the event on
    /// surface `k` at `t_event` into `new_mode` (with the reset map's Jacobian if `reset`):
    /// the saltation matrix from the fields on both sides (`f_minus`, set by the caller, and
    /// `f_plus`) and the surface's gradient.
    fn saltation_update(
        &mut self,
        k: usize,
        new_mode: Mode,
        t_event: f64,
        reset: bool,
    ) -> Result<(), HybridError> {
        let (system, n) = (self.system, self.n);
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
        Ok(())
    }

    /// Copy the transition matrix carried in `z` into the matrix [`Solver::transition`] returns.
    pub(super) fn sync_transition(&mut self) {
        if self.sensitivity.transition() {
            let n = self.n;
            self.buffers
                .transition
                .as_mut_slice()
                .copy_from_slice(&self.buffers.z[n..n + n * n]);
        }
    }
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
pub(super) fn is_rounding(
    side: f64,
    previous_rate: f64,
    g_b: f64,
    rate: f64,
    value_tolerance: f64,
) -> bool {
    g_b >= -value_tolerance && side * previous_rate > 0.0 && side * rate > 0.0
}
