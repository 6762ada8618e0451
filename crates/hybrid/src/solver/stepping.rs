//! The stepping loop: one step of the right kind, the sampling of the switching functions
//! over it, and the event that truncates it.

use crate::error::HybridError;
use crate::event::ExtremumKind;
use crate::extrema::Clearance;
use crate::system::{HybridSystem, Mode, MAX_SURFACES};

use super::dense_output::state_in_step;
use super::{Solver, StepKind, StepOutcome};

impl<'a, S: HybridSystem + ?Sized> Solver<'a, S> {
    pub(super) fn check_attempts(&self) -> Result<(), HybridError> {
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
        self.span_bounded = false;
        let t1 = if self.accelerations.has_exact_flow(mode) {
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
        self.search_step(mode, t0, t1, time_tolerance)?;
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
                self.keep_extrema_until(event.t, time_tolerance);
                self.buffers
                    .extrema
                    .sort_unstable_by(|a, b| a.t.total_cmp(&b.t).then(a.surface.cmp(&b.surface)));
                Ok(StepOutcome::Event(event))
            }
        }
    }
    /// Sample `h_k` and `dh_k/dt` over the step `[t0, t1]` just taken and locate its extrema,
    /// unless the step is proven to hold nothing interior samples would find (then it is
    /// sampled at its ends only; see the module docs).
    fn search_step(
        &mut self,
        mode: Mode,
        t0: f64,
        t1: f64,
        time_tolerance: f64,
    ) -> Result<(), HybridError> {
        // The curvature bounds of the step (if the system gives them): a step they prove
        // monotone holds no extremum; with a finite extremum height, a step, or a sample
        // interval of it, that they prove farther than the height from every surface is not
        // searched for extrema.
        let mut bounds = [0.0; MAX_SURFACES];
        let surfaces = self.surfaces;
        let bounded = !self.proven_clear
            && if self.span_bounded {
                // The bounds over the span the step lies in, from the same start.
                bounds[..surfaces].copy_from_slice(&self.span_bounds[..surfaces]);
                true
            } else {
                self.curvature_bounds(mode, t0, t1, &mut bounds)
            };
        let clearance = (bounded && self.settings.extremum_height.is_finite()).then(|| Clearance {
            height: self.settings.extremum_height,
            bounds: &bounds[..self.surfaces],
        });
        // A Runge-Kutta step with affine switching functions, or a Taylor step with switching
        // functions affine in the state, may be proven settled on its interpolant, whatever the
        // height.
        let polynomial = match self.kind {
            StepKind::RungeKutta => self.affine_switching,
            StepKind::Taylor => self.series_switching,
            _ => false,
        };
        let ends_sampled = self.settings.extremum_height.is_finite() || polynomial || bounded;
        let clear = ends_sampled && {
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
            self.sample_inside(mode, t0, t1, time_tolerance, clearance, ends_sampled)?;
        }
        Ok(())
    }

    /// Sample the step `[t0, t1]` at its interior points and locate the extrema of every
    /// `h_k` between them (skipping sample intervals `clearance` proves clear); `ends_sampled`:
    /// its ends were just sampled ([`Samples::sample_ends`]), and are not sampled again.
    fn sample_inside(
        &mut self,
        mode: Mode,
        t0: f64,
        t1: f64,
        time_tolerance: f64,
        clearance: Option<Clearance<'_>>,
        ends_sampled: bool,
    ) -> Result<(), HybridError> {
        self.statistics.sampled_steps += 1;
        let system = self.system;
        let exact_flow = self.accelerations.exact_flow;
        let n = self.n;
        let kind = self.kind;
        let dense = (&self.buffers.rk, &self.buffers.taylor);
        let z_start = &self.buffers.z_start;
        let z_new = &self.buffers.z_new;
        let clock = (self.clock, self.sigma_start);
        let mut state_at = |t: f64, out: &mut [f64]| {
            state_in_step(
                exact_flow, kind, mode, dense, clock, z_start, z_new, t0, t1, n, t, out,
            );
        };
        // Exact steps: every interior state from one call (a linear flow reuses its
        // transition over one spacing). Taylor steps: from one pass over the series, at
        // the sample times `Samples::sample` takes (each the value `state_in_step` gives).
        let grid = match kind {
            StepKind::Exact => {
                let count = self.buffers.samples.points() - 1;
                if let Some(flow) = exact_flow {
                    flow.exact_flow_grid(
                        mode,
                        t0,
                        &z_start[..n],
                        t1 - t0,
                        count,
                        &mut self.buffers.grid,
                    );
                }
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
            (t0, t1, ends_sampled),
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
        Ok(())
    }
}

impl<S: HybridSystem + ?Sized> Solver<'_, S> {
    /// Keep the step's extrema up to the event at `t_event`, which cut the step there. An
    /// extremum located past it by at most `time_tolerance` (the two are located to that
    /// precision each) that the state after the event has already passed (the rate of its
    /// switching function there on the far side: `>= 0` after a minimum, `<= 0` after a
    /// maximum) is kept too: the next step starts past it and would not report it (an extremum
    /// of another surface's switching function right at an event, as at a double grazing).
    fn keep_extrema_until(&mut self, t_event: f64, time_tolerance: f64) {
        let (system, mode, t) = (self.system, self.mode, self.t);
        let n = system.dim();
        let x = &self.buffers.z[..n];
        self.buffers.extrema.retain(|e| {
            if e.t <= t_event {
                return true;
            }
            if e.t - t_event > time_tolerance {
                return false;
            }
            let rate = system.switching_rate(e.surface, mode, t, x);
            match e.kind {
                ExtremumKind::Minimum => rate >= 0.0,
                ExtremumKind::Maximum => rate <= 0.0,
            }
        });
    }
}
