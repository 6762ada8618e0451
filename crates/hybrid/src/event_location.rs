//! Root finding for events and extrema: the Illinois variant of regula falsi from the `roots`
//! crate, wrapped so that the result is a *bracket* whose ends lie on known sides of the root,
//! with separate tolerances for time and for the function value. Where the solver has the
//! switching function's values and rates at both ends of the interval (its samples), the
//! search starts from the zero of their cubic Hermite interpolant, refined by secant steps and
//! closed by two evaluations a tolerance apart; Illinois finishes what that leaves (the state
//! is then interpolated fewer times than by Illinois from the bracket ends alone).

use std::cell::Cell;

use roots::{find_root_regula_falsi, Convergency};

/// A located sign change of a function `g` that is positive at the start of its interval:
/// `g(near) > 0` (or `near` is the interval start, taken positive by convention) and
/// `g(far) <= 0`, with `near < far`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Bracket {
    /// Latest time at which `g` was seen positive.
    pub near: f64,
    /// Earliest time at which `g` was seen non-positive.
    pub far: f64,
    /// `g(near)`.
    pub near_value: f64,
    /// `g(far)`.
    pub far_value: f64,
}

impl Bracket {
    /// Whether the bracket meets either tolerance: width `<= time_tolerance`, or both ends
    /// within `value_tolerance` of zero, or an exact zero at `far`.
    pub fn converged(&self, time_tolerance: f64, value_tolerance: f64) -> bool {
        self.far - self.near <= time_tolerance
            || self.far_value == 0.0
            || (self.near_value <= value_tolerance && self.far_value >= -value_tolerance)
    }
}

/// Convergence test handed to `roots`: reads the tracked bracket rather than the single values
/// the crate passes, so that time and value are judged separately.
struct BracketConvergency<'a> {
    near: &'a Cell<(f64, f64)>,
    far: &'a Cell<(f64, f64)>,
    time_tolerance: f64,
    value_tolerance: f64,
    max_iterations: usize,
}

impl BracketConvergency<'_> {
    fn bracket(&self) -> Bracket {
        let (near, near_value) = self.near.get();
        let (far, far_value) = self.far.get();
        Bracket {
            near,
            far,
            near_value,
            far_value,
        }
    }
}

impl Convergency<f64> for BracketConvergency<'_> {
    fn is_root_found(&mut self, _y: f64) -> bool {
        let b = self.bracket();
        b.far_value == 0.0
            || (b.near_value <= self.value_tolerance && b.far_value >= -self.value_tolerance)
    }
    fn is_converged(&mut self, x1: f64, x2: f64) -> bool {
        (x1 - x2).abs() <= self.time_tolerance
            || self
                .bracket()
                .converged(self.time_tolerance, self.value_tolerance)
    }
    fn is_iteration_limit_reached(&mut self, iter: usize) -> bool {
        iter >= self.max_iterations
    }
}

/// A first estimate of a root for [`locate_sign_change`]: a time inside the interval and the
/// slope of `g` expected there (negative: `g` goes from positive to non-positive).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RootGuess {
    /// The estimated root.
    pub t: f64,
    /// The estimated `dg/dt` near it.
    pub slope: f64,
}

/// The cubic Hermite interpolant of a function on `[a, b]` from its values and rates at both
/// ends, in the power basis of `s = (t - a) / (b - a)`: `c0 + c1 s + c2 s^2 + c3 s^3`.
pub(crate) struct CubicHermite {
    a: f64,
    width: f64,
    c: [f64; 4],
}

impl CubicHermite {
    /// The interpolant of `(t, value, rate)` at `a` and at `b`.
    pub(crate) fn new(
        (a, value_a, rate_a): (f64, f64, f64),
        (b, value_b, rate_b): (f64, f64, f64),
    ) -> Self {
        let width = b - a;
        let (ra, rb) = (width * rate_a, width * rate_b);
        Self {
            a,
            width,
            c: [
                value_a,
                ra,
                3.0 * (value_b - value_a) - 2.0 * ra - rb,
                2.0 * (value_a - value_b) + ra + rb,
            ],
        }
    }

    /// `d^k H / ds^k` at `s` for `k` in `0..=2` (`k = 0`: the interpolant's value).
    pub(crate) fn derivative(&self, k: usize, s: f64) -> f64 {
        let [c0, c1, c2, c3] = self.c;
        match k {
            0 => c0 + s * (c1 + s * (c2 + s * c3)),
            1 => c1 + s * (2.0 * c2 + s * 3.0 * c3),
            _ => 2.0 * c2 + 6.0 * s * c3,
        }
    }

