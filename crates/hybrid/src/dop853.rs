//! One embedded Dormand-Prince 8(5,3) step with Hairer's error estimate, step-size control and
//! 7th-order dense output (Hairer, Norsett, Wanner I, Sec. II.10; the `dop853` code).
//!
//! The stepper works on an augmented state `z` of length `N` (state plus variational
//! components) but measures the local error on the first `n` (state) components only. All
//! buffers are allocated in [`Dop853::new`]; a step allocates nothing.

// Index loops over stages and components mirror the tableau's formulas.
#![allow(clippy::needless_range_loop)]

use crate::tableau::{A, BHH, C, D, E5, STAGES, STAGES_EXTENDED};

/// An augmented right-hand side `rhs(t, z, dz)`.
pub(crate) type Rhs<'a> = dyn FnMut(f64, &[f64], &mut [f64]) + 'a;

/// Coefficients of the dense-output polynomial of one component (degree 7, value at 0 apart).
const DENSE_COEFFICIENTS: usize = 7;

/// For row `i` of the tableau `A` (row 12: the solution's weights), the index from which its
/// weights after the first are summed: `A[i][1..SKIP_FROM[i]]` are zero (stages 2 to 5 feed
/// only the first few stages; checked by a test). Row 0 has no weights.
const SKIP_FROM: [usize; STAGES_EXTENDED] = [1, 1, 1, 2, 2, 3, 3, 3, 3, 3, 3, 3, 5, 6, 5, 5];

/// The same for the error estimate's weights `E5`, `BHH` and the dense output's `D`: zero on
/// stages 2 to 5.
const ESTIMATE_SKIP_FROM: usize = 5;

/// Safety factor of the step-size controller (Hairer's `safe`).
const SAFETY: f64 = 0.9;
/// Smallest ratio new step / old step (Hairer's `fac1`).
const MIN_FACTOR: f64 = 0.333;
/// Largest ratio new step / old step (Hairer's `fac2`).
const MAX_FACTOR: f64 = 6.0;

/// Workspace and results of DOP853 steps on an augmented state of length `dim`.
///
/// Stage derivatives are stored component-major (`stages[c * 16 + j]` is component `c` of
/// stage `j`), so that every Runge-Kutta sum over stages is a short contiguous dot product.
pub(crate) struct Dop853 {
    /// Length `N` of the augmented state.
    dim: usize,
    /// Number `n` of leading (state) components under error control with the main tolerances.
    controlled: usize,
    /// Tolerance (relative and absolute) for the remaining (variational) components, if they
    /// are under error control.
    variational_tolerance: Option<f64>,
    /// Stage derivatives, component-major; stage 0 holds `f(t, z)`, stage 12 `f(t + h, z_new)`
    /// after [`Dop853::derivative_at_end`].
    stages: Vec<f64>,
    /// Scratch stage argument.
    argument: Vec<f64>,
    /// Scratch derivative written by the right-hand side.
    derivative: Vec<f64>,
    /// Dense-output coefficients, component-major: `dense[c * 7 + r]` is coefficient `r` of
    /// component `c`.
    dense: Vec<f64>,
    /// Step size of the last attempted step.
    pub h: f64,
}

/// `sum_j a_j k_j` over the leading entries.
#[inline]
fn dot(a: &[f64], k: &[f64]) -> f64 {
    a.iter().zip(k).map(|(a, k)| a * k).sum()
}

/// `out[c] = z[c] + h (w_0 k_0[c] + sum_{FIRST <= j < N} w_j k_j[c])` for every component `c`
/// of `out`: the sum over `N` weights of which `w_1 .. w_{FIRST-1}` are zero (the tableau's
/// stages 2 to 5 feed only the first few stages): one [`dot_skipping`] per component.
#[inline(always)]
fn combine_fixed<const N: usize, const FIRST: usize>(
    out: &mut [f64],
    z: &[f64],
    stages: &[f64],
    weights: &[f64],
    h: f64,
) {
    for ((y, &zc), k) in out
        .iter_mut()
        .zip(z)
        .zip(stages.chunks_exact(STAGES_EXTENDED))
    {
        *y = zc + h * dot_skipping::<N, FIRST>(weights, k);
    }
}

