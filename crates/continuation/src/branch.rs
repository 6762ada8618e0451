//! Pseudo-arclength continuation of a branch of periodic orbits, driven as an iterator of
//! [`BranchPoint`]s, with the detection and location of special points in every step.
//!
//! Each step predicts along the unit tangent, `u_pred = u_A + ds t_A`, and corrects on the
//! hyperplane `t_A . (u - u_pred) = 0` (Keller's pseudo-arclength method), so the branch goes
//! on through folds and its unstable parts are computed too. The step grows after easy steps
//! and is cut when the corrector fails (or lands further than `ds` from the predictor), when
//! the tangent turns by more than `max_tangent_angle`, when two structure events (MODEL.md
//! Sec. 5) fall in one step and can be separated, or when the impact count changes with no
//! extremum crossing zero (cut down to the minimum step, so that such a change is resolved as
//! sharply as possible). Every test function that changes sign between two accepted points is
//! located by root finding along that step (`location.rs`); the branch then carries on from
//! the ordinary point that ends the step, so it crosses every grazing by itself.
//!
//! **Corners.** At the grazing of a *hard* impact (a reset map) the branch has a square-root
//! corner (Nordmark): the impacting orbits move away from the grazing orbit like a power of
//! the parameter distance below one, and the corrector cannot turn there. When the corrector
//! keeps failing (six times, or at the minimum step) at a point where an extremum of the
//! switching function is within `1e-3` of its value past the change, the continuation *jumps*:
//! it shoots at fixed parameters `1e-4 .. 100` initial steps ahead and accepts the first orbit
//! with the changed structure; the grazing is then located in the natural parameter. If no
//! orbit exists past the corner (no period-one impacting orbit near grazing) the branch ends
//! there with [`StopReason::StepTooSmall`], after locating the grazing it ran into between the
//! last orbit and the first parameter without one.

use nalgebra::{Complex, DVector};

use crate::corrector::{correct, tangent};
use crate::error::ContinuationError;
use crate::floquet::{floquet_multipliers, is_stable};
use crate::hermite::hermite_basis;
use crate::location::{Location, Sample, Segment};
use crate::problem::{OrbitStructure, PeriodicProblem};
use crate::settings::ContinuationSettings;
use crate::shooting::{shoot, NewtonSettings};
use crate::special_point::{SpecialPoint, SpecialPointKind};
use crate::test_function::{
    has_complex_pair_on_unit_circle, neimark_sacker_test, period_doubling_test, structure_changes,
    ExtremumKind, StructureTest,
};

/// One accepted point of a branch of periodic orbits.
#[derive(Debug, Clone, PartialEq)]
pub struct BranchPoint {
    /// Position on the branch: 0 for the start, then 1, 2, ...
    pub index: usize,
    /// The fixed point `x` of the period map (state units).
    pub state: DVector<f64>,
    /// The parameter `p` (parameter units).
    pub parameter: f64,
    /// Unit tangent `(dx/ds, dp/ds)` (length `n + 1`) in the direction of continuation.
    pub tangent: DVector<f64>,
    /// Floquet multipliers (eigenvalues of the monodromy), by decreasing modulus.
    pub multipliers: Vec<Complex<f64>>,
    /// Whether every multiplier lies strictly inside the unit circle.
    pub stable: bool,
    /// Extrema and impacts of the contact switching function over the period.
    pub structure: OrbitStructure,
    /// Newton updates of the corrector (of the shooting, for the start).
    pub iterations: usize,
    /// `|P(x; p) - x|_2` (state units).
    pub residual: f64,
    /// Arclength step that reached this point (0 for the start; for a point reached by a
    /// jump over a corner, the distance jumped in `(x, p)`).
    pub step: f64,
    /// Special points located in the step that ended at this point, in branch order.
    pub special_points: Vec<SpecialPoint>,
}

/// Why a branch ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum StopReason {
    /// `max_points` branch points were produced.
    MaxPoints,
    /// The parameter reached `parameter_min` or `parameter_max` (the last point lies on it).
    ParameterBound,
    /// The user's stop predicate returned `true` on the last point.
    UserStop,
    /// The corrector failed at the minimum step (for example at a non-smooth point it cannot
    /// cross); see [`ContinuationError::StepTooSmall`].
    StepTooSmall,
    /// Another error ended the branch.
    Error,
}

