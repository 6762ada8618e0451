//! Single shooting: Newton's method on `P(x; p) - x = 0` at fixed `p`, with the exact
//! monodromy `dP/dx` as Jacobian (quadratic convergence).

use nalgebra::{DMatrix, DVector};

use crate::error::ContinuationError;
use crate::problem::{check_period_map, PeriodMap, PeriodicProblem};

/// Settings of Newton's method, used by [`shoot`] and by the continuation corrector.
#[derive(Debug, Clone, PartialEq)]
pub struct NewtonSettings {
    /// Convergence when the residual `|P(x; p) - x|_2` is at most this (state units).
    /// Allowed: `> 0`, finite. Default `1e-10` (a little above the integration error of the
    /// hybrid solver at its default tolerances, 1e-12 relative, on states of order 1-100).
    pub tolerance: f64,
    /// Newton updates allowed before giving up. Allowed: `>= 1`. Default 12 for shooting
    /// (the continuation corrector uses 6: a good predictor converges in 2-4).
    pub max_iterations: usize,
    /// Divergence guard: the iteration stops (not converged) when the residual grows by more
    /// than this factor in one update. Allowed: `> 1`. Default `1e3`.
    pub divergence_factor: f64,
}

impl Default for NewtonSettings {
    fn default() -> Self {
        Self {
            tolerance: 1e-10,
            max_iterations: 12,
            divergence_factor: 1e3,
        }
    }
}

impl NewtonSettings {
    /// Check every field against its documented range.
    ///
    /// # Errors
    /// [`ContinuationError::InvalidSettings`] naming the first field out of range.
    pub fn validate(&self) -> Result<(), ContinuationError> {
        let t = self.tolerance;
        if !(t.is_finite() && t > 0.0) {
            return Err(ContinuationError::InvalidSettings {
                field: "tolerance",
                value: t,
                allowed: "> 0, finite",
            });
        }
        if self.max_iterations < 1 {
            return Err(ContinuationError::InvalidSettings {
                field: "max_iterations",
                value: self.max_iterations as f64,
                allowed: ">= 1",
            });
        }
        let d = self.divergence_factor;
        if d.is_nan() || d <= 1.0 {
            return Err(ContinuationError::InvalidSettings {
                field: "divergence_factor",
                value: d,
                allowed: "> 1",
            });
        }
        Ok(())
    }
}

/// The outcome of [`shoot`].
#[derive(Debug, Clone, PartialEq)]
pub struct ShootingResult {
    /// The last iterate `x` (the fixed point when `converged`), state units.
    pub state: DVector<f64>,
    /// Newton updates made.
    pub iterations: usize,
    /// `|P(x; p) - x|_2` at `state` (state units).
    pub residual: f64,
    /// Whether `residual <= tolerance`.
    pub converged: bool,
    /// The period map evaluated at `state` (its monodromy gives the Floquet multipliers).
    pub period_map: PeriodMap,
}

/// Find a periodic orbit at fixed parameter `p` by Newton's method on `F(x) = P(x; p) - x`,
/// `x_{k+1} = x_k - (M - I)^{-1} F(x_k)` with the exact monodromy `M = dP/dx`, from `x0`.
///
/// Non-convergence within `settings.max_iterations` (or divergence) is not an error: the
/// result says `converged: false` with its iterations and residual.
///
/// # Errors
/// Invalid settings, a wrong length of `x0`, a failed or non-finite period map, or a singular
/// `M - I` (a multiplier equal to 1: a fold or a non-isolated orbit).
pub fn shoot<P: PeriodicProblem + ?Sized>(
    problem: &P,
    x0: &[f64],
    p: f64,
    settings: &NewtonSettings,
) -> Result<ShootingResult, ContinuationError> {
    settings.validate()?;
    let n = problem.dim();
    if x0.len() != n {
        return Err(ContinuationError::DimensionMismatch {
            what: "initial state",
            expected: n,
            found: x0.len(),
        });
    }
    let x = DVector::from_column_slice(x0);
    let map = problem.period_map(x.as_slice(), p)?;
    check_period_map(&map, n, p)?;
    newton_continue(problem, x, map, p, 0, settings)
}

/// The Newton update of shooting, `(M - I)^{-1} F`, for the monodromy `M` and the residual
/// `F = P(x; p) - x` (state units) at parameter `p`: the next iterate is `x` minus it.
///
/// # Errors
/// [`ContinuationError::SingularMatrix`] if `M - I` is singular (a multiplier equal to 1).
pub fn newton_update(
    monodromy: &DMatrix<f64>,
    residual: &DVector<f64>,
    p: f64,
) -> Result<DVector<f64>, ContinuationError> {
    let mut jacobian = monodromy.clone();
    for i in 0..jacobian.nrows().min(jacobian.ncols()) {
        jacobian[(i, i)] -= 1.0;
    }
    jacobian
        .lu()
        .solve(residual)
        .ok_or(ContinuationError::SingularMatrix {
            what: "shooting Jacobian M - I",
            parameter: p,
        })
}

/// Newton iterations from an iterate whose period map is already evaluated.
fn newton_continue<P: PeriodicProblem + ?Sized>(
    problem: &P,
    mut x: DVector<f64>,
    mut map: PeriodMap,
    p: f64,
    mut iterations: usize,
    settings: &NewtonSettings,
) -> Result<ShootingResult, ContinuationError> {
    let n = x.len();
    loop {
        let residual_vector = &map.image - &x;
        let residual = residual_vector.norm();
        if residual <= settings.tolerance || iterations >= settings.max_iterations {
            return Ok(ShootingResult {
                state: x,
                iterations,
                residual,
                converged: residual <= settings.tolerance,
                period_map: map,
            });
        }
        let candidate = &x - newton_update(&map.monodromy, &residual_vector, p)?;
        iterations += 1;
        if !candidate.iter().all(|v| v.is_finite()) {
            return Err(ContinuationError::NonFinite {
                what: "Newton iterate",
                parameter: p,
            });
        }
        let next = problem.period_map(candidate.as_slice(), p)?;
        check_period_map(&next, n, p)?;
        let next_residual = (&next.image - &candidate).norm();
        if next_residual > settings.divergence_factor * residual {
            return Ok(ShootingResult {
                state: x,
                iterations,
                residual,
                converged: false,
                period_map: map,
            });
        }
        x = candidate;
        map = next;
    }
}