/// `a_0 k_0 + sum_{FIRST <= j < N} a_j k_j`, summed in order of `j` as [`dot`] does, for
/// weights `a` whose entries `1 .. FIRST` are zero (the same sum: the products left out are
/// exact zeros), with the lengths known at compile time (unrolled, no bounds checks inside).
/// `a` and `k` have at least `N` entries.
#[inline(always)]
fn dot_skipping<const N: usize, const FIRST: usize>(a: &[f64], k: &[f64]) -> f64 {
    let a: &[f64; N] = a[..N].try_into().expect("N weights");
    let k: &[f64; N] = k[..N].try_into().expect("N stages");
    let mut sum = -0.0 + a[0] * k[0];
    for j in FIRST..N {
        sum += a[j] * k[j];
    }
    sum
}

/// `out[c] = z[c] + h sum_j w_j k_j[c]` for every component `c` of `out`: a fixed-length sum
/// per component, dispatched once on the number of weights (faster than accumulating stage by
/// stage, even for the 24 components of a state with its sensitivities).
#[inline]
fn combine(out: &mut [f64], z: &[f64], stages: &[f64], weights: &[f64], h: f64) {
    // The number of weights is the stage index (1 to 15), or 12 for the solution: the row of
    // `A` they come from, whose zeros after the first weight `SKIP_FROM` skips.
    match weights.len() {
        1 => combine_fixed::<1, { SKIP_FROM[1] }>(out, z, stages, weights, h),
        2 => combine_fixed::<2, { SKIP_FROM[2] }>(out, z, stages, weights, h),
        3 => combine_fixed::<3, { SKIP_FROM[3] }>(out, z, stages, weights, h),
        4 => combine_fixed::<4, { SKIP_FROM[4] }>(out, z, stages, weights, h),
        5 => combine_fixed::<5, { SKIP_FROM[5] }>(out, z, stages, weights, h),
        6 => combine_fixed::<6, { SKIP_FROM[6] }>(out, z, stages, weights, h),
        7 => combine_fixed::<7, { SKIP_FROM[7] }>(out, z, stages, weights, h),
        8 => combine_fixed::<8, { SKIP_FROM[8] }>(out, z, stages, weights, h),
        9 => combine_fixed::<9, { SKIP_FROM[9] }>(out, z, stages, weights, h),
        10 => combine_fixed::<10, { SKIP_FROM[10] }>(out, z, stages, weights, h),
        11 => combine_fixed::<11, { SKIP_FROM[11] }>(out, z, stages, weights, h),
        12 => combine_fixed::<12, { SKIP_FROM[12] }>(out, z, stages, weights, h),
        13 => combine_fixed::<13, { SKIP_FROM[13] }>(out, z, stages, weights, h),
        14 => combine_fixed::<14, { SKIP_FROM[14] }>(out, z, stages, weights, h),
        15 => combine_fixed::<15, { SKIP_FROM[15] }>(out, z, stages, weights, h),
        _ => {
            for ((y, &zc), k) in out
                .iter_mut()
                .zip(z)
                .zip(stages.chunks_exact(STAGES_EXTENDED))
            {
                *y = zc + h * dot(weights, k);
            }
        }
    }
}

/// `p <- theta p` for the power-basis polynomial `p` of degree `degree` (`p` long enough).
fn times_theta(p: &mut [f64], degree: usize) {
    for i in (0..=degree).rev() {
        p[i + 1] = p[i];
    }
    p[0] = 0.0;
}

/// `p <- (1 - theta) p` for the power-basis polynomial `p` of degree `degree`.
fn times_one_minus_theta(p: &mut [f64], degree: usize) {
    p[degree + 1] = 0.0;
    for i in (1..=degree + 1).rev() {
        p[i] -= p[i - 1];
    }
}

