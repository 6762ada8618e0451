//! One continuation step: predict along the branch, correct on the pseudo-arclength
//! hyperplane, cut the step where the corrector fails, the tangent turns too far or several
//! structure events fall in it, land exactly on a parameter bound, and accept the point with
//! the special points located in the step.

use nalgebra::DVector;

use super::corner::CORNER_FAILURES;
use super::{BranchPoint, Continuation, StopReason, RECENT_STRUCTURES};
use crate::corrector::{correct, Purpose, NOISE_FLOOR};
use crate::error::ContinuationError;
use crate::floquet::is_stable;
use crate::hermite::hermite_basis;
use crate::location::{Sample, Segment};
use crate::problem::PeriodicProblem;
use crate::shooting::shoot;
use crate::test_function::{structure_changes, StructureTest};

/// A corrected orbit a step ahead, before it is accepted.
struct Trial {
    /// The orbit, at `sigma = 1` of the step.
    sample: Sample,
    /// Newton updates that corrected it.
    iterations: usize,
    /// `|P(x; p) - x|` there.
    residual: f64,
    /// The direction of the step: the current tangent, or the secant of a corner jump.
    reference: DVector<f64>,
    /// Whether it lies exactly on a parameter bound.
    at_bound: bool,
}

impl<P: PeriodicProblem + ?Sized> Continuation<'_, P> {
    /// Shoot at the parameter bound crossed by the step `A -> B`, from the state interpolated
    /// linearly in `p`. `None` if it does not converge.
    fn point_at_bound(
        &self,
        b: &Sample,
        bound: f64,
    ) -> Result<Option<(Sample, usize, f64)>, ContinuationError> {
        let a = &self.current;
        let n = self.problem.dim();
        let (pa, pb) = (a.parameter(), b.parameter());
        let w = if pb == pa {
            1.0
        } else {
            ((bound - pa) / (pb - pa)).clamp(0.0, 1.0)
        };
        let guess = a.u.rows(0, n) + w * (b.u.rows(0, n) - a.u.rows(0, n));
        let result = shoot(
            self.problem,
            guess.as_slice(),
            bound,
            &self.settings.corrector,
        )?;
        if !result.converged {
            return Ok(None);
        }
        let mut u = DVector::zeros(n + 1);
        u.rows_mut(0, n).copy_from(&result.state);
        u[n] = bound;
        Ok(Some((
            Sample::new(1.0, u, result.period_map, &a.tangent),
            result.iterations,
            result.residual,
        )))
    }

    /// The cubic Hermite extrapolation, `ds` beyond the current point, of the branch through
    /// the previous and the current point with their unit tangents (arclength measured by
    /// the chord). Its error is `O(ds^4)` against `O(ds^2)` for the tangent predictor, which
    /// saves a Newton iteration per point on smooth branches. `None` when there is no previous
    /// point, the extrapolation reaches more than two chords ahead, or it strays further than
    /// `ds / 2` from the tangent predictor.
    fn cubic_predictor(&self, ds: f64) -> Option<DVector<f64>> {
        let (u0, t0) = self.previous.as_ref()?;
        let (u1, t1) = (&self.current.u, &self.current.tangent);
        let h = (u1 - u0).norm();
        if h.is_nan() || h <= 0.0 || ds > 2.0 * h {
            return None;
        }
        let [h00, h10, h01, h11] = hermite_basis(1.0 + ds / h);
        let guess = h00 * u0 + (h10 * h) * t0 + h01 * u1 + (h11 * h) * t1;
        let linear = u1 + ds * t1;
        let finite = guess.iter().all(|v| v.is_finite());
        (finite && (&guess - &linear).norm() <= 0.5 * ds).then_some(guess)
    }

    /// One continuation step: the next accepted point, or an error. Each trial `ds` along the
    /// branch is corrected, checked and, where a check cuts the step, tried again shorter.
    pub(super) fn advance(&mut self) -> Result<BranchPoint, ContinuationError> {
        let mut failures = 0;
        let mut jump_tried = false;
        loop {
            let ds = self.step;
            let t_a = self.current.tangent.clone();
            let Some(trial) = self.corrected_trial(ds, &t_a, &mut failures, &mut jump_tried)?
            else {
                continue;
            };
            let jumped = trial.reference != t_a;
            if !jumped && self.cut_for_turn(&t_a, &trial.sample)? {
                continue;
            }
            let Some(trial) = self.landed_on_bound(trial, ds)? else {
                continue;
            };
            let structure =
                structure_changes(&self.current.map.structure, &trial.sample.map.structure);
            if self.cut_for_structure(&structure, trial.at_bound, jumped) {
                continue;
            }
            return self.accept(trial, &structure, ds, jumped);
        }
    }

    /// The orbit `ds` along the branch from the current point with tangent `t_a`: predicted
    /// (cubic, else along the tangent) and corrected on the pseudo-arclength hyperplane; where
    /// the corrector fails (or wanders further than `ds`), after [`CORNER_FAILURES`] failures
    /// or at the minimum step, once, the orbit past a corner ([`Continuation::corner_jump`]).
    /// `None` when the step was cut and is to be tried again; an error when it cannot be cut
    /// (the branch ends, after locating the structure change it ran into). Next to a hysteretic
    /// grazing whose zero the branch resolves, a correction that fails at the period map's noise
    /// floor is not cut again, and after such a failure, the point that resolves the zero is
    /// the branch's last: no correction is tried from it
    /// ([`Continuation::at_resolved_grazing`]).
    fn corrected_trial(
        &mut self,
        ds: f64,
        t_a: &DVector<f64>,
        failures: &mut usize,
        jump_tried: &mut bool,
    ) -> Result<Option<Trial>, ContinuationError> {
        let predicted = &self.current.u + ds * t_a;
        let (resolved, residual) = match self.grazing_reached {
            Some(residual) => (true, residual),
            None => {
                let guess = self
                    .cubic_predictor(ds)
                    .unwrap_or_else(|| predicted.clone());
                let corrected = correct(
                    self.problem,
                    guess,
                    &predicted,
                    t_a,
                    &self.settings.corrector,
                    Purpose::BranchPoint,
                )?;
                // A corrector that wandered further than the step itself has probably left the
                // branch: treat it as a failure.
                let wandered = (&corrected.u - &predicted).norm() > ds;
                if let (true, Some(map)) = (corrected.converged && !wandered, corrected.map) {
                    return Ok(Some(Trial {
                        sample: Sample::new(1.0, corrected.u, map, t_a),
                        iterations: corrected.iterations,
                        residual: corrected.residual,
                        reference: t_a.clone(),
                        at_bound: false,
                    }));
                }
                *failures += 1;
                let at_noise_floor = !wandered
                    && corrected.smallest_residual
                        <= NOISE_FLOOR * self.settings.corrector.tolerance;
                (self.at_resolved_grazing(at_noise_floor), corrected.residual)
            }
        };
        let stuck = *failures >= CORNER_FAILURES || self.step <= self.settings.min_step || resolved;
        let jump = if stuck && !*jump_tried {
            *jump_tried = true;
            self.corner_jump()?
        } else {
            None
        };
        if let Some(jump) = jump {
            return Ok(Some(Trial {
                sample: jump.sample,
                iterations: jump.iterations,
                residual: jump.residual,
                reference: jump.secant,
                at_bound: false,
            }));
        }
        let cut = !resolved && {
            match self.grazing_fraction(&predicted)? {
                Some(fraction) => self.cut_by(fraction),
                None => self.cut(),
            }
        };
        if cut {
            return Ok(None);
        }
        let terminal = self.terminal_location(resolved)?;
        self.special_points.extend(terminal);
        self.stop = Some(StopReason::StepTooSmall);
        Err(ContinuationError::StepTooSmall {
            parameter: self.current.parameter(),
            step: ds,
            residual,
        })
    }

    /// Whether the step from tangent `t_a` to the trial orbit `b` turns by more than
    /// `max_tangent_angle` and has been cut to be tried again. A turn that cannot be cut is
    /// accepted, unless it is not finite (a singular tangent system), which ends the branch.
    fn cut_for_turn(&mut self, t_a: &DVector<f64>, b: &Sample) -> Result<bool, ContinuationError> {
        let turn = t_a.dot(&b.tangent).clamp(-1.0, 1.0).acos();
        if turn.is_finite() && turn <= self.settings.max_tangent_angle {
            return Ok(false);
        }
        if self.cut() {
            return Ok(true);
        }
        if !turn.is_finite() {
            self.stop = Some(StopReason::Error);
            return Err(ContinuationError::SingularMatrix {
                what: "bordered Jacobian (tangent)",
                parameter: b.parameter(),
            });
        }
        Ok(false)
    }

    /// The trial, or where it crosses a parameter bound, the orbit exactly on the bound
    /// ([`Continuation::point_at_bound`]). `None` when no orbit converged there and the step
    /// was cut to be tried again; an error when it cannot be cut.
    fn landed_on_bound(
        &mut self,
        trial: Trial,
        ds: f64,
    ) -> Result<Option<Trial>, ContinuationError> {
        let pb = trial.sample.parameter();
        let bound = if pb > self.settings.parameter_max {
            self.settings.parameter_max
        } else if pb < self.settings.parameter_min {
            self.settings.parameter_min
        } else {
            return Ok(Some(trial));
        };
        match self.point_at_bound(&trial.sample, bound)? {
            Some((sample, iterations, residual)) => Ok(Some(Trial {
                sample,
                iterations,
                residual,
                at_bound: true,
                ..trial
            })),
            None => {
                if self.cut() {
                    return Ok(None);
                }
                self.stop = Some(StopReason::StepTooSmall);
                Err(ContinuationError::StepTooSmall {
                    parameter: self.current.parameter(),
                    step: ds,
                    residual: f64::INFINITY,
                })
            }
        }
    }

    /// Whether the step holds structure events it should resolve apart, and has been cut to
    /// be tried again: several whose linearly interpolated roots lie more than 5 % of the
    /// step apart, or an impact count change that no extremum explains (for example a
    /// minimum born and through zero within the step), cut down to the minimum step.
    fn cut_for_structure(
        &mut self,
        structure: &[StructureTest],
        at_bound: bool,
        jumped: bool,
    ) -> bool {
        if structure.len() >= 2 && !at_bound {
            let mut roots: Vec<f64> = structure.iter().map(|t| t.linear_root()).collect();
            roots.sort_by(f64::total_cmp);
            let separable = roots.windows(2).any(|w| w[1] - w[0] > 0.05);
            if separable && self.cut() {
                return true;
            }
        }
        let unexplained = structure
            .iter()
            .any(|t| matches!(t, StructureTest::ImpactCount { .. }));
        unexplained && !at_bound && !jumped && self.cut()
    }

    /// Accept the trial as the next branch point: locate the special points of the step from
    /// the current point to it, grow the step after an easy correction (or to the jump's
    /// length past a corner), and make it the current point.
    fn accept(
        &mut self,
        trial: Trial,
        structure: &[StructureTest],
        ds: f64,
        jumped: bool,
    ) -> Result<BranchPoint, ContinuationError> {
        let n = self.problem.dim();
        let Trial {
            sample: b,
            iterations,
            residual,
            reference,
            at_bound,
        } = trial;
        let index = self.produced;
        let mut a = self.current.clone();
        a.sigma = 0.0;
        let segment = Segment::new(
            self.problem,
            a,
            b,
            reference,
            self.settings.corrector.clone(),
            self.settings.location_tolerance,
            jumped,
        );
        let special = self.locate_all(&segment, structure, index, jumped, true)?;
        let b = segment.into_far_end();
        let covered = if jumped {
            (&b.u - &self.current.u).norm()
        } else {
            ds
        };
        if jumped {
            // Past a corner the branch's own scale is the jump.
            self.step = self.step.max(covered.min(self.settings.max_step));
        } else if iterations <= self.settings.easy_iterations {
            self.step = (self.step * self.settings.step_growth).min(self.settings.max_step);
        }
        let point = BranchPoint {
            index,
            state: b.u.rows(0, n).into_owned(),
            parameter: b.parameter(),
            tangent: b.tangent.clone(),
            multipliers: b.multipliers.clone(),
            stable: is_stable(&b.multipliers),
            structure: b.map.structure.clone(),
            iterations,
            residual,
            step: covered,
            special_points: special.clone(),
        };
        self.special_points.extend(special);
        let accepted = std::mem::replace(&mut self.current, b);
        if jumped || !self.settings.hysteretic_grazing {
            self.recent_structures.clear();
            self.bracketed_grazing = None;
            self.noise_floor_met = false;
        } else {
            if self.recent_structures.len() == RECENT_STRUCTURES {
                self.recent_structures.pop_front();
            }
            self.recent_structures
                .push_back((accepted.parameter(), accepted.map.structure));
        }
        self.previous = if jumped {
            None
        } else {
            Some((accepted.u, accepted.tangent))
        };
        self.grazing_reached =
            (self.noise_floor_met && self.grazing_resolved()).then_some(residual);
        self.aim_at_grazing();
        Ok(self.emit(point, at_bound))
    }
}