    /// The zero of `d^k H/ds^k` (`k` 0 or 1) in `(0, 1)` reached by Newton's method from `s0`,
    /// as a guess for the zero of `sign d^k h/dt^k` (time and slope in time units).
    fn newton_zero(&self, k: usize, mut s: f64, sign: f64) -> Option<RootGuess> {
        for _ in 0..NEWTON_ITERATIONS {
            let step = self.derivative(k, s) / self.derivative(k + 1, s);
            s -= step;
            if !(s > 0.0 && s < 1.0) {
                return None;
            }
            if step.abs() <= 4.0 * f64::EPSILON {
                break;
            }
        }
        let slope = sign * self.derivative(k + 1, s) / self.width.powi(k as i32 + 1);
        (slope < 0.0 && slope.is_finite()).then_some(RootGuess {
            t: self.a + s * self.width,
            slope,
        })
    }
}

/// Secant steps on `g` itself after the guess's Newton step, before the bracket is closed
/// around the estimate.
const SECANT_STEPS: usize = 2;

/// Newton iterations on an interpolating cubic (each a handful of operations).
const NEWTON_ITERATIONS: usize = 6;

/// A guess for the zero of `g = sign h` on `[a, b]` from the values and rates of `h` at both
/// ends (`sign h` positive at `a`, non-positive at `b`): the zero of their cubic Hermite
/// interpolant, whose error is of order `(b - a)^4`.
pub(crate) fn crossing_guess(
    start: (f64, f64, f64),
    end: (f64, f64, f64),
    sign: f64,
) -> Option<RootGuess> {
    let cubic = CubicHermite::new(start, end);
    let s0 = start.1 / (start.1 - end.1);
    cubic.newton_zero(0, s0, sign)
}

/// A guess for the zero of `g = sign dh/dt` on `[a, b]` (an extremum of `h`) from the values
/// and rates of `h` at both ends: the zero of the derivative of their cubic Hermite
/// interpolant.
pub(crate) fn extremum_guess(
    start: (f64, f64, f64),
    end: (f64, f64, f64),
    sign: f64,
) -> Option<RootGuess> {
    let cubic = CubicHermite::new(start, end);
    let s0 = start.2 / (start.2 - end.2);
    cubic.newton_zero(1, s0, sign)
}

/// The start of a bracket on which `g = side h_k` is monotone, for the first crossing out of
/// a mode between `start = (a, g(a) >= 0)` and `b` (`g(b) < 0`), along an interpolant that
/// gives `g` and its rate `g'` at any time (`point(t) = (g, g')`). Where `g` does not rise at
/// `a`, `start` itself. Where it rises (`g'(a) > 0`: the state moves into the mode, as on the
/// surface right after the event that entered it), the crossing lies past the maximum of `g`,
/// the zero of `g'` between `a` and `b`, located to `time_tolerance`; that maximum is the
/// start, or `None` where the interpolant does not show one excursion into the mode (`g'(b) >=
/// 0`: `g` rises again, or never fell; or `g <= 0` at the zero of `g'`).
///
/// [`locate_sign_change`] from `a` itself would search a bracket holding the maximum, and from
/// a start on the surface (`g(a)` zero or a rounding error) its first secant lands next to `a`,
/// where the rounding of `g` decides the sign: a crossing out was found one rounding step after
/// the onset, and the step that was to land on it could not advance time.
pub(crate) fn turnaround(
    start: (f64, f64),
    b: f64,
    point: &mut dyn FnMut(f64) -> (f64, f64),
    time_tolerance: f64,
) -> Option<(f64, f64)> {
    let (a, _) = start;
    let rate_a = point(a).1;
    let rising = rate_a > 0.0;
    if !rising {
        return Some(start);
    }
    let rate_b = point(b).1;
    let falls = rate_b < 0.0;
    if !falls {
        return None;
    }
    let mut rate = |t: f64| point(t).1;
    let top = locate_sign_change(a, rate_a, b, rate_b, &mut rate, time_tolerance, 0.0, None);
    // The higher end of the bracket (`far` where it is an exact zero of `g'`).
    let (near, far) = ((top.near, point(top.near).0), (top.far, point(top.far).0));
    let highest = if far.1 > near.1 { far } else { near };
    (highest.1 > 0.0).then_some(highest)
}

