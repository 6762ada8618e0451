//! The solver's Taylor-series steps: the order of the state's and the tangents' series, the
//! step's reach (how far the series may be summed within the tolerance), and the zeros and
//! ridges of a switching function along the series (what limits the step next to a contact's
//! onset or release). The series themselves are [`crate::taylor`]'s; the solver's use of them
//! is documented in [`crate::solver`].

use crate::accelerations::TaylorExpansion;
use crate::mode::Mode;
use crate::settings::{SensitivityMethod, Settings};
use crate::taylor::{ClockPolynomial, TaylorSeries};

/// The order of the solver's Taylor-series steps. At a tolerance of 1e-12 a series of order 20
/// reaches about a quarter of its radius of convergence (`1e-12^(1/20)`): a few steps through
/// a Hertz contact, where DOP853 takes tens of attempts. A higher order takes fewer steps, each
/// dearer as the order squared; a lower one more.
pub(crate) const TAYLOR_ORDER: usize = 20;

/// The order of the tangent series and the tolerance on their last two terms (limiting the
/// step with the state's) under `settings`: the state's order and `sensitivity_tolerance` for
/// [`SensitivityMethod::Coupled`] (the tangents as accurate as the state's series);
/// [`DECOUPLED_TANGENT_ORDER`] and [`DECOUPLED_TANGENT_TOLERANCE`] for
/// [`SensitivityMethod::Decoupled`].
pub(crate) fn tangent_control(settings: &Settings) -> (usize, Option<f64>) {
    match settings.sensitivity_method {
        SensitivityMethod::Coupled => (TAYLOR_ORDER, settings.sensitivity_tolerance),
        // (Decoupled settings have no sensitivity_tolerance: validation refuses one.)
        SensitivityMethod::Decoupled => {
            (DECOUPLED_TANGENT_ORDER, Some(DECOUPLED_TANGENT_TOLERANCE))
        }
    }
}

/// The order of the tangent series on the steps of a [`crate::SensitivityMethod::Decoupled`]
/// integration (the state's stays [`TAYLOR_ORDER`]): enough for Newton (the monodromy over a
/// period within about 1e-6 relative at tolerance 1e-12, where the state's order gives about
/// 1e-8; `cargo run --release -p afm --example monodromy_error` measures it), at under half
/// the cost of the state's order. A higher order costs more per step for the same Newton
/// iterations; a lower one loses accuracy.
pub(crate) const DECOUPLED_TANGENT_ORDER: usize = 12;

/// The tangent series' tolerance (relative and absolute) on the steps of a
/// [`crate::SensitivityMethod::Decoupled`] integration. It binds only where the state's is
/// looser (a first, loose Newton map), where it keeps the monodromy within a few 1e-3: enough
/// for the iteration to contract. Tighter costs more steps for no fewer iterations.
pub(crate) const DECOUPLED_TANGENT_TOLERANCE: f64 = 1e-5;

/// The rows of `columns` values beyond the tangents' order that the scratch space of
/// [`crate::TaylorExpansion::taylor_tangents`] holds without allocating (the AFM model's contact
/// recurrence keeps one row per power up to the order, and one more).
pub(crate) const TANGENT_SCRATCH_ROWS: usize = 2;

/// The capacity (values) of the `shared` vector a [`TaylorStep`] passes to
/// [`crate::TaylorExpansion::taylor_series`] and `taylor_tangents`: sixteen series of order 40,
/// so that an implementation keeping no more there allocates nothing in a step.
pub const SHARED_SERIES_CAPACITY: usize = 16 * 41;

