//! The Taylor series of Eq. 1 in Hertz contact (and DMT's shifted Hertz contact and van der
//! Waals free flight, [`SeriesForce`]; MODEL.md section 9), by the recurrences of automatic
//! differentiation, in the clock offset `s` of a solver step (`t = t(s)`, a quadratic
//! [`ClockPolynomial`]).
//!
//! For van der Waals, `F_ts = -A u^2` with `u = 1/d`, whose coefficients follow from
//! `u d = 1`.
//!
//! With `tau = dt/ds` and the indentation `delta = -d`, each mode obeys
//! `dq_i/ds = tau v_i`, `dv_i/ds = tau R_i`, `R_i = (w_i^2 F_i / k_i) cos(w t) + (w_i^2/k_i)
//! F_ts - w_i^2 q_i - (w_i/Q_i) v_i` (MODEL.md section 1), and `F_ts = c delta^{3/2} = c delta
//! r`, `r = sqrt(delta)`. Coefficient `k` of every product is a convolution, `r_k` follows
//! from `r^2 = delta` and `cos(w t(s))`, `sin(w t(s))` from their derivatives `-/+ w tau sin,
//! cos`: `O(k)` work for coefficient `k` (Moore 1966; Jorba and Zou 2005). `tau = a + 2 b s`
//! (`a` the clock's rate, `b` its curvature) has two coefficients, so coefficient `k` of `tau
//! y` is `a y_k + 2 b y_{k-1}`; `R` being linear in `cos`, `F_ts`, `q_i`, `v_i`, the
//! recurrences form `tau R` from those products rather than `R` at two powers.
//!
//! At the start of contact on the square-root clock centred there (`tau(0) = 0`), `delta` has a
//! double zero, `delta = s^2 g(s)`: then `r = s sqrt(g)` and `F_ts = c s^3 g sqrt(g)`, whose
//! coefficients follow from those of `g` (the recurrences never divide by `r_0 = 0`). That is
//! the point of the square-root clock: the contact is analytic in `s` there, not in `t`.
//!
//! JKR while attached (MODEL.md section 9, JKR) is parametric in `b = sqrt(a)`: `delta = b^4/R
//! - k b`, `F = (4 E*/(3 R)) b^6 - 2 E* k b^3`. The series of `b` follows from the implicit
//! relation by series reversion, one linear equation per coefficient: with `p = b^2`,
//! `(b^4)_m = 4 b_0^3 b_m + 2 p_0 sum_{j=1}^{m-1} b_j b_{m-j} + sum_{j=1}^{m-1} p_j p_{m-j}`, so
//! `b_m (4 b_0^3/R - k) = delta_m - (the sums)/R`; `b_0` is the law's own root. The divisor
//! `d delta/db` (from the law's offset from pull-off, without cancellation) vanishes at
//! pull-off, where `b(t)` has a square-root branch point: a series expanded next to it has a
//! radius as short as the time to pull-off, which the solver's reach keeps the step inside; a
//! step starting nearer than [`JKR_MARGIN`] has no series.

use hybrid::{ClockPolynomial, TaylorSeries};

use crate::contact::jkr::JkrContact;

use crate::model::modal_constants::ModalConstants;
use crate::model::phase;
use crate::model::separation::Separation;

/// The highest Taylor order the contact series is computed to (the recurrences keep their
/// intermediate series on the stack).
pub const MAX_ORDER: usize = 40;

/// The coefficients `0..=MAX_ORDER` of one series.
const LEN: usize = MAX_ORDER + 1;

/// The values [`SharedSeries`] lays out in the solver's `shared` vector: within its capacity,
/// so that no step allocates.
const SHARED_LEN: usize = 8 * LEN + ROOT_LEN;

/// The values of the force's auxiliary series in [`SharedSeries`]: three series and one value
/// (JKR's `b`, `b^2`, `b^3` and `d delta/db` at the start; the hydration force's `w` and
/// `j delta_j`).
const ROOT_LEN: usize = 3 * LEN + 1;
const _: () = assert!(SHARED_LEN <= hybrid::SHARED_SERIES_CAPACITY);

/// The series [`contact_state_series`] computes on its way and [`contact_tangent_series`]
/// reuses along the same state series (module docs), held in the solver's `shared` vector (of
/// [`hybrid::TaylorExpansion::taylor_series`]): the indentation `delta` and the force's
/// auxiliary series `root`, the same numbers the tangents' recurrence would compute again from
/// the same state series, and the state's other intermediate series, kept there rather than
/// on the stack so that no step zeroes them.
///
/// After a state series of order `p` (clock rate `a`): `delta_0..delta_{p-1}`; `root` (Hertz:
/// the indentation's square root, `r_0..r_{p-1}`, at an onset `r_0 = 0` and
/// `r_1..r_{max(p, 3) - 3}`; van der Waals: `1/d`; JKR: `b`, `b^2`, `b^3` one after the other;
/// hydration: `w`'s `[re, im]` pairs, highest power first, then `j delta_j`; each to `p - 1`);
/// the drive phase's `cos` and `sin` to `p`.
struct SharedSeries<'a> {
    /// The indentation below the contact surface, nm.
    delta: &'a mut [f64; LEN],
    /// The force's auxiliary series (three series' room and one value, for JKR's `b`, `b^2`,
    /// `b^3` and `d delta/db` at the start).
    root: &'a mut [f64; ROOT_LEN],
    /// `cos(w t(s))` and `sin(w t(s))` of the drive.
    cos: &'a mut [f64; LEN],
    sin: &'a mut [f64; LEN],
    /// The tip-sample force, nN.
    force: &'a mut [f64; LEN],
    /// A bimodal drive's `cos(w_b t(s))` and `sin(w_b t(s))`.
    second_cos: &'a mut [f64; LEN],
    second_sin: &'a mut [f64; LEN],
}

impl<'a> SharedSeries<'a> {
    /// The series laid out in `storage` (grown to their length the first time; what a state
    /// series wrote there is kept).
    fn in_storage(storage: &'a mut Vec<f64>) -> Self {
        storage.resize(SHARED_LEN, 0.0);
        let (delta, rest) = storage.split_at_mut(LEN);
        let (root, rest) = rest.split_at_mut(ROOT_LEN);
        let (cos, rest) = rest.split_at_mut(LEN);
        let (sin, rest) = rest.split_at_mut(LEN);
        let (force, rest) = rest.split_at_mut(LEN);
        let (second_cos, second_sin) = rest.split_at_mut(LEN);
        let fixed = "the storage was resized to the layout";
        Self {
            delta: delta.try_into().expect(fixed),
            root: root.try_into().expect(fixed),
            cos: cos.try_into().expect(fixed),
            sin: sin.try_into().expect(fixed),
            force: force.try_into().expect(fixed),
            second_cos: (&mut second_cos[..LEN]).try_into().expect(fixed),
            second_sin: (&mut second_sin[..LEN]).try_into().expect(fixed),
        }
    }
}

