//! Saltation matrices: how the state-transition matrix and the parameter sensitivity jump when
//! a trajectory crosses a switching surface or is reset on it.
//!
//! With `tau` the event time, `x-` and `x+ = R(x-)` the states before and after, `f-` and `f+`
//! the fields there, `h_x` the surface gradient and `hdot = h_t + h_x . f-` (the crossing rate):
//!
//! ```text
//! S      = R_x + (f+ - R_x f-) h_x^T / hdot
//! Phi+   = S Phi-
//! s+     = S s- + R_p + (f+ - R_x f-) h_p / hdot
//! ```
//!
//! (Aizerman-Gantmacher; di Bernardo et al., *Piecewise-smooth Dynamical Systems*, Sec. 2.5).
//! Without a reset `R_x = I`, `R_p = 0`; when the field is continuous across the surface (Hertz
//! contact) the jump `f+ - f-` vanishes and `S = I`. The derivation: `dtau = -(h_x dx- + h_p
//! dp) / hdot`, and the post-event flow at a fixed later time sees `dx+ = R_x (dx- + f- dtau)
//! + R_p dp - f+ dtau`.

// Index loops mirror the formulas' subscripts.
#![allow(clippy::needless_range_loop)]

use nalgebra::{DMatrix, DMatrixView, DVectorView, DVectorViewMut};

use crate::error::HybridError;

/// Preallocated buffers for applying a saltation matrix to `n`-dimensional sensitivities.
pub(crate) struct Saltation {
    /// The saltation matrix `S` of the last event.
    pub matrix: DMatrix<f64>,
    /// `f+ - R_x f-`.
    jump: Vec<f64>,
    product: DMatrix<f64>,
    vector: Vec<f64>,
}

impl Saltation {
    pub fn new(n: usize) -> Self {
        Self {
            matrix: DMatrix::identity(n, n),
            jump: vec![0.0; n],
            product: DMatrix::zeros(n, n),
            vector: vec![0.0; n],
        }
    }

    /// Form `S` from the reset Jacobian `R_x` (identity for a crossing), the fields before and
    /// after, the surface gradient `h_x` and the rate `hdot`; then update `phi` (`n x n`,
    /// column-major slice) and, if given, the parameter sensitivity `s` with `R_p` and `h_p`.
    ///
    /// # Errors
    /// [`HybridError::SingularSaltation`] if `hdot == 0` while the field jumps.
    #[allow(clippy::too_many_arguments)]
    pub fn apply(
        &mut self,
        reset_jacobian: &DMatrix<f64>,
        f_minus: &[f64],
        f_plus: &[f64],
        gradient: &[f64],
        hdot: f64,
        phi: &mut [f64],
        parameter: Option<(&mut [f64], &[f64], f64)>,
        t: f64,
        surface: usize,
    ) -> Result<(), HybridError> {
        let n = self.jump.len();
        // jump = f+ - R_x f-
        for i in 0..n {
            let mut rf = 0.0;
            for j in 0..n {
                rf += reset_jacobian[(i, j)] * f_minus[j];
            }
            self.jump[i] = f_plus[i] - rf;
        }
        let jumps = self.jump.iter().any(|&v| v != 0.0);
        if jumps && hdot == 0.0 {
            return Err(HybridError::SingularSaltation { t, surface });
        }
        self.matrix.copy_from(reset_jacobian);
        if jumps {
            for j in 0..n {
                for i in 0..n {
                    self.matrix[(i, j)] += self.jump[i] * gradient[j] / hdot;
                }
            }
        }
        {
            let phi_view = DMatrixView::from_slice(phi, n, n);
            self.product.gemm(1.0, &self.matrix, &phi_view, 0.0);
        }
        phi.copy_from_slice(self.product.as_slice());
        if let Some((s, reset_dxdp, h_p)) = parameter {
            {
                let s_view = DVectorView::from_slice(s, n);
                let mut out = DVectorViewMut::from_slice(&mut self.vector, n);
                out.gemv(1.0, &self.matrix, &s_view, 0.0);
            }
            for i in 0..n {
                let mut value = self.vector[i] + reset_dxdp[i];
                if jumps {
                    value += self.jump[i] * h_p / hdot;
                }
                s[i] = value;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bouncing ball `x' = v, v' = -g`, `h = x`, reset `v+ = -e v-`: the saltation matrix is
    /// `[[-e, 0], [-(1 + e) g / v-, -e]]` (closed form, e.g. di Bernardo et al. Sec. 2.5).
    #[test]
    fn bouncing_ball_saltation() {
        let (g, e, v) = (9.81, 0.8, -3.0);
        let mut s = Saltation::new(2);
        let mut rx = DMatrix::identity(2, 2);
        rx[(1, 1)] = -e;
        let f_minus = [v, -g];
        let f_plus = [-e * v, -g];
        let mut phi = [1.0, 0.0, 0.0, 1.0];
        s.apply(
            &rx,
            &f_minus,
            &f_plus,
            &[1.0, 0.0],
            v,
            &mut phi,
            None,
            0.0,
            0,
        )
        .expect("regular saltation");
        let expected = [-e, -(1.0 + e) * g / v, 0.0, -e];
        for (a, b) in phi.iter().zip(expected) {
            assert!((a - b).abs() < 1e-14, "{phi:?} vs {expected:?}");
        }
    }

    /// A continuous field (`f+ = f-`, no reset) gives the identity, even at `hdot = 0`.
    #[test]
    fn continuous_field_is_identity() {
        let mut s = Saltation::new(2);
        let rx = DMatrix::identity(2, 2);
        let f = [0.3, -1.0];
        let mut phi = [2.0, 3.0, 5.0, 7.0];
        s.apply(&rx, &f, &f, &[1.0, 0.0], 0.0, &mut phi, None, 0.0, 0)
            .expect("no jump");
        assert_eq!(phi, [2.0, 3.0, 5.0, 7.0]);
    }
}
