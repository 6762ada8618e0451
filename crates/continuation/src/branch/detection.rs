//! Special points in a continuation step: every test function that changes sign between the
//! step's two orbits, located along the step by root finding (MODEL.md Sec. 5 and
//! [`crate::test_function`]): structure changes (grazing, merge, split, impact count) first,
//! then the smooth tests (fold, period doubling, Neimark-Sacker) between their brackets.

use super::Continuation;
use crate::corrector::undone_update;
use crate::error::ContinuationError;
use crate::extrapolated_zero::{extrapolated_zero, ExtrapolatedZero, Vanishing};
use nalgebra::DMatrix;

use crate::location::{Location, Sample, Segment};
use crate::problem::OrbitStructure;
use crate::problem::PeriodicProblem;
use crate::special_point::{SpecialPoint, SpecialPointKind};
use crate::test_function::{
    has_complex_pair, has_complex_pair_on_unit_circle, neimark_sacker_test, period_doubling_test,
    ExtremumKind, StructureTest,
};

/// A test function of a corrected orbit on a step.
type SampleTest = fn(&Sample) -> f64;

/// How a structure test, on a branch whose period map jumps at its grazings, vanishes on the
/// near side (`A`, [`extrapolated_zero`]): quadratically where that side crosses the surface (a
/// minimum of the contact surface below it: the orbit attaches there; a release maximum above
/// the release surface: the orbit releases there), else linearly (`None`: not an extremum).
pub(super) fn near_side_vanishing(test: &StructureTest) -> Option<Vanishing> {
    let StructureTest::Extremum { kind, value_a, .. } = *test else {
        return None;
    };
    let crosses = match kind {
        ExtremumKind::Minimum => value_a < 0.0,
        ExtremumKind::ReleaseMaximum => value_a > 0.0,
        ExtremumKind::Maximum => return None,
    };
    Some(if crosses {
        Vanishing::Quadratically
    } else {
        Vanishing::Linearly
    })
}

/// Whether the location of `test` across the jump of a hysteretic grazing, ending at a failed
/// trial, reports the zero extrapolated from the near side ([`extrapolated_zero`]): where it
/// vanishes quadratically there, or it is a maximum of the release surface (see
/// `locate_structure_changes`).
pub(super) fn extrapolated_from_near_side(test: &StructureTest) -> bool {
    let release = matches!(
        test,
        StructureTest::Extremum {
            kind: ExtremumKind::ReleaseMaximum,
            ..
        }
    );
    release || near_side_vanishing(test) == Some(Vanishing::Quadratically)
}