/// The tip-sample force a series expands Eq. 1 with (MODEL.md sections 1 and 9).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum SeriesForce {
    /// `c s^{3/2} - constant` (nN), `s = d_c - d` the indentation below the contact surface
    /// `d = d_c`: the Hertz sphere (`d_c = 0`, no constant) or DMT in contact (`d_c = a0`,
    /// `constant = H R / (6 a0^2)`).
    Hertz {
        /// `c = (4/3) E* sqrt(R)`, nN/nm^{3/2}.
        coefficient: f64,
        /// `d_c`, nm.
        contact_gap: f64,
        /// The constant subtracted, nN.
        constant: f64,
    },
    /// `-A / d^2` (nN) with `A = H R / 6` (nN nm): DMT's van der Waals force outside contact.
    VanDerWaals {
        /// `A`, nN nm.
        scale: f64,
    },
    /// JKR while attached, `F = (4 E*/(3 R)) b^6 - 2 E* k b^3` with `b = sqrt(a)` the root of
    /// `b^4/R - k b = delta` on the stable branch (MODEL.md section 9, JKR).
    Jkr {
        /// The law (its constants and the root `b_0` at a step's start).
        law: JkrContact,
    },
    /// The hydration force outside contact, `B exp(-d/lambda) [cos(k d) - k lambda sin(k d)]`
    /// (nN; MODEL.md section 9): the real and imaginary parts of `w = exp(c delta)`,
    /// `c = 1/lambda - i k`, `delta = -d`, whose coefficients follow from `w' = c delta' w`.
    Hydration {
        /// `B`, nN.
        amplitude: f64,
        /// `k = 2 pi / sigma`, 1/nm.
        wavenumber: f64,
        /// `lambda`, nm.
        decay_length: f64,
    },
}

/// Coefficient `k` of `w = exp(c delta)` (complex, `c = 1/lambda - i k_w`) from `delta`'s
/// coefficients to `k` and `w`'s below `k`: `w_0 = exp(c delta_0)`, `k w_k = c sum_{j=1}^{k} j
/// delta_j w_{k-j}`. `w` holds the coefficients highest power last-in first, as `[re, im]`
/// pairs: `w_k` in `w[LEN - 1 - k]` (so that `w_{k-1}, ..., w_0` run forward, as the sum takes
/// them). `weighted` holds `j delta_j` for `j < k` and gets `k delta_k` here, so that each is
/// formed once; the sum's terms are added in the order `j = 1, ..., k`, its real and imaginary
/// parts side by side.
#[inline(always)]
fn update_layer_exponential(
    w: &mut [[f64; 2]; LEN],
    weighted: &mut [f64],
    delta: &[f64],
    k: usize,
    wavenumber: f64,
    decay_length: f64,
) {
    let (c_re, c_im) = (1.0 / decay_length, -wavenumber);
    if k == 0 {
        let magnitude = (c_re * delta[0]).exp();
        let (sin, cos) = (c_im * delta[0]).sin_cos();
        w[LEN - 1] = [magnitude * cos, magnitude * sin];
        weighted[0] = 0.0;
        return;
    }
    weighted[k] = k as f64 * delta[k];
    let mut sum = [-0.0, -0.0];
    for (factor, below) in weighted[1..=k].iter().zip(&w[LEN - k..]) {
        sum[0] += factor * below[0];
        sum[1] += factor * below[1];
    }
    let [sum_re, sum_im] = sum;
    let scale = 1.0 / k as f64;
    w[LEN - 1 - k] = [
        scale * (c_re * sum_re - c_im * sum_im),
        scale * (c_re * sum_im + c_im * sum_re),
    ];
}

/// The `LEN` pairs `[re, im]` of [`update_layer_exponential`]'s `w` laid out in `values`
/// (`2 LEN` of them).
#[inline(always)]
fn layer_exponential_pairs(values: &mut [f64]) -> &mut [[f64; 2]; LEN] {
    let (pairs, _) = values.as_chunks_mut::<2>();
    (&mut pairs[..LEN])
        .try_into()
        .expect("2 LEN values hold LEN pairs")
}

/// The drives a series expands Eq. 1 with (MODEL.md sections 1 and 14): the drive at
/// `frequency` (rad/us), an acoustic drive's base motion `base_amplitude cos(w t)` in the gap
/// (nm; 0 without), and a bimodal drive's second drive `(w_b, F_1b / F_1)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SeriesDrive {
    /// The drive angular frequency `w`, rad/us.
    pub(crate) frequency: f64,
    /// The base amplitude `Y` of an acoustic drive, nm (0 for another drive).
    pub(crate) base_amplitude: f64,
    /// A bimodal drive's `(w_b, F_1b / F_1)`.
    pub(crate) second: Option<(f64, f64)>,
}

/// Coefficients `0..=p` of `cos(w t(s))` and `sin(w t(s))` into `cos` and `sin`, by the
/// recurrence `(cos)' = -w tau sin`, `(sin)' = w tau cos` (as in [`contact_state_series`]).
pub(crate) fn phase_series(
    frequency: f64,
    clock: &ClockPolynomial,
    p: usize,
    cos: &mut [f64; MAX_ORDER + 1],
    sin: &mut [f64; MAX_ORDER + 1],
) {
    let (a, b2) = (clock.rate, 2.0 * clock.curvature);
    (sin[0], cos[0]) = phase::sin_cos(frequency * clock.start);
    for k in 0..p.min(MAX_ORDER) {
        let scale = 1.0 / (k + 1) as f64;
        let (rate, curvature, below) = if k > 0 {
            (a * scale, b2 * scale, k - 1)
        } else {
            (a * scale, 0.0, 0)
        };
        let tau_cos = rate * cos[k] + curvature * cos[below];
        let tau_sin = rate * sin[k] + curvature * sin[below];
        cos[k + 1] = -frequency * tau_sin;
        sin[k + 1] = frequency * tau_cos;
    }
}

