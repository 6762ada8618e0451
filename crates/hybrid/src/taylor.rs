//! Taylor-series steps: the solution of a mode expanded in powers of the step's clock offset.
//!
//! Where a system can give the Taylor coefficients of its solution (by the recurrences of
//! automatic differentiation: Moore 1966; Jorba and Zou, Exp. Math. 14 (2005) 99), one series
//! of high order replaces many Runge-Kutta stages: a step is as long as the series converges
//! fast enough for the tolerance, and the polynomial itself is the step's dense output, exact
//! to the same order everywhere in the step. The series is taken in the step's clock variable
//! `s` (time, or the square root of the time from a crossing): on a square-root clock the
//! solution next to a Hertz contact's onset or release is analytic in `s`, though not in time.
//!
//! The solver takes a Taylor step wherever the system gives series of the mode's solution
//! ([`crate::HybridSystem::taylor_order_limit`] at least 20, the order of the state's series;
//! the AFM model does in Hertz contact), and Runge-Kutta steps elsewhere (see the solver's
//! module documentation). The tangents (transition matrix and `dx/dp`) are expanded along the
//! state's series by the system's [`crate::HybridSystem::taylor_tangents`], to the state's
//! order, or to order 12 under a [`SensitivityMethod::Decoupled`] integration, whose steps then
//! also keep the tangents' last two terms below 1e-5.

use crate::settings::{SensitivityMethod, Settings};
use crate::system::{HybridSystem, Mode};

/// The time along a step as a polynomial in the step's clock offset `s` (the clock reading
/// minus its reading at the step start): `t(s) = start + rate s + curvature s^2`. On the time
/// clock `rate = 1`, `curvature = 0`; on a square-root clock with reference `t_r` and start
/// reading `sigma0` (`t = t_r + sigma |sigma|`, `sigma` of one sign over a step),
/// `rate = 2 |sigma0|` and `curvature = sign(sigma)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClockPolynomial {
    /// `t(0)`, the step's start time (system time units).
    pub start: f64,
    /// `dt/ds` at the start.
    pub rate: f64,
    /// `(1/2) d^2t/ds^2`.
    pub curvature: f64,
}

impl ClockPolynomial {
    /// The time at clock offset `s`.
    #[inline]
    pub fn time(&self, s: f64) -> f64 {
        self.start + s * (self.rate + s * self.curvature)
    }

    /// `dt/ds` at clock offset `s`.
    #[inline]
    pub fn time_rate(&self, s: f64) -> f64 {
        self.rate + 2.0 * s * self.curvature
    }
}

/// The Taylor coefficients `c_{k,i}` (`k = 0..=order`) of a vector function `y(s) = sum_k
/// c_{k,i} s^k` of the clock offset `s`, for `dim` components, stored power by power (row `k`
/// holds coefficient `k` of every component: the recurrences fill a row at a time, and Horner's
/// rule runs over whole rows).
#[derive(Debug, Clone, PartialEq)]
pub struct TaylorSeries {
    order: usize,
    dim: usize,
    coefficients: Vec<f64>,
}

impl TaylorSeries {
    /// A zero series of `dim` components to `order`.
    pub fn new(dim: usize, order: usize) -> Self {
        Self {
            order,
            dim,
            coefficients: vec![0.0; dim * (order + 1)],
        }
    }

    /// The highest power kept.
    pub fn order(&self) -> usize {
        self.order
    }

    /// The number of components.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Coefficient `k` of every component.
    #[inline]
    pub fn row(&self, k: usize) -> &[f64] {
        &self.coefficients[k * self.dim..(k + 1) * self.dim]
    }

    /// Every coefficient, row by row (`dim` per power).
    pub fn coefficients(&self) -> &[f64] {
        &self.coefficients
    }

    /// Every coefficient, to write.
    pub fn coefficients_mut(&mut self) -> &mut [f64] {
        &mut self.coefficients
    }

    /// Set the constant terms from `values` (length `dim`); the other rows are left for the
    /// recurrences to write.
    pub fn start_at(&mut self, values: &[f64]) {
        self.coefficients[..self.dim].copy_from_slice(values);
    }

