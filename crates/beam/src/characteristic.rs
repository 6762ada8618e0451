//! The characteristic (frequency) equation of a clamped-free Euler-Bernoulli beam carrying a
//! point mass at its free end, and its roots.
//!
//! # Derivation
//!
//! A uniform beam of length `L`, bending stiffness `EI` and mass per length `rho A`
//! (`m_c = rho A L`) carries at `x = L` a point mass `m_tip` **without rotary inertia** (the tip
//! is treated as a particle: its moment of inertia about the beam's end is neglected, which is
//! accurate while the tip's size is small compared with the beam's wavelength). In
//! `xi = x / L` a free vibration `w(x, t) = phi(xi) cos(w t)` obeys
//!
//! ```text
//! phi'''' = b^4 phi,                    b^4 = rho A w^2 L^4 / (EI)
//! phi(0) = phi'(0) = 0                  (clamped base)
//! phi''(1) = 0                          (no moment at the tip: no rotary inertia)
//! phi'''(1) = -mu b^4 phi(1)            (shear balances the tip mass' inertia), mu = m_tip / m_c
//! ```
//!
//! The last condition follows from Hamilton's principle: the boundary term of the strain energy
//! `-EI w'''(L) dw(L)` balances the tip mass' inertia `m_tip w_tt(L) dw(L)`, so
//! `EI w'''(L) = m_tip w_tt(L) = -m_tip w^2 w(L)`, which is the line above after scaling.
//! With `phi = A (cosh b xi - cos b xi) + B (sinh b xi - sin b xi)` (clamped conditions built in)
//! the two tip conditions give a 2 x 2 system whose determinant, halved, is
//!
//! ```text
//! f(b) = 1 + cos b cosh b + mu b (cos b sinh b - sin b cosh b) = 0.
//! ```
//!
//! For `mu = 0` this is the free cantilever's `1 + cos b cosh b = 0`; for small `b`,
//! `f = 2 - (1/6 + 2 mu / 3) b^4 + O(b^8)`, so a heavy tip mass gives `b_1^4 -> 3 / mu`, the
//! massless spring `k = 3 EI / L^3` carrying `m_tip` (Rayleigh's refinement, with the static
//! shape, is `b_1^4 <= 3 / (mu + 33/140)`).
//!
//! # Numerics
//!
//! `f` grows like `cosh b` (overflow past `b ~ 710`, and large cancellation well before), so the
//! code solves the equivalent scaled equation `g(b) = f(b) / cosh b`, which is bounded for all `b`.
//! At `b = k pi`, `g = (-1)^k (1 + mu k pi tanh(k pi)) + sech(k pi)`, whose sign is `(-1)^k`
//! for every `k >= 1` and every `mu >= 0` (and `g(0) = 2 > 0`): no root ever sits on a multiple
//! of `pi`. Every interval `((n-1) pi, n pi)` holds a root; it holds exactly one because the
//! eigenvalues move continuously with `mu` without crossing a multiple of `pi` and there is
//! exactly one per interval at `mu = 0` (the test suite also scans for extra sign changes).
//! So the `n`-th root is found by Brent's method on the bracket `[(n-1) pi, n pi]`.

use roots::{find_root_brent, Convergency};

use crate::error::BeamError;

/// The characteristic function divided by `cosh b`:
/// `g(b, mu) = sech b + cos b + mu b (cos b tanh b - sin b)` (dimensionless).
///
/// Its roots are the eigenvalues `b_n = (rho A w_n^2 L^4 / EI)^{1/4}` of the clamped-free
/// Euler-Bernoulli cantilever with a point tip mass ratio `mu = m_tip / m_c` and no tip rotary
/// inertia: `1 + cos b cosh b + mu b (cos b sinh b - sin b cosh b) = 0` (module documentation).
/// The scaling by `cosh b` keeps it bounded and free of overflow for every `b >= 0`.
#[must_use]
pub fn characteristic_function(b: f64, tip_mass_ratio: f64) -> f64 {
    // sech b = 2 e^{-b} / (1 + e^{-2b}) avoids overflowing cosh for large b.
    let decay = (-b).exp();
    let sech = 2.0 * decay / (1.0 + decay * decay);
    let (sin, cos) = b.sin_cos();
    sech + cos + tip_mass_ratio * b * (cos * b.tanh() - sin)
}

/// The bracket `[(n-1) pi, n pi]` that holds exactly one root, the `n`-th eigenvalue `b_n`
/// (dimensionless), of [`characteristic_function`] for any tip mass ratio `mu >= 0`
/// (module documentation). `index` counts from 1; index 0 gives the degenerate `[-pi, 0]`.
#[must_use]
pub fn eigenvalue_bracket(index: usize) -> (f64, f64) {
    let n = index as f64;
    ((n - 1.0) * std::f64::consts::PI, n * std::f64::consts::PI)
}