/// A computed branch: its points, its special points and why it ended.
#[derive(Debug, Clone, PartialEq)]
pub struct Branch {
    /// The accepted points, the start first.
    pub points: Vec<BranchPoint>,
    /// Every located special point, in branch order.
    pub special_points: Vec<SpecialPoint>,
    /// Why the branch ended.
    pub stop: StopReason,
    /// The error that ended it, for [`StopReason::StepTooSmall`] and [`StopReason::Error`].
    pub error: Option<ContinuationError>,
}

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
struct Jump {
    sample: Sample,
    iterations: usize,
    residual: f64,
    /// Unit secant from the current point to the new one.
    secant: DVector<f64>,
}

/// Consecutive corrector failures at one point after which a corner jump is tried.
const CORNER_FAILURES: usize = 6;

/// A test function of a corrected orbit on a step.
type SampleTest = fn(&Sample) -> f64;

/// A user predicate that ends the branch after the point it returns `true` on.
type StopPredicate<'a> = Box<dyn FnMut(&BranchPoint) -> bool + 'a>;

/// Pseudo-arclength continuation of the fixed points of `P(x; p)`: an iterator of
/// `Result<BranchPoint, ContinuationError>` that yields the start, then one accepted point per
/// step, and ends after an error (yielded once) or a stop.
pub struct Continuation<'a, P: PeriodicProblem + ?Sized> {
    problem: &'a P,
    settings: ContinuationSettings,
    stop_predicate: Option<StopPredicate<'a>>,
    current: Sample,
    /// The point before `current` and its tangent, for the cubic predictor (`None` at the
    /// start and after a jump over a corner).
    previous: Option<(DVector<f64>, DVector<f64>)>,
    start: Option<BranchPoint>,
    step: f64,
    produced: usize,
    special_points: Vec<SpecialPoint>,
    stop: Option<StopReason>,
}

impl<'a, P: PeriodicProblem + ?Sized> Continuation<'a, P> {
    /// Start a branch at the periodic orbit near `x0` at parameter `p0`: shoot there (with
    /// four times the corrector's iterations), compute the tangent oriented in
    /// `settings.direction`, and prepare the iteration.
    ///
    /// # Errors
    /// Invalid settings, a wrong `x0`, a failed period map, a start that does not converge
    /// ([`ContinuationError::StartNotConverged`]), or a singular tangent system (a start on a
    /// fold or branch point).
    pub fn new(
        problem: &'a P,
        x0: &[f64],
        p0: f64,
        settings: ContinuationSettings,
    ) -> Result<Self, ContinuationError> {
        settings.validate()?;
        let shooting = NewtonSettings {
            max_iterations: settings.corrector.max_iterations * 4,
            ..settings.corrector.clone()
        };
        let start = shoot(problem, x0, p0, &shooting)?;
        if !start.converged {
            return Err(ContinuationError::StartNotConverged {
                parameter: p0,
                iterations: start.iterations,
                residual: start.residual,
            });
        }
        let n = problem.dim();
        let mut u = DVector::zeros(n + 1);
        u.rows_mut(0, n).copy_from(&start.state);
        u[n] = p0;
        let mut reference = DVector::zeros(n + 1);
        reference[n] = settings.direction.sign();
        let t = tangent(&start.period_map, &reference, p0)?;
        let multipliers = floquet_multipliers(&start.period_map.monodromy);
        let first = BranchPoint {
            index: 0,
            state: start.state.clone(),
            parameter: p0,
            tangent: t.clone(),
            stable: is_stable(&multipliers),
            multipliers: multipliers.clone(),
            structure: start.period_map.structure.clone(),
            iterations: start.iterations,
            residual: start.residual,
            step: 0.0,
            special_points: Vec::new(),
        };
        let current = Sample {
            sigma: 0.0,
            u,
            map: start.period_map,
            tangent: t,
            multipliers,
        };
        Ok(Self {
            problem,
            step: settings.initial_step,
            settings,
            stop_predicate: None,
            current,
            previous: None,
            start: Some(first),
            produced: 0,
            special_points: Vec::new(),
            stop: None,
        })
    }

