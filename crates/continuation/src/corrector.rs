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
    /// The smallest residual `|P(x; p) - x|_2` of the iteration's evaluations (infinite if none
    /// could be evaluated).
    pub smallest_residual: f64,
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

/// The Newton update that the point `u = (x, p)` with period map `map` leaves undone on the
/// hyperplane `row . (u - anchor) = 0`: `du = [M - I, dP/dp; row^T]^{-1} [P(x; p) - x; row . (u
/// - anchor)]`, the next iterate being `u - du`. `None` where the bordered matrix is singular.
pub(crate) fn undone_update(
    map: &PeriodMap,
    u: &DVector<f64>,
    row: &DVector<f64>,
    anchor: &DVector<f64>,
) -> Option<DVector<f64>> {
    let n = map.image.len();
    let mut rhs = DVector::zeros(n + 1);
    for i in 0..n {
        rhs[i] = map.image[i] - u[i];
    }
    rhs[n] = row.dot(&(u - anchor));
    bordered(map, row).lu().solve(&rhs)
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

/// What a corrected point is for: whether it may become a branch point, so that its likely
/// converged evaluations go through [`PeriodicProblem::period_map_likely_accepted`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Purpose {
    /// A trial point of a continuation step, accepted as the next branch point if it converges
    /// (and passes the step's checks).
    BranchPoint,
    /// A point inside a step, sampled to locate a special point: never a branch point.
    Location,
}

/// Whether the evaluation after a Newton update from residual `residual` is likely to be the
/// converged one: Newton's quadratic convergence, `r_next ~ K r^2`, reaches `tolerance` from
/// `r^2 <= tolerance` when `K` is at most about one per state unit. Only the cost depends on
/// it (a point accepted from an evaluation not flagged is observed once more afterwards).
fn likely_converges(residual: f64, tolerance: f64) -> bool {
    residual * residual <= tolerance
}

/// The residual, in multiples of Newton's tolerance, below which the corrector does not
/// judge its progress (from the guess, or against its smallest residual): down there the
/// residual is close to the period map's integration error (the tolerance is set a little
/// above it, [`NewtonSettings::tolerance`]) and Newton's updates need not reduce it before
/// one lands below the tolerance (as next to a JKR diagram's breaks).
pub(crate) const NOISE_FLOOR: f64 = 100.0;

/// Newton's method on `[P(x; p) - x; tau . (u - anchor)] = 0` from `guess`, for `purpose`.
///
/// A failed evaluation of the period map or a singular matrix at a trial point ends the
/// iteration as not converged (the caller cuts its step), as does an iteration that has not
/// halved its residual over 3 updates ([`NEWTON_STALL`]: a guess with no orbit near it),
/// counted from the guess where its residual is above [`NOISE_FLOOR`] times the tolerance
/// (the predictor puts the guess next to the branch, and Newton's quadratic convergence
/// halves the residual in one update or two), else from the 3rd update, and an iteration
/// whose residual from its 2nd update on is no smaller than the smallest before it, where
/// that is above the noise floor (Newton cycling between the orbit structures on either side
/// of a grazing); dimension errors propagate.
pub(crate) fn correct<P: PeriodicProblem + ?Sized>(
    problem: &P,
    guess: DVector<f64>,
    anchor: &DVector<f64>,
    tau: &DVector<f64>,
    settings: &NewtonSettings,
    purpose: Purpose,
) -> Result<Corrected, ContinuationError> {
    let n = problem.dim();
    let mut u = guess;
    let mut iterations = 0;
    let mut previous_residual = f64::INFINITY;
    let mut likely_accepted = false;
    let mut checkpoint = f64::INFINITY;
    let mut best_residual = f64::INFINITY;
    let failed =
        |u: DVector<f64>, iterations, map: Option<PeriodMap>, residual, smallest| Corrected {
            u,
            map,
            iterations,
            residual,
            converged: false,
            smallest_residual: smallest,
        };
    loop {
        let p = u[n];
        let evaluated = if likely_accepted {
            problem.period_map_likely_accepted(&u.as_slice()[..n], p)
        } else {
            problem.period_map(&u.as_slice()[..n], p)
        };
        let map = match evaluated {
            Ok(map) => map,
            Err(e) if recoverable(&e) => {
                return Ok(failed(u, iterations, None, f64::INFINITY, best_residual))
            }
            Err(e) => return Err(e),
        };
        match check_period_map(&map, n, p) {
            Ok(()) => {}
            Err(e) if recoverable(&e) => {
                return Ok(failed(u, iterations, None, f64::INFINITY, best_residual))
            }
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
                smallest_residual: residual,
            });
        }
        // The stall check's first window starts at the guess (update 0) only above the noise
        // floor; below it, the check's first residual is the 3rd update's.
        let checked = iterations > 0 || residual > NOISE_FLOOR * settings.tolerance;
        if iterations >= settings.max_iterations
            || residual > settings.divergence_factor * previous_residual
            || (checked && NEWTON_STALL.stalled(iterations, residual, &mut checkpoint))
            || (iterations >= 2
                && best_residual > NOISE_FLOOR * settings.tolerance
                && residual >= best_residual)
        {
            return Ok(failed(
                u,
                iterations,
                Some(map),
                residual,
                best_residual.min(residual),
            ));
        }
        previous_residual = residual;
        best_residual = best_residual.min(residual);
        let a = bordered(&map, tau);
        let Some(update) = a.lu().solve(&rhs) else {
            return Ok(failed(u, iterations, Some(map), residual, best_residual));
        };
        u -= update;
        iterations += 1;
        likely_accepted =
            purpose == Purpose::BranchPoint && likely_converges(residual, settings.tolerance);
        if !u.iter().all(|v| v.is_finite()) {
            return Ok(failed(u, iterations, None, f64::INFINITY, best_residual));
        }
    }
}

