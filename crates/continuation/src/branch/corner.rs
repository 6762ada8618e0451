//! Corners of a branch: at the grazing of a hard impact the branch has a square-root corner
//! that the corrector cannot turn; the continuation jumps over it by shooting at fixed
//! parameters ahead, or, where no orbit exists past it, locates the structure change the branch
//! ends at.

use nalgebra::DVector;

use super::detection::extrapolated_from_near_side;
use super::Continuation;
use crate::error::ContinuationError;
use crate::location::{Sample, Segment};
use crate::problem::PeriodicProblem;
use crate::shooting::{shoot_checked, NewtonSettings, NEWTON_STALL};
use crate::special_point::SpecialPoint;
use crate::test_function::{structure_changes, StructureTest};

/// Whether the structure changes between two orbits include a corner of the branch at a
/// grazing: an extremum whose value at the first orbit is below `1e-3` of its value at the
/// second (the first orbit sits at the grazing the continuation ran into).
fn at_grazing_corner(tests: &[StructureTest]) -> bool {
    tests.iter().any(|t| match *t {
        StructureTest::Extremum {
            value_a, value_b, ..
        } => value_a.abs() <= 1e-3 * value_b.abs(),
        StructureTest::ImpactCount { .. } => false,
    })
}

/// An orbit found past a corner of the branch by [`Continuation::corner_jump`].
pub(super) struct Jump {
    pub(super) sample: Sample,
    pub(super) iterations: usize,
    pub(super) residual: f64,
    /// Unit secant from the current point to the new one.
    pub(super) secant: DVector<f64>,
}

/// Consecutive corrector failures at one point after which a corner jump is tried.
pub(super) const CORNER_FAILURES: usize = 6;

