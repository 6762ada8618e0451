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
    shoot_checked(problem, x0, p, settings, None)
}

/// A check of Newton's progress: every `updates` updates, from the first evaluation on, must
/// reduce the residual by `reduction`, else the iteration stops (not converged).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct StallCheck {
    /// The updates between two residuals compared (and before the first).
    pub(crate) updates: usize,
    /// The factor the residual must fall by over each of those windows, in (0, 1).
    pub(crate) reduction: f64,
}

impl StallCheck {
    /// Whether the iteration stops at update `iterations` with `residual`: at every multiple
    /// of `updates`, the residual is compared with the one `updates` updates earlier (the
    /// first with the residual before any update), recorded in `checkpoint` (kept across
    /// calls, set at update 0; call it at every update from 0 on).
    pub(crate) fn stalled(&self, iterations: usize, residual: f64, checkpoint: &mut f64) -> bool {
        if iterations == 0 {
            *checkpoint = residual;
            return false;
        }
        if !iterations.is_multiple_of(self.updates) {
            return false;
        }
        let stalled = residual > self.reduction * *checkpoint;
        *checkpoint = residual;
        stalled
    }
}

/// The progress a Newton iteration that may start outside its basin must make to go on: its
/// residual halved over every 3 updates from the start. From a guess in its basin Newton's
/// method converges quadratically (corrections and corner jumps that land converge in 1 to 5
/// updates), while an iteration with no orbit near its guess wanders at a residual that barely
/// moves, or cycles: on JKR's hysteretic grazings (`biolever-adhesive`'s approach) the 72 failed
/// corrections and 13 of the 18 corner-jump shots each spent all their 12 (48) updates at
/// residuals of 0.05 to 0.15 nm, 40% of the diagram's period maps; on `biolever-sticky` 4 shots
/// halved their residual between the 3rd and 6th update and ran on to 48 at 0.7 to 1.2 nm. The
/// first window counts from the start: such an iteration sits at about the residual it starts
/// with, and is given up after 3 updates.
/// Used by the continuation's corner jumps and the locations' shots, and by its corrector,
/// whose first window starts at the guess only above its noise floor (`corrector::correct`).
pub(crate) const NEWTON_STALL: StallCheck = StallCheck {
    updates: 3,
    reduction: 0.5,
};

