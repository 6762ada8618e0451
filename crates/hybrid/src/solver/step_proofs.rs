//! Proofs that a step holds nothing interior samples would find: clear of every surface by
//! the curvature bound, monotone, or settled on its polynomial interpolant (module docs of
//! [`crate::solver`], "Steps proven clear" and "Steps settled on their interpolant").

use crate::bernstein::{stays_above, strict_sign};
use crate::clock::Clock;
use crate::extrema::Clearance;
use crate::series_step::TAYLOR_ORDER;
use crate::system::{side_sign, HybridSystem, Mode, MAX_SURFACES};

use super::tuning::BOUND_ROUNDING_MARGIN;
use super::{Solver, StepKind};

impl<'a, S: HybridSystem + ?Sized> Solver<'a, S> {
    /// The longest span from `t0` (at most `longest`) over which the exact flow of `mode` is
    /// proven farther than `extremum_height` from every surface before it is taken: with the
    /// start samples `g0 = side h_k(t0)`, `g0' = side dh_k/dt(t0)` and the system's curvature
    /// bound `M` over `[t0, t0 + longest]`, `g(t0 + s) >= g0 + g0' s - M s^2 / 2`, which stays
    /// above the height up to the positive root of that parabola. `None` if the start samples
    /// are not at hand (first step after an event), the height is infinite, the system gives
    /// no bound, or a surface is already within the height. The bounds, where the system gave
    /// them all, are kept in `span_bounds` for the search of the step taken inside the span.
    pub(super) fn clear_exact_span(&mut self, mode: Mode, t0: f64, longest: f64) -> Option<f64> {
        let height = self.settings.extremum_height;
        if !height.is_finite() || !self.buffers.samples.start_valid {
            return None;
        }
        let mut bounds = [0.0; MAX_SURFACES];
        if !self.curvature_bounds_over(mode, t0, longest, &mut bounds) {
            return None;
        }
        let surfaces = self.surfaces;
        self.span_bounds[..surfaces].copy_from_slice(&bounds[..surfaces]);
        self.span_bounded = true;
        let p = self.buffers.samples.points();
        let mut span = longest;
        for (k, &bound) in bounds.iter().enumerate().take(self.surfaces) {
            let side = side_sign(mode, k);
            let margin = side * self.buffers.samples.values[k * p] - height;
            let rate = side * self.buffers.samples.rates[k * p];
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
            span = span.min(clear * (1.0 - BOUND_ROUNDING_MARGIN));
        }
        Some(span)
    }

    /// Whether the step of length `dt` just sampled at its ends ([`Samples::sample_ends`])
    /// has every `h_k` strictly monotone, by the curvature bounds `M_k` on `|h_k''|`: with end
    /// rates `r0`, `r1` of one sign, `|dh_k/dt| >= (|r0| + |r1| - M_k dt) / 2` throughout (the
    /// rate moves at most `M_k` per time unit from either end), so a positive right side
    /// leaves no extremum, and a crossing shows in the signs at the ends.
    pub(super) fn monotone_by_curvature(&self, dt: f64, bounds: &[f64]) -> bool {
        let p = self.buffers.samples.points();
        let rates = &self.buffers.samples.rates;
        (0..self.surfaces).all(|k| {
            let (r0, r1) = (rates[k * p], rates[k * p + p - 1]);
            // A margin for the rounding of the bound's product.
            r0 * r1 > 0.0 && r0.abs() + r1.abs() > bounds[k] * dt * (1.0 + BOUND_ROUNDING_MARGIN)
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
    pub(super) fn interpolant_settled(&self, mode: Mode) -> bool {
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
                let kept = match self.buffers.taylor.surface {
                    Some((kept, mut power)) if kept == k => {
                        power[0] = start_value;
                        Some(power)
                    }
                    _ => self.series_surface_polynomial(k, start_value),
                };
                let Some(mut power) = kept else {
                    return false;
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
    pub(super) fn polynomial_settled<const D: usize, const E: usize>(
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
    /// ([`crate::SwitchingStructure::switching_curvature_bound`]), written into `bounds`; `false`
    /// (and nothing usable written) when the system gives none, or a bound is NaN or negative.
    pub(super) fn curvature_bounds(
        &self,
        mode: Mode,
        t0: f64,
        t1: f64,
        bounds: &mut [f64],
    ) -> bool {
        self.curvature_bounds_over(mode, t0, t1 - t0, bounds)
    }

    /// [`Solver::curvature_bounds`] over `[t0, t0 + dt]`.
    fn curvature_bounds_over(&self, mode: Mode, t0: f64, dt: f64, bounds: &mut [f64]) -> bool {
        (0..self.surfaces).all(|k| {
            match self.accelerations.switching_curvature_bound(
                k,
                mode,
                t0,
                &self.buffers.z_start[..self.n],
                dt,
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
    pub(super) fn clear_of_surfaces(
        &self,
        mode: Mode,
        t0: f64,
        t1: f64,
        clearance: &Clearance,
    ) -> bool {
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
}