/// The separation `Z(t(s))`'s coefficients `0..=2` (`Z` constant or a linear ramp in `t`, `t`
/// quadratic in `s`: the higher ones vanish).
#[inline]
pub(crate) fn separation_coefficients(
    separation: &Separation,
    clock: &ClockPolynomial,
) -> [f64; 3] {
    let rate = separation.rate();
    [
        separation.at(clock.start),
        rate * clock.rate,
        rate * clock.curvature,
    ]
}

/// `Z(t(s)) - d_c`'s coefficients: the indentation below the contact surface is then
/// `-(Z - d_c + sum_i q_i)` (`d_c = 0`, no shift, for every force but DMT's contact).
#[inline]
fn shifted_separation(
    separation: &Separation,
    clock: &ClockPolynomial,
    force: SeriesForce,
) -> [f64; 3] {
    let mut coefficients = separation_coefficients(separation, clock);
    if let SeriesForce::Hertz { contact_gap, .. } = force {
        if contact_gap != 0.0 {
            coefficients[0] -= contact_gap;
        }
    }
    coefficients
}

/// Coefficient `k` of `u = 1/g` from `g`'s coefficients to `k` and `u`'s to `k - 1`:
/// `u_0 = 1/g_0`, `u_k = -(sum_{j=1}^{k} g_j u_{k-j}) / g_0`; here from the indentation
/// `delta = -g`.
#[inline]
fn update_reciprocal_gap(reciprocal: &mut [f64], delta: &[f64], k: usize) {
    reciprocal[k] = if k == 0 {
        -1.0 / delta[0]
    } else {
        -convolution(&delta[1..=k], &reciprocal[..k]) / delta[0]
    };
}

/// Coefficient `m` of the product of two series from their coefficients `0..=m`, `a` and `b`
/// (`b` at least as long as `a`, of length `m + 1`): `sum_{j=0}^{m} a_j b_{m-j}`.
///
/// The products are formed four at a time (independent of each other) and added one by one in
/// the order `j = 0, 1, ..., m` from `-0.0`, as `Iterator::sum` adds them: the same bits as
/// the plain loop, in fewer instructions (no loop test per term, the four products in one
/// vector multiplication where the CPU has one).
#[inline(always)]
pub(crate) fn convolution(a: &[f64], b: &[f64]) -> f64 {
    let b = &b[..a.len()];
    let mut sum = -0.0;
    let (a_blocks, b_blocks) = (a.chunks_exact(4), b.rchunks_exact(4));
    let (a_rest, b_rest) = (a_blocks.remainder(), b_blocks.remainder());
    for (x, y) in a_blocks.zip(b_blocks) {
        let products = [x[0] * y[3], x[1] * y[2], x[2] * y[1], x[3] * y[0]];
        sum += products[0];
        sum += products[1];
        sum += products[2];
        sum += products[3];
    }
    for (x, y) in a_rest.iter().zip(b_rest.iter().rev()) {
        sum += x * y;
    }
    sum
}

/// Coefficient `k` of `r = sqrt(y)` from `y`'s coefficients to `k` and `r`'s to `k - 1`
/// (`r_0 = sqrt(y_0)` at `k = 0`): `2 r_0 r_k = y_k - sum_{j=1}^{k-1} r_j r_{k-j}`, the sum
/// being symmetric in `j <-> k - j`: twice `sum_{j=1}^{h} r_j r_{k-j}` (`h = floor((k - 1)/2)`),
/// plus `r_{k/2}^2` for even `k`.
#[inline(always)]
fn update_root(root: &mut [f64], y: &[f64], k: usize) {
    root[k] = if k == 0 {
        y[0].sqrt()
    } else {
        let h = (k - 1) / 2;
        let mut middle = 2.0 * convolution(&root[1..=h], &root[k - h..k]);
        if k.is_multiple_of(2) {
            middle += root[k / 2] * root[k / 2];
        }
        (y[k] - middle) / (2.0 * root[0])
    };
}

/// Coefficient `k` of the indentation `delta = -(Z(t(s)) + sum_i q_i)` from the state's
/// coefficient row `k` (`[q_1, v_1, ...]`) and `Z(t(s))`'s coefficients `separation`.
#[inline]
pub(crate) fn indentation_coefficient(separation: &[f64; 3], row: &[f64], k: usize) -> f64 {
    let gap: f64 = row.chunks_exact(2).map(|qv| qv[0]).sum();
    -(separation.get(k).copied().unwrap_or(0.0) + gap)
}

/// How far from pull-off a JKR series starts, in `(d delta/db) / k = (b_0/b_c)^3 - 1` (`b_0 >
/// 2^{1/3} b_c`). Nearer, the series' radius (the time to pull-off) shrinks with each step and
/// DOP853 takes over. Measured on `biolever-adhesive` and `biolever-sticky`
/// (docs/guide/performance.md): 5 (the previous margin) kept 72 000 attached starts per diagram
/// on DOP853; 1 gives the same series steps as 0 there, while 0 loses the sticky approach's
/// located `pull-off` (its release maxima, approached by ever shorter series steps).
const JKR_MARGIN: f64 = 1.0;

/// `sum_{j=1}^{m-1} x_j x_{m-j}` (`m >= 1`), the sum's terms paired by its symmetry `j <-> m -
/// j`: twice `sum_{j=1}^{h} x_j x_{m-j}` (`h = floor((m - 1)/2)`), plus `x_{m/2}^2` for even `m`
/// (as in [`update_root`]).
#[inline(always)]
fn inner_square_sum(x: &[f64], m: usize) -> f64 {
    let h = (m - 1) / 2;
    let mut sum = 2.0 * convolution(&x[1..=h], &x[m - h..m]);
    if m.is_multiple_of(2) {
        sum += x[m / 2] * x[m / 2];
    }
    sum
}

/// Coefficient `k` of the square of a series, `sum_{j=0}^{k} x_j x_{k-j}`, its terms paired by
/// symmetry: twice `sum_{j=0}^{h} x_j x_{k-j}` (`h = floor((k - 1)/2)`, none at `k = 0`), plus
/// `x_{k/2}^2` for even `k`.
#[inline]
fn square_coefficient(x: &[f64], k: usize) -> f64 {
    let mut sum = if k == 0 {
        0.0
    } else {
        let h = (k - 1) / 2;
        2.0 * convolution(&x[..=h], &x[k - h..=k])
    };
    if k.is_multiple_of(2) {
        sum += x[k / 2] * x[k / 2];
    }
    sum
}