/// One Taylor-series step of the solver: the state's series (and the tangents' when
/// sensitivities are carried) about the step start, in the step's clock offset.
#[derive(Debug, Clone)]
pub(crate) struct TaylorStep {
    /// The state's series (`n` components).
    pub state: TaylorSeries,
    /// The tangent matrix's series (`n x columns`, row-major coefficients).
    pub tangents: TaylorSeries,
    /// The step's clock `t(s)`.
    pub clock: ClockPolynomial,
    /// The step's length in its clock variable.
    pub length: f64,
    /// The polynomial in the clock offset of an affine surface `k` along the state's series,
    /// `(k, coefficients)`, where the solver formed it for this series (its constant term is
    /// the caller's; cleared by [`TaylorStep::expand`]).
    pub surface: Option<(usize, [f64; TAYLOR_ORDER + 1])>,
    /// What the system's state recurrence leaves for its tangent recurrence along the same
    /// series (the `shared` of [`crate::TaylorExpansion::taylor_series`]).
    shared: Vec<f64>,
    /// Scratch for [`crate::TaylorExpansion::taylor_tangents`] and the tangents' row-major
    /// start and value.
    scratch: Vec<f64>,
    rows: Vec<f64>,
}

impl TaylorStep {
    /// Storage for `n` states and `columns` tangent columns (0: none), the tangents to the order
    /// [`tangent_control`] gives for `settings`, and scratch for
    /// [`crate::TaylorExpansion::taylor_tangents`] with room for [`TANGENT_SCRATCH_ROWS`] more rows
    /// of `columns` than that order.
    pub fn new(n: usize, columns: usize, settings: &Settings) -> Self {
        let order = tangent_control(settings).0;
        Self {
            state: TaylorSeries::new(n, TAYLOR_ORDER),
            tangents: TaylorSeries::new(n * columns, order),
            clock: ClockPolynomial {
                start: 0.0,
                rate: 1.0,
                curvature: 0.0,
            },
            length: 0.0,
            surface: None,
            shared: Vec::with_capacity(SHARED_SERIES_CAPACITY),
            scratch: Vec::with_capacity((order + TANGENT_SCRATCH_ROWS) * columns),
            rows: vec![0.0; n * columns],
        }
    }

    /// Expand the state of `mode` from `x0` on `clock`; `false` if the system gives no series.
    pub fn expand(
        &mut self,
        expansion: &dyn TaylorExpansion,
        mode: Mode,
        clock: ClockPolynomial,
        x0: &[f64],
    ) -> bool {
        self.clock = clock;
        self.surface = None;
        self.state.start_at(x0);
        expansion.taylor_series(mode, &clock, &mut self.state, &mut self.shared)
    }

    /// Expand the tangents from `start` (column-major `n x columns`, the solver's layout)
    /// along the state's series: to be called only right after [`TaylorStep::expand`]
    /// succeeded (the system reuses what its state recurrence left).
    pub fn expand_tangents(
        &mut self,
        expansion: &dyn TaylorExpansion,
        mode: Mode,
        start: &[f64],
        parameter_column: bool,
    ) {
        let n = self.state.dim();
        transpose(start, n, &mut self.rows);
        self.tangents.start_at(&self.rows);
        expansion.taylor_tangents(
            mode,
            &self.clock,
            &self.state,
            &mut self.shared,
            &mut self.tangents,
            parameter_column,
            &mut self.scratch,
        );
    }

    /// The tangents at clock offset `s` into `out` (column-major, the solver's layout).
    pub fn tangents_at(&mut self, s: f64, out: &mut [f64]) {
        let n = self.state.dim();
        self.tangents.evaluate(s, &mut self.rows);
        let columns = self.rows.len() / n.max(1);
        transpose(&self.rows, columns, out);
    }

    /// The longest clock step a series whose radius of convergence is `radius` may take when
    /// a singularity of the solution is too weak for the last terms of the state's series to
    /// show it ([`TaylorStep::reach`]): half the radius, where the singular part's terms fall by
    /// `2^-k` and the state's last terms bound the rest. A Hertz contact whose indentation has
    /// a shallow minimum between two deep ones (just after two contacts merge) has branch points
    /// off the real axis next to that ridge ([`surface_ahead`]), and series steps across it,
    /// accepted by the state's terms alone, left errors of up to 1.5e-6 nm in the period map
    /// and 4e-3 in the monodromy (MAClever on soft, A0 = 3 nm, just past the merge at 1.6263
    /// nm). Within half the radius the errors stay at the tolerance's level (tested in
    /// `afm/tests/contact_ridge.rs`); a smaller fraction costs more steps for no accuracy, a
    /// larger one loses it.
    pub fn radius_reach(radius: f64) -> f64 {
        0.5 * radius
    }

