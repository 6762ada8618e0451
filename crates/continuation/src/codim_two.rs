//! Codimension-two points along a codimension-one curve: where it meets another
//! codimension-one condition (MODEL.md section 8).
//!
//! Test functions between consecutive curve points:
//!
//! * grazing curve: `det(M - I)` changes sign (the grazing orbit passes a fold,
//!   `grazing-fold`); `det(M + I)` changes sign (`grazing-period-doubling`); the impacts per
//!   period away from the grazing minimum change (another minimum of the gap crosses zero: two
//!   grazings in one orbit, `double-grazing`);
//! * fold curve: the `q` component of the tangent changes sign (the fold curve turns in `q`:
//!   a `cusp`, where a pair of folds is born); the impacts per period change (the fold orbit
//!   grazes, `grazing-fold`);
//! * period-doubling curve: the impacts per period change (`grazing-period-doubling`).
//!
//! Each change is located by bisection along the secant of the step (each trial corrected on
//! the hyperplane through the secant point, orthogonal to the secant) until the bracket is
//! below the location tolerance in both parameters.

use nalgebra::{Complex, DMatrix, DVector};

use crate::codim_one::{CodimOneKind, Defining};
use crate::curve_corrector::{correct, tangent, Current};
use crate::curve_settings::CurveSettings;
use crate::error::ContinuationError;
use crate::floquet::floquet_multipliers;
use crate::two_parameter::SystemFamily;

/// What meets what at a codimension-two point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Codim2Kind {
    /// A grazing orbit that is also a fold (multiplier `+1`).
    GrazingFold,
    /// A grazing orbit with a multiplier `-1`.
    GrazingPeriodDoubling,
    /// Two minima of the gap grazing in one orbit (`G_n` meets `G_{n+1}`).
    DoubleGrazing,
    /// A fold curve turning in the second parameter: the birth of a pair of folds.
    Cusp,
}

impl Codim2Kind {
    /// `grazing-fold`, `grazing-period-doubling`, `double-grazing` or `cusp`.
    pub fn label(self) -> &'static str {
        match self {
            Codim2Kind::GrazingFold => "grazing-fold",
            Codim2Kind::GrazingPeriodDoubling => "grazing-period-doubling",
            Codim2Kind::DoubleGrazing => "double-grazing",
            Codim2Kind::Cusp => "cusp",
        }
    }
}

/// A located codimension-two point of a curve.
#[derive(Debug, Clone, PartialEq)]
pub struct Codim2Point {
    /// What meets what.
    pub kind: Codim2Kind,
    /// The first parameter `p` at the point.
    pub parameter: f64,
    /// The second parameter `q` at the point.
    pub second_parameter: f64,
    /// The orbit's state at `section_time`.
    pub state: DVector<f64>,
    /// Section time of `state`.
    pub section_time: f64,
    /// Floquet multipliers at the point.
    pub multipliers: Vec<Complex<f64>>,
    /// Impacts per period on either side of the point along the curve (before, after).
    pub impacts: (usize, usize),
    /// Largest extent of the final bracket in `p` and `q`.
    pub precision: f64,
    /// Whether the bracket reached the location tolerance.
    pub converged: bool,
    /// Bisection steps spent.
    pub iterations: usize,
}

/// A test function's value and whether it is a count (any change counts) or continuous (a
/// sign change counts).
type Test = (Codim2Kind, f64, bool);

/// `det(M - mu I)`.
fn shifted_determinant(monodromy: &DMatrix<f64>, mu: f64) -> f64 {
    let mut a = monodromy.clone();
    for i in 0..a.nrows() {
        a[(i, i)] -= mu;
    }
    a.determinant()
}