/// Coefficient `m` of JKR's `b = sqrt(a)`, `p = b^2` and `c = b^3` (into `b`, `p`, `c`) from
/// the indentation's coefficients to `m` and theirs below `m`, by series reversion of `b^4/R -
/// k b = delta` (module docs); at `m = 0` also the divisor `d delta/db = 4 b_0^3/R - k` (into
/// `divisor`, from [`JkrContact::root_and_slope`]), which the later coefficients divide by.
/// `false` where the divisor is below [`JKR_MARGIN`] `k` (next to, on or past pull-off) or the
/// root is not finite.
#[inline(always)]
fn update_jkr_root(
    law: &JkrContact,
    [b, p, c]: [&mut [f64]; 3],
    divisor: &mut f64,
    delta: &[f64],
    m: usize,
) -> bool {
    let r = law.tip_radius_nm;
    if m == 0 {
        let (b0, slope) = law.root_and_slope(delta[0]);
        b[0] = b0;
        p[0] = b0 * b0;
        c[0] = p[0] * b0;
        *divisor = slope;
        return slope > JKR_MARGIN * law.adhesion_root() && b0.is_finite();
    }
    let divisor = *divisor;
    let root_sum = inner_square_sum(b, m);
    let square_sum = inner_square_sum(p, m);
    b[m] = (delta[m] - (2.0 * p[0] * root_sum + square_sum) / r) / divisor;
    p[m] = 2.0 * b[0] * b[m] + root_sum;
    c[m] = convolution(&p[..=m], &b[..=m]);
    true
}

/// Coefficient `m` of `r = sqrt(delta)` from `delta`'s coefficients and `r`'s below `m`. Off
/// an onset, `delta_0 > 0` and [`update_root`] applies (it needs `delta` to `m`). On an onset
/// (`delta = s^2 g`, `g_j = delta_{j+2}`), `r = s sqrt(g)`: `r_0 = 0` and `r_m = sqrt(g)_{m-1}`
/// (it needs `delta` to `m + 1`).
#[inline(always)]
pub(crate) fn indentation_root(root: &mut [f64], delta: &[f64], m: usize, onset: bool) {
    if !onset {
        update_root(root, delta, m);
    } else if m == 0 {
        root[0] = 0.0;
    } else {
        update_root(&mut root[1..], &delta[2..], m - 1);
    }
}

/// The Taylor coefficients of the flow of Eq. 1 with the force `force` (`N` modes `modes`,
/// drives `drive`, separation `separation`) in the clock offset `s` of `clock`, through the
/// state held in the constant terms of `series` (`2N` components, `q_i`, `q_i'` in nm, nm/us);
/// `false` (series unusable) if the order exceeds [`MAX_ORDER`], the state is on the wrong
/// side of the force's surface (Hertz: `d >= d_c` where the clock runs at a finite rate; van
/// der Waals: `d <= 0` or a square-root clock), the
/// indentation does not grow from the surface at an onset (a grazing touch, not analytic in
/// `s`), or a coefficient is not finite. A clock whose rate is zero at the start (`tau(0) = 0`)
/// is the square-root clock centred on the crossing that entered contact (the only place a step
/// starts from one): the state there is taken to be on the surface (`delta_0 = 0`, whatever its
/// rounding). `shared` keeps the intermediate series ([`SharedSeries`]) for
/// [`contact_tangent_series`] along this series.
pub(crate) fn contact_state_series(
    modes: &[ModalConstants],
    force: SeriesForce,
    drive: &SeriesDrive,
    separation: &Separation,
    clock: &ClockPolynomial,
    series: &mut TaylorSeries,
    shared: &mut Vec<f64>,
) -> bool {
    if series.order() > MAX_ORDER || series.dim() != 2 * modes.len() {
        return false;
    }
    // JKR's slope `dF/dd` is infinite at pull-off, where a square-root clock is centred: its
    // tangents' series would sum a pole at the step's end. Those steps take the Runge-Kutta
    // path, with its exact limit at the crossing.
    if matches!(force, SeriesForce::Jkr { .. }) && clock.curvature != 0.0 {
        return false;
    }
    let separation = shifted_separation(separation, clock, force);
    let mut shared = SharedSeries::in_storage(shared);
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the CPU has AVX, checked just above.
        return unsafe {
            state_series_avx(modes, force, drive, &separation, clock, series, &mut shared)
        };
    }
    state_series_by_modes(modes, force, drive, &separation, clock, series, &mut shared)
}

/// [`state_series_by_modes`] compiled for AVX (its three-operand instructions and wider lanes;
/// the same operations in the same order: the same bits).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn state_series_avx(
    modes: &[ModalConstants],
    force: SeriesForce,
    drive: &SeriesDrive,
    separation: &[f64; 3],
    clock: &ClockPolynomial,
    series: &mut TaylorSeries,
    shared: &mut SharedSeries,
) -> bool {
    state_series_by_modes(modes, force, drive, separation, clock, series, shared)
}

/// [`state_recurrence`] with the common mode counts as constants, so that the loops over
/// modes unroll.
#[inline(always)]
fn state_series_by_modes(
    modes: &[ModalConstants],
    force: SeriesForce,
    drive: &SeriesDrive,
    separation: &[f64; 3],
    clock: &ClockPolynomial,
    series: &mut TaylorSeries,
    shared: &mut SharedSeries,
) -> bool {
    let mut run = |modes| state_recurrence(modes, force, drive, separation, clock, series, shared);
    match modes.len() {
        1 => run(&modes[..1]),
        2 => run(&modes[..2]),
        3 => run(&modes[..3]),
        _ => run(modes),
    }
}