    /// The longest clock step over which the last two terms of `series` stay below the
    /// tolerance `absolute + relative |y_i(0)|`, measured component-wise and taking the largest
    /// ratio: `min_{k = p-1, p} (1 / max_i (|c_{k,i}| / tolerance_i))^(1/k)` (Jorba and Zou
    /// 2005, Sec. 3.2). The terms beyond decay geometrically by about `1e-12^(1/p)` each, so the
    /// truncation error is about the tolerance.
    pub fn reach(series: &TaylorSeries, relative: f64, absolute: f64) -> f64 {
        let p = series.order();
        // The largest ratio of each of the last two terms to its component's tolerance.
        let (below, last) = series
            .row(p - 1)
            .iter()
            .zip(series.row(p))
            .zip(series.row(0))
            .fold(
                (0.0, 0.0),
                |(below, last): (f64, f64), ((c_below, c_last), y0)| {
                    let weight = 1.0 / (absolute + relative * y0.abs());
                    (
                        below.max(c_below.abs() * weight),
                        last.max(c_last.abs() * weight),
                    )
                },
            );
        // min_k size_k^(-1/k) as one exponential of the smaller exponent.
        let exponent = [(below, p - 1), (last, p)]
            .into_iter()
            .filter(|&(size, _)| size > 0.0)
            .map(|(size, k)| -size.ln() / k as f64)
            .fold(f64::INFINITY, f64::min);
        exponent.exp()
    }
}

impl TaylorStep {
    /// [`TaylorStep::reach`] of one polynomial `power` (power-basis coefficients, a switching
    /// function along the series): the longest clock step over which its last two terms stay
    /// below `absolute + relative |power[0]|`.
    pub fn polynomial_reach(power: &[f64], relative: f64, absolute: f64) -> f64 {
        let p = power.len() - 1;
        let weight = 1.0 / (absolute + relative * power[0].abs());
        [
            (power[p - 1].abs() * weight, p - 1),
            (power[p].abs() * weight, p),
        ]
        .into_iter()
        .filter(|&(size, _)| size > 0.0)
        .map(|(size, k)| -size.ln() / k as f64)
        .fold(f64::INFINITY, f64::min)
        .exp()
    }
}

/// What a step's series shows of a surface ahead, from the polynomial of `h_k` in the clock
/// offset: its first zero, and the radius of convergence a ridge limits the series to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SurfaceAhead {
    /// The first zero in `(0, upto]` ([`surface_ahead`]).
    pub zero: Option<f64>,
    /// A ridge before that zero ([`surface_ahead`]).
    pub ridge: Option<Ridge>,
}

/// A ridge of a surface: where `side h_k` has a positive local minimum `g_m`, and the half
/// width `sqrt(2 g_m / g'')` of the quadratic through it, whose complex zeros `s_m +- i
/// half_width` are branch points of a field with `|h_k|^{1/2}`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Ridge {
    /// Clock offset (or time) of the minimum.
    pub at: f64,
    /// Half width, in the same unit.
    pub half_width: f64,
}

impl Ridge {
    /// The distance from offset (or time) `s` to the ridge's complex zeros: the radius of
    /// convergence it leaves a series centred at `s`.
    pub fn radius_from(&self, s: f64) -> f64 {
        (self.at - s).hypot(self.half_width)
    }
}

