//! Two-parameter continuation of a codimension-one point of periodic orbits (a grazing, a
//! fold, a period doubling) in `(p, q)` by pseudo-arclength, through turning points in either
//! parameter (defining systems in `codim_one.rs`, MODEL.md section 8).
//!
//! A curve starts from a special point of a one-parameter branch at `q0` (corrected at fixed
//! `q = q0`) and is traced both ways until it reaches an end of `second_range`, leaves the
//! physical range of `p`, fails, or produces `max_points`. Wherever it crosses an end of the
//! range or a target value of `q`, a point is computed there exactly, at fixed `q`. Between
//! consecutive points the codimension-two test functions (`codim_two.rs`) are watched and
//! every change located.

use nalgebra::{Complex, DVector};

use crate::codim_one::{CodimOneKind, Defining};
use crate::codim_two::{detect, Codim2Point};
use crate::curve_corrector::{correct, tangent, Current, Solved};
use crate::curve_settings::CurveSettings;
use crate::error::ContinuationError;
use crate::floquet::{floquet_multipliers, is_stable};
use crate::problem::OrbitStructure;
use crate::two_parameter::{SystemFamily, TwoParameterProblem};
use hybrid::Sensitivity;

/// Where a curve starts: an orbit at (or near) the codimension-one point at `(p, q)`.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveStart {
    /// The orbit's state at `section_time` (state units).
    pub state: Vec<f64>,
    /// Section time of `state` (system time units).
    pub section_time: f64,
    /// The first parameter `p`.
    pub parameter: f64,
    /// The second parameter `q`, inside the range.
    pub second_parameter: f64,
}

/// One point of a codimension-one curve.
#[derive(Debug, Clone, PartialEq)]
pub struct CurvePoint {
    /// The first parameter `p` (for the AFM, `Z` in nm).
    pub parameter: f64,
    /// The second parameter `q`.
    pub second_parameter: f64,
    /// The orbit's state at `section_time` (state units).
    pub state: DVector<f64>,
    /// Section time of `state` (system time units).
    pub section_time: f64,
    /// Grazing curves: the time of the grazing minimum (system time units).
    pub grazing_time: Option<f64>,
    /// Floquet multipliers of the orbit, by decreasing modulus.
    pub multipliers: Vec<Complex<f64>>,
    /// Whether every multiplier lies strictly inside the unit circle.
    pub stable: bool,
    /// The contact gap's extrema and impacts over the period map.
    pub structure: OrbitStructure,
    /// `|F(u)|_2` of the defining system at the point.
    pub residual: f64,
    /// Newton updates spent on the point.
    pub iterations: usize,
    /// Whether the point was computed at a fixed `q` (a range end, a target or the start).
    pub at_fixed_second: bool,
}

/// Why one end of a curve stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CurveStop {
    /// The curve reached an end of the range of `q` (its last point lies on it).
    RangeEnd,
    /// `p` left its physical range (the last point lies on the bound).
    ParameterBound,
    /// `max_points` points in this direction.
    MaxPoints,
    /// The curve came back to its start: it is closed (an isola), and both ends say so.
    Closed,
    /// The corrector failed at the minimum step (the defining system degenerates, e.g. the
    /// grazing minimum merges with a maximum, or the orbit ceases to exist).
    StepTooSmall,
    /// Another error.
    Error,
    /// The caller's stop predicate answered `true` ([`continue_curve_until`]).
    Interrupted,
}

/// One end of a curve.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveEnd {
    /// Why it stopped.
    pub reason: CurveStop,
    /// `(p, q)` of the last point.
    pub parameters: (f64, f64),
    /// The error that stopped it ([`CurveStop::Error`] only).
    pub error: Option<ContinuationError>,
}

/// A continued codimension-one curve.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    /// What is continued.
    pub kind: CodimOneKind,
    /// The points, from the end traced in decreasing `q` at the start to the other.
    pub points: Vec<CurvePoint>,
    /// Index of the start point in `points`.
    pub start_index: usize,
    /// Located codimension-two points, in curve order.
    pub codim2_points: Vec<Codim2Point>,
    /// The two ends: first the one traced with `q` decreasing at the start.
    pub ends: [CurveEnd; 2],
}