impl Dop853 {
    pub fn new(dim: usize, controlled: usize, variational_tolerance: Option<f64>) -> Self {
        Self {
            dim,
            controlled,
            variational_tolerance,
            stages: vec![0.0; STAGES_EXTENDED * dim],
            argument: vec![0.0; dim],
            derivative: vec![0.0; dim],
            dense: vec![0.0; DENSE_COEFFICIENTS * dim],
            h: 0.0,
        }
    }

    /// The stage derivatives of component `c` (16 values).
    #[inline]
    fn component(&self, c: usize) -> &[f64] {
        &self.stages[c * STAGES_EXTENDED..(c + 1) * STAGES_EXTENDED]
    }

    /// Evaluate `rhs` at `(t, argument)` and store the result as stage `i` (components `0..m`).
    fn evaluate_stage(&mut self, rhs: &mut Rhs<'_>, i: usize, t: f64, m: usize) {
        rhs(t, &self.argument, &mut self.derivative);
        for (c, &value) in self.derivative[..m].iter().enumerate() {
            self.stages[c * STAGES_EXTENDED + i] = value;
        }
    }

    /// Stage 0: `f(t, z)` (needed before [`Dop853::attempt`] unless reused from stage 12).
    pub fn evaluate_first_stage(&mut self, rhs: &mut Rhs<'_>, t: f64, z: &[f64]) {
        let dim = self.dim;
        self.argument.copy_from_slice(&z[..dim]);
        self.evaluate_stage(rhs, 0, t, dim);
    }

    /// Stage 0 (the derivative at the start of the next attempt) for components
    /// `0..out.len()`.
    pub fn first_stage(&self, out: &mut [f64]) {
        for (c, o) in out.iter_mut().enumerate() {
            *o = self.stages[c * STAGES_EXTENDED];
        }
    }

    /// Multiply stage 0 by `factor` (a change of the independent variable at the step start:
    /// `dz/dsigma = (dt/dsigma) dz/dt`).
    pub fn scale_first_stage(&mut self, factor: f64) {
        for row in self.stages.chunks_exact_mut(STAGES_EXTENDED) {
            row[0] *= factor;
        }
    }

    /// Overwrite stage 0 on components `range` (within `0..dim`) with what `fill` writes into
    /// a contiguous buffer of that length (the stage argument's, free between stages), when it
    /// returns `true`.
    pub fn refill_first_stage(
        &mut self,
        range: std::ops::Range<usize>,
        fill: impl FnOnce(&mut [f64]) -> bool,
    ) {
        if range.end <= self.dim && fill(&mut self.argument[range.clone()]) {
            for c in range {
                self.stages[c * STAGES_EXTENDED] = self.argument[c];
            }
        }
    }

    /// Copy stage 12 (the derivative at the end of the last accepted step) to stage 0: the
    /// first-same-as-last property.
    pub fn reuse_last_derivative(&mut self) {
        for row in self.stages.chunks_exact_mut(STAGES_EXTENDED) {
            row[0] = row[12];
        }
    }

    /// Form `argument = z + h sum_{j < i} a_ij k_j` on components `0..m`.
    fn stage_argument(&mut self, i: usize, z: &[f64], h: f64, m: usize) {
        combine(&mut self.argument[..m], z, &self.stages, &A[i][..i], h);
    }

