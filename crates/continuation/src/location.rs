//! Location of a sign change of a test function along one continuation step.
//!
//! The step from branch point `A` to branch point `B` is parametrised by the fraction
//! `sigma` in `[0, 1]` of the secant `u_A -> u_B`; the orbit at `sigma` is the branch point on
//! the hyperplane `tau . (u - u_A - sigma (u_B - u_A)) = 0` (`tau` the unit secant), found by
//! the pseudo-arclength corrector. A test function of that orbit is root-found in `sigma` with
//! the Illinois method of the `roots` crate until the *parameter* bracket is below the
//! location tolerance.

use std::cell::{Cell, RefCell};

use nalgebra::{Complex, DVector};
use roots::{find_root_regula_falsi, Convergency};

use crate::corrector::{correct, tangent};
use crate::error::ContinuationError;
use crate::floquet::floquet_multipliers;
use crate::problem::{PeriodMap, PeriodicProblem};
use crate::shooting::NewtonSettings;

/// A corrected orbit on the segment, with what the test functions need.
#[derive(Debug, Clone)]
pub(crate) struct Sample {
    /// Fraction of the segment.
    pub sigma: f64,
    /// `(x, p)`.
    pub u: DVector<f64>,
    /// The period map at `u`.
    pub map: PeriodMap,
    /// Unit tangent oriented like the tangent at `A` (NaN entries if singular).
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

/// The result of locating one sign change.
#[derive(Debug, Clone)]
pub(crate) struct Location {
    /// The sample at the located point (`None` if its correction failed).
    pub point: Option<Sample>,
    /// Index (into the segment's samples) of the bracket end nearer `sigma = 0`.
    pub low: usize,
    /// Index of the bracket end nearer `sigma = 1`.
    pub high: usize,
    /// Whether the parameter bracket reached the tolerance with finite values of opposite
    /// signs (or an exact zero).
    pub converged: bool,
    /// New corrected trial points spent.
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
    samples: RefCell<Vec<Sample>>,
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

impl<'a, P: PeriodicProblem + ?Sized> Segment<'a, P> {
    /// The segment between samples `a` (`sigma = 0`) and `b` (`sigma = 1`); trial points are
    /// corrected with `settings` and their tangents oriented along `reference`.
    pub(crate) fn new(
        problem: &'a P,
        a: Sample,
        b: Sample,
        reference: DVector<f64>,
        settings: NewtonSettings,
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
            samples: RefCell::new(vec![a, b]),
        }
    }

    /// Parameter of the cached sample at exactly `sigma` (NaN if none).
    fn parameter_at(&self, sigma: f64) -> f64 {
        self.samples
            .borrow()
            .iter()
            .find(|s| s.sigma == sigma)
            .map_or(f64::NAN, Sample::parameter)
    }

    /// A clone of sample `index`.
    pub(crate) fn get(&self, index: usize) -> Sample {
        self.samples.borrow()[index].clone()
    }

    /// Index of the sample at `sigma`, correcting a new orbit if it is not cached
    /// (`Ok(None)` if the corrector fails there).
    pub(crate) fn sample(&self, sigma: f64) -> Result<Option<usize>, ContinuationError> {
        let (guess, anchor) = {
            let samples = self.samples.borrow();
            if let Some(i) = samples.iter().position(|s| s.sigma == sigma) {
                return Ok(Some(i));
            }
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
        let corrected = correct(self.problem, guess, &anchor, &self.tau, &self.settings)?;
        if !corrected.converged {
            return Ok(None);
        }
        let Some(map) = corrected.map else {
            return Ok(None);
        };
        let sample = Sample::new(sigma, corrected.u, map, &self.reference);
        let mut samples = self.samples.borrow_mut();
        samples.push(sample);
        Ok(Some(samples.len() - 1))
    }

    /// Locate a sign change of `test` between the cached samples `low` and `high`
    /// (`sigma_low < sigma_high`) to a parameter bracket of `tolerance`.
    pub(crate) fn locate(
        &self,
        low: usize,
        high: usize,
        test: &dyn Fn(&Sample) -> f64,
        tolerance: f64,
        max_iterations: usize,
    ) -> Result<Location, ContinuationError> {
        let (s_low, s_high) = {
            let samples = self.samples.borrow();
            (samples[low].sigma, samples[high].sigma)
        };
        let before = self.samples.borrow().len();
        let bracket = Cell::new((s_low, s_high));
        let error: RefCell<Option<ContinuationError>> = RefCell::new(None);
        let f = |sigma: f64| -> f64 {
            match self.sample(sigma) {
                Ok(Some(i)) => test(&self.samples.borrow()[i]),
                Ok(None) => f64::NAN,
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
        let root = find_root_regula_falsi(s_low, s_high, f, &mut convergency);
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
        let point = self.sample(sigma)?.map(|i| self.get(i));
        let value = point.as_ref().map_or(f64::NAN, test);
        let (mut bl, mut bh) = bracket.get();
        if value == 0.0 {
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
            let lo_ok = lo < sigma && self.sample(lo)?.is_some();
            let hi_ok = hi > sigma && self.sample(hi)?.is_some();
            bl = if lo_ok { lo } else { bl };
            bh = if hi_ok { hi } else { bh };
        }
        let index_of = |s: f64| {
            self.samples
                .borrow()
                .iter()
                .position(|x| x.sigma == s)
                .unwrap_or(low)
        };
        let (il, ih) = (index_of(bl), index_of(bh));
        let (gl, gh, pl, ph) = {
            let samples = self.samples.borrow();
            (
                test(&samples[il]),
                test(&samples[ih]),
                samples[il].parameter(),
                samples[ih].parameter(),
            )
        };
        let opposite = (gl == 0.0 || gh == 0.0 || (gl < 0.0) != (gh < 0.0))
            && gl.is_finite()
            && gh.is_finite();
        let converged = opposite && (pl - ph).abs() <= tolerance && point.is_some();
        let iterations = self.samples.borrow().len() - before;
        Ok(Location {
            point,
            low: il,
            high: ih,
            converged,
            iterations,
        })
    }
}