/// The test functions of a curve at a point.
fn tests<F: SystemFamily>(defining: &Defining<'_, F>, c: &Current) -> Vec<Test> {
    let evaluation = &c.solved.evaluation;
    let impacts = evaluation.structure.impacts as f64;
    match defining.kind {
        CodimOneKind::Grazing => vec![
            (
                Codim2Kind::GrazingFold,
                shifted_determinant(&evaluation.monodromy, 1.0),
                false,
            ),
            (
                Codim2Kind::GrazingPeriodDoubling,
                shifted_determinant(&evaluation.monodromy, -1.0),
                false,
            ),
            (Codim2Kind::DoubleGrazing, impacts, true),
        ],
        CodimOneKind::Fold => vec![
            (Codim2Kind::Cusp, c.tangent[c.tangent.len() - 1], false),
            (Codim2Kind::GrazingFold, impacts, true),
        ],
        CodimOneKind::PeriodDoubling => vec![(Codim2Kind::GrazingPeriodDoubling, impacts, true)],
    }
}

/// Whether two values of a test differ in the way that marks a codimension-two point.
fn changed(a: f64, b: f64, count: bool) -> bool {
    if count {
        a != b
    } else {
        a != 0.0 && b != 0.0 && (a < 0.0) != (b < 0.0)
    }
}

/// Detect and locate every codimension-two point between `a` and `b`.
pub(crate) fn detect<F: SystemFamily>(
    defining: &Defining<'_, F>,
    a: &Current,
    b: &Current,
    settings: &CurveSettings,
) -> Result<Vec<Codim2Point>, ContinuationError> {
    let (ta, tb) = (tests(defining, a), tests(defining, b));
    let mut found = Vec::new();
    for (i, (&(_, va, count), &(_, vb, _))) in ta.iter().zip(&tb).enumerate() {
        if changed(va, vb, count) {
            found.push(locate(defining, a, b, i, settings)?);
        }
    }
    Ok(found)
}

/// Bisection of test `index` between `a` and `b` along their secant.
fn locate<F: SystemFamily>(
    defining: &Defining<'_, F>,
    a: &Current,
    b: &Current,
    index: usize,
    settings: &CurveSettings,
) -> Result<Codim2Point, ContinuationError> {
    let (ua, ub) = (&a.solved.u, &b.solved.u);
    let m = ua.len();
    let delta = ub - ua;
    let tau = &delta / delta.norm().max(f64::MIN_POSITIVE);
    let value_of = |c: &Current| tests(defining, c)[index];
    let (kind, va, count) = value_of(a);
    let (mut lo, mut hi) = (a.clone(), b.clone());
    let (mut s_lo, mut s_hi) = (0.0, 1.0);
    let extent = |x: &Current, y: &Current| {
        (x.solved.u[m - 1] - y.solved.u[m - 1])
            .abs()
            .max((x.solved.u[m - 2] - y.solved.u[m - 2]).abs())
    };
    let mut iterations = 0;
    while extent(&lo, &hi) > settings.location_tolerance
        && iterations < settings.location_max_iterations
    {
        iterations += 1;
        let sigma = 0.5 * (s_lo + s_hi);
        let w = (sigma - s_lo) / (s_hi - s_lo);
        let guess = &lo.solved.u + w * (&hi.solved.u - &lo.solved.u);
        let target = tau.dot(&(ua + sigma * &delta));
        let Some(solved) = correct(defining, guess, &tau, target, &settings.corrector)? else {
            break;
        };
        let Ok(t) = tangent(&solved.evaluation, &lo.tangent, solved.u[m - 2]) else {
            break;
        };
        let trial = Current {
            solved,
            tangent: t,
            section: defining.section.get(),
            at_fixed_second: false,
        };
        if changed(va, value_of(&trial).1, count) {
            hi = trial;
            s_hi = sigma;
        } else {
            lo = trial;
            s_lo = sigma;
        }
    }
    let precision = extent(&lo, &hi);
    let n = defining.n();
    let point = &hi.solved;
    Ok(Codim2Point {
        kind,
        parameter: point.u[m - 2],
        second_parameter: point.u[m - 1],
        state: point.u.rows(0, n).into_owned(),
        section_time: hi.section,
        multipliers: floquet_multipliers(&point.evaluation.monodromy),
        impacts: (
            lo.solved.evaluation.structure.impacts,
            hi.solved.evaluation.structure.impacts,
        ),
        precision,
        converged: precision <= settings.location_tolerance,
        iterations,
    })
}