/// The unit vector along unknown `j` of `m`.
fn unit(m: usize, j: usize) -> DVector<f64> {
    let mut e = DVector::zeros(m);
    e[j] = 1.0;
    e
}

/// Continue the codimension-one point `kind` of the orbits of `problem` from `start` over
/// `settings.second_range`, both ways.
///
/// # Errors
/// Invalid settings, a start outside the range, a start that does not converge at fixed `q`
/// ([`ContinuationError::StartNotConverged`]), or a singular start.
pub fn continue_curve<F: SystemFamily>(
    problem: &TwoParameterProblem<F>,
    kind: CodimOneKind,
    start: &CurveStart,
    settings: &CurveSettings,
) -> Result<Curve, ContinuationError> {
    continue_curve_until(problem, kind, start, settings, &|| false)
}

/// As [`continue_curve`], asking `stop` before every step of each half whether to give up:
/// when it answers `true` that half ends there with [`CurveStop::Interrupted`] (a caller's
/// Ctrl-C or cancel button), keeping the points found.
///
/// # Errors
/// As [`continue_curve`].
pub fn continue_curve_until<F: SystemFamily>(
    problem: &TwoParameterProblem<F>,
    kind: CodimOneKind,
    start: &CurveStart,
    settings: &CurveSettings,
    stop: &dyn Fn() -> bool,
) -> Result<Curve, ContinuationError> {
    settings.validate()?;
    let q0 = start.second_parameter;
    let (low, high) = settings.second_range;
    if !(q0 >= low && q0 <= high) {
        return Err(ContinuationError::InvalidSettings {
            field: "second_parameter of the start",
            value: q0,
            allowed: "inside second_range",
        });
    }
    let n = problem.dim();
    let defining = Defining {
        problem,
        kind,
        section: std::cell::Cell::new(start.section_time),
        borders: std::cell::RefCell::new((DVector::zeros(n), DVector::zeros(n))),
    };
    let guess = initial_unknowns(&defining, start)?;
    let m = defining.unknowns();
    let first = correct(
        &defining,
        guess.clone(),
        &unit(m, m - 1),
        q0,
        &settings.corrector,
    )?
    .ok_or(ContinuationError::StartNotConverged {
        parameter: start.parameter,
        iterations: settings.corrector.max_iterations,
        residual: f64::NAN,
    })?;
    defining.accept(&first.evaluation, first.u[m - 2])?;
    let mut halves = Vec::new();
    let borders = defining.borders.borrow().clone();
    for sign in [-1.0, 1.0] {
        if halves
            .first()
            .is_some_and(|(_, _, end): &(_, _, CurveEnd)| end.reason == CurveStop::Closed)
        {
            let closed = halves[0].2.clone();
            halves.push((Vec::new(), Vec::new(), closed));
            continue;
        }
        *defining.borders.borrow_mut() = borders.clone();
        let t = tangent(&first.evaluation, &(sign * unit(m, m - 1)), first.u[m - 2])?;
        let current = Current {
            solved: first.clone(),
            tangent: t,
            section: defining.section.get(),
            at_fixed_second: true,
        };
        halves.push(half_curve(&defining, current, settings, stop));
    }
    let (mut low_points, mut low_codim, low_end) = halves.remove(0);
    let (high_points, high_codim, high_end) = halves.remove(0);
    low_points.reverse();
    low_codim.reverse();
    let start_index = low_points.len();
    let start_point = point_of(&defining, &first, true);
    let mut points = low_points;
    points.push(start_point);
    points.extend(high_points);
    let mut codim2_points = low_codim;
    codim2_points.extend(high_codim);
    Ok(Curve {
        kind,
        points,
        start_index,
        codim2_points,
        ends: [low_end, high_end],
    })
}