    /// Attempt a step of size `h` from `(t, z)` (stage 0 must hold `f(t, z)`); writes the
    /// 8th-order solution into `z_new` and returns Hairer's scaled error norm (accept if `<= 1`).
    ///
    /// `rhs(t, z, dz)` evaluates the augmented field.
    #[allow(clippy::too_many_arguments)]
    pub fn attempt(
        &mut self,
        rhs: &mut Rhs<'_>,
        t: f64,
        z: &[f64],
        h: f64,
        z_new: &mut [f64],
        rtol: f64,
        atol: f64,
    ) -> f64 {
        let dim = self.dim;
        self.h = h;
        for i in 1..STAGES {
            self.stage_argument(i, z, h, dim);
            self.evaluate_stage(rhs, i, t + C[i] * h, dim);
        }
        // z_new = z + h sum b_j k_j (b = row 12 of A).
        combine(z_new, z, &self.stages, &A[12][..STAGES], h);
        // Error estimate (Hairer's err / err2 combination) on the state, and on the
        // variational components with their own tolerance if they are controlled: the larger.
        let state = self.error_norm(0..self.controlled, z, z_new, h, rtol, atol);
        match self.variational_tolerance {
            Some(tol) if dim > self.controlled => {
                state.max(self.error_norm(self.controlled..dim, z, z_new, h, tol, tol))
            }
            _ => state,
        }
    }

    /// Hairer's scaled error norm of the last attempt over `components`.
    fn error_norm(
        &self,
        components: std::ops::Range<usize>,
        z: &[f64],
        z_new: &[f64],
        h: f64,
        rtol: f64,
        atol: f64,
    ) -> f64 {
        let b = &A[12][..STAGES];
        let count = components.len();
        let mut err5 = 0.0;
        let mut err3 = 0.0;
        for c in components {
            let scale = atol + rtol * z[c].abs().max(z_new[c].abs());
            let k = self.component(c);
            // E5, b and BHH vanish on stages 2 to 5 (tested).
            let e5 = dot_skipping::<STAGES, ESTIMATE_SKIP_FROM>(&E5, k);
            let e3 = dot_skipping::<STAGES, ESTIMATE_SKIP_FROM>(b, k)
                - dot_skipping::<STAGES, ESTIMATE_SKIP_FROM>(&BHH, k);
            err5 += (e5 / scale) * (e5 / scale);
            err3 += (e3 / scale) * (e3 / scale);
        }
        if err5 == 0.0 && err3 == 0.0 {
            return 0.0;
        }
        let denominator = err5 + 0.01 * err3;
        h.abs() * err5 / (denominator * count as f64).sqrt()
    }

    /// Next step size from the error norm of an attempt (Hairer's controller with `beta = 0`):
    /// `h_new = h / clamp(err^(1/8) / 0.9, 1/6, 1/0.333)`; after a rejection the step does not
    /// grow.
    pub fn next_step(h: f64, error: f64, after_rejection: bool) -> f64 {
        // err^(1/8) as three square roots (each correctly rounded; `powf` is a library call
        // several times dearer, and this runs once per attempt).
        let eighth_root = error.sqrt().sqrt().sqrt();
        let factor = (eighth_root / SAFETY).clamp(1.0 / MAX_FACTOR, 1.0 / MIN_FACTOR);
        let h_new = h / factor;
        if after_rejection && error <= 1.0 {
            h_new.min(h)
        } else {
            h_new
        }
    }

    /// Complete an accepted step to `z_new`: stage 12, the augmented derivative at the new point
    /// (reused as stage 0 of the next step, and needed by the dense output).
    pub fn derivative_at_end(&mut self, rhs: &mut Rhs<'_>, t: f64, z_new: &[f64]) {
        let dim = self.dim;
        self.argument.copy_from_slice(&z_new[..dim]);
        self.evaluate_stage(rhs, 12, t + self.h, dim);
    }

