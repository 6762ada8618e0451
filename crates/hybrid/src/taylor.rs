//! Taylor-series steps: the solution of a mode expanded in powers of the step's clock offset.
//!
//! Where a system can give the Taylor coefficients of its solution (by the recurrences of
//! automatic differentiation: Moore 1966; Jorba and Zou, Exp. Math. 14 (2005) 99), one series
//! of high order replaces many Runge-Kutta stages: a step is as long as the series converges
//! fast enough for the tolerance, and the polynomial itself is the step's dense output, exact
//! to the same order everywhere in the step. The series is taken in the step's clock variable
//! `s` (time, or the square root of the time from a crossing): on a square-root clock the
//! solution next to a Hertz contact's onset or release is analytic in `s`, though not in time.
//!
//! Status: systems state their series through [`crate::HybridSystem::taylor_series`] and
//! [`crate::HybridSystem::taylor_tangents`] (the AFM contact does, tested against DOP853), but
//! the solver does not take Taylor steps yet: a first integration took 8 series steps per
//! contact of the Biolever on mica against ~30 DOP853 attempts, yet no fewer instructions per
//! period map than DOP853 until the series themselves get cheaper.

/// The time along a step as a polynomial in the step's clock offset `s` (the clock reading
/// minus its reading at the step start): `t(s) = start + rate s + curvature s^2`. On the time
/// clock `rate = 1`, `curvature = 0`; on a square-root clock with reference `t_r` and start
/// reading `sigma0` (`t = t_r + sigma |sigma|`, `sigma` of one sign over a step),
/// `rate = 2 |sigma0|` and `curvature = sign(sigma)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClockPolynomial {
    /// `t(0)`, the step's start time (system time units).
    pub start: f64,
    /// `dt/ds` at the start.
    pub rate: f64,
    /// `(1/2) d^2t/ds^2`.
    pub curvature: f64,
}

impl ClockPolynomial {
    /// The time at clock offset `s`.
    #[inline]
    pub fn time(&self, s: f64) -> f64 {
        self.start + s * (self.rate + s * self.curvature)
    }

    /// `dt/ds` at clock offset `s`.
    #[inline]
    pub fn time_rate(&self, s: f64) -> f64 {
        self.rate + 2.0 * s * self.curvature
    }
}

/// The Taylor coefficients `c_{k,i}` (`k = 0..=order`) of a vector function `y(s) = sum_k
/// c_{k,i} s^k` of the clock offset `s`, for `dim` components, stored power by power (row `k`
/// holds coefficient `k` of every component: the recurrences fill a row at a time, and Horner's
/// rule runs over whole rows).
#[derive(Debug, Clone, PartialEq)]
pub struct TaylorSeries {
    order: usize,
    dim: usize,
    coefficients: Vec<f64>,
}

impl TaylorSeries {
    /// A zero series of `dim` components to `order`.
    pub fn new(dim: usize, order: usize) -> Self {
        Self {
            order,
            dim,
            coefficients: vec![0.0; dim * (order + 1)],
        }
    }

    /// The highest power kept.
    pub fn order(&self) -> usize {
        self.order
    }

    /// The number of components.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Coefficient `k` of every component.
    #[inline]
    pub fn row(&self, k: usize) -> &[f64] {
        &self.coefficients[k * self.dim..(k + 1) * self.dim]
    }

    /// Every coefficient, row by row (`dim` per power).
    pub fn coefficients(&self) -> &[f64] {
        &self.coefficients
    }

    /// Every coefficient, to write.
    pub fn coefficients_mut(&mut self) -> &mut [f64] {
        &mut self.coefficients
    }

    /// Set the constant terms from `values` (length `dim`); the other rows are left for the
    /// recurrences to write.
    pub fn start_at(&mut self, values: &[f64]) {
        self.coefficients[..self.dim].copy_from_slice(values);
    }

    /// `y(s)` into `out` (length `dim`), by Horner's rule.
    pub fn evaluate(&self, s: f64, out: &mut [f64]) {
        let dim = self.dim;
        out.copy_from_slice(&self.coefficients[self.order * dim..]);
        for row in self.coefficients.chunks_exact(dim).rev().skip(1) {
            for (o, &c) in out.iter_mut().zip(row) {
                *o = *o * s + c;
            }
        }
    }

    /// `dy/ds` at `s` into `out` (length `dim`).
    pub fn derivative(&self, s: f64, out: &mut [f64]) {
        let dim = self.dim;
        out.fill(0.0);
        for (k, row) in self
            .coefficients
            .chunks_exact(dim)
            .enumerate()
            .skip(1)
            .rev()
        {
            let k = k as f64;
            for (o, &c) in out.iter_mut().zip(row) {
                *o = *o * s + k * c;
            }
        }
    }

    /// The polynomial `sum_k (w . c_k) s^k` of the weighted sum `w . y(s)` of the components
    /// (`w` of length `dim`), into `out` (length `order + 1`).
    pub fn weighted_sum(&self, weights: &[f64], out: &mut [f64]) {
        for (o, row) in out.iter_mut().zip(self.coefficients.chunks_exact(self.dim)) {
            *o = row.iter().zip(weights).map(|(c, w)| c * w).sum();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn series_evaluates_every_component_and_its_derivative() {
        // y_0 = 1 + 2 s - s^3, y_1 = 3 - s^2 (order 3).
        let mut series = TaylorSeries::new(2, 3);
        series
            .coefficients_mut()
            .copy_from_slice(&[1.0, 3.0, 2.0, 0.0, 0.0, -1.0, -1.0, 0.0]);
        let s = -0.4_f64;
        let mut y = [0.0; 2];
        series.evaluate(s, &mut y);
        assert!((y[0] - (1.0 + 2.0 * s - s.powi(3))).abs() < 1e-15);
        assert!((y[1] - (3.0 - s * s)).abs() < 1e-15);
        series.derivative(s, &mut y);
        assert!((y[0] - (2.0 - 3.0 * s * s)).abs() < 1e-15);
        assert!((y[1] + 2.0 * s).abs() < 1e-15);
        let mut sum = [0.0; 4];
        series.weighted_sum(&[1.0, 2.0], &mut sum);
        assert_eq!(sum, [7.0, 2.0, -2.0, -1.0]);
    }

    #[test]
    fn clock_polynomial_of_a_square_root_clock_matches_the_clock() {
        // t = 2 + sigma |sigma| from sigma0 = -0.5 (reading negative over the step).
        let sigma0 = -0.5_f64;
        let clock = ClockPolynomial {
            start: 2.0 - 0.25,
            rate: 2.0 * sigma0.abs(),
            curvature: -1.0,
        };
        for s in [0.0, 0.1, 0.3, 0.5] {
            let sigma = sigma0 + s;
            assert!((clock.time(s) - (2.0 + sigma * sigma.abs())).abs() < 1e-15);
            assert!((clock.time_rate(s) - 2.0 * sigma.abs()).abs() < 1e-15);
        }
    }
}
