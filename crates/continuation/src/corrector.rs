//! The pseudo-arclength corrector and the branch tangent.
//!
//! With `u = (x, p)` and `F(u) = P(x; p) - x`, the Jacobian is `J = [M - I, dP/dp]`
//! (`n x (n + 1)`). The tangent solves `J t = 0`, `|t| = 1`; the corrector solves
//! `F(u) = 0` together with the hyperplane constraint `tau . (u - anchor) = 0` by Newton's
//! method on the bordered matrix `[J; tau^T]` (Keller's pseudo-arclength method; Allgower &
//! Georg, *Introduction to Numerical Continuation Methods*, Ch. 2).

use nalgebra::{DMatrix, DVector};

use crate::error::ContinuationError;
use crate::problem::{check_period_map, PeriodMap, PeriodicProblem};
use crate::shooting::{NewtonSettings, NEWTON_STALL};

/// A corrected point `u = (x, p)` and the period map there.
#[derive(Debug, Clone)]
pub(crate) struct Corrected {
    /// `(x, p)`, length `n + 1`.
    pub u: DVector<f64>,
    /// The period map at `u` (valid when `converged`; the last evaluation otherwise).
    pub map: Option<PeriodMap>,
    /// Newton updates made.
    pub iterations: usize,
    /// `|P(x; p) - x|_2` at `u` (infinite if the map could not be evaluated).
    pub residual: f64,
    /// Whether the residual reached the tolerance.
    pub converged: bool,
}

/// The bordered matrix `[M - I, dP/dp; row^T]` (`(n + 1) x (n + 1)`).
pub(crate) fn bordered(map: &PeriodMap, row: &DVector<f64>) -> DMatrix<f64> {
    let n = map.image.len();
    let mut a = DMatrix::zeros(n + 1, n + 1);
    a.view_mut((0, 0), (n, n)).copy_from(&map.monodromy);
    for i in 0..n {
        a[(i, i)] -= 1.0;
        a[(i, n)] = map.parameter_derivative[i];
    }
    for j in 0..=n {
        a[(n, j)] = row[j];
    }
    a
}

/// The unit tangent `t` of the branch at a point with period map `map`: `J t = 0`,
/// `|t| = 1`, oriented so that `t . reference > 0`.
pub(crate) fn tangent(
    map: &PeriodMap,
    reference: &DVector<f64>,
    p: f64,
) -> Result<DVector<f64>, ContinuationError> {
    unit_tangent(
        bordered(map, reference),
        reference,
        p,
        ("bordered Jacobian (tangent)", "branch tangent"),
    )
}

/// The unit null vector `t` of a Jacobian `J` from the bordered matrix `a = [J; reference^T]`:
/// the solution of `a t = e_last`, normalised and oriented so that `t . reference > 0`.
/// `what` names the matrix and the tangent in errors (at parameter `p`).
pub(crate) fn unit_tangent(
    a: DMatrix<f64>,
    reference: &DVector<f64>,
    p: f64,
    what: (&'static str, &'static str),
) -> Result<DVector<f64>, ContinuationError> {
    let m = a.ncols();
    let mut rhs = DVector::zeros(m);
    rhs[m - 1] = 1.0;
    let t = a
        .lu()
        .solve(&rhs)
        .ok_or(ContinuationError::SingularMatrix {
            what: what.0,
            parameter: p,
        })?;
    let norm = t.norm();
    if !(norm.is_finite() && norm > 0.0) {
        return Err(ContinuationError::NonFinite {
            what: what.1,
            parameter: p,
        });
    }
    let t = t / norm;
    Ok(if t.dot(reference) < 0.0 { -t } else { t })
}

/// Whether an error of the period map means "this trial point is bad" (cut the step) rather
/// than "the problem is misconfigured" (stop).
fn recoverable(error: &ContinuationError) -> bool {
    matches!(
        error,
        ContinuationError::PeriodMapFailed { .. }
            | ContinuationError::Hybrid { .. }
            | ContinuationError::NonFinite { .. }
            | ContinuationError::SingularMatrix { .. }
    )
}

/// Newton's method on `[P(x; p) - x; tau . (u - anchor)] = 0` from `guess`.
///
/// A failed evaluation of the period map or a singular matrix at a trial point ends the
/// iteration as not converged (the caller cuts its step), as does an iteration that has not
/// halved its residual over 3 updates, from its start on ([`NEWTON_STALL`]: a guess with no
/// orbit near it); dimension errors propagate.
pub(crate) fn correct<P: PeriodicProblem + ?Sized>(
    problem: &P,
    guess: DVector<f64>,
    anchor: &DVector<f64>,
    tau: &DVector<f64>,
    settings: &NewtonSettings,
) -> Result<Corrected, ContinuationError> {
    let n = problem.dim();
    let mut u = guess;
    let mut iterations = 0;
    let mut previous_residual = f64::INFINITY;
    let mut checkpoint = f64::INFINITY;
    let failed = |u: DVector<f64>, iterations, map: Option<PeriodMap>, residual| Corrected {
        u,
        map,
        iterations,
        residual,
        converged: false,
    };
    loop {
        let p = u[n];
        // After a Newton update the evaluation is usually the converged one.
        let evaluated = if iterations > 0 {
            problem.period_map_likely_accepted(&u.as_slice()[..n], p)
        } else {
            problem.period_map(&u.as_slice()[..n], p)
        };
        let map = match evaluated {
            Ok(map) => map,
            Err(e) if recoverable(&e) => return Ok(failed(u, iterations, None, f64::INFINITY)),
            Err(e) => return Err(e),
        };
        match check_period_map(&map, n, p) {
            Ok(()) => {}
            Err(e) if recoverable(&e) => return Ok(failed(u, iterations, None, f64::INFINITY)),
            Err(e) => return Err(e),
        }
        let mut rhs = DVector::zeros(n + 1);
        for i in 0..n {
            rhs[i] = map.image[i] - u[i];
        }
        let residual = rhs.rows(0, n).norm();
        rhs[n] = tau.dot(&(&u - anchor));
        if residual <= settings.tolerance {
            return Ok(Corrected {
                u,
                map: Some(map),
                iterations,
                residual,
                converged: true,
            });
        }
        if iterations >= settings.max_iterations
            || residual > settings.divergence_factor * previous_residual
            || NEWTON_STALL.stalled(iterations, residual, &mut checkpoint)
        {
            return Ok(failed(u, iterations, Some(map), residual));
        }
        previous_residual = residual;
        let a = bordered(&map, tau);
        let Some(update) = a.lu().solve(&rhs) else {
            return Ok(failed(u, iterations, Some(map), residual));
        };
        u -= update;
        iterations += 1;
        if !u.iter().all(|v| v.is_finite()) {
            return Ok(failed(u, iterations, None, f64::INFINITY));
        }
    }
}
