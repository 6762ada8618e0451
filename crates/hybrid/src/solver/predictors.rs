//! Crossing prediction before a Runge-Kutta step, from the state alone.

use crate::system::{side_sign, HybridSystem, Mode};

use super::tuning::{PREDICTION_DIFFERENCE, RESOLVABLE_EPSILONS};

/// Whether a crossing `distance` ahead of `t0` is far enough to land a step on:
/// `1024 eps |t0|`, a few hundred rounding steps of time. Nearer, a step cannot hold it
/// (a Zeno accumulation, or a state on the surface whose rounding puts the crossing next to
/// it): the step is left to the controller, and a crossing inside the accepted step to the
/// event location.
pub(super) fn resolvable(distance: f64, t0: f64) -> bool {
    distance > RESOLVABLE_EPSILONS * f64::EPSILON * t0.abs()
}

/// The predicted time from `t0` to the first crossing of any switching surface, with that
/// surface, from the quadratic `g + r s + a s^2 / 2` in the current state (`g = |h_k|`, `r`
/// its rate, `a` the rate's derivative along the field by a forward difference over
/// `1e-4 h`), if one is predicted. `velocity` is `f(t0, x)`.
#[allow(clippy::too_many_arguments)]
pub(super) fn predict_crossing<S: HybridSystem + ?Sized>(
    system: &S,
    velocity: &[f64],
    x_ahead: &mut [f64],
    x: &[f64],
    mode: Mode,
    surfaces: usize,
    t0: f64,
    h: f64,
) -> Option<(f64, usize)> {
    let delta = PREDICTION_DIFFERENCE * h;
    if !(delta > 0.0 && delta.is_finite()) {
        return None;
    }
    for ((ahead, &xc), &v) in x_ahead.iter_mut().zip(x).zip(velocity) {
        *ahead = xc + delta * v;
    }
    let mut earliest: Option<(f64, usize)> = None;
    for k in 0..surfaces {
        let side = side_sign(mode, k);
        let g = (side * system.switching(k, t0, x)).max(0.0);
        let r = side * system.switching_rate(k, mode, t0, x);
        let r_ahead = side * system.switching_rate(k, mode, t0 + delta, x_ahead);
        let a = (r_ahead - r) / delta;
        if let Some(s) = first_positive_root(0.5 * a, r, g) {
            if earliest.is_none_or(|(e, _)| s < e) {
                earliest = Some((s, k));
            }
        }
    }
    earliest
}

/// The smallest positive root of `a s^2 + b s + c` (`c >= 0`), if any (finite values only).
pub(super) fn first_positive_root(a: f64, b: f64, c: f64) -> Option<f64> {
    if !(a.is_finite() && b.is_finite() && c.is_finite()) {
        return None;
    }
    let root = if a == 0.0 {
        if b >= 0.0 {
            return None;
        }
        -c / b
    } else {
        let discriminant = b * b - 4.0 * a * c;
        if discriminant < 0.0 {
            return None;
        }
        // Stable form: q = -(b + sign(b) sqrt(D)) / 2; roots q / a and c / q.
        let q = -0.5 * (b + b.signum() * discriminant.sqrt());
        let roots = [q / a, if q != 0.0 { c / q } else { f64::NAN }];
        roots
            .into_iter()
            .filter(|r| *r > 0.0)
            .min_by(f64::total_cmp)?
    };
    (root > 0.0 && root.is_finite()).then_some(root)
}
