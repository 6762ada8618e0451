//! Which derivatives of the flow the solver carries, and the variational equations that
//! propagate them alongside the state.
//!
//! The augmented state is `z = [x, vec(Phi), s]` (`Phi` column-major, `n x n`; `s` length `n`)
//! with `x' = f(t, x)`, `Phi' = J Phi`, `s' = J s + df/dp`, `J = df/dx`: the first variational
//! equation of the flow (Hairer, Norsett, Wanner I, Sec. I.14).

use nalgebra::{DMatrix, DMatrixView, DMatrixViewMut, DVectorView, DVectorViewMut};

use crate::system::{HybridSystem, Mode};

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

/// The augmented right-hand side `[f, J Phi, J s + df/dp]` of one mode, with preallocated
/// Jacobian and `df/dp` buffers and a count of vector-field evaluations.
pub(crate) struct VariationalField {
    n: usize,
    sensitivity: Sensitivity,
    jacobian: DMatrix<f64>,
    dfdp: Vec<f64>,
    /// Number of calls of `HybridSystem::vector_field` made through this object.
    pub evaluations: usize,
}

impl VariationalField {
    pub fn new(n: usize, sensitivity: Sensitivity) -> Self {
        Self {
            n,
            sensitivity,
            jacobian: DMatrix::zeros(n, n),
            dfdp: vec![0.0; n],
            evaluations: 0,
        }
    }

    /// Evaluate `dz/dt` at `(t, z)` in `mode`; with `variational == false` only the state part
    /// `dz[..n]` is written.
    pub fn eval<S: HybridSystem + ?Sized>(
        &mut self,
        system: &S,
        mode: Mode,
        t: f64,
        z: &[f64],
        dz: &mut [f64],
        variational: bool,
    ) {
        let n = self.n;
        system.vector_field(mode, t, &z[..n], &mut dz[..n]);
        self.evaluations += 1;
        if !variational || !self.sensitivity.transition() {
            return;
        }
        system.jacobian(mode, t, &z[..n], &mut self.jacobian);
        let nn = n * n;
        {
            let phi = DMatrixView::from_slice(&z[n..n + nn], n, n);
            let mut dphi = DMatrixViewMut::from_slice(&mut dz[n..n + nn], n, n);
            dphi.gemm(1.0, &self.jacobian, &phi, 0.0);
        }
        if self.sensitivity.parameter() {
            system.parameter_derivative(mode, t, &z[..n], &mut self.dfdp);
            let s = DVectorView::from_slice(&z[n + nn..n + nn + n], n);
            let ds_slice = &mut dz[n + nn..n + nn + n];
            ds_slice.copy_from_slice(&self.dfdp);
            let mut ds = DVectorViewMut::from_slice(ds_slice, n);
            ds.gemv(1.0, &self.jacobian, &s, 1.0);
        }
    }
}