/// Locate the first sign change of `g` on `[a, b]` where `g(a) = g_a > 0` (supplied, not
/// evaluated: at the start of a step the side is fixed by the mode) and `g(b) = g_b <= 0`.
///
/// With a `guess`, `g` is first evaluated there, then at the Newton step from it and at up to
/// [`SECANT_STEPS`] secant steps (while they move by more than the tolerance), and then on
/// both sides of the last estimate, `0.45` time tolerances away: with a guess close enough,
/// that is the bracket.
/// Then, on the tightest bracket found, Illinois regula falsi
/// (`roots::find_root_regula_falsi`) while tracking the tightest bracket among all
/// evaluations, then bisection if the iteration limit was reached before either tolerance.
/// Returns a bracket meeting [`Bracket::converged`] or as narrow as floating point allows.
/// `g` must be monotone on `[a, b]` for the root to be the only one.
#[allow(clippy::too_many_arguments)]
pub(crate) fn locate_sign_change(
    a: f64,
    g_a: f64,
    b: f64,
    g_b: f64,
    g: &mut dyn FnMut(f64) -> f64,
    time_tolerance: f64,
    value_tolerance: f64,
    guess: Option<RootGuess>,
) -> Bracket {
    let near = Cell::new((a, g_a.max(f64::MIN_POSITIVE)));
    let far = Cell::new((b, g_b));
    let initial = Bracket {
        near: a,
        far: b,
        near_value: near.get().1,
        far_value: g_b,
    };
    if initial.converged(time_tolerance, value_tolerance) {
        return initial;
    }
    {
        let mut tracked = |t: f64| -> f64 {
            let y = if t == near.get().0 {
                near.get().1
            } else if t == far.get().0 {
                far.get().1
            } else {
                g(t)
            };
            if y > 0.0 {
                if t > near.get().0 && t < far.get().0 {
                    near.set((t, y));
                }
            } else if t < far.get().0 && t > near.get().0 {
                far.set((t, y));
            }
            y
        };
        let mut convergency = BracketConvergency {
            near: &near,
            far: &far,
            time_tolerance,
            value_tolerance,
            max_iterations: 60,
        };
        let inside = |t: f64| t > near.get().0 && t < far.get().0;
        if let Some(guess) = guess.filter(|guess| inside(guess.t) && guess.slope < 0.0) {
            let half = 0.45 * time_tolerance;
            let (mut t, mut value) = (guess.t, tracked(guess.t));
            let mut root = t - value / guess.slope;
            for _ in 0..SECANT_STEPS {
                if (root - t).abs() <= half || !inside(root) {
                    break;
                }
                let next = tracked(root);
                let slope = (next - value) / (root - t);
                if !(slope < 0.0 && slope.is_finite()) {
                    break;
                }
                (t, value) = (root, next);
                root = t - value / slope;
            }
            for t in [root - half, root + half] {
                if inside(t) {
                    tracked(t);
                }
            }
        }
        if !convergency
            .bracket()
            .converged(time_tolerance, value_tolerance)
        {
            // The result is read from the tracked bracket; the crate's own return value (a
            // point on an unknown side, or a non-convergence report) is not needed.
            let (start, end) = (near.get().0, far.get().0);
            let _ = find_root_regula_falsi(start, end, &mut tracked, &mut convergency);
        }
    }
    let mut bracket = Bracket {
        near: near.get().0,
        far: far.get().0,
        near_value: near.get().1,
        far_value: far.get().1,
    };
    while !bracket.converged(time_tolerance, value_tolerance) {
        let mid = bracket.near + 0.5 * (bracket.far - bracket.near);
        if mid <= bracket.near || mid >= bracket.far {
            break;
        }
        let y = g(mid);
        if y > 0.0 {
            bracket.near = mid;
            bracket.near_value = y;
        } else {
            bracket.far = mid;
            bracket.far_value = y;
        }
    }
    bracket
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `g(t) = cos(t)` from 0 to 3 crosses zero at pi/2: the bracket must straddle pi/2 with
    /// width below the time tolerance (the value tolerance is set to 0 so only time counts).
    #[test]
    fn brackets_cosine_root() {
        let mut g = |t: f64| t.cos();
        let b = locate_sign_change(0.0, 1.0, 3.0, 3.0f64.cos(), &mut g, 1e-14, 0.0, None);
        let root = std::f64::consts::FRAC_PI_2;
        assert!(b.near <= root + 1e-15 && b.far >= root - 1e-15, "{b:?}");
        assert!(b.far - b.near <= 1e-14);
        assert!(b.near_value > 0.0 && b.far_value <= 0.0);
    }

    /// From a start on the surface moving into the mode, `g = t (1 - t)` on `[0, 2]`: the
    /// bracket starts at the maximum `t = 1/2` (`g = 1/4`), and the crossing out located from
    /// there is `t = 1`, not the start's own zero. Where `g` falls at the start it is the start;
    /// where `g` rises again at the end (`t (1 - t) (2 - t)` on `[0, 1.9]`: a maximum and a
    /// minimum, more than one monotone bracket holds) there is none.
    #[test]
    fn turnaround_starts_the_bracket_at_the_maximum() {
        let mut point = |t: f64| (t * (1.0 - t), 1.0 - 2.0 * t);
        let (top, value) = turnaround((0.0, 0.0), 2.0, &mut point, 1e-14).expect("a maximum");
        assert!(
            (top - 0.5).abs() < 1e-14 && (value - 0.25).abs() < 1e-15,
            "{top} {value}"
        );
        let mut g = |t: f64| t * (1.0 - t);
        let crossing = locate_sign_change(top, value, 2.0, -2.0, &mut g, 1e-14, 0.0, None);
        assert!((crossing.far - 1.0).abs() <= 1e-14, "{crossing:?}");
        let mut falling = |t: f64| (1.0 - t, -1.0);
        assert_eq!(
            turnaround((0.0, 1.0), 2.0, &mut falling, 1e-14),
            Some((0.0, 1.0))
        );
        let mut cubic = |t: f64| (t * (1.0 - t) * (2.0 - t), 2.0 - 6.0 * t + 3.0 * t * t);
        assert_eq!(turnaround((0.0, 0.0), 1.9, &mut cubic, 1e-14), None);
    }

    /// With the guesses from the ends' values and rates (a crossing of `cos t` on
    /// `[1.5, 1.6]`, an extremum of `cos t` on `[3.1, 3.2]` where its rate `-sin t` changes
    /// sign at pi: intervals of a sixtieth of a period, as between a solver's samples), the
    /// brackets are those found without a guess, to the tolerance, on the right sides, and
    /// cost no more evaluations (fewer in all).
    #[test]
    fn guesses_bracket_the_same_roots_with_fewer_evaluations() {
        let tolerance = 1e-13;
        let locate = |a: f64, b: f64, h: &dyn Fn(f64) -> f64, guess| {
            let mut count = 0;
            let mut g = |t: f64| {
                count += 1;
                h(t)
            };
            let bracket = locate_sign_change(a, h(a), b, h(b), &mut g, tolerance, 0.0, guess);
            (bracket, count)
        };
        let end = |t: f64| (t, t.cos(), -t.sin());
        // Crossing of cos: g = cos (positive at 1.5, negative at 1.6), root pi/2.
        let guess = crossing_guess(end(1.5), end(1.6), 1.0);
        let root = std::f64::consts::FRAC_PI_2;
        /// Interval, function, guess and root.
        type Case<'a> = (f64, f64, &'a dyn Fn(f64) -> f64, Option<RootGuess>, f64);
        let cases: [Case; 2] = [
            (1.5, 1.6, &|t: f64| t.cos(), guess, root),
            // Minimum of cos at pi: g = -(rate) = sin t, positive before pi.
            (
                3.1,
                3.2,
                &|t: f64| t.sin(),
                extremum_guess(end(3.1), end(3.2), -1.0),
                std::f64::consts::PI,
            ),
        ];
        let mut totals = (0, 0);
        for (a, b, h, guess, root) in cases {
            assert!(guess.is_some(), "a guess on [{a}, {b}]");
            let (plain, plain_count) = locate(a, b, h, None);
            let (guided, guided_count) = locate(a, b, h, guess);
            for bracket in [plain, guided] {
                assert!(bracket.near <= root + 1e-15 && bracket.far >= root - 1e-15);
                assert!(bracket.far - bracket.near <= tolerance, "{bracket:?}");
                assert!(bracket.near_value > 0.0 && bracket.far_value <= 0.0);
            }
            eprintln!("[{a}, {b}]: {plain_count} evaluations plain, {guided_count} guided");
            assert!(
                guided_count <= plain_count,
                "{guided_count} > {plain_count}"
            );
            totals = (totals.0 + plain_count, totals.1 + guided_count);
        }
        // Measured: 5 -> 3 for the crossing, 4 -> 4 for the extremum.
        assert!(totals.1 < totals.0, "{totals:?}");
    }

    /// A function that is exactly zero on a whole interval: the far end must be a point with
    /// `g <= 0`, and the search must terminate.
    #[test]
    fn flat_zero_terminates() {
        let mut g = |t: f64| if t < 1.0 { 1.0 - t } else { 0.0 };
        let b = locate_sign_change(0.0, 1.0, 2.0, 0.0, &mut g, 1e-14, 0.0, None);
        assert!(b.far_value <= 0.0 && b.far <= 2.0);
    }
}
