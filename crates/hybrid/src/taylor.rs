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
//! The solver takes a Taylor step wherever the system gives series of the mode's solution
//! ([`crate::TaylorExpansion::taylor_order_limit`] at least 20, the order of the state's series;
//! the AFM model does in Hertz contact), and Runge-Kutta steps elsewhere (see the solver's module
//! documentation). The tangents (transition matrix and `dx/dp`) are expanded along the state's
//! series by the system's [`crate::TaylorExpansion::taylor_tangents`], to the state's order, or to
//! order 12 under a [`crate::SensitivityMethod::Decoupled`] integration, whose steps then also keep
//! the tangents' last two terms below 1e-5.

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

    /// `y(s)` into `out` (its leading `out.len() <= dim` components), by Horner's rule,
    /// compiled for the CPU's AVX where it has it (wider lanes, the same operations in the same
    /// order: the same bits).
    pub fn evaluate(&self, s: f64, out: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU has AVX, checked just above.
            unsafe { self.evaluate_avx(s, out) };
            return;
        }
        self.evaluate_dims(s, out);
    }

    /// [`TaylorSeries::evaluate_dims`] compiled with AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    fn evaluate_avx(&self, s: f64, out: &mut [f64]) {
        self.evaluate_dims(s, out);
    }

    /// [`TaylorSeries::evaluate`] for any CPU.
    #[inline(always)]
    fn evaluate_dims(&self, s: f64, out: &mut [f64]) {
        // The common small dimensions as constants, so that the row loop unrolls into
        // registers (the state of one or two modes, their tangents with and without dx/dp).
        match self.dim {
            2 => self.evaluate_fixed::<2>(s, out),
            4 => self.evaluate_fixed::<4>(s, out),
            16 => self.evaluate_fixed::<16>(s, out),
            20 => self.evaluate_fixed::<20>(s, out),
            dim => {
                let m = out.len();
                out.copy_from_slice(&self.coefficients[self.order * dim..][..m]);
                for row in self.coefficients.chunks_exact(dim).rev().skip(1) {
                    for (o, &c) in out.iter_mut().zip(row) {
                        *o = *o * s + c;
                    }
                }
            }
        }
    }

    /// `y(r_j - origin)` for every reading `r_j` of `readings` (a clock whose reading is
    /// `origin` where the series starts), into `out` (`dim` per reading, in order), by Horner's
    /// rule across the readings at once: each value is the one [`TaylorSeries::evaluate`] gives
    /// at `r_j - origin`, for less work than one call per reading (compiled for the CPU's AVX
    /// where it has it, as [`TaylorSeries::evaluate`]).
    pub fn evaluate_many(&self, origin: f64, readings: &[f64], out: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU has AVX, checked just above.
            unsafe { self.evaluate_many_avx(origin, readings, out) };
            return;
        }
        self.evaluate_many_blocks(origin, readings, out);
    }

    /// [`TaylorSeries::evaluate_many_blocks`] compiled with AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    fn evaluate_many_avx(&self, origin: f64, readings: &[f64], out: &mut [f64]) {
        self.evaluate_many_blocks(origin, readings, out);
    }

    /// [`TaylorSeries::evaluate_many`] for any CPU.
    #[inline(always)]
    fn evaluate_many_blocks(&self, origin: f64, readings: &[f64], out: &mut [f64]) {
        const BLOCK: usize = 8;
        let dim = self.dim;
        for (readings, values) in readings.chunks(BLOCK).zip(out.chunks_mut(BLOCK * dim)) {
            // The offsets, padded with zeros (lanes evaluated and dropped).
            let mut offsets = [0.0; BLOCK];
            for (offset, reading) in offsets.iter_mut().zip(readings) {
                *offset = reading - origin;
            }
            // The state of one or two modes as constants, at 4 offsets (a 4-point quadrature)
            // or up to 8.
            match (dim, readings.len()) {
                (2, 4) => self.evaluate_block::<2, 4>(&offsets, values),
                (4, 4) => self.evaluate_block::<4, 4>(&offsets, values),
                (2, _) => self.evaluate_block::<2, BLOCK>(&offsets, values),
                (4, _) => self.evaluate_block::<4, BLOCK>(&offsets, values),
                _ => {
                    for (&s, value) in offsets.iter().zip(values.chunks_exact_mut(dim)) {
                        self.evaluate_dims(s, value);
                    }
                }
            }
        }
    }

    /// [`TaylorSeries::evaluate_many`] for `dim == D` at the first `P` offsets of `s`, into the
    /// points `out` holds (`out.len() / D <= P`): the values held component by component, so
    /// that the loop over offsets vectorises.
    #[inline(always)]
    fn evaluate_block<const D: usize, const P: usize>(&self, s: &[f64], out: &mut [f64]) {
        let s = &s[..P];
        let mut value = [[0.0; P]; D];
        for row in self.coefficients.chunks_exact(D).rev() {
            for (component, &c) in value.iter_mut().zip(row) {
                for (v, &s) in component.iter_mut().zip(s) {
                    *v = *v * s + c;
                }
            }
        }
        for (j, point) in out.chunks_exact_mut(D).enumerate() {
            for (d, x) in point.iter_mut().enumerate() {
                *x = value[d][j];
            }
        }
    }

    /// [`TaylorSeries::evaluate`] for `dim == D`.
    #[inline(always)]
    fn evaluate_fixed<const D: usize>(&self, s: f64, out: &mut [f64]) {
        let mut value = [0.0; D];
        for row in self.coefficients.chunks_exact(D).rev() {
            for (v, &c) in value.iter_mut().zip(row) {
                *v = *v * s + c;
            }
        }
        out.copy_from_slice(&value[..out.len()]);
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
        // The common small dimensions as constants, so that the dot products unroll.
        match (self.dim, weights.len()) {
            (2, 2) => Self::weighted_sum_rows::<2>(&self.coefficients, weights, out),
            (4, 4) => Self::weighted_sum_rows::<4>(&self.coefficients, weights, out),
            _ => {
                for (o, row) in out.iter_mut().zip(self.coefficients.chunks_exact(self.dim)) {
                    *o = row.iter().zip(weights).map(|(c, w)| c * w).sum();
                }
            }
        }
    }

    /// [`TaylorSeries::weighted_sum`] of rows of `D` coefficients (`weights` of length `D`).
    #[inline(always)]
    fn weighted_sum_rows<const D: usize>(coefficients: &[f64], weights: &[f64], out: &mut [f64]) {
        let weights = &weights[..D];
        for (o, row) in out.iter_mut().zip(coefficients.chunks_exact(D)) {
            *o = row.iter().zip(weights).map(|(c, w)| c * w).sum();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `evaluate_many` gives, bit for bit, what `evaluate` gives at each reading's offset from
    /// the origin: for the dimensions it specialises (2 and 4 components; 4 readings, and up to
    /// 8 in a padded block) and for another (3 components), with 4, 5, 7, 8 and 11 readings (a
    /// block of 8 and a rest).
    #[test]
    fn evaluation_at_many_offsets_equals_one_at_a_time() {
        for dim in [2, 3, 4] {
            let mut series = TaylorSeries::new(dim, 20);
            for (i, c) in series.coefficients_mut().iter_mut().enumerate() {
                *c = ((i * 37 % 23) as f64 - 11.0) / (1.0 + i as f64);
            }
            for count in [4, 5, 7, 8, 11] {
                let origin = 0.3;
                let readings: Vec<f64> = (0..count).map(|j| 0.9 * j as f64 / 7.0 + 0.1).collect();
                let mut together = vec![0.0; count * dim];
                series.evaluate_many(origin, &readings, &mut together);
                for (&reading, value) in readings.iter().zip(together.chunks_exact(dim)) {
                    let mut alone = vec![0.0; dim];
                    let s = reading - origin;
                    series.evaluate(s, &mut alone);
                    assert_eq!(value, &alone[..], "dim {dim}, {count} offsets, s = {s}");
                }
            }
        }
    }

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