    /// `y(s)` into `out` (its leading `out.len() <= dim` components), by Horner's rule.
    pub fn evaluate(&self, s: f64, out: &mut [f64]) {
        // The common small dimensions as constants, so that the row loop unrolls into
        // registers (the state of one or two modes, their tangents with and without dx/dp).
        match self.dim {
            2 => self.evaluate_fixed::<2>(s, out),
            4 => self.evaluate_fixed::<4>(s, out),
            16 => self.evaluate_fixed::<16>(s, out),
            20 => self.evaluate_fixed::<20>(s, out),
            dim => {
                let m = out.len();
                out.copy_from_slice(&self.coefficients[self.order * dim..][..m]);
                for row in self.coefficients.chunks_exact(dim).rev().skip(1) {
                    for (o, &c) in out.iter_mut().zip(row) {
                        *o = *o * s + c;
                    }
                }
            }
        }
    }

    /// `y(r_j - origin)` for every reading `r_j` of `readings` (a clock whose reading is
    /// `origin` where the series starts), into `out` (`dim` per reading, in order), by Horner's
    /// rule across the readings at once: each value is the one [`TaylorSeries::evaluate`] gives
    /// at `r_j - origin`, for less work than one call per reading.
    pub fn evaluate_many(&self, origin: f64, readings: &[f64], out: &mut [f64]) {
        const BLOCK: usize = 8;
        let dim = self.dim;
        for (readings, values) in readings.chunks(BLOCK).zip(out.chunks_mut(BLOCK * dim)) {
            // The offsets, padded with zeros (lanes evaluated and dropped).
            let mut offsets = [0.0; BLOCK];
            for (offset, reading) in offsets.iter_mut().zip(readings) {
                *offset = reading - origin;
            }
            // The state of one or two modes as constants, at 4 offsets (a 4-point quadrature)
            // or up to 8.
            match (dim, readings.len()) {
                (2, 4) => self.evaluate_block::<2, 4>(&offsets, values),
                (4, 4) => self.evaluate_block::<4, 4>(&offsets, values),
                (2, _) => self.evaluate_block::<2, BLOCK>(&offsets, values),
                (4, _) => self.evaluate_block::<4, BLOCK>(&offsets, values),
                _ => {
                    for (&s, value) in offsets.iter().zip(values.chunks_exact_mut(dim)) {
                        self.evaluate(s, value);
                    }
                }
            }
        }
    }

    /// [`TaylorSeries::evaluate_many`] for `dim == D` at the first `P` offsets of `s`, into the
    /// points `out` holds (`out.len() / D <= P`): the values held component by component, so
    /// that the loop over offsets vectorises.
    #[inline(always)]
    fn evaluate_block<const D: usize, const P: usize>(&self, s: &[f64], out: &mut [f64]) {
        let s = &s[..P];
        let mut value = [[0.0; P]; D];
        for row in self.coefficients.chunks_exact(D).rev() {
            for (component, &c) in value.iter_mut().zip(row) {
                for (v, &s) in component.iter_mut().zip(s) {
                    *v = *v * s + c;
                }
            }
        }
        for (j, point) in out.chunks_exact_mut(D).enumerate() {
            for (d, x) in point.iter_mut().enumerate() {
                *x = value[d][j];
            }
        }
    }

    /// [`TaylorSeries::evaluate`] for `dim == D`.
    #[inline(always)]
    fn evaluate_fixed<const D: usize>(&self, s: f64, out: &mut [f64]) {
        let mut value = [0.0; D];
        for row in self.coefficients.chunks_exact(D).rev() {
            for (v, &c) in value.iter_mut().zip(row) {
                *v = *v * s + c;
            }
        }
        out.copy_from_slice(&value[..out.len()]);
    }

    /// `dy/ds` at `s` into `out` (length `dim`).
    pub fn derivative(&self, s: f64, out: &mut [f64]) {
        let dim = self.dim;
        out.fill(0.0);
        for (k, row) in self
            .coefficients
            .chunks_exact(dim)
            .enumerate()
            .skip(1)
            .rev()
        {
            let k = k as f64;
            for (o, &c) in out.iter_mut().zip(row) {
                *o = *o * s + k * c;
            }
        }
    }

    /// The polynomial `sum_k (w . c_k) s^k` of the weighted sum `w . y(s)` of the components
    /// (`w` of length `dim`), into `out` (length `order + 1`).
    pub fn weighted_sum(&self, weights: &[f64], out: &mut [f64]) {
        // The common small dimensions as constants, so that the dot products unroll.
        match (self.dim, weights.len()) {
            (2, 2) => Self::weighted_sum_rows::<2>(&self.coefficients, weights, out),
            (4, 4) => Self::weighted_sum_rows::<4>(&self.coefficients, weights, out),
            _ => {
                for (o, row) in out.iter_mut().zip(self.coefficients.chunks_exact(self.dim)) {
                    *o = row.iter().zip(weights).map(|(c, w)| c * w).sum();
                }
            }
        }
    }

