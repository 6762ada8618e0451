//! Where a rejected Runge-Kutta trial, or the last step continued, crosses a switching surface:
//! the targets of landings and square-root clocks.

use crate::clock::Clock;
use crate::event_location::{locate_sign_change, turnaround, CubicHermite};
use crate::system::{side_sign, HybridSystem, Mode};

use super::tuning::{HERMITE_FRACTION_TOLERANCE, TRIAL_SAMPLES};
use super::Solver;
use crate::variational_field::clocked_field;

impl<'a, S: HybridSystem + ?Sized> Solver<'a, S> {
    /// The time at which surface `k` is crossed within `reach` of the current time, located on
    /// the last accepted step's dense output continued past its end (which ended here, with
    /// no event since), if it is crossed there.
    ///
    /// In a mode whose Jacobian diverges at the crossing
    /// ([`crate::SwitchingStructure::jacobian_diverges_at_crossing`]: no series centred ahead of
    /// it, so Runge-Kutta steps make the whole approach), a last step on a square-root clock
    /// centred ahead is continued up to its reference at most: past it the continuation in the
    /// clock's variable retraces the approach (`t - reference` is even in it), so it never shows
    /// the crossing the clock was centred just past, and the next step would fall back to the
    /// time clock, whose steps the crossing's square root cuts short. Elsewhere (a series makes
    /// the approach, and these steps are rare) the continuation is as before, so that those
    /// systems' steps do not change.
    pub(super) fn continue_last_step(&mut self, k: usize, reach: f64) -> Option<f64> {
        let n = self.n;
        let system = self.system;
        let mode = self.mode;
        let (clock, sigma0, dsigma) = (self.clock, self.sigma_start, self.buffers.rk.h);
        let t0 = self.t;
        let t1 = match clock {
            Clock::SquareRoot { reference }
                if reference > t0 && self.accelerations.jacobian_diverges_at_crossing(mode) =>
            {
                (t0 + reach).min(reference)
            }
            _ => t0 + reach,
        };
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
    pub(super) fn locate_in_trial(
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
}

/// If the trial step on `clock` from `(t0, sigma0, z0)` over `dsigma` to `(t1, z1)` ends
/// across a switching surface (on the other side of the one the mode says), the fraction
/// `theta` of the step (in the clock's variable) at which the cubic Hermite interpolant of
/// `h_k` (values and rates at both ends) first crosses zero, with that surface `k`.
pub(super) fn crossing_fraction<S: HybridSystem + ?Sized>(
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
        let bracket = locate_sign_change(
            0.0,
            g0,
            1.0,
            g1,
            &mut hermite,
            HERMITE_FRACTION_TOLERANCE,
            0.0,
            None,
        );
        let theta = bracket.far;
        if earliest.is_none_or(|(e, _)| theta < e) {
            earliest = Some((theta, k));
        }
    }
    earliest
}
