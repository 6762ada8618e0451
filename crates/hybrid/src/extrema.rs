//! Sampling the switching functions inside a step, and locating the smooth extrema of each
//! `h_k` (the zeros of `dh_k/dt`).
//!
//! Every step is sampled at its two ends and at `m = samples_per_step` equally spaced interior
//! points. A sign change of `dh_k/dt` between neighbouring samples is a local extremum, located
//! by root finding on `dh_k/dt` along the step's interpolant. Between the samples and extrema,
//! each `h_k` is monotone, which is what event location relies on (a brief dip through a surface
//! shows as a negative minimum even when both ends of the step are positive).

use crate::error::HybridError;
use crate::event::{Extremum, ExtremumKind};
use crate::event_location::{extremum_guess, locate_sign_change};
use crate::system::{side_sign, HybridSystem, Mode};

/// The state at time `t` inside the current step, written into the slice.
pub(crate) type StateAt<'a> = dyn FnMut(f64, &mut [f64]) + 'a;

/// What lets [`Samples::locate_extrema`] leave a sample interval unsearched: the system's bound
/// `M_k` on `|h_k''|` over the step, and the distance from the surfaces beyond which extrema
/// need not be found (`Settings::extremum_height`).
pub(crate) struct Clearance<'a> {
    /// `Settings::extremum_height`, switching-function units (finite).
    pub height: f64,
    /// `M_k` for every surface `k`, switching-function units per time squared.
    pub bounds: &'a [f64],
}

impl Clearance<'_> {
    /// Whether `h_k` stays above the height (and zero) between two samples `spacing` apart
    /// with values `a` and `b`, in a mode on the positive side of surface `k` (`side = 1`):
    /// the chord bent by `M_k spacing^2 / 8` stays above. On the negative side (inside a
    /// contact) nothing is proven: every extremum there is wanted. Used for a sample interval
    /// and for a whole step between its ends.
    pub fn proves(&self, k: usize, side: f64, a: f64, b: f64, spacing: f64) -> bool {
        let lowest = a.min(b) - self.bounds[k] * spacing * spacing / 8.0;
        side > 0.0 && lowest > self.height && lowest > 0.0
    }
}

/// Samples of every switching function over one step, and the extrema found between them.
pub(crate) struct Samples {
    surfaces: usize,
    points: usize,
    /// Sample times `t0 = times[0] < ... < times[m + 1] = t1`.
    pub times: Vec<f64>,
    /// `h_k(times[i])` at `values[k * points + i]`.
    pub values: Vec<f64>,
    /// `dh_k/dt(times[i])` at `rates[k * points + i]`.
    pub rates: Vec<f64>,
    /// Time of the extremum of `h_k` in sample interval `i` at `[k * (points - 1) + i]`, NaN if
    /// none.
    pub extremum_time: Vec<f64>,
    /// Value of `h_k` at that extremum.
    pub extremum_value: Vec<f64>,
    /// Whether column 0 already holds the samples at the step start (carried over from the end
    /// of the previous step in the same mode).
    pub start_valid: bool,
    /// Whether the step was sampled at its ends only ([`Samples::sample_ends`]): only the first
    /// and last points are this step's, and it has no extrema.
    pub ends_only: bool,
}

impl Samples {
    pub fn new(surfaces: usize, interior: usize) -> Self {
        let points = interior + 2;
        Self {
            surfaces,
            points,
            times: vec![0.0; points],
            values: vec![0.0; surfaces * points],
            rates: vec![0.0; surfaces * points],
            extremum_time: vec![f64::NAN; surfaces * (points - 1)],
            extremum_value: vec![f64::NAN; surfaces * (points - 1)],
            start_valid: false,
            ends_only: false,
        }
    }

    /// Number of sample points per step (interior plus both ends).
    pub fn points(&self) -> usize {
        self.points
    }

    /// The time of sample point `i` of the step `[t0, t1]` ([`Samples::sample`]): the ends
    /// exactly, the interior points equally spaced.
    pub fn time(&self, t0: f64, t1: f64, i: usize) -> f64 {
        let last = self.points - 1;
        if i == 0 {
            t0
        } else if i == last {
            t1
        } else {
            t0 + (t1 - t0) * (i as f64 / last as f64)
        }
    }

