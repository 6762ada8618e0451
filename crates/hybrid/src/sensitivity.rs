//! Which derivatives of the flow the solver carries, and the variational equations that
//! propagate them alongside the state.
//!
//! The augmented state is `z = [x, vec(Phi), s]` (`Phi` column-major, `n x n`; `s` length `n`)
//! with `x' = f(t, x)`, `Phi' = J Phi`, `s' = J s + df/dp`, `J = df/dx`: the first variational
//! equation of the flow (Hairer, Norsett, Wanner I, Sec. I.14).

use nalgebra::DMatrix;

/// Which derivatives of the flow to integrate with the state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Sensitivity {
    /// State only (fast time-domain sweeps).
    #[default]
    None,
    /// Also the state-transition matrix `dx(t)/dx(t0)` (`n x n`, the monodromy matrix over a
    /// period).
    Transition,
    /// Also the parameter sensitivity `dx(t)/dp` (length `n`) for the system's parameter `p`.
    TransitionAndParameter,
}

impl Sensitivity {
    /// Whether the transition matrix is tracked.
    pub fn transition(self) -> bool {
        !matches!(self, Sensitivity::None)
    }

    /// Whether the parameter sensitivity is tracked.
    pub fn parameter(self) -> bool {
        matches!(self, Sensitivity::TransitionAndParameter)
    }

    /// Length of the augmented state `[x, vec(Phi), s]` for a system of dimension `n`.
    pub fn augmented_dim(self, n: usize) -> usize {
        match self {
            Sensitivity::None => n,
            Sensitivity::Transition => n + n * n,
            Sensitivity::TransitionAndParameter => n + n * n + n,
        }
    }
}

/// Scratch space for the Jacobian `J = df/dx` (`n x n`) and `df/dp` (length `n`) of one point,
/// in which the default [`crate::HybridSystem::variational_field`] forms them.
#[derive(Debug, Clone)]
pub struct LinearisationBuffers {
    /// `df/dx`, `n x n`.
    pub jacobian: DMatrix<f64>,
    /// `df/dp`, length `n`.
    pub dfdp: Vec<f64>,
}

impl LinearisationBuffers {
    /// Zeroed buffers for a system of dimension `n`.
    pub fn new(n: usize) -> Self {
        Self {
            jacobian: DMatrix::zeros(n, n),
            dfdp: vec![0.0; n],
        }
    }
}

/// `tangent_rates[:, c] = J tangents[:, c]` for every column `c` (column-major, `n` rows),
/// plus `dfdp` on the last column if given: the variational right-hand side with a dense
/// Jacobian (`n^2` multiply-adds per column), written out with fixed sizes for the common small
/// systems (unrolled by the compiler).
pub fn jacobian_products(
    jacobian: &DMatrix<f64>,
    tangents: &[f64],
    tangent_rates: &mut [f64],
    dfdp: Option<&[f64]>,
) {
    let j = jacobian.as_slice();
    match jacobian.nrows() {
        2 => products::<2>(j, tangents, tangent_rates, dfdp),
        4 => products::<4>(j, tangents, tangent_rates, dfdp),
        6 => products::<6>(j, tangents, tangent_rates, dfdp),
        8 => products::<8>(j, tangents, tangent_rates, dfdp),
        n => products_any(n, j, tangents, tangent_rates, dfdp),
    }
}

/// `out[:, c] = J input[:, c]` for every column `c` of the column-major `n x m` blocks (`J`
/// column-major `n x n`), plus `dfdp` on the last column if given; `N = n` fixed.
#[inline]
fn products<const N: usize>(j: &[f64], input: &[f64], out: &mut [f64], dfdp: Option<&[f64]>) {
    let mut matrix = [[0.0; N]; N];
    for (k, column) in matrix.iter_mut().enumerate() {
        column.copy_from_slice(&j[k * N..k * N + N]);
    }
    let columns = out.len() / N;
    for (c, (o, v)) in out
        .chunks_exact_mut(N)
        .zip(input.chunks_exact(N))
        .enumerate()
    {
        let mut acc = [0.0; N];
        if let Some(d) = dfdp {
            if c + 1 == columns {
                acc.copy_from_slice(&d[..N]);
            }
        }
        for (column, &vk) in matrix.iter().zip(v) {
            for (a, &m) in acc.iter_mut().zip(column) {
                *a += m * vk;
            }
        }
        o.copy_from_slice(&acc);
    }
}

/// [`products`] for any `n`.
fn products_any(n: usize, j: &[f64], input: &[f64], out: &mut [f64], dfdp: Option<&[f64]>) {
    let columns = out.len() / n;
    for (c, (o, v)) in out
        .chunks_exact_mut(n)
        .zip(input.chunks_exact(n))
        .enumerate()
    {
        match dfdp {
            Some(d) if c + 1 == columns => o.copy_from_slice(&d[..n]),
            _ => o.fill(0.0),
        }
        for (k, &vk) in v.iter().enumerate() {
            for (a, &m) in o.iter_mut().zip(&j[k * n..k * n + n]) {
                *a += m * vk;
            }
        }
    }
}