/// [`shoot`], with an optional [`StallCheck`] that gives up on an iteration that wanders at a
/// residual it does not reduce; without one (or where it does not stop the iteration) the
/// iterates are exactly [`shoot`]'s.
///
/// # Errors
/// As [`shoot`].
pub(crate) fn shoot_checked<P: PeriodicProblem + ?Sized>(
    problem: &P,
    x0: &[f64],
    p: f64,
    settings: &NewtonSettings,
    stall: Option<StallCheck>,
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
    newton_continue(problem, x, map, p, settings, stall)
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
    settings: &NewtonSettings,
    stall: Option<StallCheck>,
) -> Result<ShootingResult, ContinuationError> {
    let n = x.len();
    let mut iterations = 0;
    let mut checkpoint = f64::INFINITY;
    loop {
        let residual_vector = &map.image - &x;
        let residual = residual_vector.norm();
        let stalled =
            stall.is_some_and(|check| check.stalled(iterations, residual, &mut checkpoint));
        if residual <= settings.tolerance || iterations >= settings.max_iterations || stalled {
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

#[cfg(test)]
mod tests {
    use nalgebra::{DMatrix, DVector};

    use super::{shoot, shoot_checked, NewtonSettings, StallCheck};
    use crate::error::ContinuationError;
    use crate::problem::{OrbitStructure, PeriodMap, PeriodicProblem};

    /// `P(x; p) = x + x^2 + p`: Newton's method solves `x^2 + p = 0`.
    struct Quadratic;

    impl PeriodicProblem for Quadratic {
        fn dim(&self) -> usize {
            1
        }

        fn period_map(&self, x: &[f64], p: f64) -> Result<PeriodMap, ContinuationError> {
            Ok(PeriodMap {
                image: DVector::from_element(1, x[0] + x[0] * x[0] + p),
                monodromy: DMatrix::from_element(1, 1, 1.0 + 2.0 * x[0]),
                parameter_derivative: DVector::from_element(1, 1.0),
                structure: OrbitStructure::default(),
            })
        }
    }

    const CHECK: StallCheck = StallCheck {
        updates: 3,
        reduction: 0.5,
    };

    /// With no fixed point (`x^2 + 1 = 0`), Newton's iterates from `x_0 = cot(theta)` are
    /// `x_k = cot(2^k theta)` (`x -> (x - 1/x)/2` doubles the angle), with residuals `1 +
    /// x_k^2 = 1/sin^2(2^k theta)`: from `theta = 0.3`, 11.4 at the start, 2.19 after 3 updates
    /// (halved) and 8.50 after 6 (not halved), so the checked iteration stops after 6 updates at
    /// `cot(19.2)`, where the unchecked one runs on to its 12.
    #[test]
    fn a_wandering_iteration_stops_after_two_checks() {
        let theta: f64 = 0.3;
        let x0 = 1.0 / theta.tan();
        let settings = NewtonSettings::default();
        let checked = shoot_checked(&Quadratic, &[x0], 1.0, &settings, Some(CHECK)).expect("shot");
        assert!(!checked.converged);
        assert_eq!(checked.iterations, 6);
        // The angle doubling amplifies x_0's rounding by 2^6 (relative 1e-14 at most).
        let x6 = 1.0 / (64.0 * theta).tan();
        assert!((checked.state[0] - x6).abs() < 1e-12 * x6.abs().max(1.0));
        let residual = 1.0 / (64.0 * theta).sin().powi(2);
        assert!((checked.residual - residual).abs() < 1e-11 * residual);
        let unchecked = shoot(&Quadratic, &[x0], 1.0, &settings).expect("shot");
        assert_eq!(unchecked.iterations, settings.max_iterations);
    }

    /// The first window counts from the start: from `theta = 1.2` (iterates and residuals as
    /// above) the residual is 1.15 at the start and 33.0 after 3 updates, not halved, so the
    /// checked iteration stops after 3 updates at `cot(9.6)`.
    #[test]
    fn an_iteration_that_does_not_start_converging_stops_at_the_first_check() {
        let theta: f64 = 1.2;
        let x0 = 1.0 / theta.tan();
        let settings = NewtonSettings::default();
        let checked = shoot_checked(&Quadratic, &[x0], 1.0, &settings, Some(CHECK)).expect("shot");
        assert!(!checked.converged);
        assert_eq!(checked.iterations, 3);
        let x3 = 1.0 / (8.0 * theta).tan();
        assert!((checked.state[0] - x3).abs() < 1e-12 * x3.abs().max(1.0));
        let residual = 1.0 / (8.0 * theta).sin().powi(2);
        assert!((checked.residual - residual).abs() < 1e-11 * residual);
    }

    /// A converging iteration is the unchecked one, iterate for iterate: `x^2 - 2 = 0` from
    /// `x_0 = 10` (residuals falling by about 4 per update at first, then quadratically) ends at
    /// `sqrt(2)` (to 1e-15) after the same updates with the same state.
    #[test]
    fn a_converging_iteration_is_not_changed() {
        let settings = NewtonSettings::default();
        let checked =
            shoot_checked(&Quadratic, &[10.0], -2.0, &settings, Some(CHECK)).expect("shot");
        let unchecked = shoot(&Quadratic, &[10.0], -2.0, &settings).expect("shot");
        assert!(checked.converged);
        assert!(checked.iterations > 2 * CHECK.updates);
        assert_eq!(checked.iterations, unchecked.iterations);
        assert_eq!(checked.state, unchecked.state);
        assert!((checked.state[0] - 2f64.sqrt()).abs() < 1e-15);
    }
}
