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
//!
//! **Hysteretic grazings.** Where the period map jumps at a grazing (a hysteretic contact,
//! [`ContinuationSettings::hysteretic_grazing`]) the branch also ends there, and the step that
//! fails across the grazing is cut to just short of it, extrapolated from the last two points,
//! rather than halved, and the steps after it are aimed the same way
//! (`branch/hysteretic_break.rs`), so that the minimum step is reached in a few steps. Next to
//! such a grazing the period map's own error exceeds Newton's tolerance; once the grazing's zero
//! is extrapolated from the branch to within the location tolerance, a correction that fails
//! at that noise floor, or after one such failure the point that resolves the zero, ends the
//! branch as a failure at the minimum step does.

use std::collections::VecDeque;

use nalgebra::{Complex, DVector};

use crate::corrector::tangent;
use crate::error::ContinuationError;
use crate::floquet::{floquet_multipliers, is_stable};
use crate::location::Sample;
use crate::problem::{OrbitStructure, PeriodicProblem};
use crate::settings::ContinuationSettings;
use crate::shooting::{shoot, NewtonSettings};
use crate::special_point::SpecialPoint;
use crate::test_function::StructureTest;

mod corner;
mod detection;
mod hysteretic_break;
mod step;

/// The most points before the current one whose orbit structures a branch keeps
/// (`Continuation::recent_structures`): enough that the last steps cut towards a hysteretic
/// grazing, which shrink towards it, still leave points a few times further back than the
/// distance the zero is extrapolated over, also where the branch creeps towards the grazing at
/// its smallest step (`biolever-adhesive --a0 8`'s retract at `--max-step` 0.025: about 60
/// points within a factor of 2 of the last one's `sqrt(|g|)`).
const RECENT_STRUCTURES: usize = 256;

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
    /// The parameters and orbit structures of the points before `current` on a branch whose
    /// period map jumps at its grazings, oldest first, at most [`RECENT_STRUCTURES`] (empty at
    /// the start, after a jump over a corner and without `hysteretic_grazing`): the step
    /// towards a hysteretic grazing extrapolates its test function from the last of them and
    /// the current point (`branch/hysteretic_break.rs`), and the zero of a grazing test that
    /// Newton's method does not reach is extrapolated from them (`extrapolated_zero.rs`).
    recent_structures: VecDeque<(f64, OrbitStructure)>,
    /// The test function of the hysteretic grazing the step was last cut towards, at which the
    /// steps after it are aimed (`branch/hysteretic_break.rs`); `None` otherwise.
    grazing_test: Option<StructureTest>,
    /// The test function of the last hysteretic grazing that a failed step's prediction had
    /// crossed (`branch/hysteretic_break.rs`), which the branch is approaching: a correction that
    /// fails at the period map's noise floor ends the branch once that test's zero is
    /// extrapolated to within the location tolerance. `None` at the start and after a jump over
    /// a corner.
    bracketed_grazing: Option<StructureTest>,
    /// Whether a correction has failed at the period map's noise floor since the grazing was
    /// bracketed (`bracketed_grazing`): the branch is as near it as the map resolves.
    noise_floor_met: bool,
    /// Where a point accepted after such a failure resolves the grazing's zero, the residual of
    /// its correction: the branch ends there, with no further correction
    /// (`branch/hysteretic_break.rs`). `None` otherwise.
    grazing_reached: Option<f64>,
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
            recent_structures: VecDeque::new(),
            grazing_test: None,
            bracketed_grazing: None,
            noise_floor_met: false,
            grazing_reached: None,
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

    /// Cut the step by `factor` (in `(0, 1)`), not below the minimum; `false` if it is already
    /// at the minimum.
    fn cut_by(&mut self, factor: f64) -> bool {
        if self.step <= self.settings.min_step {
            return false;
        }
        self.step = (self.step * factor).max(self.settings.min_step);
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
