//! The solver's dense output: the state (and its sensitivities) anywhere inside the last
//! step, from DOP853's interpolant, the Taylor series or the exact flow.

use crate::accelerations::ExactFlow;
use crate::clock::Clock;
use crate::dop853::Dop853;
use crate::series_step::TaylorStep;
use crate::system::{HybridSystem, Mode};

use super::{Solver, StepKind};
use crate::variational_field::clocked_field;

impl<'a, S: HybridSystem + ?Sized> Solver<'a, S> {
    /// The states at the interior sample times ([`Samples::time`]) of the Taylor step `[t0,
    /// t1]` just taken, into `grid` (`n` per point): by [`Solver::interpolate_clock`], each the
    /// value `state_in_step` gives (the end's state where a sample time rounds onto an end).
    pub(super) fn series_grid(&self, t0: f64, t1: f64, grid: &mut [f64]) {
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
                let Some(flow) = self.accelerations.exact_flow else {
                    return;
                };
                if m == self.n {
                    flow.exact_flow(
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
                    flow.exact_flow(
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

    /// The augmented state (state, transition, parameter sensitivity) at time `t` of the
    /// current step, into `z`.
    pub(super) fn augmented_at(&mut self, t: f64) {
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
}

/// The state at `t` in the current (not yet accepted) step: dense output or exact flow.
#[allow(clippy::too_many_arguments)]
pub(super) fn state_in_step(
    exact_flow: Option<&dyn ExactFlow>,
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
            if let Some(flow) = exact_flow {
                flow.exact_flow(mode, t0, &z_start[..n], t - t0, out, None, None);
            }
        }
        StepKind::None => out.copy_from_slice(&z_start[..n]),
    }
}