/// Stopping rule for Brent's method with separate tolerances on `b` (relative) and on `g`.
struct EigenvalueConvergence {
    /// Absolute tolerance on the scaled characteristic function (rounding level of `g`).
    residual: f64,
    /// Relative tolerance on `b`.
    relative_step: f64,
    /// Iteration cap.
    max_iterations: usize,
}

impl Convergency<f64> for EigenvalueConvergence {
    fn is_root_found(&mut self, y: f64) -> bool {
        y.abs() <= self.residual
    }
    fn is_converged(&mut self, x1: f64, x2: f64) -> bool {
        (x1 - x2).abs() <= self.relative_step * x1.abs().max(x2.abs())
    }
    fn is_iteration_limit_reached(&mut self, iter: usize) -> bool {
        iter >= self.max_iterations
    }
}

/// The `index`-th root `b_n` (1-based, dimensionless) of the characteristic equation
/// `1 + cos b cosh b + mu b (cos b sinh b - sin b cosh b) = 0`, found by Brent's method (the
/// `roots` crate) on the bracket [`eigenvalue_bracket`]. The natural frequency in vacuum is
/// `w_n = b_n^2 sqrt(EI / (rho A L^4))`.
///
/// The arguments are not range-checked here ([`crate::Beam`] does that); the result is checked:
/// after Brent's method and a secant polish, `b` is within about one ulp of the exact root
/// (its residual `|g(b)|` is at most `16 eps (2 + mu b) (1 + b)`, the rounding level of `g`
/// plus its slope times the spacing of doubles near `b`).
///
/// # Errors
/// [`BeamError::EigenvalueNotFound`] if the root finder fails or returns a point whose residual
/// is not at rounding level (for instance for a non-finite or negative `tip_mass_ratio`).
pub fn eigenvalue(index: usize, tip_mass_ratio: f64) -> Result<f64, BeamError> {
    let (lower, upper) = eigenvalue_bracket(index);
    let not_found = |reason: String| BeamError::EigenvalueNotFound {
        index,
        tip_mass_ratio,
        lower,
        upper,
        reason,
    };
    if index == 0 {
        return Err(not_found("mode indices count from 1".to_string()));
    }
    // Attainable residual: g's terms and its slope are O(1 + mu b), so rounding of g gives
    // ~ eps (2 + mu b) and the spacing of doubles near b (eps b) gives ~ eps b (2 + mu b).
    let residual = 4.0 * f64::EPSILON * (2.0 + tip_mass_ratio * upper) * (1.0 + upper);
    let mut convergence = EigenvalueConvergence {
        residual,
        relative_step: 4.0 * f64::EPSILON,
        max_iterations: 200,
    };
    let g = |b: f64| characteristic_function(b, tip_mass_ratio);
    let root = find_root_brent(lower, upper, g, &mut convergence)
        .map_err(|error| not_found(format!("Brent's method: {error}")))?;
    // The crate's Brent may stop on the bracket width and return the previous iterate, a few
    // ulps off. Higher modes normalised to unit tip deflection amplify an error in b by about
    // |phi'(1)| ~ mu b^2 (their tip barely moves), so polish to the nearest representable root.
    let root = polish(root, lower, upper, g);
    // Accept the point only if it is a root to rounding level.
    let check = g(root);
    let accepted = root > lower && root < upper && check.abs() <= 4.0 * residual;
    if !accepted {
        return Err(not_found(format!(
            "returned b = {root} with residual {check:e} (tolerance {:e})",
            4.0 * residual
        )));
    }
    Ok(root)
}

/// Refines a bracketed root `b` of `g` by up to four secant steps through `b -+ h`
/// (`h = 64` ulps of `b`: large enough for the difference quotient to rise above the rounding
/// noise of `g`, small enough to be exact for a function that is linear on that scale),
/// keeping a step only while it reduces `|g|` and stays inside `[lower, upper]`.
fn polish(root: f64, lower: f64, upper: f64, g: impl Fn(f64) -> f64) -> f64 {
    let mut best = root;
    let mut best_value = g(best).abs();
    for _ in 0..4 {
        if best_value == 0.0 {
            break;
        }
        let h = 64.0 * f64::EPSILON * best.abs().max(1.0);
        let slope = (g(best + h) - g(best - h)) / (2.0 * h);
        let candidate = best - g(best) / slope;
        if !(candidate > lower && candidate < upper) {
            break;
        }
        let value = g(candidate).abs();
        if value < best_value {
            best = candidate;
            best_value = value;
        } else {
            break;
        }
    }
    best
}
