//! Newton's method on a codimension-one defining system `F(u) = 0` (`m - 1` equations in `m`
//! unknowns) closed by one linear condition `row . u = target` (a pseudo-arclength hyperplane,
//! or a fixed parameter), and the curve's unit tangent `J t = 0`.
//!
//! For a grazing curve an update whose grazing minimum touches the surface (the non-smooth
//! side of a hard impact) is replaced by one aiming the gap slightly above zero (see
//! `safe_side_step`), so that the iterates approach the grazing orbit from the side where the
//! period map is smooth.

use nalgebra::{DMatrix, DVector};

use crate::codim_one::{Defining, Evaluation};
use crate::corrector::unit_tangent;
use crate::error::ContinuationError;
use crate::shooting::NewtonSettings;
use crate::two_parameter::SystemFamily;

/// A converged point of the defining system.
#[derive(Debug, Clone)]
pub(crate) struct Solved {
    /// The unknowns.
    pub u: DVector<f64>,
    /// The evaluation at `u`.
    pub evaluation: Evaluation,
    /// Newton updates made.
    pub iterations: usize,
    /// `|F(u)|_2`.
    pub residual: f64,
}

/// Whether an error means "this trial point is bad" rather than "the problem is wrong".
pub(crate) fn recoverable(error: &ContinuationError) -> bool {
    matches!(
        error,
        ContinuationError::PeriodMapFailed { .. }
            | ContinuationError::Hybrid { .. }
            | ContinuationError::NonFinite { .. }
            | ContinuationError::SingularMatrix { .. }
            | ContinuationError::SecondParameter { .. }
    )
}

/// Evaluate, mapping recoverable failures (and non-finite values) to `None`.
fn try_evaluate<F: SystemFamily>(
    defining: &Defining<'_, F>,
    u: &DVector<f64>,
) -> Result<Option<Evaluation>, ContinuationError> {
    if !u.iter().all(|v| v.is_finite()) {
        return Ok(None);
    }
    match defining.evaluate(u) {
        Ok(e)
            if e.residual
                .iter()
                .chain(e.jacobian.iter())
                .all(|v| v.is_finite()) =>
        {
            Ok(Some(e))
        }
        Ok(_) => Ok(None),
        Err(e) if recoverable(&e) => Ok(None),
        Err(e) => Err(e),
    }
}

/// The square matrix `[J; row^T]`.
fn closed(jacobian: &DMatrix<f64>, row: &DVector<f64>) -> DMatrix<f64> {
    let (r, m) = jacobian.shape();
    let mut a = DMatrix::zeros(r + 1, m);
    a.rows_mut(0, r).copy_from(jacobian);
    for j in 0..m {
        a[(r, j)] = row[j];
    }
    a
}

/// Newton on `[F(u); row . u - target] = 0` from `guess`. `Ok(None)` when it does not
/// converge (the caller cuts its step); errors only for a misconfigured problem.
pub(crate) fn correct<F: SystemFamily>(
    defining: &Defining<'_, F>,
    guess: DVector<f64>,
    row: &DVector<f64>,
    target: f64,
    settings: &NewtonSettings,
) -> Result<Option<Solved>, ContinuationError> {
    let mut u = guess;
    let Some(mut evaluation) = try_evaluate(defining, &u)? else {
        return Ok(None);
    };
    let mut iterations = 0;
    loop {
        let residual = evaluation.residual.norm();
        let constraint = row.dot(&u) - target;
        if residual <= settings.tolerance && constraint.abs() <= 1e-12 * (1.0 + target.abs()) {
            return Ok(Some(Solved {
                u,
                evaluation,
                iterations,
                residual,
            }));
        }
        if iterations >= settings.max_iterations {
            return Ok(None);
        }
        let a = closed(&evaluation.jacobian, row);
        let mut rhs = evaluation
            .residual
            .clone()
            .insert_row(evaluation.residual.len(), 0.0);
        let last = rhs.len() - 1;
        rhs[last] = constraint;
        let Some(update) = a.clone().lu().solve(&rhs) else {
            return Ok(None);
        };
        let mut next = None;
        if let Some(e) = try_evaluate(defining, &(&u - &update))? {
            if !e.touching || evaluation.touching {
                next = Some((&u - &update, e));
            }
        }
        if next.is_none() && !evaluation.touching {
            next = safe_side_step(defining, &u, &evaluation, &a, &rhs)?;
        }
        let Some((candidate, e)) = next else {
            return Ok(None);
        };
        iterations += 1;
        if e.residual.norm() > settings.divergence_factor * residual.max(settings.tolerance) {
            return Ok(None);
        }
        u = candidate;
        evaluation = e;
    }
}

/// A grazing iterate whose full Newton step touches the surface: steps that aim the gap at
/// `h_target = min(h / 2, c h^2)` (`h > 0` its current value, `c = 1, 10^2, 10^4, ...`)
/// instead of zero, so that the quadratic error of the step stays on the free side and the
/// iteration keeps converging quadratically; last, plain halving of the full step.
fn safe_side_step<F: SystemFamily>(
    defining: &Defining<'_, F>,
    u: &DVector<f64>,
    evaluation: &Evaluation,
    a: &DMatrix<f64>,
    rhs: &DVector<f64>,
) -> Result<Option<(DVector<f64>, Evaluation)>, ContinuationError> {
    let gap_row = defining.n();
    let h = evaluation.residual[gap_row];
    let lu = a.clone().lu();
    if h > 0.0 {
        let mut factor = 1.0;
        for _ in 0..8 {
            let target = (0.5 * h).min(factor * h * h);
            let mut shifted = rhs.clone();
            shifted[gap_row] = h - target;
            if let Some(update) = lu.solve(&shifted) {
                let candidate = u - update;
                if let Some(e) = try_evaluate(defining, &candidate)? {
                    if !e.touching {
                        return Ok(Some((candidate, e)));
                    }
                }
            }
            factor *= 100.0;
        }
    }
    let Some(update) = lu.solve(rhs) else {
        return Ok(None);
    };
    let mut fraction = 0.5;
    for _ in 0..12 {
        let candidate = u - fraction * &update;
        if let Some(e) = try_evaluate(defining, &candidate)? {
            if !e.touching {
                return Ok(Some((candidate, e)));
            }
        }
        fraction *= 0.5;
    }
    Ok(None)
}

/// The unit tangent `t` with `J t = 0`, oriented so that `t . reference > 0`.
pub(crate) fn tangent(
    evaluation: &Evaluation,
    reference: &DVector<f64>,
    p: f64,
) -> Result<DVector<f64>, ContinuationError> {
    unit_tangent(
        closed(&evaluation.jacobian, reference),
        reference,
        p,
        ("bordered Jacobian of the curve (tangent)", "curve tangent"),
    )
}

/// The state of a curve's continuation at an accepted point.
#[derive(Clone)]
pub(crate) struct Current {
    /// The corrected point with its residual and period map.
    pub solved: Solved,
    /// The unit tangent of the curve there, in the unknowns' order.
    pub tangent: DVector<f64>,
    /// The time of the Poincare section the point's state is taken at (system time units).
    pub section: f64,
    /// Whether the point was solved with the second parameter held fixed (a range end or a
    /// target value), rather than by pseudo-arclength.
    pub at_fixed_second: bool,
}