/// Coefficient `k` of the force series from the indentation's coefficients to `k` (to
/// `k + 1` at an onset) and the auxiliary series `root` (the indentation's square root for
/// Hertz, the reciprocal gap `1/d` for van der Waals) below `k`, which it extends; `None` where
/// the series does not exist (van der Waals on or inside the surface, or at an onset).
#[inline(always)]
fn force_coefficient(
    law: SeriesForce,
    root: &mut [f64],
    delta: &[f64],
    k: usize,
    onset: bool,
) -> Option<f64> {
    match law {
        SeriesForce::Hertz {
            coefficient,
            constant,
            ..
        } => {
            let mut value = if onset {
                // delta_0 = delta_1 = 0: delta = s^2 g (g_j = delta_{j+2}), r = s sqrt(g),
                // F = c s^3 g sqrt(g); coefficient k needs g and sqrt(g) = r_{.+1} to k - 3.
                if k >= 3 {
                    indentation_root(root, delta, k - 2, true);
                    coefficient * convolution(&delta[2..k], &root[1..k - 1])
                } else {
                    if k == 0 {
                        indentation_root(root, delta, 0, true);
                    }
                    0.0
                }
            } else {
                indentation_root(root, delta, k, false);
                coefficient * convolution(&delta[..=k], &root[..=k])
            };
            if k == 0 && constant != 0.0 {
                value -= constant;
            }
            Some(value)
        }
        SeriesForce::VanDerWaals { scale } => {
            // -A / d^2 = -A u^2, u = 1/d, only off the surface on the time clock.
            if onset || delta[0] >= 0.0 {
                return None;
            }
            update_reciprocal_gap(root, delta, k);
            Some(-scale * convolution(&root[..=k], &root[..=k]))
        }
        SeriesForce::Jkr { law } => {
            // Not at an onset (the attached mode is entered at d = 0 with a jump of the
            // force, on the time clock); `root` holds b, then p = b^2, then c = b^3, then
            // d delta/db at the start.
            if onset {
                return None;
            }
            let (b, rest) = root.split_at_mut(MAX_ORDER + 1);
            let (p, rest) = rest.split_at_mut(MAX_ORDER + 1);
            let (c, rest) = rest.split_at_mut(MAX_ORDER + 1);
            if !update_jkr_root(&law, [b, p, c], &mut rest[0], delta, k) {
                return None;
            }
            let e = law.effective_modulus_gpa;
            Some(
                4.0 * e / (3.0 * law.tip_radius_nm) * square_coefficient(c, k)
                    - 2.0 * e * law.adhesion_root() * c[k],
            )
        }
        SeriesForce::Hydration {
            amplitude,
            wavenumber,
            decay_length,
        } => {
            // Analytic in d everywhere, on the time clock; `root` holds `w`'s coefficients as
            // `[re, im]` pairs, the highest power first (`update_layer_exponential`), then
            // `j delta_j`.
            if onset {
                return None;
            }
            let (pairs, weighted) = root.split_at_mut(2 * LEN);
            let w = layer_exponential_pairs(pairs);
            update_layer_exponential(w, weighted, delta, k, wavenumber, decay_length);
            let [re, im] = w[LEN - 1 - k];
            Some(amplitude * (re - wavenumber * decay_length * im))
        }
    }
}

/// The recurrence of [`contact_state_series`] (`Z(t(s))`'s coefficients `separation`), inlined
/// into each call so that a constant mode count unrolls its loops over modes.
#[inline(always)]
fn state_recurrence(
    modes: &[ModalConstants],
    law: SeriesForce,
    drive: &SeriesDrive,
    separation: &[f64; 3],
    clock: &ClockPolynomial,
    series: &mut TaylorSeries,
    shared: &mut SharedSeries,
) -> bool {
    let p = series.order();
    let n = 2 * modes.len();
    let (a, b2) = (clock.rate, 2.0 * clock.curvature);
    let onset = a == 0.0;
    // The auxiliary series is twice as long for the hydration force's complex exponential,
    // three times for JKR's b, b^2, b^3.
    let SharedSeries {
        delta,
        root,
        cos,
        sin,
        force,
        second_cos,
        second_sin,
    } = shared;
    let drive_frequency = drive.frequency;
    (sin[0], cos[0]) = phase::sin_cos(drive_frequency * clock.start);
    // A bimodal drive's second phase series (MODEL.md section 14).
    let (second_frequency, second_factor) = drive.second.unwrap_or((0.0, 0.0));
    if drive.second.is_some() {
        phase_series(second_frequency, clock, p, second_cos, second_sin);
    }
    let x = series.coefficients_mut();
    // The sum of every coefficient and force, finite only if each of them is (or rejecting
    // coefficients near f64::MAX, of no use either).
    let mut total: f64 = x[..n].iter().sum();
    for k in 0..p {
        let (done, rest) = x.split_at_mut((k + 1) * n);
        let (earlier, row) = done.split_at(k * n);
        let next = &mut rest[..n];
        // An acoustic drive's base motion `Y cos(w t)` is in the gap (MODEL.md section 14).
        delta[k] = indentation_coefficient(separation, row, k) - drive.base_amplitude * cos[k];
        match force_coefficient(law, &mut root[..], &delta[..], k, onset) {
            Some(value) => force[k] = value,
            None => return false,
        }
        total += force[k];
        // y' = tau z: y_{k+1} = (a z_k + b2 z_{k-1}) / (k + 1), z_{-1} = 0 (the coefficient
        // below k is row k itself at k = 0, times zero).
        let scale = 1.0 / (k + 1) as f64;
        let rate = a * scale;
        let (curvature, below, previous) = if k > 0 {
            (b2 * scale, k - 1, &earlier[(k - 1) * n..])
        } else {
            (0.0, 0, row)
        };
        // The drive phase: (cos)' = -w tau sin, (sin)' = w tau cos.
        let tau_cos = rate * cos[k] + curvature * cos[below];
        let tau_sin = rate * sin[k] + curvature * sin[below];
        let tau_force = rate * force[k] + curvature * force[below];
        cos[k + 1] = -drive_frequency * tau_sin;
        sin[k + 1] = drive_frequency * tau_cos;
        // Both drives' factor `cos(w t) + (F_1b / F_1) cos(w_b t)`, times tau.
        let tau_drive = clocked_drive_coefficient(
            tau_cos,
            drive.second.map(|_| (second_factor, &second_cos[..])),
            (rate, curvature),
            (k, below),
        );
        total += modal_coefficients(
            modes,
            (rate, curvature),
            (tau_drive, tau_force),
            row,
            previous,
            next,
        );
    }
    total.is_finite()
}

