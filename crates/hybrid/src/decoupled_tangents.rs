//! The variational equations over one accepted Runge-Kutta step of the state, integrated apart
//! from it ([`crate::settings::SensitivityMethod::Decoupled`]) on the step's clock `sigma`,
//!
//! `dV/dsigma = (dt/dsigma) (J(t, x) V + [df/dp])`, `V = [dx/dx0 | dx/dp]`,
//!
//! by Butcher's explicit Runge-Kutta method of order 6 with 7 stages (J. C. Butcher, 1964; the
//! seven-stage sixth-order example of Hairer, Norsett, Wanner, *Solving ODEs I*, Sec. II.5), the
//! state at the stage nodes taken from the step's 7th-order dense output. On a square-root clock
//! the Jacobian of a half-power contact (`J ~ sqrt(-h)`) is smooth in `sigma`, so the method keeps
//! its order through contact onset and release.

use crate::clock::Clock;
use crate::sensitivity::Sensitivity;
use crate::system::{HybridSystem, Mode};
use crate::variational_field::{clocked_field, VariationalField};

/// Stages of the method.
const STAGES: usize = 7;

/// Nodes `c_i`: the fraction of the step at which stage `i` evaluates the field.
const C: [f64; STAGES] = [
    0.0,
    1.0 / 3.0,
    2.0 / 3.0,
    1.0 / 3.0,
    5.0 / 6.0,
    1.0 / 6.0,
    1.0,
];

/// Coefficients `a_ij` (`j < i`) of the stage arguments.
const A: [[f64; STAGES - 1]; STAGES] = [
    [0.0; 6],
    [1.0 / 3.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [0.0, 2.0 / 3.0, 0.0, 0.0, 0.0, 0.0],
    [1.0 / 12.0, 1.0 / 3.0, -1.0 / 12.0, 0.0, 0.0, 0.0],
    [25.0 / 48.0, -55.0 / 24.0, 35.0 / 48.0, 15.0 / 8.0, 0.0, 0.0],
    [
        3.0 / 20.0,
        -11.0 / 24.0,
        -1.0 / 8.0,
        1.0 / 2.0,
        1.0 / 10.0,
        0.0,
    ],
    [
        -261.0 / 260.0,
        33.0 / 13.0,
        43.0 / 156.0,
        -118.0 / 39.0,
        32.0 / 195.0,
        80.0 / 39.0,
    ],
];

/// Weights `b_i` of the solution.
const B: [f64; STAGES] = [
    13.0 / 200.0,
    0.0,
    11.0 / 40.0,
    11.0 / 40.0,
    4.0 / 25.0,
    4.0 / 25.0,
    13.0 / 200.0,
];

/// Scratch buffers and the variational field of the decoupled integration (allocated once).
pub(crate) struct DecoupledTangents {
    n: usize,
    /// The augmented field (state rate plus `J V` and `df/dp`).
    field: VariationalField,
    /// Stage argument `[x, V]` (augmented length).
    argument: Vec<f64>,
    /// Stage rate `[dx/dsigma, dV/dsigma]` (augmented length), from the solver's clocked
    /// field.
    rate: Vec<f64>,
    /// The variational part of every stage's rate, stage-major (`STAGES` blocks).
    stages: Vec<f64>,
}

impl DecoupledTangents {
    /// Buffers for a state of dimension `n` with `sensitivity` (which tracks the transition).
    pub fn new(n: usize, sensitivity: Sensitivity) -> Self {
        let dim = sensitivity.augmented_dim(n);
        Self {
            n,
            field: VariationalField::new(n, sensitivity),
            argument: vec![0.0; dim],
            rate: vec![0.0; dim],
            stages: vec![0.0; STAGES * (dim - n)],
        }
    }

    /// Advance the variational part `tangents` (`V` at `sigma0`, column-major) over
    /// `[sigma0, sigma0 + dsigma]` on `clock` in `mode`, `state_at(fraction, x)` writing the
    /// state at `sigma0 + fraction dsigma`: `V` at the end is written into `tangents_end`.
    /// Returns the evaluations of the variational field made (7).
    #[allow(clippy::too_many_arguments)]
    pub fn advance<S: HybridSystem + ?Sized>(
        &mut self,
        system: &S,
        mode: Mode,
        clock: Clock,
        (sigma0, dsigma): (f64, f64),
        state_at: &mut dyn FnMut(f64, &mut [f64]),
        tangents: &[f64],
        tangents_end: &mut [f64],
    ) -> usize {
        let Self {
            n,
            field,
            argument,
            rate,
            stages,
        } = self;
        let n = *n;
        let mut rhs = clocked_field(field, system, mode, clock, true);
        let m = tangents.len();
        for i in 0..STAGES {
            let (x, v) = argument.split_at_mut(n);
            state_at(C[i], x);
            v.copy_from_slice(tangents);
            axpy_stages(v, stages, &A[i][..i], dsigma);
            rhs(sigma0 + C[i] * dsigma, argument, rate);
            stages[i * m..(i + 1) * m].copy_from_slice(&rate[n..]);
        }
        tangents_end.copy_from_slice(tangents);
        axpy_stages(tangents_end, stages, &B, dsigma);
        STAGES
    }
}

/// `v += h sum_j w_j k_j` over the stages `k_j` (blocks of length `v.len()` of `stages`) with
/// a nonzero weight; unrolled for the common lengths (the transition matrix of a 2-mode
/// model, with and without the parameter column).
fn axpy_stages(v: &mut [f64], stages: &[f64], weights: &[f64], h: f64) {
    match v.len() {
        16 => axpy_fixed::<16>(v, stages, weights, h),
        20 => axpy_fixed::<20>(v, stages, weights, h),
        _ => axpy_fixed::<0>(v, stages, weights, h),
    }
}

/// [`axpy_stages`] for `M = v.len()` (`M = 0`: any length, not unrolled).
#[inline(always)]
fn axpy_fixed<const M: usize>(v: &mut [f64], stages: &[f64], weights: &[f64], h: f64) {
    let m = v.len();
    for (&w, k) in weights.iter().zip(stages.chunks_exact(m)) {
        if w == 0.0 {
            continue;
        }
        let scale = h * w;
        match (<&mut [f64; M]>::try_from(&mut *v), <&[f64; M]>::try_from(k)) {
            (Ok(v), Ok(k)) if M > 0 => {
                for (a, &r) in v.iter_mut().zip(k) {
                    *a += scale * r;
                }
            }
            _ => {
                for (a, &r) in v.iter_mut().zip(k) {
                    *a += scale * r;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tableau is consistent (each row of `A` sums to its node) and integrates
    /// polynomials in time up to degree 5 exactly (`sum_i b_i c_i^q = 1 / (q + 1)`): the
    /// conditions that fix the order of a linear time-dependent system's integration at the
    /// quadrature level. (The full order is checked by the sixth-order convergence of the
    /// linear oscillator's transition matrix, `tests/linear_oscillator.rs`.)
    #[test]
    fn tableau_rows_sum_to_nodes_and_weights_integrate_quintics() {
        for (row, &c) in A.iter().zip(&C) {
            assert!((row.iter().sum::<f64>() - c).abs() < 1e-15);
        }
        for q in 0..6 {
            let sum: f64 = B.iter().zip(&C).map(|(b, c)| b * c.powi(q)).sum();
            assert!((sum - 1.0 / f64::from(q + 1)).abs() < 1e-15, "degree {q}");
        }
    }
}