    /// Dense-output stages 13..=15 and coefficients for components `0..m` (the state with
    /// `m = n`, every component with `m = N`). `rhs` must write at least components `0..m`.
    pub fn dense_coefficients(
        &mut self,
        rhs: &mut Rhs<'_>,
        t: f64,
        z: &[f64],
        z_new: &[f64],
        m: usize,
    ) {
        let h = self.h;
        for i in 13..STAGES_EXTENDED {
            // The remaining components of the argument are left as they are: for m < dim the
            // caller's field reads only the state part.
            self.stage_argument(i, z, h, m);
            self.evaluate_stage(rhs, i, t + C[i] * h, m);
        }
        for ((c, k), coefficients) in self
            .stages
            .chunks_exact(STAGES_EXTENDED)
            .enumerate()
            .zip(self.dense.chunks_exact_mut(DENSE_COEFFICIENTS))
            .take(m)
        {
            let delta = z_new[c] - z[c];
            let f0 = k[0];
            let f1 = k[12];
            coefficients[0] = delta;
            coefficients[1] = h * f0 - delta;
            coefficients[2] = 2.0 * delta - h * (f1 + f0);
            for (coefficient, d) in coefficients[3..].iter_mut().zip(&D) {
                // The dense weights vanish on stages 2 to 5 (tested).
                *coefficient = h * dot_skipping::<STAGES_EXTENDED, ESTIMATE_SKIP_FROM>(d, k);
            }
        }
    }

    /// The power-basis coefficients in `theta` (`[c_0, ..., c_7]`, `c_j` multiplying
    /// `theta^j`, `c_0 = 0`) of `sum_c w_c (y_c(theta) - y_c(0))`, the weighted sum of the
    /// dense-output polynomials of the components `c < weights.len()` less their values at the
    /// step start: the interpolant of a switching function affine in the state. Components
    /// with weight zero are skipped.
    pub fn dense_polynomial(&self, weights: &[f64]) -> [f64; DENSE_COEFFICIENTS + 1] {
        // The weighted nested coefficients e_j = sum_c w_c d_j[c].
        let mut e = [0.0; DENSE_COEFFICIENTS];
        for (&w, d) in weights
            .iter()
            .zip(self.dense.chunks_exact(DENSE_COEFFICIENTS))
        {
            if w != 0.0 {
                for (ej, &dj) in e.iter_mut().zip(d) {
                    *ej += w * dj;
                }
            }
        }
        // Expand theta (e0 + s (e1 + theta (e2 + s (e3 + theta (e4 + s (e5 + theta e6))))))
        // with s = 1 - theta from the inside out, in the power basis: before e_j is added the
        // bracket so far is multiplied by theta (odd j) or by s (even j), and the whole by
        // theta at the end.
        let mut p = [0.0; DENSE_COEFFICIENTS + 1];
        p[0] = e[DENSE_COEFFICIENTS - 1];
        let mut degree = 0;
        for j in (0..DENSE_COEFFICIENTS - 1).rev() {
            if j % 2 == 1 {
                times_theta(&mut p, degree);
            } else {
                times_one_minus_theta(&mut p, degree);
            }
            degree += 1;
            p[0] += e[j];
        }
        times_theta(&mut p, degree);
        p
    }

    /// Dense output at `theta = (t - t0) / h` in `[0, 1]` for components `0..out.len()`:
    /// `z0 + theta (d0 + (1-theta) (d1 + theta (d2 + (1-theta) (d3 + theta (d4 + (1-theta)
    /// (d5 + theta d6))))))` (Hairer's `contd8`).
    pub fn interpolate(&self, z0: &[f64], theta: f64, out: &mut [f64]) {
        for (c, o) in out.iter_mut().enumerate() {
            *o = z0[c] + self.dense_increment(c, theta);
        }
    }

    /// The dense output of the last step continued to `theta` (beyond 1 an extrapolation of
    /// its polynomial), from the step's end state `z1` (`z0 = z1 - d0`), for components
    /// `0..out.len()`.
    pub fn extrapolate_from_end(&self, z1: &[f64], theta: f64, out: &mut [f64]) {
        for (c, o) in out.iter_mut().enumerate() {
            // Coefficient 0 is `d0 = z1 - z0`.
            *o = z1[c] - self.dense[c * DENSE_COEFFICIENTS] + self.dense_increment(c, theta);
        }
    }