impl<P: PeriodicProblem + ?Sized> Continuation<'_, P> {
    /// Locate every sign change of a test function in the step held by `segment`.
    pub(super) fn locate_all(
        &self,
        segment: &Segment<'_, P>,
        structure: &[StructureTest],
        index: usize,
        jumped: bool,
        smooth_tests: bool,
    ) -> Result<Vec<SpecialPoint>, ContinuationError> {
        let mut found: Vec<(f64, SpecialPoint)> = Vec::new();
        let breaks =
            self.locate_structure_changes(segment, structure, index, jumped, &mut found)?;
        if smooth_tests {
            self.locate_smooth_changes(segment, &breaks, index, jumped, &mut found)?;
        }
        found.sort_by(|x, y| x.0.total_cmp(&y.0));
        Ok(found.into_iter().map(|(_, s)| s).collect())
    }

    /// Locate each structure test's sign change in the step (grazing, merge, split, impact
    /// count) into `found` as `(sigma, point)`; returns the brackets `(low, high)` of the
    /// segment's samples around each, between which the smooth tests are located.
    fn locate_structure_changes(
        &self,
        segment: &Segment<'_, P>,
        structure: &[StructureTest],
        index: usize,
        jumped: bool,
        found: &mut Vec<(f64, SpecialPoint)>,
    ) -> Result<Vec<(usize, usize)>, ContinuationError> {
        let tolerance = self.settings.location_tolerance;
        let max_iterations = self.settings.location_max_iterations;
        let across_families = jumped && self.settings.hysteretic_grazing;
        let mut breaks: Vec<(usize, usize)> = Vec::new();
        for test in structure {
            let value = |s: &Sample| test.value(s.sigma, &s.map.structure);
            // Across a corner, a failed trial lies past the structure change (B side).
            let failure = if jumped {
                value(&segment.sample_ref(1))
            } else {
                f64::NAN
            };
            let location = segment.locate(0, 1, &value, failure, tolerance, max_iterations)?;
            // Across a hysteretic grazing Newton stops converging short of the zero: from the
            // side that crosses the surface always (the test vanishes quadratically there);
            // from an orbit attached through the release surface's maximum where the location
            // ended at a failed trial (the free side of a contact grazing, whose flight is
            // exact, is located between orbits as on any branch).
            let release = matches!(
                test,
                StructureTest::Extremum {
                    kind: ExtremumKind::ReleaseMaximum,
                    ..
                }
            );
            let extrapolates = match near_side_vanishing(test) {
                Some(vanishing)
                    if across_families
                        && (vanishing == Vanishing::Quadratically
                            || (release && location.high.is_none())) =>
                {
                    Some(vanishing)
                }
                _ => None,
            };
            let extrapolated =
                extrapolates.and_then(|vanishing| self.extrapolated_zero(segment, test, vanishing));
            let kind = match *test {
                StructureTest::Extremum {
                    kind: ExtremumKind::Minimum,
                    ..
                } => SpecialPointKind::Grazing,
                StructureTest::Extremum {
                    kind: ExtremumKind::ReleaseMaximum,
                    ..
                } => SpecialPointKind::PullOff,
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
            // Across the jump of a hysteretic grazing, a merge, split or impact count located
            // between an orbit of the near family and one of the far family is the jump itself
            // (the far family's structure), not a change along either branch: the grazing
            // that causes the jump is the point reported there.
            if across_families
                && !matches!(kind, SpecialPointKind::Grazing | SpecialPointKind::PullOff)
                && location
                    .low
                    .zip(location.high)
                    .is_some_and(|(low, high)| segment.across_jump(low, high))
            {
                continue;
            }
            let mut point = self.special_point(segment, kind, &location, location.converged, index);
            if let Some((zero, nearest)) = extrapolated {
                let nearest = segment.sample_ref(nearest);
                let n = nearest.u.len() - 1;
                let special = &mut point.1;
                special.parameter = zero.parameter;
                special.bracket = (zero.parameter - zero.error, zero.parameter + zero.error);
                special.precision = 2.0 * zero.error;
                special.converged = special.precision <= tolerance;
                special.state = nearest.u.rows(0, n).into_owned();
                special.orbit_parameter = nearest.parameter();
                special.multipliers = nearest.multipliers.clone();
            } else if let Some(error) = self.orbit_error_in_parameter(segment, test, &location) {
                widen_by_orbit_error(&mut point.1, error, tolerance);
            }
            if extrapolated.is_none() && extrapolates.is_some() {
                // No zero to extrapolate: the location's bracket ends where Newton stopped
                // converging, not at the zero, which lies somewhere up to the far end.
                let special = &mut point.1;
                let far = segment.sample_ref(1).parameter();
                special.bracket = (special.bracket.0.min(far), special.bracket.1.max(far));
                special.precision = special.bracket.1 - special.bracket.0;
                special.converged = false;
            }
            found.push(point);
        }
        Ok(breaks)
    }

    /// How far in the parameter the located orbit's own error moves the zero of `test`
    /// (parameter units): the orbit's error at its fixed parameter, `dx = (I - M)^{-1} (P(x) -
    /// x)` (the Newton step its residual leaves undone, `M` the monodromy), carried into the
    /// test by period maps at `x + dx` and `x - dx` (the smaller change of the two, among those
    /// whose orbit has the located one's impacts and extrema: at a grazing one of them can
    /// cross the surface, where the structure changes and a hysteretic law's force jumps in),
    /// divided by the test's slope in the parameter from the located orbit to the segment's
    /// start (or, at the start itself, its end). `None` where any of these is not available.
    fn orbit_error_in_parameter(
        &self,
        segment: &Segment<'_, P>,
        test: &StructureTest,
        location: &Location,
    ) -> Option<f64> {
        let point = location.point.as_ref()?;
        let n = point.u.len() - 1;
        let x = point.u.rows(0, n);
        let residual = &point.map.image - x;
        let step = (DMatrix::identity(n, n) - &point.map.monodromy)
            .lu()
            .solve(&residual)?;
        let g = test.value(point.sigma, &point.map.structure);
        let shape = |s: &OrbitStructure| {
            (
                s.impacts,
                s.minima.len(),
                s.maxima.len(),
                s.release_maxima.len(),
            )
        };
        let mut dg = f64::INFINITY;
        for moved in [x + &step, x - &step] {
            let Ok(map) = self.problem.period_map(moved.as_slice(), point.parameter()) else {
                continue;
            };
            if shape(&map.structure) == shape(&point.map.structure) {
                dg = dg.min((test.value(point.sigma, &map.structure) - g).abs());
            }
        }
        let slope = slope_from(segment, point, g, |s| test.value(s.sigma, &s.map.structure))?;
        let error = dg / slope;
        error.is_finite().then_some(error)
    }

    /// The zero of a structure test that vanishes as `vanishing` says on the segment's near
    /// side, extrapolated from its values on the orbits of that side: the segment's (its start
    /// and the location's converged trials) and the branch's points before it
    /// ([`extrapolated_zero`]); with the index of the segment's orbit nearest it. `None` where
    /// no zero can be extrapolated or it falls outside the interval from that orbit to the
    /// segment's far end.
    fn extrapolated_zero(
        &self,
        segment: &Segment<'_, P>,
        test: &StructureTest,
        vanishing: Vanishing,
    ) -> Option<(ExtrapolatedZero, usize)> {
        let value = |s: &Sample| test.value(s.sigma, &s.map.structure);
        let on_segment = segment.values(&value);
        let (_, p_a, g_a) = *on_segment.first()?;
        let far = segment.sample_ref(1).parameter();
        let direction = (far - p_a).signum();
        let near = |g: f64| g.is_finite() && g != 0.0 && (g < 0.0) == (g_a < 0.0);
        let points: Vec<(f64, f64)> = on_segment
            .iter()
            .map(|&(_, p, g)| (p, g))
            .chain(
                self.recent_structures
                    .iter()
                    .map(|(p, structure)| (*p, test.value(0.0, structure))),
            )
            .filter(|&(_, g)| near(g))
            .collect();
        // Never behind the nearest orbit ([`extrapolated_zero`]); nor past the segment's far
        // end, where the structure has changed: a line that reaches zero there does not
        // describe the test (a branch whose extremum turns before it vanishes).
        let zero = extrapolated_zero(&points, direction, vanishing)?;
        if (far - zero.parameter) * direction < 0.0 {
            return None;
        }

        let nearest = on_segment
            .iter()
            .find(|&&(_, p, g)| p == zero.nearest && near(g))?
            .0;
        Some((zero, nearest))
    }

    /// Locate the sign changes of the smooth (tangent and multiplier) tests, fold and, with
    /// `detect_bifurcations`, period doubling and Neimark-Sacker, into `found`: within the
    /// intervals between the structure brackets `breaks` where the test changes sign
    /// continuously, else (a sign change across a structure change) at that bracket, not
    /// converged; except across the jump of a hysteretic grazing (`jumped` on a branch whose
    /// period map jumps there), where the two sides are different families of orbits (the far
    /// one's tangent oriented along the jump's secant) and trials between them converge onto
    /// either: there a test is located only between two orbits of one family
    /// ([`Segment::across_jump`]), and a sign change across the jump is not reported.
    fn locate_smooth_changes(
        &self,
        segment: &Segment<'_, P>,
        breaks: &[(usize, usize)],
        index: usize,
        jumped: bool,
        found: &mut Vec<(f64, SpecialPoint)>,
    ) -> Result<(), ContinuationError> {
        let tolerance = self.settings.location_tolerance;
        let max_iterations = self.settings.location_max_iterations;
        let mut smooth: Vec<(SpecialPointKind, SampleTest)> = Vec::new();
        smooth.push((SpecialPointKind::Fold, |s: &Sample| {
            s.tangent[s.tangent.len() - 1]
        }));
        if self.settings.detect_bifurcations {
            smooth.push((SpecialPointKind::PeriodDoubling, |s: &Sample| {
                period_doubling_test(&s.multipliers)
            }));
            smooth.push((SpecialPointKind::NeimarkSacker, |s: &Sample| {
                neimark_sacker_test(&s.multipliers)
            }));
        }
        let sign = |g: f64| g < 0.0;
        let across_families = jumped && self.settings.hysteretic_grazing;
        for (kind, test) in smooth {
            // The ends are borrowed only here: the location below adds orbits to the segment.
            let (ga, gb) = (test(&segment.sample_ref(0)), test(&segment.sample_ref(1)));
            if !(ga.is_finite() && gb.is_finite()) || sign(ga) == sign(gb) {
                continue;
            }
            // A Neimark-Sacker test's sign change between two ends without a complex pair is a
            // neutral saddle, which the location below would find and drop.
            if kind == SpecialPointKind::NeimarkSacker
                && !has_complex_pair(&segment.sample_ref(0).multipliers)
                && !has_complex_pair(&segment.sample_ref(1).multipliers)
            {
                continue;
            }
            // Intervals between the structure brackets, in sigma order.
            let mut cuts: Vec<(f64, usize, usize)> = breaks
                .iter()
                .map(|&(l, h)| (segment.sample_ref(l).sigma, l, h))
                .collect();
            cuts.sort_by(|x, y| x.0.total_cmp(&y.0));
            let mut intervals = Vec::new();
            let mut lo = 0;
            for &(_, l, h) in &cuts {
                intervals.push((lo, l));
                lo = h;
            }
            intervals.push((lo, 1));
            // Across the jump of a hysteretic grazing an interval is continuous only between
            // orbits of one family (trials at parameters between the ends converge onto either).
            let continuous = intervals.iter().copied().find(|&(l, h)| {
                let (gl, gh) = (test(&segment.sample_ref(l)), test(&segment.sample_ref(h)));
                gl.is_finite()
                    && gh.is_finite()
                    && sign(gl) != sign(gh)
                    && !(across_families && segment.across_jump(l, h))
            });
            let (kind, location) = match continuous {
                Some((l, h)) => {
                    let location =
                        segment.locate(l, h, &test, f64::NAN, tolerance, max_iterations)?;
                    (kind, location)
                }
                None => {
                    // The sign change happens across a structure change (a jump); across the
                    // jump of a hysteretic grazing it is between two families of orbits and
                    // tells nothing of either.
                    if across_families {
                        continue;
                    }
                    let Some(&(_, l, h)) = cuts.iter().find(|&&(_, l, h)| {
                        sign(test(&segment.sample_ref(l))) != sign(test(&segment.sample_ref(h)))
                    }) else {
                        continue;
                    };
                    let location = Location {
                        point: Some(segment.get(l)),
                        low: Some(l),
                        high: Some(h),
                        parameters: (
                            segment.sample_ref(l).parameter(),
                            segment.sample_ref(h).parameter(),
                        ),
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
            let mut point = self.special_point(segment, kind, &location, converged, index);
            if continuous.is_some() {
                if let Some(error) = self.smooth_orbit_error_in_parameter(segment, test, &location)
                {
                    widen_by_orbit_error(&mut point.1, error, tolerance);
                }
            }
            found.push(point);
        }
        Ok(())
    }

    /// How far in the parameter the located orbit's own error moves the zero of the smooth
    /// test `test` (parameter units): the step `du = (dx, dp)` that Newton's bordered system
    /// `[M - I, dP/dp; t^T] du = -[P(x; p) - x; 0]` leaves undone at the located point `u` (`t`
    /// its unit tangent: `du` is orthogonal to the branch, so `u + du` lies on the branch at
    /// the same arclength to first order), `|dp| + |g(u + du) - g(u)| / |dg/dp|`, with `g(u +
    /// du)` from a period map, tangent and multipliers at `u + du` and the slope `dg/dp` from
    /// the located point to the segment's start (or, at the start itself, its end). At a fold
    /// (`g = t_p`, whose slope in `p` is unbounded there) this is `|dp|`: the fold's parameter
    /// to first order. `None` where any of these is not available.
    fn smooth_orbit_error_in_parameter(
        &self,
        segment: &Segment<'_, P>,
        test: SampleTest,
        location: &Location,
    ) -> Option<f64> {
        let point = location.point.as_ref()?;
        let n = point.u.len() - 1;
        if point.tangent.iter().any(|t| !t.is_finite()) {
            return None;
        }
        let step = undone_update(&point.map, &point.u, &point.tangent, &point.u)?;
        let moved = &point.u - &step;
        let map = self
            .problem
            .period_map(&moved.as_slice()[..n], moved[n])
            .ok()?;
        let corrected = Sample::new(point.sigma, moved, map, &point.tangent);
        let g = test(point);
        let slope = slope_from(segment, point, g, test)?;
        let error = step[n].abs() + (test(&corrected) - g).abs() / slope;
        error.is_finite().then_some(error)
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
        let low = segment.sample_ref(location.low.unwrap_or(0));
        let high = segment.sample_ref(location.high.unwrap_or(1));
        let (pl, ph) = location.parameters;
        let point = location.point.as_ref().unwrap_or(&*low);
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
                    | SpecialPointKind::PullOff
            )
        {
            impacts_before = segment.sample_ref(0).map.structure.impacts;
            impacts_after = segment.sample_ref(1).map.structure.impacts;
        }
        (
            point.sigma,
            SpecialPoint {
                label: kind.label(impacts_before.max(impacts_after)),
                kind,
                parameter: point.parameter(),
                bracket: (pl.min(ph), pl.max(ph)),
                precision: (pl - ph).abs(),
                converged,
                impacts_before,
                impacts_after,
                state: point.u.rows(0, n).into_owned(),
                orbit_parameter: point.parameter(),
                multipliers: point.multipliers.clone(),
                iterations: location.iterations,
                branch_index: index,
            },
        )
    }
}

/// Widen a located point's bracket by its orbit's own error `error` (parameter units) where
/// that error reaches outside the bracket (the bracket's ends, orbits with about the same
/// error, each moved out by it; within it, the bracket is at least twice that error wide
/// already), its precision the new width and `converged` kept only within `tolerance`.
fn widen_by_orbit_error(special: &mut SpecialPoint, error: f64, tolerance: f64) {
    let (low, high) = special.bracket;
    if special.parameter - error < low || special.parameter + error > high {
        special.bracket = (low - error, high + error);
        special.precision = special.bracket.1 - special.bracket.0;
        special.converged = special.converged && special.precision <= tolerance;
    }
}

/// The slope `|dg/dp|` of the test `value` (`g` at the located `point`) from `point` to the
/// segment's start, or, where the start has `point`'s parameter, to its end (test units per
/// parameter unit). `None` where both ends have it.
fn slope_from<P: PeriodicProblem + ?Sized>(
    segment: &Segment<'_, P>,
    point: &Sample,
    g: f64,
    value: impl Fn(&Sample) -> f64,
) -> Option<f64> {
    let other = [0, 1]
        .into_iter()
        .map(|index| segment.sample_ref(index))
        .find(|s| s.parameter() != point.parameter())?;
    Some((value(&other) - g).abs() / (other.parameter() - point.parameter()).abs())
}