    /// End the branch after the first point on which `predicate` returns `true`. The
    /// predicate is called once on every point produced, the start and the last included
    /// (so it may also collect per-point data).
    pub fn stop_when(mut self, predicate: impl FnMut(&BranchPoint) -> bool + 'a) -> Self {
        self.stop_predicate = Some(Box::new(predicate));
        self
    }

    /// Every special point located so far, in branch order.
    pub fn special_points(&self) -> &[SpecialPoint] {
        &self.special_points
    }

    /// Why the branch ended (`None` while it goes on).
    pub fn stop_reason(&self) -> Option<StopReason> {
        self.stop
    }

    /// The arclength step the next continuation step will try.
    pub fn current_step(&self) -> f64 {
        self.step
    }

    /// Run the branch to its end and collect it. An error after the start ends the branch
    /// and is kept in [`Branch::error`] with the points computed before it.
    pub fn run(mut self) -> Branch {
        let mut points = Vec::new();
        let mut error = None;
        for item in self.by_ref() {
            match item {
                Ok(point) => points.push(point),
                Err(e) => error = Some(e),
            }
        }
        Branch {
            points,
            special_points: self.special_points,
            stop: self.stop.unwrap_or(StopReason::Error),
            error,
        }
    }

    /// Cut the step; `false` if it is already at the minimum.
    fn cut(&mut self) -> bool {
        if self.step <= self.settings.min_step {
            return false;
        }
        self.step = (self.step * self.settings.step_cut).max(self.settings.min_step);
        true
    }

    /// Count a produced point and apply the stop rules to it (the user's predicate sees
    /// every point, the start and the last included).
    fn emit(&mut self, point: BranchPoint, at_bound: bool) -> BranchPoint {
        self.produced += 1;
        let user = self
            .stop_predicate
            .as_mut()
            .is_some_and(|predicate| predicate(&point));
        if at_bound {
            self.stop = Some(StopReason::ParameterBound);
        } else if user {
            self.stop = Some(StopReason::UserStop);
        } else if self.produced >= self.settings.max_points {
            self.stop = Some(StopReason::MaxPoints);
        }
        point
    }

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