    /// [`TaylorSeries::weighted_sum`] of rows of `D` coefficients (`weights` of length `D`).
    #[inline(always)]
    fn weighted_sum_rows<const D: usize>(coefficients: &[f64], weights: &[f64], out: &mut [f64]) {
        let weights = &weights[..D];
        for (o, row) in out.iter_mut().zip(coefficients.chunks_exact(D)) {
            *o = row.iter().zip(weights).map(|(c, w)| c * w).sum();
        }
    }
}

/// The order of the solver's Taylor-series steps. At a tolerance of 1e-12 a series of order 20
/// reaches about a quarter of its radius of convergence (`1e-12^(1/20)`); through a Hertz
/// contact of the Biolever on mica that is 8 steps per contact against ~30 DOP853 attempts
/// (orders 16 / 24 / 30: 12 / 6 / 5 steps, each dearer as the order squared).
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
/// period of the Biolever on mica at tolerance 1e-12 within 1.3e-6 and 2.3e-6 relative at
/// A/A0 = 0.95 and 0.5, against 6e-9 and 4e-8 at the state's order; `cargo run --release -p
/// afm --example monodromy_error`), at under half the cost. Order 14 was as accurate at
/// tolerance 1e-12 (1.0e-6 and 2.3e-6) and more so at the first Newton map's 1e-9 (4.9e-7
/// and 1.9e-4 against 8.7e-4 and 1.6e-4), for 3.3% more instructions per steady orbit from
/// its neighbour at A/A0 = 0.5 (1.765M against 1.708M) and 4.8% at 0.9. Along approach
/// branches in 0.01 to 0.02 nm steps (scratch driver, callgrind) order 12 took 1.9%, 0.7% and
/// 3.7% fewer instructions for the Biolever on mica, MAClever on mica and Biolever on the
/// soft sample, with the same Newton iterations except 12 more of 965 MAClever orbits taking
/// 3 instead of 2; orders 10, 11 and 13 were slower or less accurate.
pub(crate) const DECOUPLED_TANGENT_ORDER: usize = 12;

/// The tangent series' tolerance (relative and absolute) on the steps of a
/// [`crate::SensitivityMethod::Decoupled`] integration. It binds only where the state's is
/// looser: at 1e-8 the monodromy above comes within 2.0e-3 and 2.3e-3 (at order 14, where
/// this was chosen, 3e-4 and 8e-4; there 1e-6 gave 1e-5 and 4e-5 for 3% more instructions per
/// steady orbit from its neighbour, 1e-4 gave 7e-3).
pub(crate) const DECOUPLED_TANGENT_TOLERANCE: f64 = 1e-5;

/// The rows of `columns` values beyond the tangents' order that the scratch space of
/// [`HybridSystem::taylor_tangents`] holds without allocating (the AFM model's contact
/// recurrence keeps one row per power up to the order, and one more).
pub(crate) const TANGENT_SCRATCH_ROWS: usize = 2;

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
    /// Scratch for [`crate::HybridSystem::taylor_tangents`] and the tangents' row-major
    /// start and value.
    scratch: Vec<f64>,
    rows: Vec<f64>,
}