/// The unknowns at the start: for a grazing, the section moved half a period map away from
/// the gap minimum nearest zero, and that minimum's time.
fn initial_unknowns<F: SystemFamily>(
    defining: &Defining<'_, F>,
    start: &CurveStart,
) -> Result<DVector<f64>, ContinuationError> {
    let problem = defining.problem;
    let (p, q) = (start.parameter, start.second_parameter);
    let n = problem.dim();
    if start.state.len() != n {
        return Err(ContinuationError::DimensionMismatch {
            what: "state of the curve start",
            expected: n,
            found: start.state.len(),
        });
    }
    let t0 = start.section_time;
    let d = problem.duration(q)?;
    let full = problem.flow(&start.state, p, q, t0, d, Sensitivity::Transition)?;
    let mut u = DVector::zeros(defining.unknowns());
    match defining.kind {
        CodimOneKind::Grazing => {
            let structure = problem.structure(&[&full], t0, d, &start.state, p, q)?;
            let (tau, _) = structure
                .minima
                .iter()
                .copied()
                .min_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
                .ok_or(ContinuationError::PeriodMapFailed {
                    parameter: p,
                    message: "no local minimum of the gap on the starting orbit".into(),
                })?;
            let shift = (tau - 0.5 * d).rem_euclid(d);
            let moved = problem.flow(&start.state, p, q, t0, shift, Sensitivity::None)?;
            let section = t0 + tau - 0.5 * d;
            defining.section.set(section);
            u.rows_mut(0, n).copy_from_slice(&moved.state);
            u[n] = section + 0.5 * d;
            u[n + 1] = p;
            u[n + 2] = q;
        }
        _ => {
            defining.init_borders(&full.transition);
            u.rows_mut(0, n).copy_from_slice(&start.state);
            u[n] = p;
            u[n + 1] = q;
        }
    }
    Ok(u)
}

/// A curve point from a solved point.
pub(crate) fn point_of<F: SystemFamily>(
    defining: &Defining<'_, F>,
    solved: &Solved,
    at_fixed_second: bool,
) -> CurvePoint {
    let m = solved.u.len();
    let n = defining.n();
    let multipliers = floquet_multipliers(&solved.evaluation.monodromy);
    CurvePoint {
        parameter: solved.u[m - 2],
        second_parameter: solved.u[m - 1],
        state: solved.u.rows(0, n).into_owned(),
        section_time: defining.section.get(),
        grazing_time: (defining.kind == CodimOneKind::Grazing).then(|| solved.u[n]),
        stable: is_stable(&multipliers),
        multipliers,
        structure: solved.evaluation.structure.clone(),
        residual: solved.residual,
        iterations: solved.iterations,
        at_fixed_second,
    }
}

/// The first value in `values` strictly beyond `from` towards `to`, up to and including `to`.
fn crossed(values: &[f64], from: f64, to: f64) -> Option<f64> {
    values
        .iter()
        .copied()
        .filter(|&t| (t - from) * (to - t) >= 0.0 && t != from)
        .min_by(|a, b| (a - from).abs().total_cmp(&(b - from).abs()))
}

