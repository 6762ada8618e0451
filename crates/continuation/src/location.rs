//! Location of a sign change of a test function along one continuation step.
//!
//! The step from branch point `A` to branch point `B` is parametrised by the fraction
//! `sigma` in `[0, 1]` of the secant `u_A -> u_B`; the orbit at `sigma` is the branch point on
//! the hyperplane `tau . (u - u_A - sigma (u_B - u_A)) = 0` (`tau` the unit secant), found by
//! the pseudo-arclength corrector. A test function of that orbit is root-found in `sigma` with
//! the Illinois method of the `roots` crate until the *parameter* bracket is below the
//! location tolerance.
//!
//! A step that jumped over a corner of the branch (a hard-impact grazing, see
//! [`crate::Continuation`]) is located in the *natural* parameter instead: `p` runs linearly
//! from `p_A` to `p_B` and each trial orbit is shot at fixed `p` from the state extrapolated
//! along the tangent at `A` (then at `B`). There a trial that converges on neither side is
//! counted as lying on the far (`B`) side of a structure change: near the grazing of a hard
//! impact the orbit past it is too singular for Newton's method, while the orbit before it is
//! smooth and its extrapolated guess is excellent. The far side's values there are not the test
//! function's own (a failed trial, or past a jump of the period map), so the root is found by
//! regula falsi with the Anderson-Bjorck modification, which follows the near side's secant,
//! rather than the Illinois method.

use std::cell::{Cell, Ref, RefCell};

use nalgebra::{Complex, DVector};
use roots::{find_root_regula_falsi, Convergency, SearchError};

use crate::corrector::{correct, tangent, undone_update, Purpose};
use crate::error::ContinuationError;
use crate::floquet::floquet_multipliers;
use crate::problem::{PeriodMap, PeriodicProblem};
use crate::shooting::{shoot_checked, NewtonSettings, NEWTON_STALL};

/// A located point's parameter is polished to this fraction of the location tolerance
/// ([`Segment::polished`]).
const POLISH_FRACTION: f64 = 0.1;

/// Newton steps at most that polish a location's trial ([`Segment::polished`]).
const POLISH_STEPS: usize = 2;

/// A corrected orbit on the segment, with what the test functions need.
#[derive(Debug, Clone)]
pub(crate) struct Sample {
    /// Fraction of the segment.
    pub sigma: f64,
    /// `(x, p)`.
    pub u: DVector<f64>,
    /// The period map at `u`.
    pub map: PeriodMap,
    /// Unit tangent (NaN entries if singular), oriented along the step's direction; in natural
    /// mode like the tangent of the end the trial was shot from, so that the orientation is
    /// continued along each side of a corner and never taken from the corner's secant.
    pub tangent: DVector<f64>,
    /// Floquet multipliers at `u`.
    pub multipliers: Vec<Complex<f64>>,
}

impl Sample {
    /// Build a sample from a corrected point, computing its tangent (oriented along
    /// `reference`) and multipliers.
    pub(crate) fn new(
        sigma: f64,
        u: DVector<f64>,
        map: PeriodMap,
        reference: &DVector<f64>,
    ) -> Self {
        let n = map.image.len();
        let tangent = tangent(&map, reference, u[n])
            .unwrap_or_else(|_| DVector::from_element(n + 1, f64::NAN));
        let multipliers = floquet_multipliers(&map.monodromy);
        Self {
            sigma,
            u,
            map,
            tangent,
            multipliers,
        }
    }

    /// The parameter `p` of the sample.
    pub(crate) fn parameter(&self) -> f64 {
        self.u[self.u.len() - 1]
    }
}

/// A corrected trial orbit `(x, p)`, its period map, and the direction its tangent is oriented
/// along.
type OrientedTrial = (DVector<f64>, PeriodMap, DVector<f64>);

/// The result of locating one sign change.
#[derive(Debug, Clone)]
pub(crate) struct Location {
    /// The sample at the located point (`None` if its correction failed).
    pub point: Option<Sample>,
    /// Index (into the segment's samples) of the bracket end nearer `sigma = 0`; `None` if
    /// that end is a failed trial (natural mode), which stands for the far side.
    pub low: Option<usize>,
    /// Index of the bracket end nearer `sigma = 1` (`None`: a failed trial).
    pub high: Option<usize>,
    /// Parameters at the bracket ends (low, high).
    pub parameters: (f64, f64),
    /// Whether the parameter bracket reached the tolerance with values of opposite signs (or
    /// an exact zero).
    pub converged: bool,
    /// New trial points spent.
    pub iterations: usize,
}