#[cfg(test)]
mod tests {
    use std::cell::RefCell;

    use nalgebra::{DMatrix, DVector};

    use super::{correct, Purpose};
    use crate::error::ContinuationError;
    use crate::problem::{OrbitStructure, PeriodMap, PeriodicProblem};
    use crate::shooting::NewtonSettings;

    /// `P(x; p) = x + x^2 - p`, fixed points `x = +-sqrt(p)`, recording the states of its
    /// evaluations `(x, likely accepted)`.
    #[derive(Default)]
    struct Recording {
        calls: RefCell<Vec<(f64, bool)>>,
    }

    impl Recording {
        fn map(&self, x: f64, p: f64, likely: bool) -> PeriodMap {
            self.calls.borrow_mut().push((x, likely));
            PeriodMap {
                image: DVector::from_element(1, x + x * x - p),
                monodromy: DMatrix::from_element(1, 1, 1.0 + 2.0 * x),
                parameter_derivative: DVector::from_element(1, -1.0),
                structure: OrbitStructure::default(),
            }
        }
    }

    impl PeriodicProblem for Recording {
        fn dim(&self) -> usize {
            1
        }

        fn period_map(&self, x: &[f64], p: f64) -> Result<PeriodMap, ContinuationError> {
            Ok(self.map(x[0], p, false))
        }

        fn period_map_likely_accepted(
            &self,
            x: &[f64],
            p: f64,
        ) -> Result<PeriodMap, ContinuationError> {
            Ok(self.map(x[0], p, true))
        }
    }

    /// Newton on `x^2 - 4 = 0` at `p = 4` (the hyperplane `p = 4`) from `x = 2.5`,
    /// `x_{k+1} = (x_k + 4 / x_k) / 2`, has residuals `x_k^2 - 4` of 2.25, 0.2025, 2.4e-3,
    /// 3.7e-7, then below 1e-14 (recomputed in the test): only the update from 3.7e-7
    /// (squared 1.4e-13, below the tolerance 1e-10) is followed by a likely-accepted
    /// evaluation, the converged one; a location's corrections never are.
    #[test]
    fn only_the_evaluation_after_a_small_residual_is_likely_accepted() {
        let settings = NewtonSettings {
            max_iterations: 6,
            ..NewtonSettings::default()
        };
        let anchor = DVector::from_vec(vec![2.5, 4.0]);
        let tau = DVector::from_vec(vec![0.0, 1.0]);
        let mut residuals = Vec::new();
        let mut x: f64 = 2.5;
        while (x * x - 4.0).abs() > settings.tolerance {
            residuals.push((x * x - 4.0).abs());
            x = 0.5 * (x + 4.0 / x);
        }
        assert_eq!(residuals.len(), 4);
        for (purpose, likely_calls) in [(Purpose::BranchPoint, 1), (Purpose::Location, 0)] {
            let problem = Recording::default();
            let corrected = correct(&problem, anchor.clone(), &anchor, &tau, &settings, purpose)
                .expect("corrected");
            assert!(corrected.converged);
            assert_eq!(corrected.iterations, 4);
            assert!((corrected.u[0] - 2.0).abs() < 1e-12);
            let calls = problem.calls.borrow();
            assert_eq!(calls.len(), 5);
            let likely: Vec<f64> = calls.iter().filter(|c| c.1).map(|c| c.0).collect();
            assert_eq!(likely.len(), likely_calls);
            if let Some(&x_likely) = likely.first() {
                assert_eq!(x_likely, corrected.u[0], "the converged evaluation");
                assert_eq!(calls.last().map(|c| c.1), Some(true));
            }
        }
    }