/// Coefficient `k` of `tau(s) D(t(s))`, the clock's rate times both drives' factor
/// `D = cos(w t) + (F_1b / F_1) cos(w_b t)` (MODEL.md section 14), from `tau_cos`, coefficient
/// `k` of `tau cos(w t)`, and with a second drive `(F_1b / F_1, the series of cos(w_b t))`;
/// `clock = (a / (k + 1), 2 b / (k + 1))` as in [`modal_coefficients`], `(k, below)` the
/// coefficients it multiplies (`below = k - 1`, or `0` with zero curvature at `k = 0`).
#[inline(always)]
pub(crate) fn clocked_drive_coefficient(
    tau_cos: f64,
    second: Option<(f64, &[f64])>,
    (rate, curvature): (f64, f64),
    (k, below): (usize, usize),
) -> f64 {
    match second {
        Some((factor, second_cos)) => {
            tau_cos + factor * (rate * second_cos[k] + curvature * second_cos[below])
        }
        None => tau_cos,
    }
}

/// Coefficient `k + 1` of each mode's `[q_i, q_i']` (Eq. 1 on the clock `t(s)`, MODEL.md
/// section 1: `q' = tau v`, `v' = tau ((w_i^2/k_i) (F_i D(t) + F_ts) - w_i^2 q - (w_i/Q_i) v)`),
/// into `next`'s pairs, from the state's coefficients `k` (`row`) and `k - 1` (`previous`) and
/// `clock = (a / (k + 1), 2 b / (k + 1))` (zero curvature at `k = 0`), with `forcing` the
/// coefficient `k` of `tau` times the drive factor `D` and of `tau F_ts` (nN). Returns the sum
/// of the new coefficients (for the recurrence's finiteness check). Pairs beyond the modes (a
/// sample's state) are left to the caller.
#[inline(always)]
pub(crate) fn modal_coefficients(
    modes: &[ModalConstants],
    (rate, curvature): (f64, f64),
    (tau_drive, tau_force): (f64, f64),
    row: &[f64],
    previous: &[f64],
    next: &mut [f64],
) -> f64 {
    let mut total = 0.0;
    for ((m, out), (qv, previous_qv)) in modes
        .iter()
        .zip(next.chunks_exact_mut(2))
        .zip(row.chunks_exact(2).zip(previous.chunks_exact(2)))
    {
        let tau_q = rate * qv[0] + curvature * previous_qv[0];
        let tau_v = rate * qv[1] + curvature * previous_qv[1];
        out[0] = tau_v;
        out[1] = m.drive_acceleration * tau_drive + m.omega_squared_over_stiffness * tau_force
            - m.omega_squared * tau_q
            - m.damping * tau_v;
        total += out[0] + out[1];
    }
    total
}

/// The Taylor coefficients of the tangent matrix `V` (`2N` rows: the transition matrix's
/// columns, then, with `parameter_column`, `dx/dZ`) along the contact flow whose state series is
/// `state` (from [`contact_state_series`] with the same arguments, which left its intermediate
/// series in `shared`; the drives enter only through an acoustic drive's base motion in the
/// gap): `dV/ds = tau J(t(s), x(s)) V` (`+ tau df/dZ` on the parameter column), `J`'s contact
/// part being `(w_i^2/k_i) F_ts'(d)` on every `q_j` with `F_ts' = -(3/2) c r` (Hertz) or `2 A /
/// d^3` (van der Waals). Each coefficient of `tangents` is `V`'s row-major matrix (component
/// `row * columns + column`); the constant terms hold `V` at the step start. `gaps` is scratch
/// space (resized here).
#[allow(clippy::too_many_arguments)]
pub(crate) fn contact_tangent_series(
    modes: &[ModalConstants],
    force: SeriesForce,
    drive: &SeriesDrive,
    separation: &Separation,
    clock: &ClockPolynomial,
    state: &TaylorSeries,
    shared: &mut Vec<f64>,
    tangents: &mut TaylorSeries,
    parameter_column: bool,
    gaps: &mut Vec<f64>,
) {
    let state_order = state.order();
    let p = tangents.order().min(state_order);
    let n = state.dim();
    let (a, b2) = (clock.rate, 2.0 * clock.curvature);
    let onset = a == 0.0;
    let SharedSeries {
        delta, root, cos, ..
    } = SharedSeries::in_storage(shared);
    debug_assert_eq!(
        delta[0].to_bits(),
        (indentation_coefficient(
            &shifted_separation(separation, clock, force),
            state.row(0),
            0
        ) - drive.base_amplitude * cos[0])
            .to_bits(),
        "the shared series come from another state series"
    );
    // The series of F_ts'(d) / slope to order p - 1 (all the recurrence below uses; on an
    // onset it needs the indentation to order p), from the state recurrence's indentation and
    // auxiliary series (`SharedSeries`), extended where the state's stopped short: the
    // indentation's square root for Hertz (`F' = -(3/2) c r`), `u^3 = 1/d^3` for van der Waals
    // (`F' = 2 A u^3`).
    let mut derivative = [0.0; MAX_ORDER];
    let (slope, series): (f64, &[f64]) = match force {
        SeriesForce::Hertz { coefficient, .. } => {
            if onset && p + 2 > state_order {
                // The state's recurrence stopped at `r_{max(p, 3) - 3}` and `delta_{p - 1}`
                // (its order `p`); the root to `p - 1` needs the indentation to `p`.
                let separation = shifted_separation(separation, clock, force);
                for k in state_order..=p {
                    delta[k] = indentation_coefficient(&separation, state.row(k), k)
                        - drive.base_amplitude * cos[k];
                }
                for m in state_order.max(3) - 2..p {
                    indentation_root(&mut root[..], &delta[..], m, true);
                }
            }
            (-1.5 * coefficient, &root[..p])
        }
        SeriesForce::VanDerWaals { scale } => {
            let reciprocal = &root[..p];
            let mut square = [0.0; MAX_ORDER];
            for m in 0..p {
                square[m] = convolution(&reciprocal[..=m], &reciprocal[..=m]);
                derivative[m] = convolution(&square[..=m], &reciprocal[..=m]);
            }
            (2.0 * scale, &derivative[..p])
        }
        SeriesForce::Jkr { law } => {
            // F' = -dF/ddelta = -2 E* p N / D, N = 4 c/R - 3 k, D = 4 c/R - k (module docs:
            // dF/db = 2 E* b^2 (4 b^3/R - 3 k), d delta/db = 4 b^3/R - k); `derivative` gets
            // p N / D, from the state recurrence's `p = b^2`, `c = b^3` and `d delta/db` at the
            // start.
            let square = &root[LEN..LEN + p];
            let cube = &root[2 * LEN..2 * LEN + p];
            let divisor = root[3 * LEN];
            jkr_slope_series(&law, square, cube, divisor, &mut derivative[..p]);
            (-2.0 * law.effective_modulus_gpa, &derivative[..p])
        }
        SeriesForce::Hydration {
            amplitude,
            wavenumber,
            decay_length,
        } => {
            // F' = -B (1/lambda + k^2 lambda) exp(-d/lambda) cos(k d) = slope Re w (`w`'s
            // pairs are in `root`, the highest power first).
            let w = layer_exponential_pairs(&mut root[..2 * LEN]);
            for (m, pair) in derivative[..p].iter_mut().zip(w.iter().rev()) {
                *m = pair[0];
            }
            (
                -amplitude * (1.0 / decay_length + wavenumber * wavenumber * decay_length),
                &derivative[..p],
            )
        }
    };
    // Highest power first, so that the convolutions below run forward through both series.
    let mut root_reversed = [0.0; MAX_ORDER];
    for (reversed, r) in root_reversed.iter_mut().zip(series.iter().rev()) {
        *reversed = *r;
    }
    let columns = tangents.dim() / n;
    let recurrence = TangentRecurrence {
        modes,
        root_reversed: &root_reversed[..p],
        slope,
        rate: a,
        curvature: b2,
        parameter_column,
    };
    recurrence.run_all(columns, tangents.coefficients_mut(), gaps);
}