/// One continuation step `A -> B` with a cache of corrected orbits on it.
pub(crate) struct Segment<'a, P: PeriodicProblem + ?Sized> {
    problem: &'a P,
    u_a: DVector<f64>,
    delta: DVector<f64>,
    tau: DVector<f64>,
    reference: DVector<f64>,
    settings: NewtonSettings,
    /// The located points' tolerance in the parameter: a pseudo-arclength trial is polished
    /// until Newton's undone step moves its parameter by less than a tenth of it
    /// ([`Segment::polished`]).
    location_tolerance: f64,
    natural: bool,
    /// Whether the far end (`sigma = 1`) is an orbit, whose tangent a shot in natural mode can
    /// start from (not where it is the trajectory past the end of a branch).
    far_is_orbit: bool,
    /// Whether a new trial is taken as failed without a correction
    /// ([`Segment::with_failing_trials`]).
    trials_fail: bool,
    samples: RefCell<Vec<Sample>>,
    trials: Cell<usize>,
}

/// Stop rule for the Illinois iteration: parameter bracket below the tolerance.
struct ParameterBracket<'s, 'a, P: PeriodicProblem + ?Sized> {
    segment: &'s Segment<'a, P>,
    tolerance: f64,
    max_iterations: usize,
    bracket: &'s Cell<(f64, f64)>,
}

impl<P: PeriodicProblem + ?Sized> Convergency<f64> for ParameterBracket<'_, '_, P> {
    fn is_root_found(&mut self, y: f64) -> bool {
        y == 0.0
    }

    fn is_converged(&mut self, x1: f64, x2: f64) -> bool {
        self.bracket.set((x1.min(x2), x1.max(x2)));
        let p1 = self.segment.parameter_at(x1);
        let p2 = self.segment.parameter_at(x2);
        (p1 - p2).abs() <= self.tolerance || (x1 - x2).abs() <= 4.0 * f64::EPSILON
    }

    fn is_iteration_limit_reached(&mut self, iter: usize) -> bool {
        iter >= self.max_iterations
    }
}

/// Regula falsi with the Anderson-Bjorck modification (Anderson and Bjorck, BIT 12, 1973):
/// where the new point falls on the same side as the last one, the value kept at the other end
/// is scaled by `m = 1 - y / y_side` (`y_side` the value the new point replaces; 0.5, as in the
/// Illinois method, where `m <= 0`), stopping by `convergency` as `roots`' regula falsi does.
/// Where one end's value is not the test function's own (in natural mode, a failed trial or
/// the far trajectory standing for the far side), the Illinois halving takes a step per
/// doubling of the distance covered from the near end; the scaling by `m` takes the secant of
/// the near side's values instead.
fn anderson_bjorck(
    a: f64,
    b: f64,
    mut f: impl FnMut(f64) -> f64,
    convergency: &mut dyn Convergency<f64>,
) -> Result<f64, SearchError> {
    let (mut x1, mut x2) = if a > b { (b, a) } else { (a, b) };
    let mut y1 = f(x1);
    if convergency.is_root_found(y1) {
        return Ok(x1);
    }
    let mut y2 = f(x2);
    if convergency.is_root_found(y2) {
        return Ok(x2);
    }
    if y1 * y2 > 0.0 {
        return Err(SearchError::NoBracketing);
    }
    let scale = |y: f64, side: f64| {
        let m = 1.0 - y / side;
        if m > 0.0 {
            m
        } else {
            0.5
        }
    };
    let mut iterations = 0;
    loop {
        let x = (x1 * y2 - x2 * y1) / (y2 - y1);
        if convergency.is_converged(x1, x2) {
            return Ok(x);
        }
        let y = f(x);
        if convergency.is_root_found(y) {
            return Ok(x);
        }
        if y * y1 > 0.0 {
            y2 *= scale(y, y1);
            (x1, y1) = (x, y);
        } else if y * y2 > 0.0 {
            y1 *= scale(y, y2);
            (x2, y2) = (x, y);
        } else {
            return Ok(x);
        }
        iterations += 1;
        if convergency.is_iteration_limit_reached(iterations) {
            return Err(SearchError::NoConvergency);
        }
    }
}