/// The polynomial with power-basis coefficients `power` (the half-power surface `h_k` along a
/// step's series, `side` the sign of `h_k` on the mode's side) sampled at 8 points in `(0,
/// upto]`:
///
/// * its first zero there, if its sign changes: bracketed on the samples, then bisection
///   safeguarding Newton's method to the last bits. Two zeros between neighbouring samples go
///   unseen: the solver uses this only to choose a step's clock, and finds crossings inside a
///   step by its own tests. (The solver looks up to two steps' reach ahead, so the samples are
///   a quarter of a step apart, where the series' radius is about four steps: denser samples
///   would find nothing more.)
/// * a ridge before it: the first point (the start or a sample) nearer the surface than both
///   its neighbours (`side h` a local minimum, still on the mode's side; at the start, falling
///   towards the surface), the minimum `g_m = side h(s_m) > 0` located as the zero of the
///   slope between them, and with the curvature `g''` there the
///   distance `sqrt(s_m^2 + 2 g_m / g'')` to the pair of complex zeros `s_m +- i sqrt(2 g_m /
///   g'')` of the quadratic through it. A field with `|h|^{1/2}` (Hertz) is singular there: two
///   contacts just merged leave a shallow ridge of indentation between them, and a series step
///   across it had diverged unseen, the force there being below the tolerance (see
///   [`TaylorStep::radius_reach`]).
pub(crate) fn surface_ahead<const D: usize>(
    power: &[f64; D],
    upto: f64,
    side: f64,
) -> SurfaceAhead {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the CPU has AVX, checked just above.
        return unsafe { surface_ahead_avx(power, upto, side) };
    }
    surface_ahead_any(power, upto, side)
}

/// [`surface_ahead_any`] compiled for AVX (wider lanes for the samples, the same operations in
/// the same order: the same bits).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn surface_ahead_avx<const D: usize>(power: &[f64; D], upto: f64, side: f64) -> SurfaceAhead {
    surface_ahead_any(power, upto, side)
}

/// [`surface_ahead`] for any CPU.
#[inline(always)]
fn surface_ahead_any<const D: usize>(power: &[f64; D], upto: f64, side: f64) -> SurfaceAhead {
    const SAMPLES: usize = 8;
    let none = SurfaceAhead {
        zero: None,
        ridge: None,
    };
    let value = |s: f64| power.iter().rev().fold(0.0, |acc, &c| acc * s + c);
    let slope = |s: f64| {
        power
            .iter()
            .enumerate()
            .skip(1)
            .rev()
            .fold(0.0, |acc, (k, &c)| acc * s + k as f64 * c)
    };
    let start = power[0];
    // No zero where the constant term outweighs the rest on the whole interval (nor a ridge,
    // which comes near zero).
    let mut scale = 1.0;
    let spread: f64 = power[1..]
        .iter()
        .map(|c| {
            scale *= upto;
            c.abs() * scale
        })
        .sum();
    if spread < start.abs() {
        return none;
    }
    // The samples evaluated together (Horner's rule across them), so that the loop vectorises.
    let mut points = [0.0; SAMPLES];
    for (j, point) in points.iter_mut().enumerate() {
        *point = upto * (j + 1) as f64 / SAMPLES as f64;
    }
    let mut values = [0.0; SAMPLES];
    for &c in power.iter().rev() {
        for (v, &s) in values.iter_mut().zip(&points) {
            *v = *v * s + c;
        }
    }
    let mut lower = 0.0;
    let mut zero = None;
    let mut crossed = SAMPLES;
    for (j, (&s, &v)) in points.iter().zip(&values).enumerate() {
        if v == 0.0 || (v > 0.0) != (start > 0.0) {
            zero = Some(bisect_newton(value, slope, lower, s, start > 0.0));
            crossed = j;
            break;
        }
        lower = s;
    }
    // A ridge: a point before the crossing nearer the surface than its neighbours, on the
    // mode's side; the series' start is one, with its slope (towards the surface) for the
    // neighbour before it.
    let g = |j: usize| side * if j == 0 { start } else { values[j - 1] };
    let ridge = (0..SAMPLES).take_while(|&j| j <= crossed).find(|&j| {
        let falling = if j == 0 {
            side * power[1] < 0.0
        } else {
            g(j) < g(j - 1)
        };
        g(j) > 0.0 && falling && g(j) <= g(j + 1)
    });
    let ridge = ridge.and_then(|j| {
        let left = if j <= 1 { 0.0 } else { points[j - 2] };
        let right = points[j];
        // side h' goes from negative to positive across the minimum.
        let rate = |s: f64| side * slope(s);
        let curvature = |s: f64| {
            side * power
                .iter()
                .enumerate()
                .skip(2)
                .rev()
                .fold(0.0, |acc, (k, &c)| acc * s + (k * (k - 1)) as f64 * c)
        };
        if !(rate(left) < 0.0 && rate(right) > 0.0) {
            return None;
        }
        let s_m = bisect_newton(rate, curvature, left, right, false);
        let (g_m, g2) = (side * value(s_m), curvature(s_m));
        (g_m > 0.0 && g2 > 0.0).then(|| Ridge {
            at: s_m,
            half_width: (2.0 * g_m / g2).sqrt(),
        })
    });
    SurfaceAhead { zero, ridge }
}