impl<P: PeriodicProblem + ?Sized> Continuation<'_, P> {
    /// The parameter offsets `dp` (parameter units) at which [`Continuation::corner_jump`] shoots
    /// and [`Continuation::terminal_location`] probes past a corner: `1e-4 .. 100` times the
    /// initial step by factors of 10, each capped at the largest step, without repeating an
    /// offset the cap has already given (the same shot, or the same trajectory, again).
    fn offsets_past_corner(&self) -> Vec<f64> {
        let mut offsets: Vec<f64> = Vec::with_capacity(7);
        for j in 0..=6 {
            let dp = (self.settings.initial_step * 10f64.powi(j - 4)).min(self.settings.max_step);
            if offsets.last() != Some(&dp) {
                offsets.push(dp);
            }
        }
        offsets
    }

    /// Jump over a corner of the branch at a structure change (the square-root singularity
    /// of a hard impact at grazing, where the branch turns too sharply for the corrector):
    /// shoot at fixed parameters `p_A + dp` beyond the current point, `dp` growing from
    /// `1e-4` to `100` times the initial step ([`Continuation::offsets_past_corner`], within
    /// the parameter range), from the state extrapolated along the tangent. On a branch whose
    /// period map jumps at its grazings ([`crate::ContinuationSettings::hysteretic_grazing`])
    /// only at the largest of those offsets: across such a jump no orbit lies near the branch,
    /// and what a shot can converge to is an orbit coexisting across the hysteresis.
    /// The first converged orbit whose structure differs from the current one is returned,
    /// with its tangent oriented along the secant (also returned).
    pub(super) fn corner_jump(&self) -> Result<Option<Jump>, ContinuationError> {
        let a = &self.current;
        let n = self.problem.dim();
        let tp = a.tangent[n];
        let direction = if tp < 0.0 { -1.0 } else { 1.0 };
        let shooting = NewtonSettings {
            max_iterations: self.settings.corrector.max_iterations * 4,
            ..self.settings.corrector.clone()
        };
        let in_range = |dp: &f64| {
            let p = a.parameter() + direction * dp;
            p <= self.settings.parameter_max && p >= self.settings.parameter_min
        };
        let mut offsets: Vec<f64> = self
            .offsets_past_corner()
            .into_iter()
            .take_while(in_range)
            .collect();
        if self.settings.hysteretic_grazing {
            // Where the period map jumps at the grazing, no orbit lies just past it near the
            // branch: only the largest offset can reach one (an orbit coexisting across the
            // hysteresis).
            offsets.drain(..offsets.len().saturating_sub(1));
        }
        for dp in offsets {
            let p = a.parameter() + direction * dp;
            let slope = if tp.abs() > 1e-12 { 1.0 / tp } else { 0.0 };
            let guess = a.u.rows(0, n) + (direction * dp * slope) * a.tangent.rows(0, n);
            let result = match shoot_checked(
                self.problem,
                guess.as_slice(),
                p,
                &shooting,
                Some(NEWTON_STALL),
            ) {
                Ok(result) => result,
                Err(ContinuationError::DimensionMismatch { .. }) => {
                    return Err(ContinuationError::DimensionMismatch {
                        what: "period map",
                        expected: n,
                        found: 0,
                    })
                }
                Err(_) => continue,
            };
            if !result.converged
                || !at_grazing_corner(&structure_changes(
                    &a.map.structure,
                    &result.period_map.structure,
                ))
            {
                continue;
            }
            let mut u = DVector::zeros(n + 1);
            u.rows_mut(0, n).copy_from(&result.state);
            u[n] = p;
            let secant = (&u - &a.u).normalize();
            let sample = Sample::new(1.0, u, result.period_map, &secant);
            if sample.tangent.iter().any(|v| !v.is_finite()) {
                continue;
            }
            return Ok(Some(Jump {
                sample,
                iterations: result.iterations,
                residual: result.residual,
                secant,
            }));
        }
        Ok(None)
    }

    /// At the end of a branch that cannot go on (the corrector fails at the minimum step and
    /// no corner jump finds an orbit past it), locate the structure change the branch runs
    /// into, if any: a trajectory started from the state extrapolated along the tangent,
    /// `dp = 1e-4 .. 100` initial steps ahead, that has a different structure marks the far
    /// side; the change is then located in the natural parameter between the last orbit and
    /// that parameter, trials (shot from the state extrapolated along the last orbit's tangent)
    /// with no orbit counting as the far side. `impacts_after` is the
    /// impact count of that extrapolated trajectory (no orbit exists there). Where the branch
    /// ends at a hysteretic grazing whose zero its points resolve (`resolved`,
    /// [`Continuation::grazing_resolved`]) and every change found is one whose zero is
    /// extrapolated from the near side ([`extrapolated_from_near_side`]), no trial is shot:
    /// trials between the last orbit and the grazing meet the period map's noise floor, and the
    /// zero is extrapolated from the branch's points as it would be past their failures.
    pub(super) fn terminal_location(
        &self,
        resolved: bool,
    ) -> Result<Vec<SpecialPoint>, ContinuationError> {
        let a = &self.current;
        let n = self.problem.dim();
        let tp = a.tangent[n];
        if !(tp.abs() > 1e-12 && tp.is_finite()) {
            return Ok(Vec::new());
        }
        let direction = tp.signum();
        for dp in self.offsets_past_corner() {
            let p = a.parameter() + direction * dp;
            if p > self.settings.parameter_max || p < self.settings.parameter_min {
                break;
            }
            let guess = a.u.rows(0, n) + (direction * dp / tp) * a.tangent.rows(0, n);
            let Ok(map) = self.problem.period_map(guess.as_slice(), p) else {
                continue;
            };
            let structure: Vec<StructureTest> = structure_changes(&a.map.structure, &map.structure)
                .into_iter()
                .filter(|t| at_grazing_corner(std::slice::from_ref(t)))
                .collect();
            if structure.is_empty() {
                continue;
            }
            let mut u = DVector::zeros(n + 1);
            u.rows_mut(0, n).copy_from(&guess);
            u[n] = p;
            let far = Sample::new(1.0, u, map, &a.tangent);
            let mut start = a.clone();
            start.sigma = 0.0;
            let segment = Segment::new(
                self.problem,
                start,
                far,
                a.tangent.clone(),
                self.settings.corrector.clone(),
                self.settings.location_tolerance,
                true,
            )
            .with_far_trajectory();
            let segment = if resolved && structure.iter().all(extrapolated_from_near_side) {
                segment.with_failing_trials()
            } else {
                segment
            };
            let index = self.produced.saturating_sub(1);
            return self.locate_all(&segment, &structure, index, true, false);
        }
        Ok(Vec::new())
    }
}