impl<'a, P: PeriodicProblem + ?Sized> Segment<'a, P> {
    /// The segment between samples `a` (`sigma = 0`) and `b` (`sigma = 1`); trial points are
    /// corrected with `settings` and their tangents oriented along `reference`. With
    /// `natural`, trials are shot at fixed parameters (see the module documentation).
    pub(crate) fn new(
        problem: &'a P,
        a: Sample,
        b: Sample,
        reference: DVector<f64>,
        settings: NewtonSettings,
        location_tolerance: f64,
        natural: bool,
    ) -> Self {
        let delta = &b.u - &a.u;
        let length = delta.norm();
        let tau = if length > 0.0 {
            &delta / length
        } else {
            reference.clone()
        };
        Self {
            problem,
            u_a: a.u.clone(),
            delta,
            tau,
            reference,
            settings,
            location_tolerance,
            natural,
            far_is_orbit: true,
            trials_fail: false,
            samples: RefCell::new(vec![a, b]),
            trials: Cell::new(0),
        }
    }

    /// The segment with a far end (`b`) that is a trajectory, not an orbit (the state
    /// extrapolated past the end of a branch): natural-mode trials shoot from the near end's
    /// tangent only.
    pub(crate) fn with_far_trajectory(mut self) -> Self {
        self.far_is_orbit = false;
        self
    }

    /// The segment whose new trials all count as failed, with no correction made: at the end of
    /// a branch next to a hysteretic grazing whose zero the branch's own points resolve, where
    /// trials between it and the grazing meet the period map's noise floor, and the grazing's
    /// zero is extrapolated from the branch (`extrapolated_zero.rs`). In natural mode a failed
    /// trial stands for the far side, so a location ends at the near end.
    pub(crate) fn with_failing_trials(mut self) -> Self {
        self.trials_fail = true;
        self
    }

    /// Whether cached sample `index` lies on the far side of the segment's jump: its state
    /// nearer (Euclidean norm) to the far end's state than to the near end's. Across the jump of
    /// a hysteretic grazing the two ends are orbits of different families, far apart in state
    /// while their parameters differ little, and a trial shot at a parameter between them can
    /// converge onto either family; this says which.
    fn nearer_far_end(&self, index: usize) -> bool {
        let n = self.u_a.len() - 1;
        let samples = self.samples.borrow();
        let x = samples[index].u.rows(0, n);
        let from_near = (x - self.u_a.rows(0, n)).norm();
        let from_far = (x - self.u_a.rows(0, n) - self.delta.rows(0, n)).norm();
        from_far < from_near
    }

    /// Whether cached samples `a` and `b` lie on different sides of the segment's jump, one
    /// nearer its near end, the other nearer its far end ([`Segment::nearer_far_end`]).
    pub(crate) fn across_jump(&self, a: usize, b: usize) -> bool {
        self.nearer_far_end(a) != self.nearer_far_end(b)
    }

    /// Parameter at `sigma`: linear in natural mode, else that of the cached sample at
    /// exactly `sigma` (NaN if none).
    fn parameter_at(&self, sigma: f64) -> f64 {
        let n = self.u_a.len() - 1;
        if self.natural {
            return self.u_a[n] + sigma * self.delta[n];
        }
        self.samples
            .borrow()
            .iter()
            .find(|s| s.sigma == sigma)
            .map_or(f64::NAN, Sample::parameter)
    }

    /// `(index, p, test)` of every cached orbit on the segment (`0 <= sigma <= 1`).
    pub(crate) fn values(&self, test: &dyn Fn(&Sample) -> f64) -> Vec<(usize, f64, f64)> {
        self.samples
            .borrow()
            .iter()
            .enumerate()
            .filter(|(_, s)| (0.0..=1.0).contains(&s.sigma))
            .map(|(i, s)| (i, s.parameter(), test(s)))
            .collect()
    }

    /// A clone of sample `index`.
    pub(crate) fn get(&self, index: usize) -> Sample {
        self.samples.borrow()[index].clone()
    }