    /// Without a fixed point (`x^2 + 1 = 0` at `p = -1`), Newton's iterates from
    /// `x_0 = cot(theta)` are `x_k = cot(2^k theta)` with residuals `1 / sin^2(2^k theta)`:
    /// from `theta = 1`, 1.41, 1.21, then 1.75 after the 2nd update, above the best so far,
    /// so the correction stops there (by the check over 3 updates alone, it would stop
    /// after the 3rd, 1.02 > 1.41 / 2).
    #[test]
    fn a_correction_whose_residual_rises_above_its_best_stops() {
        let theta: f64 = 1.0;
        let residual = |k: i32| 1.0 / (2f64.powi(k) * theta).sin().powi(2);
        assert!(residual(2) > residual(0).min(residual(1)));
        assert!(residual(3) > 0.5 * residual(0));
        let settings = NewtonSettings {
            max_iterations: 12,
            ..NewtonSettings::default()
        };
        let anchor = DVector::from_vec(vec![1.0 / theta.tan(), -1.0]);
        let tau = DVector::from_vec(vec![0.0, 1.0]);
        let problem = Recording::default();
        let corrected = correct(
            &problem,
            anchor.clone(),
            &anchor,
            &tau,
            &settings,
            Purpose::BranchPoint,
        )
        .expect("corrected");
        assert!(!corrected.converged);
        assert_eq!(corrected.iterations, 2);
        assert!((corrected.residual - residual(2)).abs() < 1e-9 * residual(2));
        // The smallest of the three residuals, 1.21 after the 1st update.
        let smallest = residual(0).min(residual(1));
        assert!((corrected.smallest_residual - smallest).abs() < 1e-9 * smallest);
        assert_eq!(problem.calls.borrow().len(), 3);
    }

    /// `P(x) = 0.8 x` with a monodromy reported as 0 (not 0.8): Newton's updates are
    /// `x -> 0.8 x`, residuals `0.2 * 0.8^k` from `x = 1`, decreasing but by only 0.512 over
    /// the first 3 updates, so the correction stops after the 3rd (counted from the 3rd
    /// update, it would compare the 6th, 0.262 of the guess's, with half the 3rd's, 0.256,
    /// and stop after 6).
    #[test]
    fn a_correction_that_does_not_halve_its_guess_residual_in_3_updates_stops() {
        struct SlowNewton;
        impl PeriodicProblem for SlowNewton {
            fn dim(&self) -> usize {
                1
            }

            fn period_map(&self, x: &[f64], _p: f64) -> Result<PeriodMap, ContinuationError> {
                Ok(PeriodMap {
                    image: DVector::from_element(1, 0.8 * x[0]),
                    monodromy: DMatrix::zeros(1, 1),
                    parameter_derivative: DVector::zeros(1),
                    structure: OrbitStructure::default(),
                })
            }
        }
        let settings = NewtonSettings {
            max_iterations: 12,
            ..NewtonSettings::default()
        };
        let anchor = DVector::from_vec(vec![1.0, 0.0]);
        let tau = DVector::from_vec(vec![0.0, 1.0]);
        let corrected = correct(
            &SlowNewton,
            anchor.clone(),
            &anchor,
            &tau,
            &settings,
            Purpose::BranchPoint,
        )
        .expect("corrected");
        assert!(!corrected.converged);
        assert_eq!(corrected.iterations, 3);
        assert!((corrected.u[0] - 0.512).abs() < 1e-15);
        assert!((corrected.residual - 0.2 * 0.512).abs() < 1e-15);
    }
}