/// Trace one half of a curve from `current`, asking `stop` before every step; returns its
/// points (without the start), its codimension-two points and its end.
fn half_curve<F: SystemFamily>(
    defining: &Defining<'_, F>,
    mut current: Current,
    settings: &CurveSettings,
    stop: &dyn Fn() -> bool,
) -> (Vec<CurvePoint>, Vec<Codim2Point>, CurveEnd) {
    defining.section.set(current.section);
    let m = defining.unknowns();
    let (iq, ip) = (m - 1, m - 2);
    let (p_start, q_start) = (current.solved.u[ip], current.solved.u[iq]);
    let mut targets = settings.targets.clone();
    targets.push(q_start);
    targets.push(settings.second_range.0);
    targets.push(settings.second_range.1);
    let (p_low, p_high) = settings.parameter_range;
    let mut points = Vec::new();
    let mut codim2 = Vec::new();
    let mut step = settings.initial_step;
    let end = |reason, current: &Current, error| CurveEnd {
        reason,
        parameters: (current.solved.u[ip], current.solved.u[iq]),
        error,
    };
    let (low, high) = settings.second_range;
    let leaving = current.tangent[iq];
    if (q_start >= high && leaving > 0.0) || (q_start <= low && leaving < 0.0) {
        return (points, codim2, end(CurveStop::RangeEnd, &current, None));
    }
    loop {
        if points.len() >= settings.max_points {
            return (points, codim2, end(CurveStop::MaxPoints, &current, None));
        }
        if stop() {
            return (points, codim2, end(CurveStop::Interrupted, &current, None));
        }
        let tq = current.tangent[iq].abs();
        if tq * step > settings.max_second_step {
            step = settings.max_second_step / tq;
        }
        let (next, range_end) = match advance(defining, &current, step, &targets, settings) {
            Ok(Some(found)) => found,
            Ok(None) => {
                if step <= settings.min_step {
                    let stop = end(CurveStop::StepTooSmall, &current, None);
                    return (points, codim2, stop);
                }
                step = (step * settings.step_cut).max(settings.min_step);
                continue;
            }
            Err(e) => return (points, codim2, end(CurveStop::Error, &current, Some(e))),
        };
        let p = next.solved.u[ip];
        let out_of_range = p < p_low || p > p_high;
        let next = if out_of_range {
            let bound = if p < p_low { p_low } else { p_high };
            match fixed_parameter(defining, &current, &next, ip, bound, settings) {
                Ok(Some(at_bound)) => at_bound,
                Ok(None) => next,
                Err(e) => return (points, codim2, end(CurveStop::Error, &current, Some(e))),
            }
        } else {
            next
        };
        match detect(defining, &current, &next, settings) {
            Ok(found) => codim2.extend(found),
            Err(e) => return (points, codim2, end(CurveStop::Error, &current, Some(e))),
        }
        if next.solved.iterations <= settings.easy_iterations {
            step = (step * settings.step_growth).min(settings.max_step);
        }
        points.push(point_of(defining, &next.solved, next.at_fixed_second));
        if let Err(e) = defining.accept(&next.solved.evaluation, next.solved.u[ip]) {
            return (points, codim2, end(CurveStop::Error, &next, Some(e)));
        }
        current = match recentre(defining, next, &settings.corrector) {
            Ok(c) => c,
            Err(e) => return (points, codim2, end(CurveStop::Error, &current, Some(e))),
        };
        if out_of_range {
            return (
                points,
                codim2,
                end(CurveStop::ParameterBound, &current, None),
            );
        }
        if range_end {
            return (points, codim2, end(CurveStop::RangeEnd, &current, None));
        }
        let (p_now, q_now) = (current.solved.u[ip], current.solved.u[iq]);
        let scale = 1.0 + p_start.abs() + q_start.abs();
        if points.len() > 2
            && current.at_fixed_second
            && (q_now - q_start).abs() <= 1e-12 * scale
            && (p_now - p_start).abs() <= 1e-7 * scale
        {
            points.pop();
            return (points, codim2, end(CurveStop::Closed, &current, None));
        }
    }
}

/// One predictor-corrector step of arclength `step` from `current`, its tangent turn checked
/// and the point placed on a crossed target. `Ok(None)`: cut the step. The flag says whether
/// the point is on an end of the range.
fn advance<F: SystemFamily>(
    defining: &Defining<'_, F>,
    current: &Current,
    step: f64,
    targets: &[f64],
    settings: &CurveSettings,
) -> Result<Option<(Current, bool)>, ContinuationError> {
    let u_pred = &current.solved.u + step * &current.tangent;
    let target = current.tangent.dot(&u_pred);
    let corrected = correct(
        defining,
        u_pred,
        &current.tangent,
        target,
        &settings.corrector,
    )?;
    match corrected {
        Some(solved) => finish_step(defining, current, solved, targets, settings),
        None => Ok(None),
    }
}