/// The series of JKR's `-dF/ddelta / (-2 E*) = p N / D` to the length of `derivative` (module
/// docs, [`contact_tangent_series`]: `N = 4 c/R - 3 k`, `D = d delta/db = 4 c/R - k`), from the
/// state recurrence's `p = b^2` (`square`), `c = b^3` (`cube`) and `D_0` (`divisor`), compiled
/// for the CPU's AVX where it has it (the same operations in the same order: the same bits).
fn jkr_slope_series(
    law: &JkrContact,
    square: &[f64],
    cube: &[f64],
    divisor: f64,
    derivative: &mut [f64],
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the CPU has AVX, checked just above.
        unsafe { jkr_slope_series_avx(law, square, cube, divisor, derivative) };
        return;
    }
    jkr_slope_recurrence(law, square, cube, divisor, derivative);
}

/// [`jkr_slope_recurrence`] compiled with AVX.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn jkr_slope_series_avx(
    law: &JkrContact,
    square: &[f64],
    cube: &[f64],
    divisor: f64,
    derivative: &mut [f64],
) {
    jkr_slope_recurrence(law, square, cube, divisor, derivative);
}

/// The recurrence of [`jkr_slope_series`]: the ratio `N / D` by series division (`D_m = N_m =
/// 4 c_m / R` for `m >= 1`, `N_0 = D_0 - 2 k`), then its product with `p`.
#[inline(always)]
fn jkr_slope_recurrence(
    law: &JkrContact,
    square: &[f64],
    cube: &[f64],
    divisor: f64,
    derivative: &mut [f64],
) {
    let p = derivative.len();
    let (r, k) = (law.tip_radius_nm, law.adhesion_root());
    // `D_m` for m >= 1, each formed once.
    let mut scaled_cube = [0.0; MAX_ORDER];
    for (scaled, c) in scaled_cube[..p].iter_mut().zip(&cube[..p]) {
        *scaled = 4.0 * c / r;
    }
    // The ratio's coefficients highest power first (`ratio_i` at `MAX_ORDER - 1 - i`), so that
    // both sums below run forward through both their series.
    let mut reversed = [0.0; MAX_ORDER];
    for m in 0..p {
        // The sum `sum_{j=1}^{m} D_j ratio_{m-j}` added in the order j = 1, ..., m from -0.0.
        let ratio = if m == 0 {
            (divisor - 2.0 * k) / divisor
        } else {
            let below = ordered_dot(&scaled_cube[1..=m], &reversed[MAX_ORDER - m..]);
            (scaled_cube[m] - below) / divisor
        };
        reversed[MAX_ORDER - 1 - m] = ratio;
        derivative[m] = ordered_dot(&square[..=m], &reversed[MAX_ORDER - 1 - m..]);
    }
}

/// `sum_j a_j b_j` over the length of `a` (`b` at least as long), the products formed four at a
/// time and added one by one in the order `j = 0, 1, ...` from `-0.0`: the same bits as
/// [`convolution`] of `a` with `b` reversed, without reversing lanes.
#[inline(always)]
fn ordered_dot(a: &[f64], b: &[f64]) -> f64 {
    let b = &b[..a.len()];
    let mut sum = -0.0;
    let (a_blocks, b_blocks) = (a.chunks_exact(4), b.chunks_exact(4));
    let (a_rest, b_rest) = (a_blocks.remainder(), b_blocks.remainder());
    for (x, y) in a_blocks.zip(b_blocks) {
        let products = [x[0] * y[0], x[1] * y[1], x[2] * y[2], x[3] * y[3]];
        sum += products[0];
        sum += products[1];
        sum += products[2];
        sum += products[3];
    }
    for (x, y) in a_rest.iter().zip(b_rest) {
        sum += x * y;
    }
    sum
}

/// The coefficients of the tangent recurrence of [`contact_tangent_series`].
struct TangentRecurrence<'a> {
    modes: &'a [ModalConstants],
    /// The series of `F_ts'(d) / slope` to order `p - 1` (the indentation's square root for
    /// Hertz), highest power first (`r_{p-1-i}` at `i`).
    root_reversed: &'a [f64],
    /// `-(3/2) c` (Hertz) or `2 A` (van der Waals).
    slope: f64,
    /// `tau = rate + curvature s` (`curvature` is twice the clock's).
    rate: f64,
    curvature: f64,
    parameter_column: bool,
}