    /// Sample `index`, borrowed: read in place instead of cloned (its period map, tangent and
    /// multipliers are eight heap vectors). The borrow must end before the segment corrects a
    /// new orbit ([`Segment::sample`] adds it to the cache).
    pub(crate) fn sample_ref(&self, index: usize) -> Ref<'_, Sample> {
        Ref::map(self.samples.borrow(), |samples| &samples[index])
    }

    /// The segment's far end `b` (`sigma = 1`, the sample it was built with), taken out of it.
    pub(crate) fn into_far_end(self) -> Sample {
        self.samples.into_inner().swap_remove(1)
    }

    /// Index of the cached sample at exactly `sigma`.
    fn index_of(&self, sigma: f64) -> Option<usize> {
        self.samples.borrow().iter().position(|s| s.sigma == sigma)
    }

    /// Index of the sample at `sigma`, correcting a new orbit if it is not cached
    /// (`Ok(None)` if the correction fails there).
    pub(crate) fn sample(&self, sigma: f64) -> Result<Option<usize>, ContinuationError> {
        if let Some(i) = self.index_of(sigma) {
            return Ok(Some(i));
        }
        if self.trials_fail {
            return Ok(None);
        }
        self.trials.set(self.trials.get() + 1);
        let found = if self.natural {
            self.shoot_at(sigma)?
        } else {
            self.correct_at(sigma)?
                .map(|(u, map)| (u, map, self.reference.clone()))
        };
        Ok(found.map(|(u, map, reference)| {
            let sample = Sample::new(sigma, u, map, &reference);
            let mut samples = self.samples.borrow_mut();
            samples.push(sample);
            samples.len() - 1
        }))
    }

    /// Pseudo-arclength correction on the hyperplane through the secant point at `sigma`.
    fn correct_at(
        &self,
        sigma: f64,
    ) -> Result<Option<(DVector<f64>, PeriodMap)>, ContinuationError> {
        let (guess, anchor) = {
            let samples = self.samples.borrow();
            // Interpolate between the nearest cached samples on either side.
            let below = samples
                .iter()
                .filter(|s| s.sigma < sigma)
                .max_by(|x, y| x.sigma.total_cmp(&y.sigma));
            let above = samples
                .iter()
                .filter(|s| s.sigma > sigma)
                .min_by(|x, y| x.sigma.total_cmp(&y.sigma));
            let anchor = &self.u_a + sigma * &self.delta;
            let guess = match (below, above) {
                (Some(l), Some(h)) => {
                    let w = (sigma - l.sigma) / (h.sigma - l.sigma);
                    &l.u + w * (&h.u - &l.u)
                }
                _ => anchor.clone(),
            };
            (guess, anchor)
        };
        let corrected = correct(
            self.problem,
            guess,
            &anchor,
            &self.tau,
            &self.settings,
            Purpose::Location,
        )?;
        Ok(match (corrected.converged, corrected.map) {
            (true, Some(map)) => Some(self.polished(corrected.u, map, &anchor)),
            _ => None,
        })
    }

    /// A converged pseudo-arclength trial `u` (period map `map`) on the hyperplane through
    /// `anchor`, polished: while the Newton step that its residual leaves undone, `du = -[M -
    /// I, dP/dp; tau^T]^{-1} [P(x; p) - x; tau . (u - anchor)]`, moves the parameter by more
    /// than [`POLISH_FRACTION`] of the location tolerance, the step is taken (at most
    /// [`POLISH_STEPS`] times), and kept only if the new residual is no larger (below the
    /// residual's noise floor a step can only add noise). Next to a fold, where `M - I` is
    /// nearly singular, a residual within Newton's tolerance can leave the parameter off by
    /// far more than the location tolerance (1e-8 nm from a residual of 1e-11 on
    /// `silicon-air-polymer`), and the located point would be no better than its orbit.
    fn polished(
        &self,
        mut u: DVector<f64>,
        mut map: PeriodMap,
        anchor: &DVector<f64>,
    ) -> (DVector<f64>, PeriodMap) {
        let n = u.len() - 1;
        let residual_of = |u: &DVector<f64>, map: &PeriodMap| (&map.image - u.rows(0, n)).norm();
        let mut residual = residual_of(&u, &map);
        for _ in 0..POLISH_STEPS {
            let Some(update) = undone_update(&map, &u, &self.tau, anchor) else {
                break;
            };
            // (A NaN step stops too.)
            if update[n].abs().is_nan()
                || update[n].abs() <= POLISH_FRACTION * self.location_tolerance
            {
                break;
            }
            let moved = &u - update;
            let Ok(moved_map) = self.problem.period_map(&moved.as_slice()[..n], moved[n]) else {
                break;
            };
            let moved_residual = residual_of(&moved, &moved_map);
            if moved_residual.is_nan() || moved_residual > residual {
                break;
            }
            (u, map, residual) = (moved, moved_map, moved_residual);
        }
        (u, map)
    }

    /// Shooting at the fixed parameter of `sigma`, from the states extrapolated along the
    /// tangents at `A`, then at `B` where `B` is an orbit (each shot given up when it stalls,
    /// [`NEWTON_STALL`]: a trial past the structure change, with no orbit near its guess); with
    /// the tangent of the end it was shot from, which orients the trial's tangent.
    fn shoot_at(&self, sigma: f64) -> Result<Option<OrientedTrial>, ContinuationError> {
        let n = self.u_a.len() - 1;
        let p = self.parameter_at(sigma);
        let ends: &[usize] = if self.far_is_orbit { &[0, 1] } else { &[0] };
        let settings = NewtonSettings {
            max_iterations: self.settings.max_iterations * 4,
            ..self.settings.clone()
        };
        for &end_index in ends {
            let guess = {
                let end = self.sample_ref(end_index);
                let tp = end.tangent[n];
                let slope = if tp.abs() > 1e-12 && tp.is_finite() {
                    (p - end.parameter()) / tp
                } else {
                    0.0
                };
                end.u.rows(0, n) + slope * end.tangent.rows(0, n)
            };
            let result = match shoot_checked(
                self.problem,
                guess.as_slice(),
                p,
                &settings,
                Some(NEWTON_STALL),
            ) {
                Ok(result) => result,
                Err(ContinuationError::DimensionMismatch {
                    what,
                    expected,
                    found,
                }) => {
                    return Err(ContinuationError::DimensionMismatch {
                        what,
                        expected,
                        found,
                    })
                }
                Err(_) => continue,
            };
            if result.converged {
                let mut u = DVector::zeros(n + 1);
                u.rows_mut(0, n).copy_from(&result.state);
                u[n] = p;
                let tangent = self.sample_ref(end_index).tangent.clone();
                return Ok(Some((u, result.period_map, tangent)));
            }
        }
        Ok(None)
    }

    /// Locate a sign change of `test` between the cached samples `low` and `high`
    /// (`sigma_low < sigma_high`) to a parameter bracket of `tolerance`. A trial that fails
    /// counts as `failure_value` (NaN: unknown, which ends the search).
    pub(crate) fn locate(
        &self,
        low: usize,
        high: usize,
        test: &dyn Fn(&Sample) -> f64,
        failure_value: f64,
        tolerance: f64,
        max_iterations: usize,
    ) -> Result<Location, ContinuationError> {
        let (s_low, s_high) = (self.sample_ref(low).sigma, self.sample_ref(high).sigma);
        let before = self.trials.get();
        let bracket = Cell::new((s_low, s_high));
        let error: RefCell<Option<ContinuationError>> = RefCell::new(None);
        let value = |sigma: f64| -> f64 {
            match self.sample(sigma) {
                Ok(Some(i)) => test(&self.samples.borrow()[i]),
                Ok(None) => failure_value,
                Err(e) => {
                    error.borrow_mut().get_or_insert(e);
                    f64::NAN
                }
            }
        };
        let mut convergency = ParameterBracket {
            segment: self,
            tolerance,
            max_iterations,
            bracket: &bracket,
        };
        let root = if self.natural {
            anderson_bjorck(s_low, s_high, value, &mut convergency)
        } else {
            find_root_regula_falsi(s_low, s_high, value, &mut convergency)
        };
        if let Some(e) = error.into_inner() {
            return Err(e);
        }
        let sigma = match root {
            Ok(sigma) => sigma,
            Err(_) => {
                let (l, h) = bracket.get();
                0.5 * (l + h)
            }
        };
        let mut point = self.sample(sigma)?.map(|i| self.get(i));
        let (mut bl, mut bh) = bracket.get();
        if point.as_ref().is_some_and(|s| test(s) == 0.0) {
            // An exact zero: bracket it by two orbits a quarter of the tolerance (in p) on
            // either side, so that both sides (and their impact counts) are known.
            let slope =
                (self.parameter_at(s_high) - self.parameter_at(s_low)).abs() / (s_high - s_low);
            let delta = if slope > 0.0 {
                0.25 * tolerance / slope
            } else {
                0.25 * (bh - bl)
            };
            let lo = (sigma - delta).max(bl);
            let hi = (sigma + delta).min(bh);
            if lo < sigma && self.sample(lo)?.is_some() {
                bl = lo;
            }
            // In natural mode a failed trial stands for the far side.
            let inferred = self.natural && failure_value.is_finite();
            if hi > sigma && (self.sample(hi)?.is_some() || inferred) {
                bh = hi;
            }
        }
        let (il, ih) = (self.index_of(bl), self.index_of(bh));
        let value_at =
            |index: Option<usize>| index.map_or(failure_value, |i| test(&self.sample_ref(i)));
        let (gl, gh) = (value_at(il), value_at(ih));
        let (pl, ph) = (self.parameter_at(bl), self.parameter_at(bh));
        let opposite = (gl == 0.0 || gh == 0.0 || (gl < 0.0) != (gh < 0.0))
            && gl.is_finite()
            && gh.is_finite();
        if point.is_none() {
            point = il.or(ih).map(|i| self.get(i));
        }
        let converged = opposite && (pl - ph).abs() <= tolerance && point.is_some();
        Ok(Location {
            point,
            low: il,
            high: ih,
            parameters: (pl, ph),
            converged,
            iterations: self.trials.get() - before,
        })
    }
}