/// Check a corrected point's tangent turn and place it on a crossed target. `Ok(None)`: cut
/// the step. The flag says whether the point is on an end of the range.
fn finish_step<F: SystemFamily>(
    defining: &Defining<'_, F>,
    current: &Current,
    solved: Solved,
    targets: &[f64],
    settings: &CurveSettings,
) -> Result<Option<(Current, bool)>, ContinuationError> {
    let m = solved.u.len();
    let iq = m - 1;
    let t = match tangent(&solved.evaluation, &current.tangent, solved.u[m - 2]) {
        Ok(t) => t,
        Err(_) => return Ok(None),
    };
    if t.dot(&current.tangent).clamp(-1.0, 1.0).acos() > settings.max_tangent_angle {
        return Ok(None);
    }
    let next = Current {
        solved,
        tangent: t,
        section: defining.section.get(),
        at_fixed_second: false,
    };
    let (q_from, q_to) = (current.solved.u[iq], next.solved.u[iq]);
    let Some(target) = crossed(targets, q_from, q_to) else {
        return Ok(Some((next, false)));
    };
    let range_end = target == settings.second_range.0 || target == settings.second_range.1;
    Ok(fixed_parameter(defining, current, &next, iq, target, settings)?.map(|c| (c, range_end)))
}

/// The point between `current` and `next` with unknown `j` fixed at `value` (from the linear
/// interpolation), with its tangent; `Ok(None)` if it does not converge.
fn fixed_parameter<F: SystemFamily>(
    defining: &Defining<'_, F>,
    current: &Current,
    next: &Current,
    j: usize,
    value: f64,
    settings: &CurveSettings,
) -> Result<Option<Current>, ContinuationError> {
    let (a, b) = (&current.solved.u, &next.solved.u);
    let w = if b[j] != a[j] {
        ((value - a[j]) / (b[j] - a[j])).clamp(0.0, 1.0)
    } else {
        1.0
    };
    let mut guess = a + w * (b - a);
    guess[j] = value;
    let m = a.len();
    let Some(solved) = correct(defining, guess, &unit(m, j), value, &settings.corrector)? else {
        return Ok(None);
    };
    let Ok(t) = tangent(&solved.evaluation, &next.tangent, solved.u[m - 2]) else {
        return Ok(None);
    };
    Ok(Some(Current {
        solved,
        tangent: t,
        section: defining.section.get(),
        at_fixed_second: j == m - 1,
    }))
}

/// Grazing curves: move the section half a period map away from the grazing time once the
/// latter drifts into the outer twentieths of the period map (state flowed to the new section
/// and corrected there at fixed `q`; if that fails, the section stays).
fn recentre<F: SystemFamily>(
    defining: &Defining<'_, F>,
    current: Current,
    corrector: &crate::shooting::NewtonSettings,
) -> Result<Current, ContinuationError> {
    if defining.kind != CodimOneKind::Grazing {
        return Ok(current);
    }
    let n = defining.n();
    let u = &current.solved.u;
    let (s, p, q) = (u[n], u[n + 1], u[n + 2]);
    let t0 = defining.section.get();
    let d = defining.problem.duration(q)?;
    let fraction = (s - t0) / d;
    if (0.05..=0.95).contains(&fraction) {
        return Ok(current);
    }
    let shift = (s - t0 - 0.5 * d).rem_euclid(d);
    let x = &u.as_slice()[..n];
    let moved = defining
        .problem
        .flow(x, p, q, t0, shift, Sensitivity::None)?;
    defining.section.set(s - 0.5 * d);
    let mut v = u.clone();
    v.rows_mut(0, n).copy_from_slice(&moved.state);
    let mut reference = current.tangent.clone();
    reference.rows_mut(0, n).fill(0.0);
    let m = v.len();
    let corrector = crate::shooting::NewtonSettings {
        max_iterations: 3 * corrector.max_iterations,
        ..corrector.clone()
    };
    let recorrected = correct(defining, v, &unit(m, m - 1), q, &corrector)?;
    let Some(solved) = recorrected.filter(|s| !s.evaluation.touching) else {
        // Keep the old section: the orbit is still inside it.
        defining.section.set(t0);
        return Ok(current);
    };
    let t = tangent(&solved.evaluation, &reference, p)?;
    Ok(Current {
        solved,
        tangent: t,
        section: defining.section.get(),
        at_fixed_second: current.at_fixed_second,
    })
}