impl TangentRecurrence<'_> {
    /// Rows `1..=p` of every column of `v` ([`TangentRecurrence::run`]), compiled for the
    /// CPU's AVX where it has it (four lanes where the baseline x86-64 has two; the same
    /// arithmetic in the same order, so the same bits: the compiler never fuses or
    /// reassociates floating-point operations).
    fn run_all(&self, columns: usize, v: &mut [f64], gaps: &mut Vec<f64>) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU has AVX, checked just above.
            unsafe { self.run_all_avx(columns, v, gaps) };
            return;
        }
        self.run_columns(columns, v, gaps);
    }

    /// [`TangentRecurrence::run_columns`] compiled with AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    fn run_all_avx(&self, columns: usize, v: &mut [f64], gaps: &mut Vec<f64>) {
        self.run_columns(columns, v, gaps);
    }

    /// The column counts of N = 1 to 3 modes, with and without dZ, as one block of constant
    /// width (its loops unrolled, its values in registers); more columns in blocks of
    /// [`COLUMN_BLOCK`], the rest one by one.
    #[inline(always)]
    fn run_columns(&self, columns: usize, v: &mut [f64], gaps: &mut Vec<f64>) {
        // `2N` or `2N + 1` columns for `N` modes: `modes` as a slice of constant length, so
        // that the loops over modes unroll too.
        let modes = self.modes;
        match (columns, modes.len()) {
            (2, 1) => self.run::<2>(&modes[..1], 2, 0, v, gaps),
            (3, 1) => self.run::<3>(&modes[..1], 3, 0, v, gaps),
            (4, 2) => self.run::<4>(&modes[..2], 4, 0, v, gaps),
            (5, 2) => self.run::<5>(&modes[..2], 5, 0, v, gaps),
            (6, 3) => self.run::<6>(&modes[..3], 6, 0, v, gaps),
            (7, 3) => self.run::<7>(&modes[..3], 7, 0, v, gaps),
            _ => {
                let blocks = columns / COLUMN_BLOCK * COLUMN_BLOCK;
                for start in (0..blocks).step_by(COLUMN_BLOCK) {
                    self.run::<COLUMN_BLOCK>(modes, columns, start, v, gaps);
                }
                for start in blocks..columns {
                    self.run::<1>(modes, columns, start, v, gaps);
                }
            }
        }
    }

    /// Rows `1..=p` of columns `start..start + C` of `v` (row-major `2N x columns` matrices)
    /// from row 0: with the gap `g = sum_j q_j` of each column (plus `dZ/dZ = 1` on the
    /// parameter column), `(k + 1) q_{i,k+1} = (tau v_i)_k` and `(k + 1) v_{i,k+1} = (w_i^2/k_i)
    /// (-(3/2) c) (tau r g)_k - w_i^2 (tau q_i)_k - (w_i/Q_i) (tau v_i)_k`, `(r g)_k` a
    /// convolution. The columns evolve independently along the given state series, so the
    /// recurrence runs over a block of them at once, its values in arrays of the constant width
    /// `C`. `modes` are the recurrence's modes (`self.modes`, passed as a slice of a length the
    /// caller may make a constant); `scratch` holds the gap's coefficients (resized here).
    #[inline(always)]
    fn run<const C: usize>(
        &self,
        modes: &[ModalConstants],
        columns: usize,
        start: usize,
        v: &mut [f64],
        scratch: &mut Vec<f64>,
    ) {
        let p = self.root_reversed.len();
        let dim = 2 * modes.len() * columns;
        let (a, b2) = (self.rate, self.curvature);
        // The block's `q` (half 0) or `v` (half 1) values of one mode's rows `qv`.
        let block = |qv: &[f64], half: usize| -> [f64; C] {
            qv[half * columns + start..][..C]
                .try_into()
                .expect("a block of C columns")
        };
        // Rows of the gap's coefficients, one per power: the gap `sum_i q_i` plus, on the
        // parameter column, `dZ/dZ = 1`.
        scratch.resize((p + 1) * C, 0.0);
        let (gaps, _) = scratch.as_chunks_mut::<C>();
        let mut gap = [0.0; C];
        for qv in v[..dim].chunks_exact(2 * columns) {
            for (g, q) in gap.iter_mut().zip(block(qv, 0)) {
                *g += q;
            }
        }
        if self.parameter_column && start + C == columns {
            gap[C - 1] += 1.0;
        }
        gaps[0] = gap;
        // The coupling `r gap` at the previous power.
        let mut previous_coupling = [0.0; C];
        let mut power = 0.0;
        for k in 0..p {
            let (done, after) = v.split_at_mut((k + 1) * dim);
            let (earlier, row) = done.split_at(k * dim);
            let next = &mut after[..dim];
            // y' = tau z: y_{k+1} = (a z_k + b2 z_{k-1}) / (k + 1), z_{-1} = 0 (the
            // coefficient below k is row k itself at k = 0, times zero).
            power += 1.0;
            let rate = a / power;
            let (curvature, previous) = if k > 0 {
                (b2 / power, &earlier[(k - 1) * dim..])
            } else {
                (0.0, row)
            };
            // The coupling's coefficient k, sum_{j=0}^{k} r_{k-j} gap_j, and tau times it.
            let mut coupling = [0.0; C];
            for (gap, r) in gaps[..=k].iter().zip(&self.root_reversed[p - 1 - k..]) {
                for (c, g) in coupling.iter_mut().zip(gap) {
                    *c += r * g;
                }
            }
            let mut tau_coupling = [0.0; C];
            for c in 0..C {
                tau_coupling[c] = rate * coupling[c] + curvature * previous_coupling[c];
            }
            previous_coupling = coupling;
            // Every mode's new coefficients, and the gap's next coefficient summed on the way.
            let mut gap = [0.0; C];
            for ((m, out), (qv, previous_qv)) in
                modes.iter().zip(next.chunks_exact_mut(2 * columns)).zip(
                    row.chunks_exact(2 * columns)
                        .zip(previous.chunks_exact(2 * columns)),
                )
            {
                let coupling_gain = m.omega_squared_over_stiffness * self.slope;
                let (q, velocity) = (block(qv, 0), block(qv, 1));
                let (previous_q, previous_velocity) =
                    (block(previous_qv, 0), block(previous_qv, 1));
                let mut new_q = [0.0; C];
                let mut new_v = [0.0; C];
                for c in 0..C {
                    let tau_q = rate * q[c] + curvature * previous_q[c];
                    let tau_v = rate * velocity[c] + curvature * previous_velocity[c];
                    new_q[c] = tau_v;
                    new_v[c] = coupling_gain * tau_coupling[c]
                        - m.omega_squared * tau_q
                        - m.damping * tau_v;
                    gap[c] += tau_v;
                }
                out[start..start + C].copy_from_slice(&new_q);
                out[columns + start..][..C].copy_from_slice(&new_v);
            }
            gaps[k + 1] = gap;
        }
    }
}

/// The width of the blocks of tangent columns [`TangentRecurrence::run`] handles at once
/// beyond 7 columns (`2N + 1` for `N` up to 3 take one block of their own width).
const COLUMN_BLOCK: usize = 8;