impl TaylorStep {
    /// Storage for `n` states and `columns` tangent columns (0: none), the tangents to the
    /// order [`tangent_control`] gives for `settings`, and scratch for
    /// [`HybridSystem::taylor_tangents`] with room for [`TANGENT_SCRATCH_ROWS`] more rows of
    /// `columns` than that order.
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
            scratch: Vec::with_capacity((order + TANGENT_SCRATCH_ROWS) * columns),
            rows: vec![0.0; n * columns],
        }
    }

    /// Expand the state of `mode` from `x0` on `clock`; `false` if the system gives no series.
    pub fn expand<S: HybridSystem + ?Sized>(
        &mut self,
        system: &S,
        mode: Mode,
        clock: ClockPolynomial,
        x0: &[f64],
    ) -> bool {
        self.clock = clock;
        self.surface = None;
        self.state.start_at(x0);
        system.taylor_series(mode, &clock, &mut self.state)
    }

    /// Expand the tangents from `start` (column-major `n x columns`, the solver's layout)
    /// along the state's series.
    pub fn expand_tangents<S: HybridSystem + ?Sized>(
        &mut self,
        system: &S,
        mode: Mode,
        start: &[f64],
        parameter_column: bool,
    ) {
        let n = self.state.dim();
        transpose(start, n, &mut self.rows);
        self.tangents.start_at(&self.rows);
        system.taylor_tangents(
            mode,
            &self.clock,
            &self.state,
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
    /// and 4e-3 in the monodromy (MAClever on soft, A0 = 3 nm, up to 2e-5 nm past the merge at
    /// 1.6263 nm). Measured there with this bound: at most 1.3e-11 nm and 2.4e-8 (relative),
    /// against DOP853 at 1e-13, for 27 to 40 series steps per period instead of 11; a quarter
    /// of the radius took 52 to 77 and was no more accurate, three quarters 21 to 30 (9e-8).
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
///   a quarter of a step apart, where the series' radius is about four steps; 16 samples cost
///   1.6% more of an orbit at A/A0 = 0.5 and gave the same outputs.)
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

    /// `evaluate_many` gives, bit for bit, what `evaluate` gives at each reading's offset from
    /// the origin: for the dimensions it specialises (2 and 4 components; 4 readings, and up to
    /// 8 in a padded block) and for another (3 components), with 4, 5, 7, 8 and 11 readings (a
    /// block of 8 and a rest).
    #[test]
    fn evaluation_at_many_offsets_equals_one_at_a_time() {
        for dim in [2, 3, 4] {
            let mut series = TaylorSeries::new(dim, 20);
            for (i, c) in series.coefficients_mut().iter_mut().enumerate() {
                *c = ((i * 37 % 23) as f64 - 11.0) / (1.0 + i as f64);
            }
            for count in [4, 5, 7, 8, 11] {
                let origin = 0.3;
                let readings: Vec<f64> = (0..count).map(|j| 0.9 * j as f64 / 7.0 + 0.1).collect();
                let mut together = vec![0.0; count * dim];
                series.evaluate_many(origin, &readings, &mut together);
                for (&reading, value) in readings.iter().zip(together.chunks_exact(dim)) {
                    let mut alone = vec![0.0; dim];
                    let s = reading - origin;
                    series.evaluate(s, &mut alone);
                    assert_eq!(value, &alone[..], "dim {dim}, {count} offsets, s = {s}");
                }
            }
        }
    }

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

    #[test]
    fn series_evaluates_every_component_and_its_derivative() {
        // y_0 = 1 + 2 s - s^3, y_1 = 3 - s^2 (order 3).
        let mut series = TaylorSeries::new(2, 3);
        series
            .coefficients_mut()
            .copy_from_slice(&[1.0, 3.0, 2.0, 0.0, 0.0, -1.0, -1.0, 0.0]);
        let s = -0.4_f64;
        let mut y = [0.0; 2];
        series.evaluate(s, &mut y);
        assert!((y[0] - (1.0 + 2.0 * s - s.powi(3))).abs() < 1e-15);
        assert!((y[1] - (3.0 - s * s)).abs() < 1e-15);
        series.derivative(s, &mut y);
        assert!((y[0] - (2.0 - 3.0 * s * s)).abs() < 1e-15);
        assert!((y[1] + 2.0 * s).abs() < 1e-15);
        let mut sum = [0.0; 4];
        series.weighted_sum(&[1.0, 2.0], &mut sum);
        assert_eq!(sum, [7.0, 2.0, -2.0, -1.0]);
    }

    #[test]
    fn clock_polynomial_of_a_square_root_clock_matches_the_clock() {
        // t = 2 + sigma |sigma| from sigma0 = -0.5 (reading negative over the step).
        let sigma0 = -0.5_f64;
        let clock = ClockPolynomial {
            start: 2.0 - 0.25,
            rate: 2.0 * sigma0.abs(),
            curvature: -1.0,
        };
        for s in [0.0, 0.1, 0.3, 0.5] {
            let sigma = sigma0 + s;
            assert!((clock.time(s) - (2.0 + sigma * sigma.abs())).abs() < 1e-15);
            assert!((clock.time_rate(s) - 2.0 * sigma.abs()).abs() < 1e-15);
        }
    }
}