    /// Sample `h_k` and `dh_k/dt` (in `mode`) at the step's points between `t0` and `t1`;
    /// with `grid`, the interior states are read from it (interior point `i` at
    /// `grid[(i - 1) n .. i n]`, as [`crate::ExactFlow::exact_flow_grid`] writes them) instead of
    /// `state_at`. With `ends_sampled`, the step's ends were just recorded by
    /// [`Samples::sample_ends`] (from the same states `state_at` gives there), and only the
    /// interior points are sampled.
    ///
    /// # Errors
    /// [`HybridError::NonFiniteSwitching`] if a sample is NaN or infinite.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn sample<S: HybridSystem + ?Sized>(
        &mut self,
        system: &S,
        mode: Mode,
        (t0, t1, ends_sampled): (f64, f64, bool),
        state_at: &mut StateAt<'_>,
        grid: Option<&[f64]>,
        x: &mut [f64],
    ) -> Result<(), HybridError> {
        let p = self.points;
        let n = x.len();
        let last = p - 1;
        for i in 0..p {
            self.times[i] = self.time(t0, t1, i);
        }
        self.ends_only = false;
        let first = usize::from(self.start_valid);
        let end = if ends_sampled { last } else { p };
        for i in first..end {
            let t = self.times[i];
            match grid {
                Some(states) if i > 0 && i < last => {
                    x.copy_from_slice(&states[(i - 1) * n..i * n]);
                }
                _ => state_at(t, x),
            }
            self.record(system, mode, i, t, x)?;
        }
        Ok(())
    }

    /// Record `h_k` and `dh_k/dt` of every surface at sample point `i` (time `t`, state `x`).
    #[inline]
    fn record<S: HybridSystem + ?Sized>(
        &mut self,
        system: &S,
        mode: Mode,
        i: usize,
        t: f64,
        x: &[f64],
    ) -> Result<(), HybridError> {
        let p = self.points;
        for k in 0..self.surfaces {
            let value = system.switching(k, t, x);
            let rate = system.switching_rate(k, mode, t, x);
            if !value.is_finite() || !rate.is_finite() {
                return Err(HybridError::NonFiniteSwitching { t, surface: k });
            }
            self.values[k * p + i] = value;
            self.rates[k * p + i] = rate;
        }
        Ok(())
    }

    /// Sample `h_k` and `dh_k/dt` at the step's two ends only (the start from `x0` unless
    /// carried over, the end from `x1`), for a step proven clear of every surface, and mark
    /// the samples [`Samples::ends_only`]: the step reads as one interval from the first point
    /// to the last, with no extrema, and the interior points and extrema hold nothing of this
    /// step. [`Samples::locate_extrema`] is not to be called after it.
    ///
    /// # Errors
    /// [`HybridError::NonFiniteSwitching`] if a sample is NaN or infinite.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn sample_ends<S: HybridSystem + ?Sized>(
        &mut self,
        system: &S,
        mode: Mode,
        t0: f64,
        t1: f64,
        x0: &[f64],
        x1: &[f64],
    ) -> Result<(), HybridError> {
        let p = self.points;
        self.times[0] = t0;
        self.times[p - 1] = t1;
        let ends: &[(usize, f64, &[f64])] = if self.start_valid {
            &[(p - 1, t1, x1)]
        } else {
            &[(0, t0, x0), (p - 1, t1, x1)]
        };
        for &(i, t, x) in ends {
            self.record(system, mode, i, t, x)?;
        }
        self.start_valid = true;
        self.ends_only = true;
        Ok(())
    }

    /// Make the end samples of this step the start samples of the next one.
    pub fn carry_over(&mut self) {
        let p = self.points;
        for k in 0..self.surfaces {
            self.values[k * p] = self.values[k * p + p - 1];
            self.rates[k * p] = self.rates[k * p + p - 1];
        }
        self.start_valid = true;
    }

    /// Locate every extremum of every `h_k` in the step: a sign change of `dh_k/dt` from `< 0`
    /// to `>= 0` is a minimum, from `> 0` to `<= 0` a maximum (a zero of the rate exactly at
    /// the step start is therefore never reported: it belongs to the previous step's end).
    /// Appends to `found` (unsorted) and records per-interval extrema for event location.
    /// With a `clearance`, an interval that it proves farther than the extremum height from
    /// the surface is not searched (its extremum, if any, is neither located nor reported:
    /// it cannot hide a crossing).
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn locate_extrema<S: HybridSystem + ?Sized>(
        &mut self,
        system: &S,
        mode: Mode,
        state_at: &mut StateAt<'_>,
        x: &mut [f64],
        time_tolerance: f64,
        clearance: Option<Clearance<'_>>,
        found: &mut Vec<Extremum>,
    ) {
        let p = self.points;
        self.extremum_time.fill(f64::NAN);
        self.extremum_value.fill(f64::NAN);
        for k in 0..self.surfaces {
            let side = side_sign(mode, k);
            for i in 0..p - 1 {
                let ra = self.rates[k * p + i];
                let rb = self.rates[k * p + i + 1];
                let kind = if ra < 0.0 && rb >= 0.0 {
                    ExtremumKind::Minimum
                } else if ra > 0.0 && rb <= 0.0 {
                    ExtremumKind::Maximum
                } else {
                    continue;
                };
                if clearance.as_ref().is_some_and(|clearance| {
                    clearance.proves(
                        k,
                        side,
                        self.values[k * p + i],
                        self.values[k * p + i + 1],
                        self.times[i + 1] - self.times[i],
                    )
                }) {
                    continue;
                }
                // Orient so that g > 0 at the interval start and g <= 0 at its end.
                let sign = match kind {
                    ExtremumKind::Minimum => -1.0,
                    ExtremumKind::Maximum => 1.0,
                };
                let (a, b) = (self.times[i], self.times[i + 1]);
                let bracket = {
                    let mut g = |t: f64| {
                        state_at(t, x);
                        sign * system.switching_rate(k, mode, t, x)
                    };
                    let guess = extremum_guess(
                        (a, self.values[k * p + i], ra),
                        (b, self.values[k * p + i + 1], rb),
                        sign,
                    );
                    locate_sign_change(
                        a,
                        sign * ra,
                        b,
                        sign * rb,
                        &mut g,
                        time_tolerance,
                        0.0,
                        guess,
                    )
                };
                let t = bracket.far;
                let value = if t == b {
                    self.values[k * p + i + 1]
                } else {
                    state_at(t, x);
                    system.switching(k, t, x)
                };
                self.extremum_time[k * (p - 1) + i] = t;
                self.extremum_value[k * (p - 1) + i] = value;
                if found.len() < found.capacity() {
                    found.push(Extremum {
                        t,
                        surface: k,
                        kind,
                        value,
                        mode,
                    });
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    /// `h(t) = m + (t - t_m)^2` as the state `[h, dh/dt]` (so `|h''| = 2` everywhere).
    struct Valley {
        depth: f64,
        t_m: f64,
    }

    impl Valley {
        fn state_at(&self, t: f64, x: &mut [f64]) {
            x[0] = self.depth + (t - self.t_m) * (t - self.t_m);
            x[1] = 2.0 * (t - self.t_m);
        }
    }

    impl HybridSystem for Valley {
        fn dim(&self) -> usize {
            2
        }
        fn surface_count(&self) -> usize {
            1
        }
        fn vector_field(&self, _mode: Mode, _t: f64, x: &[f64], dxdt: &mut [f64]) {
            dxdt[0] = x[1];
            dxdt[1] = 2.0;
        }
        fn jacobian(&self, _mode: Mode, _t: f64, _x: &[f64], j: &mut DMatrix<f64>) {
            j.fill(0.0);
            j[(0, 1)] = 1.0;
        }
        fn switching(&self, _k: usize, _t: f64, x: &[f64]) -> f64 {
            x[0]
        }
        fn switching_rate(&self, _k: usize, _mode: Mode, _t: f64, x: &[f64]) -> f64 {
            x[1]
        }
        fn switching_gradient(
            &self,
            _k: usize,
            _t: f64,
            _x: &[f64],
            g: &mut [f64],
        ) -> crate::SwitchingPartials {
            g[0] = 1.0;
            g[1] = 0.0;
            crate::SwitchingPartials::default()
        }
    }

    /// The minimum of `h` found over one step `[0, 1]` sampled at 4 interior points (spacing
    /// 0.2; the minimum at `t_m = 0.37` lies in `[0.2, 0.4]`, where the samples are
    /// `m + 0.0289` and `m + 0.0009`), with the curvature bound 2 and `height` if given.
    fn minima(depth: f64, height: Option<f64>) -> Vec<Extremum> {
        let valley = Valley { depth, t_m: 0.37 };
        let mut samples = Samples::new(1, 4);
        let mut x = [0.0; 2];
        let mut state_at = |t: f64, x: &mut [f64]| valley.state_at(t, x);
        samples
            .sample(&valley, 0, (0.0, 1.0, false), &mut state_at, None, &mut x)
            .expect("finite samples");
        let mut found = Vec::with_capacity(4);
        let bounds = [2.0];
        samples.locate_extrema(
            &valley,
            0,
            &mut state_at,
            &mut x,
            1e-13,
            height.map(|height| Clearance {
                height,
                bounds: &bounds,
            }),
            &mut found,
        );
        found
    }

    /// An interval is left unsearched exactly when the chord of its samples, bent by the
    /// curvature bound (`2 * 0.2^2 / 8 = 0.01`), stays above the height: its lowest possible
    /// value is `m + 0.0009 - 0.01`, which never exceeds the true minimum `m`.
    #[test]
    fn intervals_proven_clear_are_not_searched() {
        // m = 0.02: the bound proves the interval above 0.0109, so heights 0 and 0.01 skip it,
        // 0.015 does not; without a clearance it is always searched.
        for (height, searched) in [
            (Some(0.0), false),
            (Some(0.01), false),
            (Some(0.015), true),
            (None, true),
        ] {
            let found = minima(0.02, height);
            assert_eq!(found.len(), usize::from(searched), "height {height:?}");
            for minimum in &found {
                assert_eq!(minimum.kind, ExtremumKind::Minimum);
                assert!((minimum.t - 0.37).abs() < 1e-12, "{minimum:?}");
                assert!((minimum.value - 0.02).abs() < 1e-15, "{minimum:?}");
            }
        }
        // m = 0.005: the bound only proves the interval above -0.0041, so the minimum is
        // located even at height 0, and so is a dip below the surface.
        for depth in [0.005, -1e-9] {
            let found = minima(depth, Some(0.0));
            assert_eq!(found.len(), 1, "depth {depth}");
            assert!((found[0].value - depth).abs() < 1e-15);
        }
    }
}