/// The zero of `value` in `(lower, upper]`, where it changes sign (`positive_start`: the sign
/// at `lower`), by bisection safeguarding Newton's method to the last bits.
#[inline(always)]
fn bisect_newton(
    value: impl Fn(f64) -> f64,
    slope: impl Fn(f64) -> f64,
    mut lower: f64,
    mut upper: f64,
    positive_start: bool,
) -> f64 {
    let mut x = 0.5 * (lower + upper);
    for _ in 0..200 {
        let f = value(x);
        if f == 0.0 {
            return x;
        }
        if (f > 0.0) == positive_start {
            lower = x;
        } else {
            upper = x;
        }
        let newton = x - f / slope(x);
        x = if newton > lower && newton < upper {
            newton
        } else {
            0.5 * (lower + upper)
        };
        if upper - lower <= 4.0 * f64::EPSILON * upper {
            break;
        }
    }
    upper
}

/// Transpose the `rows x (len / rows)` matrix `from` (column-major) into `to` (row-major);
/// the same call maps row-major `len / rows` rows back to column-major.
fn transpose(from: &[f64], rows: usize, to: &mut [f64]) {
    if rows == 0 {
        return;
    }
    let columns = from.len() / rows;
    for (c, column) in from.chunks_exact(rows).enumerate() {
        for (r, &v) in column.iter().enumerate() {
            to[r * columns + c] = v;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// In contact (`h < 0` inside, side -1) the indentation `g = -h = g_m + a (s - s_m)^2` has a
    /// ridge at `s_m` and zeros at `s_m +- i sqrt(g_m / a)`: the radius is `sqrt(s_m^2 + g_m /
    /// a)` exactly (the quadratic is its own fit), with no zero on the real axis. Deepened
    /// into a crossing (`g_m < 0`) it has a first zero at `s_m - sqrt(-g_m / a)` and no ridge.
    /// A monotone indentation has neither.
    #[test]
    fn surface_ahead_finds_a_ridge_and_its_complex_zeros_or_the_crossing() {
        let (s_m, a) = (0.37, 2.0);
        let polynomial = |g_m: f64| {
            let mut power = [0.0; TAYLOR_ORDER + 1];
            power[0] = -(g_m + a * s_m * s_m);
            power[1] = 2.0 * a * s_m;
            power[2] = -a;
            power
        };
        for g_m in [1e-3, 1e-7, 1e-12] {
            let ahead = surface_ahead(&polynomial(g_m), 1.0, -1.0);
            assert_eq!(ahead.zero, None);
            let radius = ahead.ridge.expect("a ridge").radius_from(0.0);
            let exact = (s_m * s_m + g_m / a).sqrt();
            assert!(
                (radius - exact).abs() < 1e-12 * exact,
                "g_m {g_m}: {radius} vs {exact}"
            );
        }
        let g_m = -1e-4;
        let ahead = surface_ahead(&polynomial(g_m), 1.0, -1.0);
        let exact = s_m - (-g_m / a).sqrt();
        assert!((ahead.zero.expect("a crossing") - exact).abs() < 1e-14);
        assert_eq!(ahead.ridge, None);
        let mut monotone = [0.0; TAYLOR_ORDER + 1];
        monotone[0] = -0.5;
        monotone[1] = -1.0;
        assert_eq!(
            surface_ahead(&monotone, 1.0, -1.0),
            SurfaceAhead {
                zero: None,
                ridge: None
            }
        );
    }
}
