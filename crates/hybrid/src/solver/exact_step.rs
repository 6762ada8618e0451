//! Exact free flight: a step of the system's closed-form flow, with the transition matrix and
//! parameter sensitivity carried by the flow's own.

use nalgebra::DMatrixView;

use crate::error::HybridError;
use crate::sensitivity::Sensitivity;
use crate::system::{HybridSystem, Mode};

use super::{Solver, StepKind};

impl<'a, S: HybridSystem + ?Sized> Solver<'a, S> {
    /// An exact-flow step of length `min(exact_step_limit, max_step, t_end - t)`; returns the
    /// end time. Writes `z_new`.
    pub(super) fn exact_step(&mut self, t_end: f64) -> Result<f64, HybridError> {
        self.check_attempts()?;
        let mode = self.mode;
        let limit = self
            .accelerations
            .exact_flow
            .map_or(f64::INFINITY, |flow| flow.exact_step_limit(mode))
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
    pub(super) fn exact_advance(&mut self, mode: Mode, t0: f64, dt: f64) {
        let n = self.n;
        let (x_start, _) = self.buffers.z_start.split_at(n);
        let (x_new, rest) = self.buffers.z_new.split_at_mut(n);
        if let Some(flow) = self.accelerations.exact_flow {
            match self.sensitivity {
                Sensitivity::None => {
                    flow.exact_flow(mode, t0, x_start, dt, x_new, None, None);
                }
                Sensitivity::Transition => {
                    flow.exact_flow(
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
                    flow.exact_flow(
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
}