    /// The dense-output polynomial of component `c` at `theta`, less its value at 0.
    #[inline]
    fn dense_increment(&self, c: usize, theta: f64) -> f64 {
        let start = c * DENSE_COEFFICIENTS;
        let d: &[f64; DENSE_COEFFICIENTS] = self.dense[start..start + DENSE_COEFFICIENTS]
            .try_into()
            .expect("7 coefficients per component");
        let s1 = 1.0 - theta;
        let inner = d[4] + s1 * (d[5] + theta * d[6]);
        theta * (d[0] + s1 * (d[1] + theta * (d[2] + s1 * (d[3] + theta * inner))))
    }

    /// Hairer's starting step (`hinit`, order 8): balances `0.01 / max(|f'|, |f|)^(1/8)` against
    /// the scale of the solution. Stage 0 must hold `f(t, z)`; uses one evaluation of `rhs`
    /// (stored as stage 1, which the next attempt overwrites).
    pub fn initial_step(
        &mut self,
        rhs: &mut Rhs<'_>,
        t: f64,
        z: &[f64],
        rtol: f64,
        atol: f64,
        max_step: f64,
    ) -> f64 {
        let dim = self.dim;
        let n = self.controlled;
        let mut dnf = 0.0;
        let mut dny = 0.0;
        for c in 0..n {
            let scale = atol + rtol * z[c].abs();
            dnf += (self.component(c)[0] / scale).powi(2);
            dny += (z[c] / scale).powi(2);
        }
        let mut h = if dnf <= 1e-10 || dny <= 1e-10 {
            1e-6
        } else {
            (dny / dnf).sqrt() * 0.01
        };
        h = h.min(max_step);
        for c in 0..dim {
            self.argument[c] = z[c] + h * self.component(c)[0];
        }
        self.evaluate_stage(rhs, 1, t + h, dim);
        let mut der2 = 0.0;
        for c in 0..n {
            let scale = atol + rtol * z[c].abs();
            let k = self.component(c);
            der2 += ((k[1] - k[0]) / scale).powi(2);
        }
        let der2 = der2.sqrt() / h;
        let der12 = der2.abs().max(dnf.sqrt());
        let h1 = if der12 <= 1e-15 {
            (h * 1e-3).max(1e-6)
        } else {
            (0.01 / der12).powf(0.125)
        };
        (100.0 * h).min(h1).min(max_step)
    }
}

#[cfg(test)]
mod tests {

    /// The power-basis form of a weighted sum of dense outputs equals the nested form
    /// (`dense_increment`) it was expanded from, at points across the step.
    #[test]
    fn dense_polynomial_equals_the_nested_dense_output() {
        let mut stepper = Dop853::new(3, 3, None);
        for (i, d) in stepper.dense.iter_mut().enumerate() {
            *d = ((i * 37) % 11) as f64 / 11.0 - 0.4;
        }
        let weights = [1.0, 0.0, -2.5];
        let power = stepper.dense_polynomial(&weights);
        assert_eq!(power[0], 0.0);
        for theta in [0.0, 0.2, 0.5, 0.77, 1.0, 1.3] {
            let nested: f64 = weights
                .iter()
                .enumerate()
                .map(|(c, w)| w * stepper.dense_increment(c, theta))
                .sum();
            let expanded = power.iter().rev().fold(0.0, |acc, &a| acc * theta + a);
            assert!(
                (nested - expanded).abs() < 1e-13,
                "theta {theta}: {nested} vs {expanded}"
            );
        }
    }

    use super::*;

    /// Harmonic oscillator `y1' = y2, y2' = -y1`, exact `y = (cos t, -sin t)` from `(1, 0)`.
    fn rhs(_t: f64, z: &[f64], dz: &mut [f64]) {
        dz[0] = z[1];
        dz[1] = -z[0];
    }

