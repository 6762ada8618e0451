//! Root finding for events and extrema: the Illinois variant of regula falsi from the `roots`
//! crate, wrapped so that the result is a *bracket* whose ends lie on known sides of the root,
//! with separate tolerances for time and for the function value.

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

/// Locate the first sign change of `g` on `[a, b]` where `g(a) = g_a > 0` (supplied, not
/// evaluated: at the start of a step the side is fixed by the mode) and `g(b) = g_b <= 0`.
///
/// Runs Illinois regula falsi (`roots::find_root_regula_falsi`) while tracking the tightest
/// bracket among all evaluations, then bisects if the iteration limit was reached before
/// either tolerance. Returns a bracket meeting [`Bracket::converged`] or as narrow as floating
/// point allows. `g` must be monotone on `[a, b]` for the root to be the only one.
pub(crate) fn locate_sign_change(
    a: f64,
    g_a: f64,
    b: f64,
    g_b: f64,
    g: &mut dyn FnMut(f64) -> f64,
    time_tolerance: f64,
    value_tolerance: f64,
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
            let y = if t == a {
                near.get().1
            } else if t == b {
                g_b
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
        // The result is read from the tracked bracket; the crate's own return value (a point
        // on an unknown side, or a non-convergence report) is not needed.
        let _ = find_root_regula_falsi(a, b, &mut tracked, &mut convergency);
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
        let b = locate_sign_change(0.0, 1.0, 3.0, 3.0f64.cos(), &mut g, 1e-14, 0.0);
        let root = std::f64::consts::FRAC_PI_2;
        assert!(b.near <= root + 1e-15 && b.far >= root - 1e-15, "{b:?}");
        assert!(b.far - b.near <= 1e-14);
        assert!(b.near_value > 0.0 && b.far_value <= 0.0);
    }

    /// A function that is exactly zero on a whole interval: the far end must be a point with
    /// `g <= 0`, and the search must terminate.
    #[test]
    fn flat_zero_terminates() {
        let mut g = |t: f64| if t < 1.0 { 1.0 - t } else { 0.0 };
        let b = locate_sign_change(0.0, 1.0, 2.0, 0.0, &mut g, 1e-14, 0.0);
        assert!(b.far_value <= 0.0 && b.far <= 2.0);
    }
}