#[cfg(test)]
mod tests {
    use std::cell::Cell;

    use roots::{find_root_regula_falsi, Convergency};

    use super::anderson_bjorck;

    /// Stop when the bracket is narrower than `width`.
    struct Bracket {
        width: f64,
    }

    impl Convergency<f64> for Bracket {
        fn is_root_found(&mut self, y: f64) -> bool {
            y == 0.0
        }

        fn is_converged(&mut self, x1: f64, x2: f64) -> bool {
            (x1 - x2).abs() <= self.width
        }

        fn is_iteration_limit_reached(&mut self, iter: usize) -> bool {
            iter >= 200
        }
    }

    /// A test function that vanishes at `x = 0.004` on the near side and is replaced past
    /// `0.0041` by the far end's value -0.04 (a failed trial in natural mode): the bracket
    /// `[x, 0.0041]` around the root shrinks only from the near side until the search lands in
    /// `(0.004, 0.0041]`.
    fn near_side_then_proxy(x: f64) -> f64 {
        if x < 0.0041 {
            1e-6 * (0.004 - x)
        } else {
            -0.04
        }
    }

    #[test]
    fn anderson_bjorck_takes_the_near_side_secant_where_illinois_doubles() {
        let (illinois_calls, scaled_calls) = (Cell::new(0), Cell::new(0));
        fn counted(calls: &Cell<usize>) -> impl FnMut(f64) -> f64 + '_ {
            move |x: f64| {
                calls.set(calls.get() + 1);
                near_side_then_proxy(x)
            }
        }
        let width = 2e-4;
        let illinois =
            find_root_regula_falsi(0.0, 1.0, counted(&illinois_calls), &mut Bracket { width });
        let scaled = anderson_bjorck(0.0, 1.0, counted(&scaled_calls), &mut Bracket { width });
        // The zero of the near side's values within the bracket's width (the sign change itself
        // lies in [0.004, 0.0041]).
        let (scaled, illinois) = (scaled.expect("converges"), illinois.expect("converges"));
        assert!((scaled - 0.004).abs() <= width, "{scaled}");
        assert!((illinois - 0.004).abs() <= width, "{illinois}");
        assert!(
            scaled_calls.get() + 5 < illinois_calls.get(),
            "Anderson-Bjorck {} evaluations, Illinois {}",
            scaled_calls.get(),
            illinois_calls.get()
        );
    }

    #[test]
    fn anderson_bjorck_finds_a_smooth_root() {
        // x^3 - 2 on [0, 2]: the root 2^(1/3).
        let root = anderson_bjorck(0.0, 2.0, |x| x * x * x - 2.0, &mut Bracket { width: 1e-12 });
        assert!((root.unwrap() - 2f64.cbrt()).abs() <= 1e-12);
    }
}