    /// Global error at `t = 2` after `steps` fixed DOP853 steps (error estimate ignored).
    fn fixed_step_error(steps: usize) -> f64 {
        let mut rk = Dop853::new(2, 2, None);
        let h = 2.0 / steps as f64;
        let mut z = [1.0, 0.0];
        let mut z_new = [0.0; 2];
        let mut t = 0.0;
        let mut f = rhs;
        for _ in 0..steps {
            rk.evaluate_first_stage(&mut f, t, &z);
            rk.attempt(&mut f, t, &z, h, &mut z_new, 1e-12, 1e-12);
            z = z_new;
            t += h;
        }
        ((z[0] - 2.0f64.cos()).powi(2) + (z[1] + 2.0f64.sin()).powi(2)).sqrt()
    }

    /// The weights the sums leave out are zero: `A[i][1..SKIP_FROM[i]]` for every row (row 12
    /// is the solution), and entries `1..ESTIMATE_SKIP_FROM` of the error estimate's and the
    /// dense output's weights.
    #[test]
    fn zero_weights_skipped_are_zero() {
        for (row, &first) in SKIP_FROM.iter().enumerate() {
            let skipped = &A[row][1..first];
            assert!(
                skipped.iter().all(|&w| w == 0.0),
                "row {row}: {skipped:?} not all zero"
            );
        }
        // The error estimate's and the dense output's weights.
        for weights in [
            &E5[..],
            &A[12][..STAGES],
            &BHH[..],
            &D[0],
            &D[1],
            &D[2],
            &D[3],
        ] {
            assert!(
                weights[1..ESTIMATE_SKIP_FROM].iter().all(|&w| w == 0.0),
                "{weights:?}"
            );
        }
    }

    /// Halving a fixed step divides the global error by `2^8` for an 8th-order method.
    /// Measured (this implementation): errors 5.1e-9, 2.0e-11, 7.6e-14 with 3, 6, 12 steps over
    /// [0, 2], slopes 8.02 and 8.01; asserted within `[7.5, 8.6]` (the 12-step error is still
    /// ~300 times the rounding level).
    #[test]
    fn global_order_is_eight() {
        let e3 = fixed_step_error(3);
        let e6 = fixed_step_error(6);
        let e12 = fixed_step_error(12);
        let s1 = (e3 / e6).log2();
        let s2 = (e6 / e12).log2();
        eprintln!("fixed-step errors {e3:e} {e6:e} {e12:e}; slopes {s1:.3} {s2:.3}");
        assert!((7.5..=8.6).contains(&s1), "slope {s1} ({e3:e}, {e6:e})");
        assert!((7.5..=8.6).contains(&s2), "slope {s2} ({e6:e}, {e12:e})");
    }

    /// The dense output inside one step has local error `O(h^8)` (order 7): halving the step
    /// divides the error at mid-step by about `2^8` (measured: 8.07); asserted slope `>= 7.5`.
    #[test]
    fn dense_output_order_is_seven() {
        let error_at_midstep = |h: f64| {
            let mut rk = Dop853::new(2, 2, None);
            let z = [1.0, 0.0];
            let mut z_new = [0.0; 2];
            let mut f = rhs;
            rk.evaluate_first_stage(&mut f, 0.0, &z);
            rk.attempt(&mut f, 0.0, &z, h, &mut z_new, 1e-12, 1e-12);
            rk.derivative_at_end(&mut f, 0.0, &z_new);
            rk.dense_coefficients(&mut f, 0.0, &z, &z_new, 2);
            let mut out = [0.0; 2];
            rk.interpolate(&z, 0.5, &mut out);
            let t: f64 = 0.5 * h;
            ((out[0] - t.cos()).powi(2) + (out[1] + t.sin()).powi(2)).sqrt()
        };
        let e1 = error_at_midstep(1.0);
        let e2 = error_at_midstep(0.5);
        let slope = (e1 / e2).log2();
        eprintln!("dense errors {e1:e} {e2:e}; slope {slope:.3}");
        assert!(slope >= 7.5, "dense slope {slope} ({e1:e}, {e2:e})");
    }
}