    /// Jump over a corner of the branch at a structure change (the square-root singularity
    /// of a hard impact at grazing, where the branch turns too sharply for the corrector):
    /// shoot at fixed parameters `p_A + dp` beyond the current point, `dp` growing from
    /// `1e-4` to `100` times the initial step, from the state extrapolated along the tangent.
    /// The first converged orbit whose structure differs from the current one is returned,
    /// with its tangent oriented along the secant (also returned).
    fn corner_jump(&self) -> Result<Option<Jump>, ContinuationError> {
        let a = &self.current;
        let n = self.problem.dim();
        let tp = a.tangent[n];
        let direction = if tp < 0.0 { -1.0 } else { 1.0 };
        let shooting = NewtonSettings {
            max_iterations: self.settings.corrector.max_iterations * 4,
            ..self.settings.corrector.clone()
        };
        for j in 0..=6 {
            let dp = (self.settings.initial_step * 10f64.powi(j - 4)).min(self.settings.max_step);
            let p = a.parameter() + direction * dp;
            if p > self.settings.parameter_max || p < self.settings.parameter_min {
                break;
            }
            let slope = if tp.abs() > 1e-12 { 1.0 / tp } else { 0.0 };
            let guess = a.u.rows(0, n) + (direction * dp * slope) * a.tangent.rows(0, n);
            let result = match shoot(self.problem, guess.as_slice(), p, &shooting) {
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
    /// that parameter, trials with no orbit counting as the far side. `impacts_after` is the
    /// impact count of that extrapolated trajectory (no orbit exists there).
    fn terminal_location(&self) -> Result<Vec<SpecialPoint>, ContinuationError> {
        let a = &self.current;
        let n = self.problem.dim();
        let tp = a.tangent[n];
        if !(tp.abs() > 1e-12 && tp.is_finite()) {
            return Ok(Vec::new());
        }
        let direction = tp.signum();
        for j in 0..=6 {
            let dp = (self.settings.initial_step * 10f64.powi(j - 4)).min(self.settings.max_step);
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
                true,
            );
            let index = self.produced.saturating_sub(1);
            return self.locate_all(&segment, &structure, index, true, false);
        }
        Ok(Vec::new())
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

    /// One continuation step: the next accepted point, or an error.
    fn advance(&mut self) -> Result<BranchPoint, ContinuationError> {
        let n = self.problem.dim();
        let mut failures = 0;
        let mut jump_tried = false;
        loop {
            let ds = self.step;
            let t_a = self.current.tangent.clone();
            let predicted = &self.current.u + ds * &t_a;
            let guess = self
                .cubic_predictor(ds)
                .unwrap_or_else(|| predicted.clone());
            let corrected = correct(
                self.problem,
                guess,
                &predicted,
                &t_a,
                &self.settings.corrector,
            )?;
            let mut reference = t_a.clone();
            // A corrector that wandered further than the step itself has probably left the
            // branch: treat it as a failure.
            let wandered = (&corrected.u - &predicted).norm() > ds;
            let (mut b, mut iterations, mut residual) =
                match (corrected.converged && !wandered, corrected.map) {
                    (true, Some(map)) => (
                        Sample::new(1.0, corrected.u, map, &t_a),
                        corrected.iterations,
                        corrected.residual,
                    ),
                    _ => {
                        failures += 1;
                        let stuck =
                            failures >= CORNER_FAILURES || self.step <= self.settings.min_step;
                        let jump = if stuck && !jump_tried {
                            jump_tried = true;
                            self.corner_jump()?
                        } else {
                            None
                        };
                        match jump {
                            Some(jump) => {
                                reference = jump.secant;
                                (jump.sample, jump.iterations, jump.residual)
                            }
                            None => {
                                if self.cut() {
                                    continue;
                                }
                                let terminal = self.terminal_location()?;
                                self.special_points.extend(terminal);
                                self.stop = Some(StopReason::StepTooSmall);
                                return Err(ContinuationError::StepTooSmall {
                                    parameter: self.current.parameter(),
                                    step: ds,
                                    residual: corrected.residual,
                                });
                            }
                        }
                    }
                };
            let jumped = reference != t_a;
            let turn = t_a.dot(&b.tangent).clamp(-1.0, 1.0).acos();
            if !jumped && (!turn.is_finite() || turn > self.settings.max_tangent_angle) {
                if self.cut() {
                    continue;
                }
                if !turn.is_finite() {
                    self.stop = Some(StopReason::Error);
                    return Err(ContinuationError::SingularMatrix {
                        what: "bordered Jacobian (tangent)",
                        parameter: b.parameter(),
                    });
                }
            }
            // Parameter bounds: end exactly on the bound.
            let mut at_bound = false;
            let pb = b.parameter();
            let bound = if pb > self.settings.parameter_max {
                Some(self.settings.parameter_max)
            } else if pb < self.settings.parameter_min {
                Some(self.settings.parameter_min)
            } else {
                None
            };
            if let Some(bound) = bound {
                match self.point_at_bound(&b, bound)? {
                    Some((sample, its, res)) => {
                        b = sample;
                        iterations = its;
                        residual = res;
                        at_bound = true;
                    }
                    None => {
                        if self.cut() {
                            continue;
                        }
                        self.stop = Some(StopReason::StepTooSmall);
                        return Err(ContinuationError::StepTooSmall {
                            parameter: self.current.parameter(),
                            step: ds,
                            residual: f64::INFINITY,
                        });
                    }
                }
            }
            // Several separable structure events in one step: cut it.
            let structure = structure_changes(&self.current.map.structure, &b.map.structure);
            if structure.len() >= 2 && !at_bound {
                let mut roots: Vec<f64> = structure.iter().map(|t| t.linear_root()).collect();
                roots.sort_by(f64::total_cmp);
                let separable = roots.windows(2).any(|w| w[1] - w[0] > 0.05);
                if separable && self.cut() {
                    continue;
                }
            }
            // An impact count change that no extremum explains (for example a minimum born
            // and through zero within the step): cut the step to resolve it.
            let unexplained = structure
                .iter()
                .any(|t| matches!(t, StructureTest::ImpactCount { .. }));
            if unexplained && !at_bound && !jumped && self.cut() {
                continue;
            }
            let index = self.produced;
            let mut a = self.current.clone();
            a.sigma = 0.0;
            let segment = Segment::new(
                self.problem,
                a,
                b.clone(),
                reference,
                self.settings.corrector.clone(),
                jumped,
            );
            let special = self.locate_all(&segment, &structure, index, jumped, true)?;
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
            self.previous = if jumped {
                None
            } else {
                Some((accepted.u, accepted.tangent))
            };
            return Ok(self.emit(point, at_bound));
        }
    }

    /// Locate every sign change of a test function in the step held by `segment`.
    fn locate_all(
        &self,
        segment: &Segment<'_, P>,
        structure: &[StructureTest],
        index: usize,
        jumped: bool,
        smooth_tests: bool,
    ) -> Result<Vec<SpecialPoint>, ContinuationError> {
        let tolerance = self.settings.location_tolerance;
        let max_iterations = self.settings.location_max_iterations;
        let mut found: Vec<(f64, SpecialPoint)> = Vec::new();
        let mut breaks: Vec<(usize, usize)> = Vec::new();
        for test in structure {
            let value = |s: &Sample| test.value(s.sigma, &s.map.structure);
            // Across a corner, a failed trial lies past the structure change (B side).
            let failure = if jumped {
                value(&segment.get(1))
            } else {
                f64::NAN
            };
            let location = segment.locate(0, 1, &value, failure, tolerance, max_iterations)?;
            let kind = match *test {
                StructureTest::Extremum {
                    kind: ExtremumKind::Minimum,
                    ..
                } => SpecialPointKind::Grazing,
                StructureTest::Extremum {
                    kind: ExtremumKind::Maximum,
                    value_a,
                    ..
                } => {
                    if value_a >= 0.0 {
                        SpecialPointKind::Merge
                    } else {
                        SpecialPointKind::Split
                    }
                }
                StructureTest::ImpactCount { n_a, n_b } => {
                    if n_b < n_a {
                        SpecialPointKind::ImpactVanish
                    } else {
                        SpecialPointKind::ImpactAppear
                    }
                }
            };
            breaks.push((location.low.unwrap_or(0), location.high.unwrap_or(1)));
            found.push(self.special_point(segment, kind, &location, location.converged, index));
        }
        // Smooth (tangent and multiplier) tests, located between the structure brackets.
        let mut smooth: Vec<(SpecialPointKind, SampleTest)> = Vec::new();
        if smooth_tests {
            smooth.push((SpecialPointKind::Fold, |s: &Sample| {
                s.tangent[s.tangent.len() - 1]
            }));
        }
        if smooth_tests && self.settings.detect_bifurcations {
            smooth.push((SpecialPointKind::PeriodDoubling, |s: &Sample| {
                period_doubling_test(&s.multipliers)
            }));
            smooth.push((SpecialPointKind::NeimarkSacker, |s: &Sample| {
                neimark_sacker_test(&s.multipliers)
            }));
        }
        let sign = |g: f64| g < 0.0;
        let a0 = segment.get(0);
        let b1 = segment.get(1);
        for (kind, test) in smooth {
            let (ga, gb) = (test(&a0), test(&b1));
            if !(ga.is_finite() && gb.is_finite()) || sign(ga) == sign(gb) {
                continue;
            }
            // Intervals between the structure brackets, in sigma order.
            let mut cuts: Vec<(f64, usize, usize)> = breaks
                .iter()
                .map(|&(l, h)| (segment.get(l).sigma, l, h))
                .collect();
            cuts.sort_by(|x, y| x.0.total_cmp(&y.0));
            let mut intervals = Vec::new();
            let mut lo = 0;
            for &(_, l, h) in &cuts {
                intervals.push((lo, l));
                lo = h;
            }
            intervals.push((lo, 1));
            let continuous = intervals.iter().copied().find(|&(l, h)| {
                let (gl, gh) = (test(&segment.get(l)), test(&segment.get(h)));
                gl.is_finite() && gh.is_finite() && sign(gl) != sign(gh)
            });
            let (kind, location) = match continuous {
                Some((l, h)) => {
                    let location =
                        segment.locate(l, h, &test, f64::NAN, tolerance, max_iterations)?;
                    (kind, location)
                }
                None => {
                    // The sign change happens across a structure change (a jump).
                    let Some(&(_, l, h)) = cuts.iter().find(|&&(_, l, h)| {
                        sign(test(&segment.get(l))) != sign(test(&segment.get(h)))
                    }) else {
                        continue;
                    };
                    let location = Location {
                        point: Some(segment.get(l)),
                        low: Some(l),
                        high: Some(h),
                        parameters: (segment.get(l).parameter(), segment.get(h).parameter()),
                        converged: false,
                        iterations: 0,
                    };
                    (kind, location)
                }
            };
            // The Neimark-Sacker test also vanishes where two real multipliers have product 1
            // (a neutral saddle): no bifurcation of the branch, so not a special point.
            if kind == SpecialPointKind::NeimarkSacker
                && !location
                    .point
                    .as_ref()
                    .is_some_and(|s| has_complex_pair_on_unit_circle(&s.multipliers))
            {
                continue;
            }
            let converged = location.converged && continuous.is_some();
            found.push(self.special_point(segment, kind, &location, converged, index));
        }
        found.sort_by(|x, y| x.0.total_cmp(&y.0));
        Ok(found.into_iter().map(|(_, s)| s).collect())
    }

    /// Assemble a special point from a location.
    fn special_point(
        &self,
        segment: &Segment<'_, P>,
        kind: SpecialPointKind,
        location: &Location,
        converged: bool,
        index: usize,
    ) -> (f64, SpecialPoint) {
        let low = segment.get(location.low.unwrap_or(0));
        let high = segment.get(location.high.unwrap_or(1));
        let (pl, ph) = location.parameters;
        let point = location.point.clone().unwrap_or_else(|| low.clone());
        let n = point.u.len() - 1;
        // A merge into, or a split out of, contact throughout the period has its own name.
        let kind = match kind {
            SpecialPointKind::Merge if high.map.structure.permanent_contact => {
                SpecialPointKind::PermanentContact
            }
            SpecialPointKind::Split if low.map.structure.permanent_contact => {
                SpecialPointKind::LiftOff
            }
            kind => kind,
        };
        let (mut impacts_before, mut impacts_after) =
            (low.map.structure.impacts, high.map.structure.impacts);
        // A location converged onto the structure change itself can leave both bracket ends on
        // one side of it (the extremum a rounding error from zero at both); the counts are then
        // read at the ends of the step, regular points on either side.
        if impacts_before == impacts_after
            && matches!(
                kind,
                SpecialPointKind::Grazing
                    | SpecialPointKind::Merge
                    | SpecialPointKind::Split
                    | SpecialPointKind::PermanentContact
                    | SpecialPointKind::LiftOff
            )
        {
            impacts_before = segment.get(0).map.structure.impacts;
            impacts_after = segment.get(1).map.structure.impacts;
        }
        (
            point.sigma,
            SpecialPoint {
                label: kind.label(impacts_after),
                kind,
                parameter: point.parameter(),
                bracket: (pl.min(ph), pl.max(ph)),
                precision: (pl - ph).abs(),
                converged,
                impacts_before,
                impacts_after,
                state: point.u.rows(0, n).into_owned(),
                multipliers: point.multipliers.clone(),
                iterations: location.iterations,
                branch_index: index,
            },
        )
    }
}

impl<P: PeriodicProblem + ?Sized> Iterator for Continuation<'_, P> {
    type Item = Result<BranchPoint, ContinuationError>;

    fn next(&mut self) -> Option<Self::Item> {
        if let Some(start) = self.start.take() {
            return Some(Ok(self.emit(start, false)));
        }
        if self.stop.is_some() {
            return None;
        }
        match self.advance() {
            Ok(point) => Some(Ok(point)),
            Err(e) => {
                if self.stop.is_none() {
                    self.stop = Some(StopReason::Error);
                }
                Some(Err(e))
            }
        }
    }
}
