//! The modified Bessel functions of the second kind `K_0(z)` and `K_1(z)` of a complex argument
//! with `Re z > 0`, which Sader's hydrodynamic function of a circular cylinder needs
//! ([`crate::hydrodynamic`]).
//!
//! # Method
//!
//! The integral representation (Abramowitz & Stegun 9.6.24, DLMF 10.32.9)
//!
//! ```text
//! K_nu(z) = int_0^inf exp(-z cosh t) cosh(nu t) dt,      Re z > 0,
//! ```
//!
//! is evaluated by the trapezoidal rule with step `h`. The integrand is an even entire function
//! of `t`, so the rule's error is `O(exp(-2 pi d / h))` for any strip `|Im t| < d` in which the
//! integrand stays bounded (Trefethen & Weideman, SIAM Review 56, 385 (2014)). For
//! `z = r e^{i theta}`, `Re[z cosh(t + i s)] = r [cos theta cosh t cos s - sin theta sinh t sin s]`,
//! which stays positive for large `t` while `cos(theta + s) > 0`: with `|theta| <= pi/4`
//! (Sader's arguments have `theta = -pi/4` exactly) the strip `|s| < pi/4` is safe, and
//! `h = 1/64` makes the rule's error `~exp(-2 pi (pi/4) 64) = e^{-316}`, far below rounding.
//! The sum stops once `exp(-Re(z) cosh t) cosh(nu t)` has fallen below `1e-18` of the sum's
//! size. One evaluation costs a few hundred complex exponentials (`|z|` from 1e-3 to 100).
//! The tests compare it with the ascending series (A&S 9.6.13, 9.6.11) at small `|z|` and the
//! asymptotic expansion (A&S 9.7.2) at large `|z|`.

use num_complex::Complex64;

/// The trapezoidal step, dimensionless (module documentation: error `~e^{-316}` for
/// `|arg z| <= pi/4`).
const STEP: f64 = 1.0 / 64.0;
/// The relative size of the last term kept.
const TAIL: f64 = 1e-18;
/// The largest number of trapezoidal nodes: `t` up to 64, where `exp(-Re(z) cosh t)` underflows
/// for every `Re z > 1e-26`.
const MAX_NODES: usize = 64 * 64;

/// `[K_0(z), K_1(z)]`, the modified Bessel functions of the second kind of orders 0 and 1, for
/// `Re z > 0` and `|arg z| <= pi/4` (module documentation). Returns NaN for other arguments.
#[must_use]
pub fn bessel_k0_k1(z: Complex64) -> [Complex64; 2] {
    if !(z.re > 0.0 && z.im.abs() <= z.re * (1.0 + 1e-12) && z.norm().is_finite()) {
        let nan = Complex64::new(f64::NAN, f64::NAN);
        return [nan, nan];
    }
    // t = 0 carries half weight.
    let first = (-z).exp();
    let mut k0 = 0.5 * first;
    let mut k1 = 0.5 * first;
    for node in 1..MAX_NODES {
        let t = node as f64 * STEP;
        let exponential = (-z * t.cosh()).exp();
        let term0 = exponential;
        let term1 = exponential * t.cosh();
        k0 += term0;
        k1 += term1;
        if term1.norm() <= TAIL * k1.norm() && term0.norm() <= TAIL * k0.norm() {
            break;
        }
    }
    [k0 * STEP, k1 * STEP]
}
